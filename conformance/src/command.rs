//! How a command ends, as typed values: what it did ([`Ended`]) or why it could not
//! do it ([`CommandError`]). Every front end returns them; `main` alone turns them into
//! the documented exit codes (0 PASSED or done, 1 FAILED, 2 could not run, 3
//! INCOMPLETE; `verdict::EXIT_USAGE`, `verdict::EXIT_INCOMPLETE`).

use hiperface_suite::listen::decode::DecodeError;
use hiperface_suite::master::record::ReplayError;
use hiperface_suite::profile_file::ProfileLoadError;
use hiperface_suite::slave::NoCaseMatches;
use hiperface_suite::verdict::{Outcome, EXIT_USAGE};
use std::path::PathBuf;

/// What a command did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ended {
    /// It did what it was asked (printed, served, exported).
    Done,
    /// A device, a capture or a record was graded: its outcome.
    Graded(Outcome),
    /// A check of the project's own data found something wrong: vectors that do not
    /// verify, a normative clause neither covered nor listed.
    CheckFailed,
    /// `decode` of a report: its record, graded again, does not give what the report
    /// states (verdicts, counts, outcome, the grading options): the report is no
    /// evidence, whatever the replayed outcome.
    Disagrees,
    /// `decode --verify` of a report whose signature does not hold: not signed by the
    /// key given, or changed since.
    Unverified,
    /// `compare --baseline`: a report regressed against the baseline.
    Regressed,
}

/// The exit code of a report that does not state what its record gives.
pub const EXIT_DISAGREES: u8 = 4;

/// The exit code of a report whose signature does not hold.
pub const EXIT_UNVERIFIED: u8 = 5;

impl Ended {
    /// 0 done or PASSED, 1 FAILED, a check that failed or a regression against a
    /// baseline, 3 INCOMPLETE, 4 a report
    /// that does not state what its record gives, 5 a signature that does not hold.
    pub fn exit_code(self) -> u8 {
        match self {
            Ended::Done => 0,
            Ended::Graded(outcome) => outcome.exit_code(),
            Ended::CheckFailed | Ended::Regressed => 1,
            Ended::Disagrees => EXIT_DISAGREES,
            Ended::Unverified => EXIT_UNVERIFIED,
        }
    }
}

/// Why a command could not do its job; its exit code is 2 ([`EXIT_USAGE`]). A device
/// that FAILs is not an error: it is [`Ended::Graded`].
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// Arguments that do not fit together, or a choice the command cannot make.
    #[error("{0}")]
    Usage(String),
    #[error(transparent)]
    Profile(#[from] ProfileLoadError),
    #[error(transparent)]
    NoCaseMatches(#[from] NoCaseMatches),
    /// A glob of master scenarios that selects none.
    #[error("no scenario matches `{0}`")]
    NoScenarioMatches(String),
    /// A line (serial port, pseudo-terminal, TCP) that cannot be opened, or failed.
    #[error("{0}")]
    Line(String),
    /// The report directory cannot be used (checked before a run).
    #[error("--report {}: {why}", dir.display())]
    ReportDir { dir: PathBuf, why: String },
    /// The report's files cannot be written.
    #[error("cannot write the report to {}: {source}", dir.display())]
    WriteReport { dir: PathBuf, source: std::io::Error },
    /// A file the command reads or writes.
    #[error("{}: {source}", path.display())]
    File { path: PathBuf, source: std::io::Error },
    /// An input whose content cannot be taken in: a capture, a report, a record.
    #[error("{name}: {why}")]
    Input { name: String, why: String },
    #[error(transparent)]
    Decode(#[from] DecodeError),
    /// A master report's record that cannot be taken in again.
    #[error("{name}: {source}")]
    Replay { name: String, source: ReplayError },
    /// Vector files that do not load.
    #[error(transparent)]
    Vectors(#[from] hiperface_suite::vectors::LoadError),
    #[error(transparent)]
    BuiltinVectors(#[from] crate::clauses::BadBuiltinVectors),
    /// Standard output went away for another reason than its reader leaving.
    #[error("standard output: {0}")]
    Output(std::io::Error),
}

impl CommandError {
    /// Every error is a run that could not start or finish: 2.
    pub fn exit_code(&self) -> u8 {
        EXIT_USAGE
    }

    /// A file's error, with its path.
    pub fn file(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> CommandError {
        let path = path.into();
        move |source| CommandError::File { path, source }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn main_maps_each_ending_to_its_documented_exit_code() {
        assert_eq!(Ended::Done.exit_code(), 0);
        assert_eq!(Ended::Graded(Outcome::Passed).exit_code(), 0);
        assert_eq!(Ended::Graded(Outcome::Failed).exit_code(), 1);
        assert_eq!(Ended::Graded(Outcome::Incomplete).exit_code(), 3);
        assert_eq!(Ended::CheckFailed.exit_code(), 1);
        assert_eq!(Ended::Disagrees.exit_code(), 4);
        assert_eq!(Ended::Unverified.exit_code(), 5);
        assert_eq!(CommandError::Usage("x".into()).exit_code(), 2);
        let e = CommandError::file("/nowhere")(std::io::Error::from(std::io::ErrorKind::NotFound));
        assert!(e.to_string().starts_with("/nowhere: "), "{e}");
    }
}
