//! The one vocabulary of verdicts that every front end uses: `certify slave`,
//! `certify master` and the listener (`decode`, `monitor`).
//!
//! - [`CaseVerdict`]: the verdict of one graded unit (a slave case, a master scenario,
//!   an exchange heard), and the rule that a result only gets worse as findings come;
//! - [`Finding`], [`CaseResult`]: what a unit found, and its result;
//! - [`Outcome`]: what a whole run adds up to, and its exit code;
//! - [`timing`]: a reply's timing against the windows the line can vouch for;
//! - [`glob_match`]: which units `--cases` and `--scenarios` select.
//!
//! A verdict is earned: PASS only for what was observed. A unit that never met its
//! situation is NOT-EXERCISED, what the harness cannot tell is UNKNOWN, and a run with
//! either (or with nothing graded at all) is INCOMPLETE, never PASSED.

mod finding;
mod glob;
pub mod timing;

pub use finding::{CaseResult, Figure, Finding, WireEntry};
pub use glob::{glob_match, MAX_ALTERNATIVES};

use hiperface_model::oracle::Verdict;
use serde::Serialize;
use std::process::ExitCode;

/// The verdict of one graded unit.
///
/// - PASS: observed, as preferred; NON-STRICT: observed, acceptable where the
///   documents leave latitude (with the reason);
/// - FAIL: observed, against a normative clause that binds the device's edition;
/// - NOT-APPLICABLE: never run: the profile or the options exclude it;
/// - NOT-EXERCISED: run, but the situation it is about never arose (the master never
///   sent the request a fault is injected on), so nothing about it was seen;
/// - UNKNOWN: heard, but the harness cannot tell (the listener does not know the
///   encoder's stored state; a character carried a line error);
/// - ERROR: the harness could not run it (port gone, the master exited).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "SCREAMING-KEBAB-CASE")]
pub enum CaseVerdict {
    Pass,
    NonStrict,
    Fail,
    NotApplicable,
    NotExercised,
    Unknown,
    Error,
}

impl CaseVerdict {
    /// Every verdict, from the best to the worst.
    pub const ALL: [CaseVerdict; 7] = [
        CaseVerdict::NotApplicable,
        CaseVerdict::Pass,
        CaseVerdict::NonStrict,
        CaseVerdict::Unknown,
        CaseVerdict::NotExercised,
        CaseVerdict::Error,
        CaseVerdict::Fail,
    ];

    /// Severity for "worst of": FAIL > ERROR > NOT-EXERCISED > UNKNOWN > NON-STRICT >
    /// PASS > NOT-APPLICABLE.
    fn rank(self) -> u8 {
        match self {
            CaseVerdict::NotApplicable => 0,
            CaseVerdict::Pass => 1,
            CaseVerdict::NonStrict => 2,
            CaseVerdict::Unknown => 3,
            CaseVerdict::NotExercised => 4,
            CaseVerdict::Error => 5,
            CaseVerdict::Fail => 6,
        }
    }

    /// The worse of two verdicts.
    pub fn worst(self, other: CaseVerdict) -> CaseVerdict {
        if other.rank() > self.rank() {
            other
        } else {
            self
        }
    }

    /// The verdict's name, as every report, C and Python spell it (a grade's three
    /// are the oracle's own).
    pub fn label(self) -> &'static str {
        match self {
            CaseVerdict::Pass => Verdict::Pass.name(),
            CaseVerdict::NonStrict => Verdict::NonStrict.name(),
            CaseVerdict::Fail => Verdict::Fail.name(),
            CaseVerdict::NotApplicable => "NOT-APPLICABLE",
            CaseVerdict::NotExercised => "NOT-EXERCISED",
            CaseVerdict::Unknown => "UNKNOWN",
            CaseVerdict::Error => "ERROR",
        }
    }

    /// Something was observed and graded: PASS, NON-STRICT or FAIL.
    pub fn graded(self) -> bool {
        matches!(self, CaseVerdict::Pass | CaseVerdict::NonStrict | CaseVerdict::Fail)
    }
}

impl From<Verdict> for CaseVerdict {
    fn from(v: Verdict) -> Self {
        match v {
            Verdict::Pass => CaseVerdict::Pass,
            Verdict::NonStrict => CaseVerdict::NonStrict,
            Verdict::Fail => CaseVerdict::Fail,
        }
    }
}

/// What a whole run adds up to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "SCREAMING-KEBAB-CASE")]
pub enum Outcome {
    /// Every unit that ran was observed and graded PASS or NON-STRICT, and something was.
    Passed,
    /// At least one FAIL.
    Failed,
    /// No FAIL, but not everything selected was observed: a unit NOT-EXERCISED, in
    /// ERROR, or UNKNOWN where the run must be complete; nothing graded at all; or the
    /// run stopped early.
    Incomplete,
}

impl Outcome {
    /// The outcome of units with `verdicts`; `complete`: the run was not cut short.
    pub fn of(verdicts: impl IntoIterator<Item = CaseVerdict>, complete: bool) -> Outcome {
        let mut any_graded = false;
        let mut missing = !complete;
        for v in verdicts {
            match v {
                CaseVerdict::Fail => return Outcome::Failed,
                CaseVerdict::Pass | CaseVerdict::NonStrict => any_graded = true,
                CaseVerdict::NotApplicable => {}
                CaseVerdict::NotExercised | CaseVerdict::Unknown | CaseVerdict::Error => missing = true,
            }
        }
        if missing || !any_graded {
            Outcome::Incomplete
        } else {
            Outcome::Passed
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Outcome::Passed => "PASSED",
            Outcome::Failed => "FAILED",
            Outcome::Incomplete => "INCOMPLETE",
        }
    }

    pub fn passed(self) -> bool {
        self == Outcome::Passed
    }

    /// The process's exit code: 0 PASSED, 1 FAILED, 3 INCOMPLETE ([`EXIT_USAGE`] is for
    /// a run that could not start).
    pub fn exit_code(self) -> u8 {
        match self {
            Outcome::Passed => 0,
            Outcome::Failed => 1,
            Outcome::Incomplete => EXIT_INCOMPLETE,
        }
    }

    pub fn exit(self) -> ExitCode {
        ExitCode::from(self.exit_code())
    }
}

/// The exit code of a run that could not start: bad arguments, a profile that does not
/// load, a port that cannot be opened, nothing selected.
pub const EXIT_USAGE: u8 = 2;
/// The exit code of an INCOMPLETE run.
pub const EXIT_INCOMPLETE: u8 = 3;

/// How often a unit (a slave case, a master scenario) is run at most when the
/// harness's own timing was disturbed; its result is its last run's.
pub const MAX_ATTEMPTS: u32 = 3;

/// A unit still undecided after [`MAX_ATTEMPTS`] runs in a row is run again at the end
/// of the run (up to as many runs more) while that takes at most this share of the
/// run's own time (a slave run's line time until then, a master run's scenarios'
/// time); beyond it the unit keeps its undecided (UNKNOWN) result.
pub const END_BUDGET: f64 = 0.25;

#[cfg(test)]
mod tests {
    use super::CaseVerdict::*;

    use super::*;

    #[test]
    fn worst_is_a_total_order_from_not_applicable_to_fail() {
        for (i, a) in CaseVerdict::ALL.iter().enumerate() {
            for (j, b) in CaseVerdict::ALL.iter().enumerate() {
                assert_eq!(a.worst(*b), CaseVerdict::ALL[i.max(j)], "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn a_run_passes_only_with_something_graded_and_nothing_missing() {
        assert_eq!(Outcome::of([Pass, NonStrict, NotApplicable], true), Outcome::Passed);
        assert_eq!(Outcome::of([Pass, Fail, Error], true), Outcome::Failed);
        assert_eq!(Outcome::of([Pass, Error], true), Outcome::Incomplete);
        assert_eq!(Outcome::of([Pass, NotExercised], true), Outcome::Incomplete);
        assert_eq!(Outcome::of([Pass, Unknown], true), Outcome::Incomplete);
        assert_eq!(Outcome::of([Pass], false), Outcome::Incomplete, "cut short");
        assert_eq!(Outcome::of([], true), Outcome::Incomplete, "zero units");
        assert_eq!(Outcome::of([NotApplicable, NotApplicable], true), Outcome::Incomplete, "nothing ran");
        assert_eq!(Outcome::Failed.exit_code(), 1);
        assert_eq!(Outcome::Incomplete.exit_code(), 3);
    }
}
