//! The harness on lines as a lab bench has them, through the line emulator between two
//! pseudo-terminals (`common::line_emulator`): a line that echoes the harness's own
//! requests, against the simulator and against HX-1, the independent slave.

mod common;

use common::faithfully;
use common::hx1::{self, Hx1};
use common::line_emulator::{Behaviour, LineEmulator};
use hiperface_conformance::line::serial::SerialLine;
use hiperface_conformance::master;
use hiperface_conformance::simulate::PtySimulator;
use hiperface_model::{profiles, Grading, Profile, UartSettings};
use hiperface_suite::line::echo::{Echo, EchoLine, EchoMode};
use hiperface_suite::slave::{self, Options, Report};
use hiperface_suite::verdict::CaseVerdict;

/// Real time on a shared machine: the pseudo-terminal tests' generous bound.
const GENEROUS_US: u64 = 25_000;

fn certify_through(emulator: &LineEmulator, profile: Profile, echo: EchoMode, options: &Options) -> Report {
    certify_through_noting(emulator, profile, echo, options, |_, _, _| {})
}

/// As `certify_through`, with `progress` called after each case.
fn certify_through_noting(
    emulator: &LineEmulator,
    profile: Profile,
    echo: EchoMode,
    options: &Options,
    progress: impl FnMut(usize, usize, &hiperface_suite::verdict::CaseResult),
) -> Report {
    let line = SerialLine::open(&emulator.path, UartSettings::DEFAULT).unwrap_or_else(|e| panic!("{e}"));
    let line = EchoLine::new(line.with_tolerance(GENEROUS_US), echo);
    let report = slave::run(Box::new(line), profile, options, progress);
    common::replay::assert_replays(&report);
    report
}

/// The simulator (SRS50) behind the emulator behaving as `behaviour`, certified with
/// `echo`.
fn simulator_through(behaviour: Behaviour, echo: EchoMode) -> Report {
    let profile = profiles::srs50();
    faithfully(|| {
        let (_sim, device) = PtySimulator::start(profile).unwrap();
        let emulator = LineEmulator::start(device, behaviour);
        let r = certify_through(&emulator, profile, echo, &Options::all_allowed());
        (emulator.was_faithful(), r)
    })
}

/// The cases that FAILed or ERRORed, with their findings.
fn failed(r: &Report) -> Vec<String> {
    let bad = r.cases.iter().filter(|c| matches!(c.verdict, CaseVerdict::Fail | CaseVerdict::Error));
    bad.map(|c| format!("{}: {:?}", c.id, c.findings.iter().map(|f| f.to_string()).collect::<Vec<_>>())).collect()
}

/// The cases neither PASSED nor NOT-APPLICABLE, with their findings.
fn not_passed(r: &Report) -> Vec<String> {
    let bad = r.cases.iter().filter(|c| !matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable));
    bad.map(|c| {
        format!("{} {}: {:?}", c.verdict.label(), c.id, c.findings.iter().map(|f| f.to_string()).collect::<Vec<_>>())
    })
    .collect()
}

#[test]
fn an_echoing_line_is_found_and_its_echo_taken_off_against_the_simulator() {
    let _one = common::one_at_a_time();
    let r = simulator_through(Behaviour { echo: true, ..Behaviour::default() }, EchoMode::Auto);
    assert_eq!(
        failed(&r),
        Vec::<&str>::new(),
        "{:#?}",
        r.cases.iter().filter(|c| c.verdict == CaseVerdict::Fail).collect::<Vec<_>>()
    );
    assert!(r.outcome().passed(), "{:?} {:?}", r.summary, r.aborted);
    assert_eq!(r.echo, Some((Echo::Echoes, EchoMode::Auto)), "the certificate says the line echoed");
    assert!(r.summary.get("PASS").copied().unwrap_or(0) > 20, "{:?}", r.summary);
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn an_echoing_line_is_found_and_its_echo_taken_off_against_hx1() {
    let _one = common::one_at_a_time();
    let options = Options { grading: Grading::Range, ..Options::all_allowed() };
    let r = faithfully(|| {
        let hx1 = Hx1::start(&[]);
        let emulator = LineEmulator::open(&hx1.path, Behaviour { echo: true, ..Behaviour::default() });
        let r = certify_through(&emulator, hx1::profile(), EchoMode::Auto, &options);
        // HX-1's lateness spoils only an outcome it could have made (see Hx1::kept_time).
        (emulator.was_faithful() && (failed(&r).is_empty() || hx1.kept_time()), r)
    });
    assert_eq!(failed(&r), Vec::<String>::new());
    assert!(r.outcome().passed(), "{:?} {:?}", r.summary, r.aborted);
    assert_eq!(r.echo, Some((Echo::Echoes, EchoMode::Auto)));
}

#[test]
fn echo_off_on_an_echoing_line_is_a_diagnosis_not_a_wall_of_fails() {
    let _one = common::one_at_a_time();
    let r = simulator_through(Behaviour { echo: true, ..Behaviour::default() }, EchoMode::Off);
    let charged: Vec<&str> = r.cases.iter().filter(|c| c.verdict == CaseVerdict::Fail).map(|c| c.id).collect();
    assert!(charged.is_empty(), "nothing charged to the device: {:#?}", failed(&r));
    assert!(!r.outcome().passed());
    let why = r.aborted.as_deref().unwrap_or_default();
    assert!(why.contains("the line echoes") && why.contains("--echo auto"), "{why}");
}

#[test]
fn a_quiet_line_is_found_quiet_and_graded_as_before() {
    let _one = common::one_at_a_time();
    let r = simulator_through(Behaviour::default(), EchoMode::Auto);
    assert_eq!(failed(&r), Vec::<String>::new());
    assert!(r.outcome().passed(), "{:?} {:?}", r.summary, r.aborted);
    assert_eq!(r.echo, Some((Echo::Quiet, EchoMode::Auto)));
}

/// A line that holds the device's characters for 16 ms, as an FTDI adapter's latency
/// timer does by default, which the harness cannot read on a pseudo-terminal: declared
/// with `--latency-ms 16`, the run has no FAIL in the default timing mode and the
/// certificate names the latency; undeclared, the same line makes replies late.
#[test]
fn a_declared_latency_timer_is_no_fail_and_is_on_the_certificate() {
    use hiperface_conformance::port::{open_for_slave, LineOptions, PortSpec};
    let _one = common::one_at_a_time();
    let profile = profiles::srs50();
    let run = |latency_us: Option<u64>| {
        faithfully(|| {
            let (_sim, device) = PtySimulator::start(profile).unwrap();
            let emulator = LineEmulator::start(device, Behaviour { latency_ms: 16, ..Behaviour::default() });
            let spec = PortSpec::Path(emulator.path.clone());
            let opened =
                open_for_slave(&spec, profile, &Default::default(), LineOptions { latency_us, ..Default::default() })
                    .unwrap_or_else(|e| panic!("{e}"));
            // The emulator hands the device a request at once when its last character is
            // through, and the simulator's receive clock then spaces its characters a
            // character time apart from that moment: a request of n characters reaches the
            // simulator's data link n - 1 characters late. The one-too-long requests of
            // protocol.length to 5 ms commands (44h, 52h, 56h, 67h) then start their reply
            // past the limit by the rig's doing, and the harness rightly cannot tell.
            let cases = Some("!protocol.length".to_string());
            let options = Options { timing: opened.default_timing.0, cases, ..Options::all_allowed() };
            let r = slave::run(opened.line, profile, &options, |_, _, _| {});
            common::replay::assert_replays(&r);
            (emulator.was_faithful(), r)
        })
    };
    let declared = run(Some(16_000));
    assert_eq!(failed(&declared), Vec::<String>::new());
    assert!(declared.outcome().passed(), "{:?} {:?}", declared.summary, not_passed(&declared));
    assert!(declared.line_notes.iter().any(|n| n.contains("16.0 ms")), "{:?}", declared.line_notes);
    let undeclared = run(None);
    assert!(
        undeclared.cases.iter().any(|c| c.verdict == CaseVerdict::Fail),
        "the emulated latency timer is real: undeclared it makes replies late {:?}",
        undeclared.summary
    );
}

/// A line that adds 0.3 ms before each character it passes on, both ways (a slow
/// device server): within every timeout, no FAIL.
///
/// The emulator writes each character on its own, and on a busy machine one now and
/// then comes a timeout after the one before it: a request split by the test's line,
/// not by the harness. A case run while that happened is no evidence, so each case is
/// judged on the runs where the emulator was faithful throughout it: in at least one,
/// and in every such run, it PASSED (or does not apply).
#[test]
fn a_gap_before_each_character_is_no_fail() {
    use std::collections::BTreeMap;
    use std::time::Instant;
    let _one = common::one_at_a_time();
    let profile = profiles::srs50();
    let behaviour = Behaviour { gap_us: 300, ..Behaviour::default() };
    // Case id -> its verdicts (with findings) in the runs faithful throughout it.
    let mut evidence: BTreeMap<String, Vec<(CaseVerdict, Vec<String>)>> = BTreeMap::new();
    let mut unseen = Vec::new();
    for _ in 0..5 {
        let (_sim, device) = PtySimulator::start(profile).unwrap();
        let emulator = LineEmulator::start(device, behaviour);
        let mut ends = vec![Instant::now()];
        let note_end = |_: usize, _: usize, _: &hiperface_suite::verdict::CaseResult| ends.push(Instant::now());
        // The emulator passes characters on 0.3 ms apart at 9600 Bd whatever the data
        // rate: at SRS50's 38400 Bd that is more than the timeout, and every request of
        // settings.stored (stored settings taken up after a reset) would be split by the
        // test's line, its restore with them. The case that changes the stored rate is
        // run through lines that follow the rate (the pseudo-terminal, certify_pty.rs).
        let options = Options { cases: Some("!settings.stored".into()), ..Options::all_allowed() };
        let r = certify_through_noting(&emulator, profile, EchoMode::Auto, &options, note_end);
        assert!(r.aborted.is_none(), "{:?}", r.aborted);
        assert_eq!(ends.len(), r.cases.len() + 1);
        let late = emulator.late_moments();
        for (i, case) in r.cases.iter().enumerate() {
            // A character passed on late in this case, or at the end of the one
            // before (the harness may read it only now).
            let from = ends[i.saturating_sub(1)];
            if late.iter().any(|&t| from <= t && t <= ends[i + 1]) {
                continue;
            }
            let findings: Vec<String> = case.findings.iter().map(|f| f.to_string()).collect();
            evidence.entry(case.id.to_string()).or_default().push((case.verdict, findings));
        }
        unseen = r.cases.iter().map(|c| c.id.to_string()).filter(|id| !evidence.contains_key(id)).collect();
        if unseen.is_empty() {
            break;
        }
    }
    assert_eq!(
        unseen,
        Vec::<String>::new(),
        "cases the emulator was never faithful throughout: the machine is too busy"
    );
    let bad: Vec<String> = evidence
        .iter()
        .flat_map(|(id, seen)| seen.iter().map(move |(verdict, findings)| (id, verdict, findings)))
        .filter(|(_, verdict, _)| !matches!(verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable))
        .map(|(id, verdict, findings)| format!("{} {id}: {findings:?}", verdict.label()))
        .collect();
    assert_eq!(bad, Vec::<String>::new());
}

/// A drive (the reference master) behind the emulator behaving as `behaviour`,
/// certified through it with `echo` (the drive's power-on unseen).
fn drive_through(behaviour: Behaviour, echo: EchoMode) -> hiperface_suite::master::DriveReport {
    use serialport::SerialPort as _;
    let profile = profiles::srs50();
    faithfully(|| {
        let (drive_end, line_end) = serialport::TTYPort::pair().unwrap();
        let _name = line_end.name();
        let running = common::reference_drive(Box::new(drive_end), profile);
        let emulator = LineEmulator::start(Box::new(line_end), behaviour);
        let options = master::Options {
            attach: master::Attach::Port { path: emulator.path.clone(), power_on: master::PowerOn::Unseen, echo },
            scenarios: Some("protocol.checksum-error,protocol.parity,reply.corrupt".into()),
            polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
            not_used: Vec::new(),
            interrupt: None,
        };
        let report = master::run(profile, &options, |_| {});
        common::replay::assert_master_replays(&report);
        let faithful = emulator.was_faithful();
        // The drive ends when its line goes.
        drop(emulator);
        let _ = running.join();
        (faithful, report)
    })
}

/// The start of a scenario's timeline, for a failed assertion's message.
fn timeline(s: &hiperface_suite::verdict::CaseResult) -> String {
    s.wire.iter().take(40).map(|w| format!("{:>12} {} {}\n", w.t_us, w.direction, w.bytes)).collect()
}

/// As the encoder, on a line that echoes the encoder's replies: found at the first
/// reply, taken off the line, and the master graded as on a quiet line.
#[test]
fn an_echoing_line_is_found_and_its_echo_taken_off_as_the_encoder() {
    let _one = common::one_at_a_time();
    let report = drive_through(Behaviour { echo: true, ..Behaviour::default() }, EchoMode::Auto);
    for s in &report.scenarios {
        assert_eq!(s.verdict, CaseVerdict::Pass, "{}: {:#?}\n{}", s.id, s.findings, timeline(s));
    }
    assert_eq!(report.echo, Some((Echo::Echoes, EchoMode::Auto)), "the certificate says the line echoed");
}

/// As the encoder with `--echo off` on a line that echoes: a fault of the line with the
/// diagnosis, never a FAIL of the master for its own echo.
#[test]
fn echo_off_on_an_echoing_line_is_a_diagnosis_as_the_encoder() {
    let _one = common::one_at_a_time();
    let report = drive_through(Behaviour { echo: true, ..Behaviour::default() }, EchoMode::Off);
    for s in &report.scenarios {
        assert_eq!(s.verdict, CaseVerdict::Error, "{}: {:#?}\n{}", s.id, s.findings, timeline(s));
        assert!(s.findings.iter().any(|f| f.message().contains("use --echo auto")), "{}: {:#?}", s.id, s.findings);
    }
}

/// As the encoder on a quiet line: found quiet, the master graded as before.
#[test]
fn a_quiet_line_is_found_quiet_as_the_encoder() {
    let _one = common::one_at_a_time();
    let report = drive_through(Behaviour::default(), EchoMode::Auto);
    for s in &report.scenarios {
        assert_eq!(s.verdict, CaseVerdict::Pass, "{}: {:#?}\n{}", s.id, s.findings, timeline(s));
    }
    assert_eq!(report.echo, Some((Echo::Quiet, EchoMode::Auto)));
}
