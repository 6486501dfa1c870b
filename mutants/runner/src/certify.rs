//! One defective device certified as a real one is: the whole catalogue, in virtual
//! time, graded by the unmutated model and oracle, in each configuration until one
//! tells it from a conformant device.

use hiperface_suite::line::virtual_line::{SlaveDevice, VirtualLine};
use hiperface_suite::slave::{self, Options, Report};
use hiperface_suite::verdict::CaseVerdict;
use hiperface_suite::verdict::{CaseResult, Finding};
use serde::{Deserialize, Serialize};

/// How a run told a defective device from a conformant one, best first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Caught {
    /// A case FAILed: a normative clause broken.
    Fail,
    /// No FAIL, but the run could not be PASSED: a case ERROR (the device never
    /// answered once, or stopped: a black-box run cannot tell a dead device from none).
    Error,
    /// The device under test never gave the run control back (the mutated model looped
    /// for ever): the run never ended, so it was never PASSED; on a line such a device
    /// is silent.
    Hung,
    /// No FAIL nor ERROR, but NON-STRICT where the conformant device PASSed: only a
    /// "should" or a decision of ours.
    NonStrict,
    /// Every verdict as the conformant device's.
    Survived,
}

impl Caught {
    pub fn label(self) -> &'static str {
        match self {
            Caught::Fail => "FAIL",
            Caught::Error => "ERROR",
            Caught::Hung => "hung",
            Caught::NonStrict => "NON-STRICT",
            Caught::Survived => "survived",
        }
    }
}

/// What a run of one defective device found, in one configuration.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Verdicts {
    pub caught: Caught,
    /// The configuration it was told in.
    pub config: String,
    /// The case that told it, its verdict's clause and the finding.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub case: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub clause: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub finding: Option<String>,
    /// The device crashed (a panic of the mutated model), with the message.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub crashed: Option<String>,
}

impl Verdicts {
    /// A device that could not even be built (its constructor panicked).
    pub fn unbuildable(config: &str, why: String) -> Verdicts {
        Verdicts {
            caught: Caught::Error,
            config: config.to_string(),
            case: None,
            clause: None,
            finding: Some(format!("the device could not be built: {why}")),
            crashed: Some(why),
        }
    }

    /// The better-caught of two (FAIL over ERROR over NON-STRICT over survived).
    pub fn best(self, other: Verdicts) -> Verdicts {
        if other.caught < self.caught {
            other
        } else {
            self
        }
    }
}

/// Compare a slave's report with the conformant device's in the same configuration.
pub fn compare(config: &str, report: &Report, baseline: &Report, crashed: Option<String>) -> Verdicts {
    compare_results(config, &report.cases, &baseline.cases, report.aborted.as_deref(), crashed)
}

/// Compare the results of a run (a slave's cases, a master's scenarios) with the
/// conformant device's: the best-told difference. A unit the conformant device PASSed
/// that the defective one left NOT-EXERCISED or UNKNOWN leaves the run INCOMPLETE, not
/// PASSED: told as ERROR.
pub fn compare_results(
    config: &str,
    results: &[CaseResult],
    baseline: &[CaseResult],
    aborted: Option<&str>,
    crashed: Option<String>,
) -> Verdicts {
    let base = |id: &str| baseline.iter().find(|c| c.id == id).map(|c| c.verdict);
    let mut worst: Option<(Caught, &str, &Finding)> = None;
    for case in results {
        let caught = match case.verdict {
            CaseVerdict::Fail => Caught::Fail,
            CaseVerdict::Error => Caught::Error,
            CaseVerdict::NonStrict if base(case.id) != Some(CaseVerdict::NonStrict) => Caught::NonStrict,
            CaseVerdict::NotExercised | CaseVerdict::Unknown if base(case.id) == Some(CaseVerdict::Pass) => {
                Caught::Error
            }
            _ => continue,
        };
        let finding = case.findings.iter().find(|f| f.verdict() == case.verdict);
        if let Some(f) = finding {
            if worst.as_ref().is_none_or(|(w, _, _)| caught < *w) {
                worst = Some((caught, case.id, f));
            }
        }
    }
    match worst {
        Some((caught, case, f)) => Verdicts {
            caught,
            config: config.to_string(),
            case: Some(case.to_string()),
            clause: Some(f.clause_id().to_string()).filter(|c| !c.is_empty()),
            finding: Some(f.message().to_string()),
            crashed,
        },
        None => Verdicts {
            caught: if aborted.is_some() { Caught::Error } else { Caught::Survived },
            config: config.to_string(),
            case: None,
            clause: None,
            finding: aborted.map(str::to_string),
            crashed,
        },
    }
}

/// Run `certify` on each configuration until one FAILs: the best-told verdicts (after
/// `start`, where earlier configurations were run).
pub fn until_fail<T>(
    configs: impl IntoIterator<Item = T>,
    start: Option<Verdicts>,
    mut certify: impl FnMut(T) -> Verdicts,
) -> Option<Verdicts> {
    let mut best = start;
    for c in configs {
        let found = certify(c);
        let fail = found.caught == Caught::Fail;
        best = Some(match best {
            Some(b) => b.best(found),
            None => found,
        });
        if fail {
            break;
        }
    }
    best
}

/// The options a configuration runs with: every case allowed; the device's physical
/// world unknown to the harness (graded by range, as a device on a line), or given to
/// the run (graded exactly, as `slave::in_process` grades an encoder whose world it is
/// given).
pub fn options(world: &hiperface_suite::world::World) -> Options {
    let grading = if world.is_default() { hiperface_model::Grading::Range } else { hiperface_model::Grading::Exact };
    Options { grading, world: world.clone(), ..Options::all_allowed() }
}

/// Run the catalogue on a device in virtual time.
pub fn run(device: impl SlaveDevice, profile: hiperface_model::Profile, options: &Options) -> Report {
    slave::run(Box::new(VirtualLine::new(device)), profile, options, |_, _, _| {})
}
