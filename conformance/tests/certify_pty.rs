//! The harness over real pseudo-terminals, in real time (generous bounds): the whole
//! catalogue against the simulator, and bad input of every kind.

mod common;

use hiperface_conformance::line::serial::SerialLine;
use hiperface_conformance::simulate::PtySimulator;
use hiperface_model::{profiles, UartSettings};
use hiperface_suite::line::LineError;
use hiperface_suite::slave::{self, Options};
use hiperface_suite::verdict::CaseVerdict;
use serialport::SerialPort;
use std::io::Write;
use std::process::Command;
use std::time::{Duration, Instant};

const GENEROUS_US: u64 = 25_000;

#[test]
fn the_whole_catalogue_passes_against_the_simulator_over_a_pty() {
    let _one = common::one_at_a_time();
    // TTK70 with every optional command: 67h switches the data rate on the PTY too.
    let mut profile = profiles::ttk70();
    profile.commands = hiperface_model::command::CommandSet::all_for(false);
    let (sim, port) = PtySimulator::start(profile).unwrap();
    // Real time on a shared CI machine: generous timing bounds (exact timing is
    // checked in virtual time, suite/tests/certify_defects.rs).
    let line = SerialLine::from_port(port, sim.path.clone(), profile.settings, true).with_tolerance(GENEROUS_US);
    let report = slave::run(Box::new(line), profile, &Options::all_allowed(), |_, _, _| {});
    let failed: Vec<_> =
        report.cases.iter().filter(|c| !matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable)).collect();
    assert!(failed.is_empty(), "{failed:#?}");
    assert!(report.outcome().passed());
    eprintln!("PTY run: wall {:.0} ms, on a real line {:.0} ms", report.wall_time_ms, report.line_time_ms);
}

#[test]
fn unknown_port_is_a_clear_error() {
    let e = SerialLine::open("/dev/does-not-exist-hf", UartSettings::DEFAULT).err().expect("must fail");
    assert!(matches!(e, LineError::Open { .. }));
    assert!(e.to_string().contains("/dev/does-not-exist-hf"), "{e}");
}

#[test]
fn busy_port_is_a_clear_error() {
    let (_a, b) = serialport::TTYPort::pair().unwrap();
    let path = b.name().unwrap();
    let first = SerialLine::open(&path, UartSettings::DEFAULT);
    let second = SerialLine::open(&path, UartSettings::DEFAULT);
    // Ports are opened exclusively: at least the second open is refused, with the path.
    let e = first.err().or(second.err()).expect("an exclusive port cannot be opened twice");
    assert!(e.to_string().contains(&path), "{e}");
}

#[test]
fn a_silent_device_stops_the_run_quickly_with_an_error() {
    let _one = common::one_at_a_time();
    let (_silent_end, port) = serialport::TTYPort::pair().unwrap();
    let line = SerialLine::from_port(Box::new(port), "silent".into(), UartSettings::DEFAULT, true);
    let started = Instant::now();
    let report = slave::run(Box::new(line), profiles::srs50(), &Options::all_allowed(), |_, _, _| {});
    assert!(started.elapsed() < Duration::from_secs(10), "must not hang");
    // Nothing was observed: INCOMPLETE, not a verdict on the device.
    assert_eq!(report.outcome(), hiperface_suite::verdict::Outcome::Incomplete);
    assert!(report.aborted.as_deref().is_some_and(|a| a.contains("has not answered")), "{:?}", report.aborted);
    assert_eq!(report.cases[0].verdict, CaseVerdict::Error);
    assert!(
        report.cases.iter().all(|c| c.verdict != CaseVerdict::Fail),
        "nothing is blamed on a device that is not there"
    );
    // Nothing could be read: not "restored", and no line said lost that was not.
    assert!(!report.safety.restored() && !report.safety.differs(), "{:#?}", report.safety);
    assert!(report.safety.unverified.iter().all(|u| !u.contains("lost")), "{:#?}", report.safety);
}

/// The same on the command line, as a user with nothing attached meets it (issue 56:
/// the hint 17 times on each stream and a "ratio 11.01"): the reason once per stream,
/// the cases not run named together, no ratio of a run that ended early.
#[test]
fn a_silent_device_is_said_once_on_the_command_line() {
    let _one = common::one_at_a_time();
    let (_device_end, port) = serialport::TTYPort::pair().unwrap();
    let path = port.name().unwrap();
    drop(port);
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface"))
        .args(["certify", "slave", "--port", &path, "--allow-writes"])
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(3), "{stdout}{stderr}");
    let hint = "the device has not answered any request";
    assert_eq!(stderr.matches(&format!("not run: {hint}")).count(), 1, "{stderr}");
    assert!(stderr.contains("(not run, as above)"), "{stderr}");
    assert_eq!(stdout.matches(hint).count(), 3, "the reason, the first case's and the abort line: {stdout}");
    assert!(stdout.contains("findings to read first (2):") && stdout.contains("the same in "), "{stdout}");
    assert!(stdout.contains("the run ended early") && !stdout.contains("ratio"), "{stdout}");
}

#[test]
fn the_port_gone_mid_run_leaves_a_partial_report() {
    let _one = common::one_at_a_time();
    let profile = profiles::srs50();
    let (sim, port) = PtySimulator::start(profile).unwrap();
    let line = SerialLine::from_port(port, sim.path.clone(), profile.settings, true).with_tolerance(GENEROUS_US);
    let mut sim = Some(sim);
    let started = Instant::now();
    let report = slave::run(Box::new(line), profile, &Options::all_allowed(), |i, _, _| {
        if i == 4 {
            sim.take(); // the simulator and its end of the pseudo-terminal go away
        }
    });
    assert!(started.elapsed() < Duration::from_secs(30), "must not hang");
    assert!(report.aborted.is_some(), "{:#?}", report.cases.iter().map(|c| (c.id, c.verdict)).collect::<Vec<_>>());
    let n = slave::cases::catalogue().len();
    assert_eq!(report.cases.len(), n, "every case is accounted for");
    assert!(report.cases[..4].iter().all(|c| c.verdict == CaseVerdict::Pass));
    assert!(report.cases[5..n].iter().all(|c| matches!(c.verdict, CaseVerdict::Error | CaseVerdict::NotApplicable)));
    // The safety section says what the harness could not check, and why; not a verdict.
    assert!(!report.safety.restored() && !report.safety.differs(), "{:#?}", report.safety);
    assert!(report.safety.unverified.iter().any(|n| n.contains("not read back")), "{:#?}", report.safety);
}

/// Ctrl-C while the power-up window case waits (most of a second with nothing on the
/// line): the case stops at once, the device is read back once it talks again, and the
/// certificate says what is true: restored, the case cut short, the run INCOMPLETE.
#[test]
fn an_interrupt_in_a_power_up_window_stops_at_once_and_reads_the_device_back() {
    let _one = common::one_at_a_time();
    let profile = profiles::srs50();
    let (sim, port) = PtySimulator::start(profile).unwrap();
    let line = SerialLine::from_port(port, sim.path.clone(), profile.settings, true).with_tolerance(GENEROUS_US);
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let options =
        Options { cases: Some("powerup.window".into()), interrupt: Some(flag.clone()), ..Options::all_allowed() };
    let setter = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(500));
        flag.store(true, std::sync::atomic::Ordering::Relaxed);
        Instant::now()
    });
    let mut case_ended = None;
    let report = slave::run(Box::new(line), profile, &options, |_, _, _| case_ended = Some(Instant::now()));
    let interrupted_at = setter.join().unwrap();
    let took = case_ended.unwrap().saturating_duration_since(interrupted_at);
    // 50 ms steps; generous for a shared machine.
    assert!(took < Duration::from_millis(400), "the case went on {took:?} after the interrupt");
    let case = &report.cases[0];
    assert_eq!(case.verdict, CaseVerdict::NotExercised, "{:#?}", case.findings);
    assert!(case.findings.iter().any(|f| f.message().contains("cut short")), "{:#?}", case.findings);
    assert_eq!(report.outcome(), hiperface_suite::verdict::Outcome::Incomplete);
    assert!(report.safety.restored(), "{:#?}", report.safety);
    assert_eq!(report.safety.verified.len(), 4, "{:#?}", report.safety);
}

#[test]
fn garbage_on_the_line_fails_without_hanging() {
    let _one = common::one_at_a_time();
    let (mut noisy, port) = serialport::TTYPort::pair().unwrap();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = stop.clone();
    let babbler = std::thread::spawn(move || {
        let mut x = 0x5Au8;
        while !flag.load(std::sync::atomic::Ordering::Relaxed) {
            x = x.wrapping_mul(73).wrapping_add(41);
            if noisy.write_all(&[x; 8]).is_err() {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    });
    let line = SerialLine::from_port(Box::new(port), "noisy".into(), UartSettings::DEFAULT, true);
    let options = Options { cases: Some("identity.*,position.read".into()), ..Options::default() };
    let started = Instant::now();
    let report = slave::run(Box::new(line), profiles::srs50(), &options, |_, _, _| {});
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    babbler.join().unwrap();
    assert!(started.elapsed() < Duration::from_secs(20), "must not hang");
    assert!(!report.outcome().passed());
    assert!(report.cases.iter().all(|c| c.verdict == CaseVerdict::Fail), "{:#?}", report.cases);
}

#[test]
fn cli_malformed_profile_and_unknown_port() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[timing]\ninit_ms = 300\n").unwrap();
    let exe = env!("CARGO_BIN_EXE_hiperface");
    let out = Command::new(exe).args(["certify", "slave", "--port", "sim", "--profile"]).arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.toml:3: field `timing.init_ms`"), "{err}");

    // A file that is not TOML at all (a wrong path) is said to be no profile.
    let passwd = dir.join("passwd");
    std::fs::write(&passwd, "root:x:0:0:root:/root:/bin/bash\n").unwrap();
    let out = Command::new(exe).arg("check-profile").arg(&passwd).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("passwd:1: not a profile: the file is not TOML"), "{err}");

    let report_dir = dir.join("report");
    let out = Command::new(exe)
        .args(["certify", "slave", "--port", "/dev/does-not-exist-hf", "--report"])
        .arg(&report_dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot open /dev/does-not-exist-hf"));
    let json = std::fs::read_to_string(report_dir.join("report.json")).unwrap();
    assert!(json.contains("\"aborted\": \"cannot open /dev/does-not-exist-hf"), "{json}");
}

#[test]
fn cli_certifies_the_simulator_and_writes_every_report() {
    let _one = common::one_at_a_time();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("report");
    let exe = env!("CARGO_BIN_EXE_hiperface");
    let out = Command::new(exe)
        .args([
            "certify",
            "slave",
            "--port",
            "sim",
            "--tolerance-ms",
            "25",
            "--cases",
            "identity.*,protocol.*,position.read",
            "--device",
            "image: encoder.elf sha256 0123abcd",
            "--device",
            "board: <the bench's> & \"its\" cable",
            "--report",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("PASSED") && stdout.contains("on a real line"), "{stdout}");
    for f in ["report.json", "junit.xml", "certificate.md", "certificate.html"] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let junit = std::fs::read_to_string(dir.join("junit.xml")).unwrap();
    assert!(junit.contains("<testcase name=\"protocol.checksum\""), "{junit}");
    let md = std::fs::read_to_string(dir.join("certificate.md")).unwrap();
    assert!(md.contains("# HIPERFACE slave certificate: PASSED") && md.contains("000000001"), "{md}");
    // When, where and how: for the reader who must tell runs apart and redo one.
    for row in ["| run started (UTC) | 20", "| host | ", "| tool revision | ", "| profile digest | fnv1a64:"] {
        assert!(md.contains(row), "{row}: {md}");
    }
    let command = md.lines().find(|l| l.starts_with("| command line |")).unwrap_or_else(|| panic!("{md}"));
    assert!(
        command.contains("certify slave --port sim") && command.contains("'identity.*,protocol.*,position.read'"),
        "{command}"
    );
    // What was certified, as the operator said it: on the certificate, in the record.
    assert!(md.contains("| device | image: encoder.elf sha256 0123abcd |"), "{md}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["run_info"]["device"][1], "board: <the bench's> & \"its\" cable");
    let html = std::fs::read_to_string(dir.join("certificate.html")).unwrap();
    assert!(html.contains("board: &lt;the bench's&gt; &amp; \"its\" cable"), "{html}");
    let started = json["run_info"]["started_utc"].as_str().unwrap();
    assert!(started.len() == 20 && started.ends_with('Z'), "{started}");
    assert!(std::fs::read_to_string(dir.join("certificate.html")).unwrap().contains("run started (UTC)"));
}

/// A run on a port without `--allow-writes` says which cases it did not run and which
/// flag runs them: on the console and in the JSON, Markdown and HTML (issue 40).
#[test]
fn a_run_without_allow_writes_says_what_it_left_out_and_the_flag_that_runs_it() {
    let _one = common::one_at_a_time();
    let (sim, _port) = PtySimulator::start(profiles::srs50()).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("report");
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface"))
        .args(["certify", "slave", "--port", &sim.path, "--tolerance-ms", "25", "--cases", "fields.*,position.read"])
        .arg("--report")
        .arg(&dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let line = stdout.lines().find(|l| l.starts_with("not run (")).unwrap_or_else(|| panic!("{stdout}"));
    assert!(line.contains("--allow-writes") && line.contains("fields.lifecycle"), "{line}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let groups = json["not_run"].as_array().expect("not_run in the JSON");
    assert!(groups.iter().any(|g| g["reason"].as_str().unwrap().contains("--allow-writes")), "{groups:?}");
    let md = std::fs::read_to_string(dir.join("certificate.md")).unwrap();
    let not_run = md.split("## Not run").nth(1).unwrap_or_else(|| panic!("{md}"));
    assert!(not_run.contains("--allow-writes") && not_run.contains("`fields.lifecycle`"), "{md}");
    assert!(md.find("## Not run") < md.find("## Cases"), "near the top: {md}");
    let html = std::fs::read_to_string(dir.join("certificate.html")).unwrap();
    assert!(html.contains("<h2>Not run</h2>") && html.contains("--allow-writes"), "{html}");
}
