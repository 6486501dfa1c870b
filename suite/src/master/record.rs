//! The record of a master certification's wire: per scenario run, everything the
//! encoder took in, in order (each character of the master with its stamp and the
//! settings the encoder listened with, how long the line had gone unwatched before it,
//! when the model was polled, each reply as it really went out, the master's data rate
//! as read), so that `decode` of a master report takes it all in again: a fresh model
//! and a fresh encoder fed the same inputs reach the same timeline, and the scenario is
//! graded again as the run graded it. What is not on the wire (the master process
//! exiting, a port failing) is kept as the run's findings about it.
//!
//! The counterpart of `slave::record`, at the boundary the master's
//! verdicts pass through: the serving loop's calls into its hooks.

use super::encoder::DriveEncoder;
pub use super::inputs::{settings_hex, Input};
use super::scenario::Scenario;
use crate::serve::{Planned, Session};
use crate::verdict::{CaseResult, Finding};
use hiperface_model::{CommandId, Hex, Profile, Slave, UartSettings};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// A run of quiet turns being gathered: its signature (rate read, bps), its times
/// so far (the short form), the last time.
type QuietRun = Option<((bool, Option<u32>), String, u64)>;

/// The inputs with every run of quiet turns of the loop in its short form.
pub fn compact(inputs: Vec<Input>) -> Vec<Input> {
    let mut out: Vec<Input> = Vec::with_capacity(inputs.len() / 4);
    let mut run: QuietRun = None;
    let flush = |run: &mut QuietRun, out: &mut Vec<Input>| {
        if let Some(((rate_read, bps), at, _)) = run.take() {
            out.push(Input::Quiet { at, rate_read, bps });
        }
    };
    let mut i = 0;
    while i < inputs.len() {
        let quiet = match (inputs.get(i), inputs.get(i + 1), inputs.get(i + 2)) {
            (Some(Input::Read { unwatched_us: 0 }), Some(Input::Idle { now_us }), Some(Input::PeerRate { bps })) => {
                Some((*now_us, (true, *bps), 3))
            }
            (Some(Input::Read { unwatched_us: 0 }), Some(Input::Idle { now_us }), _) => {
                Some((*now_us, (false, None), 2))
            }
            _ => None,
        };
        match quiet {
            Some((t, sig, n)) => {
                match run.as_mut() {
                    Some((s, at, last)) if *s == sig && t >= *last => {
                        at.push_str(&format!(" {}", t - *last));
                        *last = t;
                    }
                    _ => {
                        flush(&mut run, &mut out);
                        run = Some((sig, t.to_string(), t));
                    }
                }
                i += n;
            }
            None => {
                flush(&mut run, &mut out);
                if let Some(input) = inputs.get(i) {
                    out.push(input.clone());
                }
                i += 1;
            }
        }
    }
    flush(&mut run, &mut out);
    out
}

/// A quiet turn's time in a record that is no number, or more inputs than a run has.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct BadQuietTurn(pub String);

/// The most inputs one scenario run's record holds written out: 650 times the largest
/// a run of the catalogue takes (`polling.long`, about 1 500), so that a record's short
/// forms cannot be written out into gigabytes (issue 55: 10 MB of quiet turns took
/// 2.4 GB).
pub const MAX_INPUTS: usize = 1_000_000;

/// The inputs with every short form written out again.
pub fn expand(inputs: &[Input]) -> Result<Vec<Input>, BadQuietTurn> {
    let too_many = || BadQuietTurn(format!("more than {MAX_INPUTS} inputs in one scenario run: no run has so many"));
    if inputs.len() > MAX_INPUTS {
        return Err(too_many());
    }
    let mut out = Vec::with_capacity(inputs.len() * 2);
    for input in inputs {
        if out.len() > MAX_INPUTS {
            return Err(too_many());
        }
        let Input::Quiet { at, rate_read, bps } = input else {
            out.push(input.clone());
            continue;
        };
        let mut t = 0u64;
        for (k, word) in at.split_whitespace().enumerate() {
            if out.len() > MAX_INPUTS {
                return Err(too_many());
            }
            let n: u64 = word.parse().map_err(|_| BadQuietTurn(format!("a quiet turn's time `{word}`")))?;
            t = if k == 0 { n } else { t.saturating_add(n) };
            out.push(Input::Read { unwatched_us: 0 });
            out.push(Input::Idle { now_us: t });
            if *rate_read {
                out.push(Input::PeerRate { bps: *bps });
            }
        }
    }
    Ok(out)
}

/// A finding about the run that is not on the wire (the master process, the port).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fact {
    pub verdict: String,
    pub message: String,
}

impl Fact {
    pub fn of(f: &Finding) -> Fact {
        Fact { verdict: f.verdict().label().to_string(), message: f.message().to_string() }
    }

    fn finding(&self) -> Finding {
        match self.verdict.as_str() {
            "NOT-APPLICABLE" => Finding::not_applicable(self.message.clone()),
            "NOT-EXERCISED" => Finding::not_exercised(self.message.clone()),
            "UNKNOWN" => Finding::unknown(self.message.clone()),
            _ => Finding::error(self.message.clone()),
        }
    }
}

/// How the scenario run's encoder was set up.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Start {
    /// The master process's start is power-on (`--exec`).
    #[default]
    PowerOnAtStart,
    /// A drive on a port whose power-on the operator switched.
    PowerOnByOperator,
    /// A drive on a port whose power-on was not seen: operational from the start.
    Operational,
}

/// One run of one scenario.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ScenarioRecord {
    pub id: String,
    pub attempt: u32,
    /// The encoder never served (it could not start): the run's findings as they were.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub early: bool,
    pub start: Start,
    /// Findings about what is not on the wire, before the grade (the master exited,
    /// the port failed), in the order the run made them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub facts: Vec<Fact>,
    pub inputs: Vec<Input>,
    pub end_us: u64,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub cut_short: bool,
    /// Faults of the line itself found in the run (an echo unlike the reply, one with
    /// `--echo off`): when (µs), and what. Facts about the line, never the master's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub line_faults: Vec<(u64, String)>,
    /// The master's process's wait for a processor as sampled (`encoder::changes_only`):
    /// `Timeline::master_slowed`. Empty where not measured, and in older records.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub master_waited: Vec<(u64, u64)>,
    /// The kernel's workers' wait alike: `Timeline::disturbed_by_kernel`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub kernel_waited: Vec<(u64, u64)>,
    /// The processors' pauses alike: `Timeline::master_slowed`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub host_paused: Vec<(u64, u64)>,
}

impl ScenarioRecord {
    /// The record of a run that ended before the encoder served (it could not start,
    /// or the master's declaration left it out): its findings as they were.
    pub fn early_of(result: &CaseResult) -> ScenarioRecord {
        let facts = result.findings.iter().map(Fact::of).collect();
        ScenarioRecord { id: result.id.to_string(), attempt: 1, early: true, facts, ..ScenarioRecord::default() }
    }
}

/// Why a master record cannot be taken in again.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("scenario {id}: {why}")]
    Departs { id: String, why: String },
    #[error("the record names scenario `{0}`, which this catalogue does not have")]
    Unknown(String),
    #[error("not a record of this tool's format: {0}")]
    Format(String),
    #[error("the record's profile does not load: {0}")]
    Profile(#[from] crate::profile_file::ProfileLoadError),
}

/// Take one scenario run in again: a fresh model and encoder, fed the recorded inputs
/// in order, the master's declaration (`not_used`) as the run had it. Returns the
/// graded result and why the harness's timing may have decided something in it (a
/// re-run), as the run itself did.
pub fn replay_scenario(
    profile: Profile,
    scenario: &Scenario,
    polling_period_ms: u32,
    not_used: &[CommandId],
    r: &ScenarioRecord,
) -> Result<(CaseResult, Option<String>), ReplayError> {
    let departs = |why: String| ReplayError::Departs { id: r.id.clone(), why };
    let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
    for f in &r.facts {
        result.push(f.finding());
    }
    if r.early {
        return Ok((result, None));
    }
    let world = (scenario.world)(&profile);
    let slave = match r.start {
        Start::Operational => {
            let mut s = Slave::operational(profile);
            world.apply(&mut s);
            s
        }
        _ => {
            let mut s = Slave::new(profile);
            world.apply_at_power_on(&mut s);
            s
        }
    };
    let inputs = expand(&r.inputs).map_err(|why| departs(format!("the record's inputs: {why}")))?;
    let rates: VecDeque<Option<u32>> = inputs
        .iter()
        .filter_map(|i| match i {
            Input::PeerRate { bps } => Some(*bps),
            _ => None,
        })
        .collect();
    let mut hooks = DriveEncoder::new(profile, scenario, r.start != Start::Operational, None)
        .replaying(rates)
        .declared_not_used(not_used);
    hooks.set_polling_period_ms(polling_period_ms);
    let mut session = Session::new(slave, hooks);
    let mut reply: Option<Planned> = None;
    for (n, input) in inputs.iter().enumerate() {
        match input {
            Input::RealTime { granted } => session.real_time(*granted),
            Input::Read { unwatched_us } => session.handle_read(*unwatched_us),
            Input::Received { ch, listening } => {
                let listening = match listening {
                    Some(hex) => {
                        let byte = u8::from_str_radix(hex, 16).map_err(|_| departs(format!("input {n}: settings")))?;
                        Some(UartSettings::decode(byte).map_err(|_| departs(format!("input {n}: settings")))?)
                    }
                    None => None,
                };
                session.receive((*ch).into(), listening);
            }
            Input::Idle { now_us } => session.handle_timeout(*now_us),
            Input::Frame => {
                if !session.next_frame() {
                    return Err(departs(format!("input {n}: no frame of the model")));
                }
            }
            Input::Reply => reply = session.plan_reply().map_err(|why| departs(format!("input {n}: {why}")))?,
            Input::Sent { frame, start_us, end_us, gap, disturbed_us, split_by_harness } => {
                let mut p =
                    reply.take().ok_or_else(|| departs(format!("input {n}: a reply sent that was not planned")))?;
                if Hex(&p.frame).to_string() != *frame {
                    return Err(departs(format!(
                        "input {n}: the record sent [{frame}], the encoder planned [{}]",
                        Hex(&p.frame)
                    )));
                }
                p.start_us = *start_us;
                p.gap = *gap;
                p.disturbed_us = *disturbed_us;
                p.split_by_harness = *split_by_harness;
                session.on_sent(&p, *end_us);
            }
            Input::PeerRate { .. } | Input::Quiet { .. } => {}
        }
    }
    let mut hooks = session.into_hooks();
    hooks.waited(r.master_waited.clone(), r.kernel_waited.clone(), r.host_paused.clone());
    hooks.finish(r.end_us);
    hooks.timeline.line_faults.extend(r.line_faults.iter().cloned());
    let by_operator = r.start == Start::PowerOnByOperator;
    // Taken in again, the run takes no time of its own.
    let disturbed = super::grade::finish(&mut result, &mut hooks, scenario, 0.0, by_operator, r.cut_short);
    Ok((result, disturbed))
}

/// The verdicts of a master report and of its record taken in again, scenario by
/// scenario: `(id, stated, again)` where they differ.
pub fn compare(stated: &[(String, String)], again: &[CaseResult]) -> Vec<(String, String, String)> {
    let mut out = Vec::new();
    for (i, (id, was)) in stated.iter().enumerate() {
        let now = again.get(i).map_or("missing".to_string(), |r| r.verdict.label().to_string());
        if *was != now {
            out.push((id.clone(), was.clone(), now));
        }
    }
    out
}

/// The record's format, as written into it.
pub const FORMAT: &str = "hiperface-master-record/1";

/// The record of a master certification: the encoder's profile and every scenario run,
/// repeated runs too, in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MasterRecord {
    pub format: String,
    pub tool: String,
    /// The encoder's profile, as TOML.
    pub profile: String,
    pub polling_period_ms: u32,
    /// The commands the master declared it never sends (`--not-used`), as bytes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_used: Vec<u8>,
    pub runs: Vec<ScenarioRecord>,
    /// The run was cut short by the operator (its outcome cannot be PASSED).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub interrupted: bool,
}

/// The scenarios of a record taken in again: each run graded as the run graded it,
/// the last run of each scenario its result (with the number of runs). `Err` where
/// the record names a scenario this catalogue lacks or departs from what the encoder
/// does; a repeated run whose grade no longer asks for a repetition is named.
pub fn replay(record: &MasterRecord) -> Result<(Profile, Vec<CaseResult>, Vec<String>), ReplayError> {
    if record.format != FORMAT {
        return Err(ReplayError::Format(record.format.clone()));
    }
    let profile = crate::profile_file::parse_recorded(&record.profile, std::path::Path::new("the record's profile"))?;
    let catalogue = super::scenarios::catalogue();
    let not_used: Vec<CommandId> = record.not_used.iter().map(|b| CommandId::decode(*b)).collect();
    let mut results: Vec<CaseResult> = Vec::new();
    let mut notes = Vec::new();
    // The runs of each scenario, in the order the scenarios first ran: a scenario still
    // undecided after its runs is run again at the end of the run (its later runs come
    // after the other scenarios').
    let mut grouped: Vec<(&str, Vec<&ScenarioRecord>)> = Vec::new();
    for run in &record.runs {
        match grouped.iter_mut().find(|(id, _)| *id == run.id) {
            Some((_, attempts)) => attempts.push(run),
            None => grouped.push((&run.id, vec![run])),
        }
    }
    for (id, attempts) in grouped {
        let scenario = catalogue.iter().find(|s| s.id == id).ok_or_else(|| ReplayError::Unknown(id.to_string()))?;
        let encoder = scenario.encoder.map_or(profile, |make| make(profile));
        let mut last = None;
        for (i, run) in attempts.iter().enumerate() {
            let (mut result, disturbed) = replay_scenario(encoder, scenario, record.polling_period_ms, &not_used, run)?;
            let repeated = i + 1 < attempts.len();
            if repeated && disturbed.is_none() {
                notes.push(format!("{}: run {} was repeated, but graded again it asks for no repetition", id, i + 1));
            }
            result.attempts = attempts.len() as u32;
            last = Some(result);
        }
        results.extend(last);
    }
    Ok((profile, results, notes))
}

#[cfg(test)]
mod tests;
