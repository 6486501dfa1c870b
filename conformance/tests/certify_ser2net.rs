//! The harness through a real serial device server: ser2net (Debian's package,
//! installed by .ci/run) bridges TCP to the simulator's pseudo-terminal.

mod common;

use hiperface_conformance::certify::{self, CaseVerdict, Options};
use hiperface_conformance::simulate::PtySimulator;
use hiperface_model::profiles;

#[test]
#[cfg_attr(not(has_ser2net), ignore = "ser2net is not installed (apt-get install ser2net)")]
fn the_catalogue_passes_through_ser2net() {
    let profile = profiles::srs50();
    let (sim, _harness_end) = PtySimulator::start(profile).unwrap();
    let server = common::Ser2net::bridge(&sim.path, "sim");
    // Real time on a shared CI machine: generous timing bounds.
    let line = server.connect().with_tolerance(25_000);
    let options = Options::all_allowed();
    let report = certify::run(Box::new(line), profile, &options, |_, _, _| {});
    let bad: Vec<_> =
        report.cases.iter().filter(|c| !matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable)).collect();
    assert!(bad.is_empty(), "{bad:#?}");
    assert!(report.line.starts_with("tcp://127.0.0.1:"));
    eprintln!("ser2net run: wall {:.0} ms, physical minimum {:.0} ms", report.wall_time_ms, report.physical_minimum_ms);
    drop(sim);
}
