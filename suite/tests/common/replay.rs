//! The record of the wire played back: `decode` of a certify report must give the
//! verdicts the run gave, unit by unit and finding by finding.

use hiperface_suite::master::record::{self, MasterRecord};
use hiperface_suite::master::DriveReport;
use hiperface_suite::slave::{self, Report};
use hiperface_suite::verdict::CaseResult;

/// Every unit's (case's, scenario's) id, verdict, runs and findings (verdict, clause,
/// message): what a certificate says.
pub fn units(results: &[CaseResult]) -> Vec<String> {
    let mut out = Vec::new();
    for c in results {
        out.push(format!("{} {} x{}", c.id, c.verdict.label(), c.attempts));
        for f in &c.findings {
            out.push(format!("  {} {} {}", f.verdict().label(), f.clause_id(), f.message()));
        }
    }
    out
}

/// A slave run's units and its outcome.
pub fn verdicts(r: &Report) -> Vec<String> {
    let mut out = units(&r.cases);
    out.push(format!("outcome {:?}, aborted {:?}", r.outcome(), r.aborted));
    out
}

/// The run's lines and the played-back lines are the same; else the first difference.
fn assert_same(what: &str, live: &[String], again: &[String]) {
    if live != again {
        let first = live.iter().zip(again).position(|(x, y)| x != y).unwrap_or(live.len().min(again.len()));
        panic!(
            "{what} gives other verdicts, from line {first}:\n live:   {:?}\n replay: {:?}",
            live.get(first),
            again.get(first)
        );
    }
}

/// Play `live`'s record back, through its JSON as report.json holds it, and check
/// that the verdicts are the run's; returns the played-back report.
pub fn assert_replays(live: &Report) -> Report {
    let record = live.record.as_ref().expect("a live run keeps its record");
    let json = serde_json::to_string(record).expect("the record serializes");
    let record = serde_json::from_str(&json).expect("the record reads back");
    let again = slave::replay(&record, |_, _, _| {}).expect("the record plays back");
    assert_same("the record played back", &verdicts(live), &verdicts(&again));
    again
}

/// Take a master certification's record in again, through its JSON, and check that
/// every scenario is graded as the run graded it.
pub fn assert_master_replays(live: &DriveReport) {
    let record = live.record.as_ref().expect("a master run keeps its record");
    let json = serde_json::to_string(record).expect("the record serializes");
    let record: MasterRecord = serde_json::from_str(&json).expect("the record reads back");
    let (_, again, notes) = record::replay(&record).unwrap_or_else(|e| panic!("the record is taken in again: {e}"));
    assert_same("the master record taken in again", &units(&live.scenarios), &units(&again));
    assert!(notes.is_empty(), "{notes:?}");
}
