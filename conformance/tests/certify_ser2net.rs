//! The harness through a real serial device server: ser2net (Debian's package,
//! installed by .ci/run) bridges TCP to the simulator's pseudo-terminal.

mod common;

use hiperface_conformance::port::{self, PortSpec};
use hiperface_conformance::simulate::PtySimulator;
use hiperface_model::profiles;
use hiperface_suite::line::Line;
use hiperface_suite::slave::{self, Options};
use hiperface_suite::verdict::CaseVerdict;

#[test]
#[cfg_attr(not(has_ser2net), ignore = "ser2net is not installed (apt-get install ser2net)")]
fn the_catalogue_passes_through_ser2net() {
    let profile = profiles::srs50();
    let (sim, _harness_end) = PtySimulator::start(profile).unwrap();
    let server = common::Ser2net::bridge(&sim.path, "sim");
    // Real time on a shared CI machine: generous timing bounds.
    let line = server.connect().with_tolerance(25_000);
    let options = Options::all_allowed();
    let report = slave::run(Box::new(line), profile, &options, |_, _, _| {});
    let bad: Vec<_> =
        report.cases.iter().filter(|c| !matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable)).collect();
    assert!(bad.is_empty(), "{bad:#?}");
    assert!(report.line.starts_with("tcp://127.0.0.1:"));
    eprintln!("ser2net run: wall {:.0} ms, on a real line {:.0} ms", report.wall_time_ms, report.line_time_ms);
    drop(sim);
}

/// RFC 2217: the harness sets ser2net's UART (here the pseudo-terminal's data rate,
/// which the simulator follows), so 67h is followed end to end instead of being
/// NOT-APPLICABLE as on raw TCP.
#[test]
#[cfg_attr(not(has_ser2net), ignore = "ser2net is not installed (apt-get install ser2net)")]
fn temporary_settings_are_followed_through_rfc2217() {
    let _one = common::one_at_a_time();
    let (profile, sim, _harness_end) = simulator_following_the_line();
    let server = common::Ser2net::bridge_rfc2217(&sim.path, "sim2217");
    let spec: PortSpec = format!("rfc2217://{}", server.address()).parse().unwrap();
    let line = connect_retrying(|| {
        port::open_for_slave(&spec, profile, &Default::default(), port::LineOptions::tolerance(25_000))
    })
    .line;
    assert!(line.describe().starts_with("rfc2217://"), "{}", line.describe());
    let report = slave::run(line, profile, &Options::all_allowed(), |_, _, _| {});
    let bad: Vec<_> =
        report.cases.iter().filter(|c| !matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable)).collect();
    assert!(bad.is_empty(), "{bad:#?}");
    let temporary = report.cases.iter().find(|c| c.id == "settings.temporary").unwrap();
    assert_eq!(temporary.verdict, CaseVerdict::Pass, "{temporary:#?}");
    drop(sim);
}

/// The same simulator on raw TCP: the device server keeps 9 600 Bd, so 67h cannot be
/// followed, and the case says so (NOT-APPLICABLE) instead of running.
#[test]
#[cfg_attr(not(has_ser2net), ignore = "ser2net is not installed (apt-get install ser2net)")]
fn without_rfc2217_the_same_case_cannot_be_followed() {
    let _one = common::one_at_a_time();
    let (profile, sim, _harness_end) = simulator_following_the_line();
    let server = common::Ser2net::bridge(&sim.path, "simraw");
    let line = server.connect().with_tolerance(25_000);
    let report = slave::run(Box::new(line), profile, &Options::all_allowed(), |_, _, _| {});
    let temporary = report.cases.iter().find(|c| c.id == "settings.temporary").unwrap();
    assert_eq!(temporary.verdict, CaseVerdict::NotApplicable, "{temporary:#?}");
    drop(sim);
}

/// TTK70 with every optional command (67h to 19 200 Bd, as over a pseudo-terminal),
/// simulated following the rate ser2net sets on its pseudo-terminal; the harness's
/// end, to be kept open (with no end open the simulator would take the line for gone).
fn simulator_following_the_line() -> (hiperface_model::Profile, PtySimulator, Box<dyn serialport::SerialPort>) {
    let mut profile = profiles::ttk70();
    profile.commands = hiperface_model::command::CommandSet::all_for(false);
    let (sim, harness_end) = PtySimulator::start_following_line_settings(profile).unwrap();
    (profile, sim, harness_end)
}

/// Connect once ser2net listens (it starts in the background).
fn connect_retrying<T, E: std::fmt::Display>(mut open: impl FnMut() -> Result<T, E>) -> T {
    let started = std::time::Instant::now();
    loop {
        match open() {
            Ok(t) => return t,
            Err(_) if started.elapsed() < std::time::Duration::from_secs(10) => {
                std::thread::sleep(std::time::Duration::from_millis(100))
            }
            Err(e) => panic!("{e}"),
        }
    }
}
