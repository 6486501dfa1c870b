//! Findings and the result of one graded unit (a slave case, a master scenario). A
//! finding is FAIL only when built from a normative clause that binds the device's
//! edition ([`Finding::fail`]) or from an oracle grade (which holds the same
//! guarantee); decisions of this project and third-party readings give NON-STRICT at
//! most, and what the harness itself does not know is UNKNOWN, NOT-EXERCISED or
//! ERROR, never charged to the device.

use super::CaseVerdict;
use hiperface_model::clause::{Clause, Normative};
use hiperface_model::oracle::Grade;
use hiperface_model::Edition;
use serde::{Serialize, Serializer};

fn clause_id<S: Serializer>(c: &Option<Clause>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(c.map_or("", |c| c.id()))
}

fn clause_ids<S: Serializer>(c: &[Clause], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(c.iter().map(|c| c.id()))
}

/// A figure measured against its limit, for the reader of a certificate who must see
/// by how much (a reply's start after the request's timeout against Table 10's limit).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Figure {
    /// What was measured, in words.
    pub what: &'static str,
    pub measured_us: i64,
    pub limit_us: i64,
    /// The limit is a most (else a least).
    pub at_most: bool,
}

impl std::fmt::Display for Figure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |us: i64| us as f64 / 1000.0;
        let bound = if self.at_most { "at most" } else { "at least" };
        write!(f, "{}: {:.3} ms measured, {bound} {:.3} ms allowed", self.what, ms(self.measured_us), ms(self.limit_us))
    }
}

/// One statement of a case's result.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Finding {
    verdict: CaseVerdict,
    message: String,
    #[serde(serialize_with = "clause_id")]
    clause: Option<Clause>,
    /// Where on the wire it is, µs since the run started: the end of the request of the
    /// exchange it grades (for a check across exchanges, the last one before it), or
    /// the moment a master broke a rule. `None` for what is about no exchange.
    #[serde(skip_serializing_if = "Option::is_none")]
    at_us: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    figure: Option<Figure>,
}

impl Finding {
    fn new(verdict: CaseVerdict, message: String, clause: Option<Clause>) -> Finding {
        Finding { verdict, message, clause, at_us: None, figure: None }
    }

    /// The device broke `rule`: FAIL if the rule binds its edition, NON-STRICT (with
    /// the reason) if it is a rule of the other edition's document.
    pub fn fail(message: impl Into<String>, rule: Normative, edition: Edition) -> Finding {
        let mut message = message.into();
        let verdict = if rule.binds(edition) {
            CaseVerdict::Fail
        } else {
            message.push_str(&format!(" ({rule} does not bind a {edition:?}-edition device)"));
            CaseVerdict::NonStrict
        };
        Finding::new(verdict, message, Some(rule.clause()))
    }

    /// Acceptable where the documents leave latitude, or a departure from a decision.
    /// A rule resting on `clause` was broken: FAIL where the clause is normative
    /// ([`Finding::fail`]), NON-STRICT where it is a recommendation or a decision.
    pub fn broken(clause: Clause, message: impl Into<String>, edition: Edition) -> Finding {
        match clause.normative() {
            Some(n) => Finding::fail(message, n, edition),
            None => Finding::non_strict(message, clause),
        }
    }

    pub fn non_strict(message: impl Into<String>, clause: impl Into<Clause>) -> Finding {
        Finding::new(CaseVerdict::NonStrict, message.into(), Some(clause.into()))
    }

    /// The situation the unit is about never arose: nothing about it was seen.
    pub fn not_exercised(message: impl Into<String>) -> Finding {
        Finding::new(CaseVerdict::NotExercised, message.into(), None)
    }

    /// Heard, but the harness cannot tell whether it was right.
    pub fn unknown(message: impl Into<String>) -> Finding {
        Finding::new(CaseVerdict::Unknown, message.into(), None)
    }

    /// The harness could not run (part of) the case.
    pub fn error(message: impl Into<String>) -> Finding {
        Finding::new(CaseVerdict::Error, message.into(), None)
    }

    /// The profile or the options exclude the case.
    pub fn not_applicable(message: impl Into<String>) -> Finding {
        Finding::new(CaseVerdict::NotApplicable, message.into(), None)
    }

    /// The oracle's grade of the exchange of `request` (PASS grades make no finding,
    /// and no message: grading is on the listener's hot path).
    pub fn graded(grade: &Grade, request: &[u8]) -> Option<Finding> {
        let verdict = CaseVerdict::from(grade.verdict());
        (verdict != CaseVerdict::Pass).then(|| {
            let reason = grade.deviation().map_or(String::new(), |d| d.to_string());
            let message = format!("request [{}]: {reason}", hiperface_model::frame::Hex(request));
            Finding::new(verdict, message, Some(grade.clause()))
        })
    }

    /// A FAIL becomes NON-STRICT, with the reason (e.g. timing graded leniently on
    /// a line whose latency the harness cannot bound). Only ever lowers a verdict.
    pub fn softened(mut self, reason: &str) -> Finding {
        if self.verdict == CaseVerdict::Fail {
            self.verdict = CaseVerdict::NonStrict;
            self.message.push_str(&format!(" ({reason})"));
        }
        self
    }

    /// A broken rule the harness's own timing could explain (a busy machine read the
    /// line late, or wrote a reply with a pause it did not plan): the harness cannot
    /// tell whether the device broke it, so it is UNKNOWN, with the reason, never
    /// charged to the device. Only a FAIL or a NON-STRICT changes.
    pub fn untold(mut self, reason: &str) -> Finding {
        if matches!(self.verdict, CaseVerdict::Fail | CaseVerdict::NonStrict) {
            self.verdict = CaseVerdict::Unknown;
            self.message.push_str(&format!(" ({reason})"));
        }
        self
    }

    /// The finding is about the wire at `at_us` (kept where it was placed already).
    pub fn at(mut self, at_us: u64) -> Finding {
        self.at_us.get_or_insert(at_us);
        self
    }

    /// The finding measured `figure`.
    pub fn with_figure(mut self, figure: Figure) -> Finding {
        self.figure = Some(figure);
        self
    }

    pub fn verdict(&self) -> CaseVerdict {
        self.verdict
    }

    pub fn at_us(&self) -> Option<u64> {
        self.at_us
    }

    pub fn figure(&self) -> Option<Figure> {
        self.figure
    }

    pub fn message(&self) -> &str {
        &self.message
    }

    pub fn clause(&self) -> Option<Clause> {
        self.clause
    }

    /// The clause id, or "" for the harness's own statements.
    pub fn clause_id(&self) -> &'static str {
        self.clause.map_or("", |c| c.id())
    }
}

/// The message, and the clause in parentheses where there is one.
impl std::fmt::Display for Finding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.clause {
            Some(c) => write!(f, "{} ({c})", self.message),
            None => f.write_str(&self.message),
        }
    }
}

/// One line of the wire log.
#[derive(Debug, Clone, Serialize)]
pub struct WireEntry {
    /// µs since the run started (receive time of the last character for requests,
    /// start of the first character for replies).
    pub t_us: u64,
    pub direction: &'static str,
    pub bytes: String,
}

impl WireEntry {
    /// A master's request (stamped at its last character).
    pub const REQUEST: &'static str = "M>";
    /// A slave's reply (stamped at its first character).
    pub const REPLY: &'static str = "S<";
    /// A fault the encoder injected or read (a master's certificate).
    pub const INJECTED: &'static str = "!";
    /// A rule the master broke (a master's certificate).
    pub const BROKEN: &'static str = "×";
    /// The harness's own timing (a master's certificate): not the device's.
    pub const HARNESS: &'static str = "?";
}

#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    pub id: &'static str,
    pub title: &'static str,
    #[serde(serialize_with = "clause_ids")]
    pub clauses: Vec<Clause>,
    pub verdict: CaseVerdict,
    pub findings: Vec<Finding>,
    pub exchanges: usize,
    pub wire: Vec<WireEntry>,
    pub duration_ms: f64,
    /// How often the unit was run: more than once where the harness's own timing was
    /// disturbed (a busy machine) and a run was repeated; this result is the last run's.
    pub attempts: u32,
}

impl CaseResult {
    /// A result for any graded unit (a slave case, a master scenario).
    pub fn named(id: &'static str, title: &'static str, clauses: &[Clause]) -> CaseResult {
        CaseResult {
            id,
            title,
            clauses: clauses.to_vec(),
            verdict: CaseVerdict::Pass,
            findings: Vec::new(),
            exchanges: 0,
            wire: Vec::new(),
            duration_ms: 0.0,
            attempts: 1,
        }
    }

    /// Record a finding; the verdict is the worst of the findings: it only gets
    /// worse (a FAIL or an ERROR is never replaced). NOT-APPLICABLE is the verdict of
    /// a unit that never ran, so it is only taken as the first finding; after others
    /// it is a note that changes nothing.
    pub fn push(&mut self, f: Finding) {
        self.verdict = match f.verdict {
            CaseVerdict::NotApplicable if self.findings.is_empty() => CaseVerdict::NotApplicable,
            v => self.verdict.worst(v),
        };
        self.findings.push(f);
    }

    /// A PASS is earned by what was observed: a unit that ended with no exchange
    /// graded (and without a finding saying why it did not apply) is NOT-EXERCISED.
    pub fn close_unobserved(&mut self, what: &str) {
        if self.exchanges == 0 && self.verdict == CaseVerdict::Pass {
            self.push(Finding::not_exercised(format!("{what} ended without an exchange to grade")));
        }
    }

    /// The clause ids, comma-separated, for reports.
    pub fn clause_list(&self) -> String {
        self.clauses.iter().map(|c| c.id()).collect::<Vec<_>>().join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::clause;

    fn result() -> CaseResult {
        CaseResult::named("x", "x", &[])
    }

    #[test]
    fn a_result_only_gets_worse() {
        // A master that exits mid-scenario, and then is found to have never sent the
        // request the fault waits for: the ERROR stands.
        let mut r = result();
        r.push(Finding::error("the master exited"));
        r.push(Finding::not_exercised("never sent a second Read Position"));
        r.push(Finding::not_applicable("late note"));
        assert_eq!(r.verdict, CaseVerdict::Error);
        r.push(Finding::non_strict("x", clause::CHECK_ORDER));
        assert_eq!(r.verdict, CaseVerdict::Error);
        r.push(Finding::fail("x", clause::READ_VERSION, Edition::Current));
        assert_eq!(r.verdict, CaseVerdict::Fail);
        r.push(Finding::error("later"));
        assert_eq!(r.verdict, CaseVerdict::Fail);
        // NOT-APPLICABLE only for what never ran.
        let mut r = result();
        r.push(Finding::not_applicable("profile"));
        assert_eq!(r.verdict, CaseVerdict::NotApplicable);
        let mut r = result();
        r.push(Finding::non_strict("x", clause::CHECK_ORDER));
        r.push(Finding::not_applicable("after"));
        assert_eq!(r.verdict, CaseVerdict::NonStrict);
    }

    #[test]
    fn nothing_observed_is_never_passed() {
        let mut r = result();
        r.close_unobserved("the case");
        assert_eq!(r.verdict, CaseVerdict::NotExercised);
        // What did not apply stays so; what was graded keeps its verdict.
        let mut r = result();
        r.push(Finding::not_applicable("profile"));
        r.close_unobserved("the case");
        assert_eq!(r.verdict, CaseVerdict::NotApplicable);
        let mut r = result();
        r.exchanges = 1;
        r.close_unobserved("the case");
        assert_eq!(r.verdict, CaseVerdict::Pass);
    }

    #[test]
    fn a_fail_binds_the_devices_edition_only() {
        let f = Finding::fail("37 bytes", clause::READ_VERSION, Edition::Current);
        assert_eq!((f.verdict(), f.clause_id()), (CaseVerdict::Fail, "000:T31"));
        let f = Finding::fail("37 bytes", clause::READ_VERSION, Edition::Legacy);
        assert_eq!(f.verdict(), CaseVerdict::NonStrict, "000:T31 is not a rule of 002");
        assert!(f.message().contains("does not bind a Legacy-edition device"), "{}", f.message());
        assert_eq!(Finding::non_strict("x", clause::CHECK_ORDER).verdict(), CaseVerdict::NonStrict);
        assert_eq!(Finding::error("port gone").clause_id(), "");
    }
}
