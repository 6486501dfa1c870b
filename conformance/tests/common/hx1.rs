//! The independent slaves as processes on a pseudo-terminal, and their data sheets as
//! profiles: HX-1 (`tests/independent/hx1_slave.py`, written from 000), HX-L
//! (`hxl_slave.py`, a legacy-edition slave written from 002), HX-3 (`hx3_slave.py`,
//! the blind trial's slave, written from 000 and the user documents) and HX-4
//! (`hx4_slave.py`, the second blind trial's, a legacy-edition slave written from 002,
//! 000 and the user documents).

use hiperface_conformance::port::{self, PortSpec};
use hiperface_model::{Grading, Profile};
use hiperface_suite::profile_file;
use hiperface_suite::slave::{self, Options, Report};
use hiperface_suite::verdict::CaseVerdict;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("independent")
}

pub fn profile() -> Profile {
    profile_file::load(&dir().join("hx1.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// HX-3's data sheet.
pub fn hx3_profile() -> Profile {
    profile_file::load(&dir().join("hx3.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// HX-4's data sheet.
pub fn hx4_profile() -> Profile {
    profile_file::load(&dir().join("hx4.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// HX-L's data sheet, with its stored settings byte set to `settings`.
pub fn legacy_profile(settings: u8) -> Profile {
    let mut p = profile_file::load(&dir().join("hxl.toml")).unwrap_or_else(|e| panic!("{e}"));
    p.settings = hiperface_model::UartSettings::decode(settings).expect("a valid settings byte");
    p
}

/// A running HX-1; stopped (stdin closed, killed) on drop.
pub struct Hx1 {
    child: Child,
    pub path: String,
    /// Where HX-1 notes each reply the machine made it late with (`--late-log`).
    late_log: Option<tempfile::NamedTempFile>,
}

impl Hx1 {
    /// Start HX-1 (a test that needs it is ignored where the build found no python3),
    /// at a real-time priority where permitted: a device has a processor of its own, and
    /// a peer starved by the machine's other work is really late on the wire, which
    /// the harness rightly FAILs (seen: late-reply's and store-read-only's replies 14 to
    /// 16 ms late in 1 of 3 runs with three busy loops on the two cores).
    pub fn start(args: &[&str]) -> Hx1 {
        Hx1::start_noting_lateness("hx1_slave.py", args)
    }

    /// Start HX-3, as HX-1 (its late replies noted the same way).
    pub fn start_hx3(args: &[&str]) -> Hx1 {
        Hx1::start_noting_lateness("hx3_slave.py", args)
    }

    fn start_noting_lateness(program: &str, args: &[&str]) -> Hx1 {
        let late_log = tempfile::NamedTempFile::new().expect("a file for the slave's lateness");
        let log = late_log.path().to_str().expect("a UTF-8 temporary path").to_string();
        let args: Vec<&str> = args.iter().copied().chain(["--late-log", log.as_str()]).collect();
        let mut slave = Hx1::start_program(program, &args, Duration::from_millis(250));
        slave.late_log = Some(late_log);
        slave
    }

    /// The replies the machine made HX-1 late with (its own clock's word, more than
    /// 3 ms: woken after a reply's time or held off a processor), empty where it kept
    /// time. A run with any is no sample of HX-1's behaviour: a device has a processor
    /// of its own. Always empty for HX-L, which does not keep the log.
    fn late_replies(&self) -> Vec<String> {
        let Some(log) = &self.late_log else { return Vec::new() };
        std::fs::read_to_string(log.path()).unwrap_or_default().lines().map(str::to_string).collect()
    }

    /// Whether HX-1 kept time throughout (see [`Hx1::late_replies`]); says so on
    /// standard error where it did not.
    pub fn kept_time(&self) -> bool {
        let late = self.late_replies();
        if !late.is_empty() {
            eprintln!("HX-1 was made late by the machine ({} replies): {late:?}; the run is taken again", late.len());
        }
        late.is_empty()
    }

    /// Start HX-L, the legacy-edition slave, past its power-up: 002 keeps the default
    /// settings for about a second before the stored ones (002:57h).
    pub fn start_legacy(args: &[&str]) -> Hx1 {
        Hx1::start_program("hxl_slave.py", args, Duration::from_millis(1200))
    }

    /// Start HX-4, the second blind trial's legacy-edition slave, past its power-up as
    /// HX-L (002's default window of about a second).
    pub fn start_hx4(args: &[&str]) -> Hx1 {
        Hx1::start_program("hx4_slave.py", args, Duration::from_millis(1200))
    }

    fn start_program(program: &str, args: &[&str], power_up: Duration) -> Hx1 {
        let mut command = if super::real_time_permitted() {
            let mut c = Command::new("chrt");
            c.args(["-f", "50", "python3"]);
            c
        } else {
            Command::new("python3")
        };
        let spawned = command
            .arg(dir().join(program))
            .arg("--pty")
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn();
        let mut child = spawned.expect("python3, to run the independent slave");
        let mut path = String::new();
        BufReader::new(child.stdout.take().expect("piped")).read_line(&mut path).expect("the pty path");
        let path = path.trim().to_string();
        assert!(path.starts_with("/dev/"), "{program} did not print its pseudo-terminal: {path:?}");
        // It has just been powered on: past its initialization (000:T9, at most 200 ms)
        // and its window of default settings it is operational, as the harness
        // expects a device under test to be.
        std::thread::sleep(power_up);
        Hx1 { child, path, late_log: None }
    }
}

impl Drop for Hx1 {
    fn drop(&mut self) {
        drop(self.child.stdin.take());
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// What a user runs: every case, writes, counter and adjustment allowed, a black box.
pub fn options() -> Options {
    Options { grading: Grading::Range, ..Options::all_allowed() }
}

/// Certify `slave` against `profile` over its pseudo-terminal, opened as `certify slave
/// --port <path>` opens it (default tolerance, default timing mode); decode reproduces
/// the run: its record played back gives its verdicts.
pub fn certify_pty_as(slave: &Hx1, profile: Profile) -> Report {
    let opened =
        port::open_for_slave(&PortSpec::Path(slave.path.clone()), profile, &Default::default(), Default::default())
            .unwrap_or_else(|e| panic!("{e}"));
    let options = Options { timing: opened.default_timing.0, ..options() };
    let report = slave::run(opened.line, profile, &options, |_, _, _| {});
    super::replay::assert_replays(&report);
    report
}

/// The slave `start` starts (`name` in messages), certified over its pseudo-terminal
/// against `profile`. A run whose outcome is not `expected` is taken again where the
/// machine made the slave late in it (`Hx1::kept_time`): a device has a processor of
/// its own, and such a run is no sample of its behaviour; and where a case was left
/// UNKNOWN (the harness's own lateness kept it from seeing: no verdict on the slave).
/// One where the slave kept time and every case was graded is returned as it is, for
/// the test to fail on.
pub fn certify_faithfully(
    name: &str,
    start: impl Fn() -> Hx1,
    profile: Profile,
    expected: impl Fn(&Report) -> bool,
) -> Report {
    super::faithfully(|| {
        let slave = start();
        let r = certify_pty_as(&slave, profile);
        let expected = expected(&r);
        if !expected {
            // Shown with the test's output if it fails: what the run that was not as
            // expected gave, and whether it is taken again.
            let remarks: Vec<_> = r
                .cases
                .iter()
                .filter(|c| c.verdict != CaseVerdict::Pass)
                .map(|c| (c.id, c.verdict, &c.findings))
                .collect();
            eprintln!("{name}: not as expected: {remarks:#?}");
        }
        (a_sample(expected, &slave, &r), r)
    })
}

/// Whether the run `r` of `slave` is a sample of its behaviour: as the test `expected`,
/// or else the slave kept time (`Hx1::kept_time`) and the harness graded every case
/// (an UNKNOWN is the harness's own lateness keeping it from seeing: no verdict on the
/// slave). A run that is no sample is taken again (`common::faithfully`).
pub fn a_sample(expected: bool, slave: &Hx1, r: &Report) -> bool {
    expected || (slave.kept_time() && r.cases.iter().all(|c| c.verdict != CaseVerdict::Unknown))
}
