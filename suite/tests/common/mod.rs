//! What the suite's integration tests share (the harness's tests use `replay` too).

#![allow(dead_code)]

pub mod replay;

use hiperface_suite::slave::Report;
use hiperface_suite::verdict::CaseVerdict;

/// The FAILs of a run as "case clause".
pub fn failing(r: &Report) -> Vec<String> {
    r.cases
        .iter()
        .filter(|c| c.verdict == CaseVerdict::Fail)
        .flat_map(|c| c.findings.iter().filter(|f| f.verdict() == CaseVerdict::Fail).map(move |f| (c.id, f)))
        .map(|(id, f)| format!("{id} {}", f.clause_id()))
        .collect()
}
