//! Certifying an independent master's process (`certify master --exec`) in the tests:
//! its command line, a run taken again while the harness's own lateness left a
//! scenario UNKNOWN, a run whose record must replay, and what a clean run is.

use hiperface_conformance::master::{self, Attach, Options};
use hiperface_model::Profile;
use hiperface_suite::master::DriveReport;
use hiperface_suite::verdict::{CaseResult, CaseVerdict};
use std::path::Path;

/// The command line of the independent master `script` (in `tests/independent/`),
/// with the defect switch `defect`.
pub fn independent_master(script: &str, defect: Option<&str>) -> String {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/independent").join(script);
    let defect = defect.map_or(String::new(), |d| format!(" --defect {d}"));
    format!("{}python3 {} {{port}}{defect}", super::real_time_prefix(), script.display())
}

/// [`certify`] until no scenario is left UNKNOWN by the harness's own lateness (the
/// report says so: no verdict on the master), as often as `super::faithfully`
/// tries: a run in which the test machine kept the harness from seeing is no sample
/// of the master. A FAIL or NON-STRICT is returned at once, for the test to fail on.
pub fn certify_seen(profile: Profile, exec: &str, scenarios: Option<&str>) -> DriveReport {
    super::faithfully(|| {
        let report = certify(profile, exec, scenarios);
        let unknown: Vec<&CaseResult> = report.scenarios.iter().filter(|s| s.verdict == CaseVerdict::Unknown).collect();
        for s in &unknown {
            // Shown with the test's output if it fails: why each run was taken again.
            eprintln!("{exec}: {} UNKNOWN, taken again: {:#?}", s.id, s.findings);
        }
        (unknown.is_empty(), report)
    })
}

pub fn certify(profile: Profile, exec: &str, scenarios: Option<&str>) -> DriveReport {
    let options = Options {
        attach: Attach::Exec(exec.into()),
        scenarios: scenarios.map(str::to_string),
        polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
        not_used: Vec::new(),
        interrupt: None,
    };
    let report = master::run(profile, &options, |_| {});
    // Decode reproduces the run: the record taken in again grades every scenario alike.
    super::replay::assert_master_replays(&report);
    report
}

/// Every scenario PASS: no FAIL, no NON-STRICT, no ERROR, nothing left unexercised.
pub fn assert_clean(report: &DriveReport) {
    let remarks: Vec<&CaseResult> = report.scenarios.iter().filter(|s| s.verdict != CaseVerdict::Pass).collect();
    assert!(remarks.is_empty(), "{remarks:#?}\n{:#?}", report.output);
    assert_eq!(report.scenarios.len(), hiperface_suite::master::scenarios::catalogue().len());
    // The catalogue took about as long as its scenarios need (nothing hung).
    assert!(report.wall_time_ms - report.rerun_ms < report.needed_ms * 1.2 + 2000.0, "{} ms", report.wall_time_ms);
}

/// A defect switch of an independent master (HX-M, HX-M3, HX-M4), the scenario it is
/// caught in, the clause and verdict there.
pub struct Defect {
    /// The defect switch, and HX-M's other options it needs.
    pub name: &'static str,
    pub scenario: &'static str,
    pub clause: &'static str,
    pub verdict: CaseVerdict,
    /// A scenario the defect does not touch: it must stay clean there (`None` where the
    /// defect shows in every scenario, at start-up).
    pub untouched: Option<&'static str>,
}
