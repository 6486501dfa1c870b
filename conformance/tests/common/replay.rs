//! The record of the wire played back: `decode` of a certify report must give the
//! verdicts the run gave, case by case and finding by finding.

use hiperface_conformance::certify::{self, Report};

/// Every case's id, verdict, runs and findings (verdict, clause, message): what a
/// certificate says.
pub fn verdicts(r: &Report) -> Vec<String> {
    let mut out = Vec::new();
    for c in &r.cases {
        out.push(format!("{} {} x{}", c.id, c.verdict.label(), c.attempts));
        for f in &c.findings {
            out.push(format!("  {} {} {}", f.verdict().label(), f.clause_id(), f.message()));
        }
    }
    out.push(format!("outcome {:?}, aborted {:?}", r.outcome(), r.aborted));
    out
}

/// Play `live`'s record back, through its JSON as report.json holds it, and check
/// that the verdicts are the run's; returns the played-back report.
pub fn assert_replays(live: &Report) -> Report {
    let record = live.record.as_ref().expect("a live run keeps its record");
    let json = serde_json::to_string(record).expect("the record serializes");
    let record = serde_json::from_str(&json).expect("the record reads back");
    let again = certify::replay(&record, |_, _, _| {}).expect("the record plays back");
    let (a, b) = (verdicts(live), verdicts(&again));
    if a != b {
        let first = a.iter().zip(&b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
        panic!(
            "the record played back gives other verdicts, from line {first}:\n live:   {:?}\n replay: {:?}",
            a.get(first),
            b.get(first)
        );
    }
    again
}

/// Every scenario's id, verdict, runs and findings of a master certification.
pub fn master_verdicts(scenarios: &[hiperface_conformance::certify::CaseResult]) -> Vec<String> {
    let mut out = Vec::new();
    for s in scenarios {
        out.push(format!("{} {} x{}", s.id, s.verdict.label(), s.attempts));
        for f in &s.findings {
            out.push(format!("  {} {} {}", f.verdict().label(), f.clause_id(), f.message()));
        }
    }
    out
}

/// Take a master certification's record in again, through its JSON, and check that
/// every scenario is graded as the run graded it.
pub fn assert_master_replays(live: &hiperface_conformance::drive::DriveReport) {
    use hiperface_conformance::drive::record::{self, MasterRecord};
    let record = live.record.as_ref().expect("a master run keeps its record");
    let json = serde_json::to_string(record).expect("the record serializes");
    let record: MasterRecord = serde_json::from_str(&json).expect("the record reads back");
    let (_, again, notes) = record::replay(&record).unwrap_or_else(|e| panic!("the record is taken in again: {e}"));
    let (a, b) = (master_verdicts(&live.scenarios), master_verdicts(&again));
    if a != b {
        let first = a.iter().zip(&b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
        panic!(
            "the master record taken in again gives other verdicts, from line {first}:\n live:   {:?}\n replay: {:?}",
            a.get(first),
            b.get(first)
        );
    }
    assert!(notes.is_empty(), "{notes:?}");
}
