//! Certifying a master (a drive) without I/O: the scenarios, the encoder a master is
//! certified against as hooks of a serving loop (it observes the master's
//! obligations, `hiperface_model::master::obligations`, and injects the scenario's
//! faults), the grade of one scenario run, the scenario loop every line runs the
//! catalogue with (`run`: in real time and in-process alike), the record of the wire
//! taken in again, and the report. A FAIL needs a normative "must" of 000 that binds
//! the profile's edition; the recommendations of 000 (read the status after power-on,
//! read out the warning's codes, react to faults as Table 74 says) are NON-STRICT at
//! most. The harness (`hiperface-conformance`) serves the encoder on a pseudo-terminal
//! or a drive's port in real time and runs the master's process.

pub mod encoder;
pub mod grade;
pub mod in_process;
pub mod inputs;
pub mod record;
pub mod report;
pub mod run;
pub mod scenario;
pub mod scenarios;
pub mod timeline;

use crate::line::echo::{Echo, EchoMode};
use crate::verdict::{CaseResult, Finding, Outcome};
use hiperface_model::{CommandId, Profile};
use serde::Serialize;

/// The scenario's result where the master declared it never sends a command the
/// scenario is about (`--not-used`): NOT-APPLICABLE, not run; `None` where it runs.
pub fn declared_out(scenario: &scenario::Scenario, not_used: &[CommandId]) -> Option<CaseResult> {
    let hit: Vec<String> =
        scenario.commands().into_iter().filter(|c| not_used.contains(c)).map(|c| c.to_string()).collect();
    (!hit.is_empty()).then(|| {
        let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
        result.push(Finding::not_applicable(format!(
            "declared not used: the master never sends {}, which this scenario is about",
            hit.join(", ")
        )));
        result
    })
}

/// A command a master declares it never sends, as people write it: `4Ah`, `4A` or
/// `0x4A`; one of 000 Table 10 (the command line's `--not-used`, Python's `not_used`).
pub fn parse_command(text: &str) -> Result<CommandId, BadCommand> {
    let t = text.trim();
    let hex = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")).unwrap_or(t);
    let hex = hex.strip_suffix(['h', 'H']).unwrap_or(hex);
    let byte = u8::from_str_radix(hex, 16).map_err(|_| BadCommand::NotAByte(text.to_string()))?;
    command_of(byte)
}

/// The command of a byte, where 000 Table 10 has one.
pub fn command_of(byte: u8) -> Result<CommandId, BadCommand> {
    let id = CommandId::decode(byte);
    id.spec().map(|_| id).ok_or(BadCommand::NotACommand(byte))
}

/// Why a declared command is none.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BadCommand {
    #[error("`{0}` is not a command byte (e.g. 4Ah)")]
    NotAByte(String),
    #[error("{0:02X}h is not a HIPERFACE command (000 Table 10)")]
    NotACommand(u8),
}

/// The declaration's note for the certificate, where there is one.
pub fn declaration_note(not_used: &[CommandId]) -> Option<String> {
    (!not_used.is_empty()).then(|| {
        let list: Vec<String> = not_used.iter().map(|c| c.to_string()).collect();
        let them = if list.len() == 1 { "it" } else { "them" };
        format!(
            "The master declared that it never sends {} (--not-used): the scenarios about {them} are NOT-APPLICABLE, \
             and a master seen sending one has that declaration contradicted (UNKNOWN) where it did.",
            list.join(", ")
        )
    })
}

/// The result of certifying a master.
#[derive(Debug, Clone, Serialize)]
pub struct DriveReport {
    pub tool: String,
    pub profile: String,
    pub edition: String,
    pub master: String,
    pub scenarios: Vec<CaseResult>,
    pub summary: std::collections::BTreeMap<String, usize>,
    /// What the master printed, per scenario id (capped).
    pub output: std::collections::BTreeMap<String, String>,
    pub wall_time_ms: f64,
    /// The sum of the scenarios' lengths (each from power-on to its end, which comes
    /// later when its situation arose late): the time the catalogue needs at least.
    pub needed_ms: f64,
    /// The time spent on runs that were repeated (their harness was disturbed).
    pub rerun_ms: f64,
    /// What the harness could not see, for the reader of the certificate.
    pub notes: Vec<String>,
    /// Why a scenario was run again.
    pub notes_per_scenario: Vec<String>,
    /// Scenarios whose encoder ran at a real-time priority (SCHED_FIFO).
    pub real_time_scenarios: usize,
    /// Why the run ended before its last scenario (an interrupt), if it did.
    pub cut_short: Option<String>,
    /// A drive on a port: whether the line echoed the encoder's replies, as found, and
    /// the `--echo` it was run with.
    pub echo: Option<(Echo, EchoMode)>,
    /// A drive on a port: the master's characters read with a parity or framing error.
    pub uart_faults: Option<usize>,
    /// A master on a pseudo-terminal: what the probe beside the line saw of the
    /// kernel's delivery.
    pub delivery: Option<crate::line::delivery::DeliveryStats>,
    /// The commands the master declared it never sends (`--not-used`), as "4Ah Read
    /// Data": the scenarios about them are NOT-APPLICABLE.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_used: Vec<String>,
    /// When, where and how the run was made, where the harness made it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run_info: Option<crate::report::RunInfo>,
    /// The record of the wire: every scenario run as the encoder took it in, which
    /// `decode` takes in again (`master::record`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub record: Option<record::MasterRecord>,
}

impl DriveReport {
    /// The run's wall time against its scenarios' own, as the console and the
    /// certificate give it.
    pub fn wall_time_text(&self) -> String {
        format!(
            "{:.0} ms for {:.0} ms of scenarios: ratio {:.2}, repeated runs ({:.0} ms) included",
            self.wall_time_ms,
            self.needed_ms,
            self.wall_time_ms / self.needed_ms.max(1.0),
            self.rerun_ms
        )
    }

    /// The report of a run before its first scenario, with an empty record of the
    /// wire: `master` names the master, the notes are the caller's.
    pub fn new(profile: &Profile, master: String, polling_period_ms: u32, not_used: &[CommandId]) -> DriveReport {
        let tool = format!("hiperface {}", env!("CARGO_PKG_VERSION"));
        DriveReport {
            tool: tool.clone(),
            profile: profile.name.as_str().to_string(),
            edition: format!("{:?}", profile.edition),
            master,
            scenarios: Vec::new(),
            summary: Default::default(),
            output: Default::default(),
            wall_time_ms: 0.0,
            needed_ms: 0.0,
            rerun_ms: 0.0,
            notes: Vec::new(),
            notes_per_scenario: Vec::new(),
            real_time_scenarios: 0,
            cut_short: None,
            echo: None,
            uart_faults: None,
            delivery: None,
            not_used: not_used.iter().map(|c| c.to_string()).collect(),
            run_info: None,
            record: Some(record::MasterRecord {
                format: record::FORMAT.into(),
                tool,
                profile: crate::profile_file::to_toml(profile),
                polling_period_ms,
                not_used: not_used.iter().map(|c| c.byte()).collect(),
                runs: Vec::new(),
                interrupted: false,
            }),
        }
    }

    /// PASSED only when every scenario was run, exercised and graded, none FAILed.
    pub fn outcome(&self) -> Outcome {
        Outcome::of(self.scenarios.iter().map(|s| s.verdict), self.cut_short.is_none())
    }

    /// The findings the certificate puts first (every form, and the console).
    pub fn attention(&self) -> Vec<crate::report::Attention> {
        crate::report::attention(&self.scenarios)
    }

    /// The scenarios not run, by reason ("declared not used").
    pub fn not_run(&self) -> Vec<crate::report::NotRun> {
        crate::report::NotRun::of(&self.scenarios)
    }
}
