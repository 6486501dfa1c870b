//! The runner: the catalogue case by case, restores after each, the safety read-back
//! around the whole run, and the report.

use super::ctx::Tally;
use super::record::{Record, RecordError, Recorder, Replay};
use super::safety::Snapshot;
use super::{cases, Case, CaseError, Ctx, Identity, Needs, Options, Safety};
use crate::exchange::{Bus, BusMaster};
use crate::line::frame_encoder::{FrameEncoder, FramedEncoder};
use crate::line::virtual_line::VirtualLine;
use crate::line::{Line, LineError, LineKind};
use crate::verdict::timing::TimingMode;
use crate::verdict::{glob_match, CaseResult, Finding, Outcome};
use crate::verdict::{END_BUDGET, MAX_ATTEMPTS};
use hiperface_model::{CommandId, Grading, Profile, Slave};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Response-time statistics of one command's own replies: the fastest, median and
/// slowest by the most the line's uncertainty allows, and the slowest by the least it
/// allows (what is proven), against the command's limit.
#[derive(Debug, Clone, Serialize)]
pub struct TimingStats {
    pub command: String,
    pub count: usize,
    /// The command's maximum response time (000:T10), ms.
    pub limit_ms: u32,
    pub min_us: i64,
    pub median_us: i64,
    pub max_us: i64,
    /// The slowest reply by the least the line's uncertainty allows: a FAIL needs this
    /// over the limit (with the tolerance).
    pub max_least_us: i64,
}

/// The result of a whole run.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub tool: String,
    pub profile: String,
    pub edition: String,
    pub line: String,
    pub line_kind: Option<LineKind>,
    /// Facts about the line that bear on timing verdicts (an adapter's latency timer).
    pub line_notes: Vec<String>,
    /// What the run found of the line's echo (`--echo`), and the mode it ran in.
    pub echo: Option<(crate::line::echo::Echo, crate::line::echo::EchoMode)>,
    pub timing: TimingMode,
    /// Jitter allowed for the line on every timing verdict, µs.
    pub tolerance_us: u64,
    /// The harness's own scheduling delay, at most, in any exchange, µs: added to the
    /// tolerance of that exchange's timing verdicts.
    pub harness_late_us: u64,
    /// The most the line itself may have delayed any exchange (both ways), as measured
    /// beside it, µs; and what the probe beside it saw over the run (a pseudo-terminal).
    pub line_late_us: u64,
    pub delivery: Option<crate::line::delivery::DeliveryStats>,
    pub grading: String,
    pub identity: Identity,
    pub cases: Vec<CaseResult>,
    pub summary: BTreeMap<&'static str, usize>,
    pub response_times: Vec<TimingStats>,
    pub safety: Safety,
    pub wall_time_ms: f64,
    pub line_time_ms: f64,
    pub notes: Vec<String>,
    /// The cases not run, grouped by why (and so by the flag that would run them:
    /// "writes EEPROM; run with --allow-writes"), for the top of every form.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub not_run: Vec<crate::report::NotRun>,
    /// When, where and how the run was made, where the harness made it.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub run_info: Option<crate::report::RunInfo>,
    /// Set when the run stopped early (port gone, Ctrl-C): the report is partial.
    pub aborted: Option<String>,
    /// The record of the wire: what `decode` grades again (see `record`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub record: Option<Record>,
}

impl Report {
    pub(crate) fn empty(profile: &Profile, line: &str, options: &Options) -> Report {
        Report {
            tool: format!("hiperface {}", env!("CARGO_PKG_VERSION")),
            profile: profile.name.to_string(),
            edition: format!("{:?}", profile.edition),
            line: line.to_string(),
            line_kind: None,
            line_notes: Vec::new(),
            echo: None,
            timing: options.timing,
            tolerance_us: 0,
            harness_late_us: 0,
            line_late_us: 0,
            delivery: None,
            grading: format!("{:?}", options.grading),
            identity: Identity::default(),
            cases: Vec::new(),
            summary: BTreeMap::new(),
            response_times: Vec::new(),
            safety: Safety::default(),
            wall_time_ms: 0.0,
            line_time_ms: 0.0,
            notes: Vec::new(),
            not_run: Vec::new(),
            run_info: None,
            aborted: None,
            record: None,
        }
    }

    /// The report of a run that could not start (e.g. the port cannot be opened).
    pub fn aborted_before_start(profile: &Profile, line: &str, options: &Options, reason: &str) -> Report {
        Report { aborted: Some(reason.to_string()), ..Report::empty(profile, line, options) }
    }

    /// What the run adds up to: PASSED only when every case that ran was observed and
    /// none FAILed, and the run was complete. (Safety is reported apart: it is the
    /// operator's information, not a verdict on the device.)
    pub fn outcome(&self) -> Outcome {
        Outcome::of(self.cases.iter().map(|c| c.verdict), self.aborted.is_none())
    }

    /// The cases run again because the harness's own lateness left a verdict untold:
    /// "id (N runs)".
    pub fn rerun_cases(&self) -> Vec<String> {
        self.cases.iter().filter(|c| c.attempts > 1).map(|c| format!("{} ({} runs)", c.id, c.attempts)).collect()
    }

    /// The findings the certificate puts first (every form, and the console).
    pub fn attention(&self) -> Vec<crate::report::Attention> {
        crate::report::attention(&self.cases)
    }
}

/// Certify an encoder under test in-process: the catalogue in virtual time against
/// `encoder`, given frame by frame (see [`FrameEncoder`]), as [`run`] certifies a
/// device on a line; the report is the same, with the record `decode` plays back.
///
/// The encoder's world (its shaft, its temperature, what it found at start-up) is its
/// own unless `options.world` gives it: then the caller has put the encoder in that
/// world (what it leaves out at its default: 25 °C, the shaft at 0 and at rest, no
/// fault), the lockstep model is put in the same one, and every value is graded
/// exactly, the warning bit and the error stack's codes included. Without it, values
/// of the physical world are graded by range, as on a real device.
pub fn in_process<E: FrameEncoder>(encoder: E, profile: Profile, options: &Options) -> Report {
    let line = VirtualLine::new(FramedEncoder::new(encoder, &profile));
    let grading = if options.world.is_default() { Grading::Range } else { Grading::Exact };
    let options = Options { grading, ..options.clone() };
    run(Box::new(line), profile, &options, |_, _, _| {})
}

/// Run the catalogue. `progress` is called after each case. The report holds the
/// record of the wire (`Report::record`).
pub fn run<'a>(
    line: Box<dyn Line + 'a>,
    profile: Profile,
    options: &Options,
    progress: impl FnMut(usize, usize, &CaseResult),
) -> Report {
    let mut live = BusMaster::new(line, profile.edition);
    let mut recorder = Recorder::new(&mut live);
    let mut report = run_on(&mut recorder, profile, options, progress);
    report.record = Some(recorder.finish(&profile, options));
    report
}

/// What a record played back to the catalogue gives: the run again, from the record
/// of its wire, with the record's profile, options and line. `Err` where the record
/// cannot be read; a record that departs from this catalogue ends the run there with
/// the reason (`Report::aborted`), its verdicts ERROR from that point.
pub fn replay(record: &Record, progress: impl FnMut(usize, usize, &CaseResult)) -> Result<Report, RecordError> {
    if record.format != super::record::FORMAT {
        return Err(RecordError::Format(record.format.clone()));
    }
    let profile = crate::profile_file::parse_recorded(&record.profile, std::path::Path::new("the record's profile"))
        .map_err(|e| RecordError::Profile(e.to_string()))?;
    let options = record.options.options()?;
    let mut bus = Replay::new(record, profile.edition);
    let mut report = run_on(&mut bus, profile, &options, progress);
    if let (None, Some(why)) = (&report.aborted, bus.departure()) {
        report.aborted = Some(why);
    }
    Ok(report)
}

/// What the runs of the cases leave for the run's end.
#[derive(Default)]
struct Runs {
    /// Requests run to restore what cases changed.
    restores_run: usize,
    /// Why the device's state cannot be read back after the run, if it cannot.
    not_read_back: Option<String>,
    /// An interrupt is the operator's, not the device's: what it cut short is
    /// NOT-EXERCISED, not an ERROR.
    interrupted: bool,
    /// The line time the last run of a case took, µs.
    last_run_us: u64,
}

impl Runs {
    /// Run `case` into `result` (fresh, or the undecided result of its `runs_before`
    /// runs so far) up to [`MAX_ATTEMPTS`] times more, again while the harness's own lateness left a
    /// verdict untold; a run that ends the whole run sets `aborted`. Returns whether its
    /// last run was still undecided so.
    #[allow(clippy::too_many_arguments)]
    fn attempt(
        &mut self,
        case: &Case,
        master: &mut dyn Bus,
        model: &mut Slave,
        tally: &mut Tally,
        options: &Options,
        result: &mut CaseResult,
        runs_before: u32,
        aborted: &mut Option<String>,
    ) -> bool {
        let first = runs_before + 1;
        for attempt in first..first + MAX_ATTEMPTS {
            if attempt > 1 {
                *result = case.result();
            }
            let run_start_us = master.now_us();
            let mut ctx = Ctx::new(master, model, result, tally, options);
            let outcome = (case.run)(&mut ctx);
            let gone = matches!(outcome, Err(CaseError::Line(LineError::Gone(_))) | Err(CaseError::Silent));
            if let Err(e) = &outcome {
                self.interrupted |= matches!(e, CaseError::Interrupted);
                ctx.push(if self.interrupted {
                    Finding::not_exercised(format!("cut short: {e}"))
                } else {
                    Finding::error(e.to_string())
                });
                if !matches!(e, CaseError::Abort(_)) {
                    *aborted = Some(e.to_string());
                }
            }
            // Restore what the case changed, also after a failure or Ctrl-C.
            if !gone && ctx.has_guards() {
                match ctx.restore() {
                    Ok(n) => self.restores_run += n,
                    Err(e) => ctx.note(format!("restoring failed: {e}")),
                }
            }
            let disturbed = ctx.disturbed();
            if gone {
                self.not_read_back = outcome.as_ref().err().map(|e| e.to_string());
            }
            result.close_unobserved("the case");
            result.attempts = attempt;
            self.last_run_us = master.now_us().saturating_sub(run_start_us);
            // The harness's own lateness left a verdict untold: run the case again,
            // as a master scenario is, so that the same device gets the same
            // verdicts on a busy machine as on an idle one.
            if !disturbed || outcome.is_err() {
                return false;
            }
        }
        true
    }
}

/// Run the catalogue on a bus, live or played back.
fn run_on(
    master: &mut dyn Bus,
    profile: Profile,
    options: &Options,
    mut progress: impl FnMut(usize, usize, &CaseResult),
) -> Report {
    let started = Instant::now();
    let facts = master.facts();
    let mut report = Report::empty(&profile, &facts.describe, options);
    report.line_kind = Some(facts.kind);
    report.tolerance_us = facts.tolerance_us;
    let mut model = Slave::operational(profile);
    options.world.apply(&mut model);
    let mut tally = Tally::default();
    // What the device reports of its stored state, before anything is changed.
    let before = Snapshot::read(master, &model, &mut tally);
    // A real device is not in its factory state: adopt what it reports.
    if options.grading == Grading::Range {
        report.notes.extend(adopt(&mut model, &before));
    }
    let initial = model.nonvolatile().clone();
    let selected = select(options.cases.as_deref());
    let mut runs = Runs::default();
    // Each case's result, and the line time its last run took (µs).
    let mut results: Vec<Option<CaseResult>> = vec![None; selected.len()];
    let mut last_run_us = vec![0u64; selected.len()];
    let run_start_us = master.now_us();
    // The cases still undecided after their runs (the harness's own lateness left a
    // verdict untold each time): run again once the others are done, when a busy spell
    // may have passed, within a budget of time.
    let mut undecided: Vec<usize> = Vec::new();
    for (i, case) in selected.iter().enumerate() {
        let mut result = case.result();
        let case_start = Instant::now();
        let excluded = (case.applies)(&profile).map(str::to_string).or_else(|| match case.needs {
            Needs::Writes if !options.allow_writes => Some("writes EEPROM; run with --allow-writes".into()),
            Needs::CounterChange if !options.allow_counter_change => {
                Some("changes the counter, which cannot be restored; run with --allow-counter-change".into())
            }
            Needs::Adjustment if !options.allow_adjustment => {
                Some("runs a Sensor Adjustment, which may recalibrate the sensor; run with --allow-adjustment".into())
            }
            _ => None,
        });
        if let Some(reason) = excluded {
            result.push(Finding::not_applicable(reason));
        } else if let Some(why) = &report.aborted {
            let why = format!("not run: {why}");
            result.push(if runs.interrupted { Finding::not_exercised(why) } else { Finding::error(why) });
        } else {
            let still_undecided =
                runs.attempt(case, master, &mut model, &mut tally, options, &mut result, 0, &mut report.aborted);
            if let Some(t) = last_run_us.get_mut(i) {
                *t = runs.last_run_us;
            }
            if still_undecided {
                undecided.push(i);
            }
        }
        result.duration_ms = case_start.elapsed().as_secs_f64() * 1000.0;
        progress(i + 1, selected.len(), &result);
        if let Some(slot) = results.get_mut(i) {
            *slot = Some(result);
        }
    }
    // The undecided cases again, while the time for it stays within the budget. Line
    // time, not the machine's: a record played back decides as the run did.
    let end_start_us = master.now_us();
    let budget_us = (END_BUDGET * end_start_us.saturating_sub(run_start_us) as f64) as u64;
    for i in undecided {
        let (Some(case), Some(Some(result))) = (selected.get(i), results.get_mut(i)) else { continue };
        let spent_us = master.now_us().saturating_sub(end_start_us);
        let last_us = last_run_us.get(i).copied().unwrap_or(0);
        if report.aborted.is_some() || spent_us + last_us > budget_us {
            report.notes.push(format!(
                "{}: not run again at the end: {}",
                case.id,
                if report.aborted.is_some() { "the run ended" } else { "the time for runs again was spent" }
            ));
            continue;
        }
        let case_start = Instant::now();
        let runs_before = result.attempts;
        runs.attempt(case, master, &mut model, &mut tally, options, result, runs_before, &mut report.aborted);
        result.duration_ms = case_start.elapsed().as_secs_f64() * 1000.0;
        progress(i + 1, selected.len(), result);
    }
    report.cases.extend(results.into_iter().flatten());
    let Runs { restores_run, not_read_back, .. } = runs;
    // Read at the end: what the run found out about the line (its echo) is known now.
    let found = master.findings();
    report.line_notes = found.notes;
    report.echo = found.echo;
    let after = match not_read_back {
        None => Ok(Snapshot::read(master, &model, &mut tally)),
        Some(why) => Err(why),
    };
    let after = after.as_ref().map_err(String::as_str);
    report.safety = Safety::compare(&before, after, &initial, model.nonvolatile(), options.allow_counter_change);
    report.safety.restores_run = restores_run;
    report.safety.eeprom_writes = model.eeprom_writes();
    report.safety.notes.append(&mut tally.notes);
    report.harness_late_us = tally.harness_late_us;
    report.line_late_us = tally.line_late_us;
    report.delivery = found.delivery;
    for r in &report.cases {
        *report.summary.entry(r.verdict.label()).or_insert(0) += 1;
    }
    report.not_run = crate::report::NotRun::of(&report.cases);
    report.response_times = tally
        .response_times
        .into_iter()
        .filter_map(|(cmd, (times, limit_ms))| {
            let max_least_us = times.iter().map(|t| t.0).max()?;
            let mut most: Vec<i64> = times.iter().map(|t| t.1).collect();
            most.sort_unstable();
            Some(TimingStats {
                command: CommandId::decode(cmd).to_string(),
                count: most.len(),
                limit_ms,
                min_us: *most.first()?,
                median_us: *most.get(most.len() / 2)?,
                max_us: *most.last()?,
                max_least_us,
            })
        })
        .collect();
    report.identity = tally.identity;
    report.wall_time_ms = started.elapsed().as_secs_f64() * 1000.0;
    report.line_time_ms = tally.line_time_us as f64 / 1000.0;
    report.notes.push(
        "Power cycling is out of reach on a serial line: the power-up cases start from an Encoder Reset (53h), which 000:T29 says leads to the same initialization as power-on.".into(),
    );
    report
}

/// The cases whose id matches `globs` (`*`, `?`, comma-separated; all without), in
/// run order.
pub fn select(globs: Option<&str>) -> Vec<Case> {
    cases::catalogue().into_iter().filter(|c| globs.is_none_or(|g| glob_match(g, c.id))).collect()
}

/// A glob of cases (`--cases`) that selects none: nothing selected is nothing graded,
/// refused before a run (the command, C and Python alike).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("no case matches `{glob}` (the cases: {groups})")]
pub struct NoCaseMatches {
    pub glob: String,
    /// The catalogue's groups ("address.*, analog.*, ...").
    pub groups: String,
}

/// `globs` checked: it selects at least one case of the catalogue.
pub fn check_selection(globs: &str) -> Result<(), NoCaseMatches> {
    if !select(Some(globs)).is_empty() {
        return Ok(());
    }
    let mut groups: Vec<String> =
        cases::catalogue().iter().map(|c| format!("{}.*", c.id.split('.').next().unwrap_or(c.id))).collect();
    groups.sort();
    groups.dedup();
    Err(NoCaseMatches { glob: globs.to_string(), groups: groups.join(", ") })
}

/// Let the lockstep model adopt a real device's data field table and counter; a note
/// for the report.
fn adopt(model: &mut Slave, s: &Snapshot) -> Option<String> {
    let ((free, count), statuses) = (s.memory?, s.statuses.as_ref()?);
    let counter = s.counter.unwrap_or(0);
    model.adopt(statuses, free, counter).then(|| {
        format!(
            "Adopted from the device before the catalogue: {count} data fields, {free} free blocks, counter {}.",
            s.counter.map_or("unknown".into(), |c| c.to_string())
        )
    })
}
