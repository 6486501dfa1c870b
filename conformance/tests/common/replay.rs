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
