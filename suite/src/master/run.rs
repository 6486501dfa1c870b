//! The scenario loop of a master's certification, once for every line: each chosen
//! scenario run on the line ([`ScenarioLine`]: a pseudo-terminal or a drive's port in
//! real time, the virtual line of an in-process master), left out where the master
//! declared it never sends what it is about, run again where the harness's own timing
//! may have decided something (at most [`MAX_ATTEMPTS`] in a row, and once more at the
//! end of the run within [`END_BUDGET`]), not run after an interrupt; each run's record
//! kept, the results summed up in catalogue order.

use super::encoder::{changes_only, DriveEncoder};
use super::grade::finish;
use super::record::{compact, Fact, ScenarioRecord, Start};
use super::scenario::Scenario;
use super::{declared_out, DriveReport};
use crate::verdict::{CaseResult, Finding, END_BUDGET, MAX_ATTEMPTS};
use hiperface_model::{CommandId, Profile};
use std::collections::VecDeque;

/// One run of one scenario on a line.
#[derive(Debug, Clone)]
pub struct ScenarioRun {
    pub result: CaseResult,
    /// What the master printed, where it is a process (`None` in-process).
    pub output: Option<String>,
    /// From power-on to the scenario's end, µs.
    pub length_us: u64,
    /// Why the harness's timing may have decided something in this run (never in
    /// virtual time).
    pub disturbed: Option<String>,
    /// The encoder's thread ran at a real-time priority.
    pub real_time: bool,
    /// The master's characters read with a parity or framing error, where the line
    /// can tell (a drive's port; `None` elsewhere).
    pub uart_faults: Option<usize>,
    /// The record of the run's wire (`master::record`).
    pub record: ScenarioRecord,
}

impl ScenarioRun {
    /// A run that ended before the encoder served (it could not start).
    pub fn early(result: CaseResult) -> ScenarioRun {
        let record = ScenarioRecord::early_of(&result);
        ScenarioRun { result, output: None, length_us: 0, disturbed: None, real_time: false, uart_faults: None, record }
    }

    /// A run the encoder served to its end (`hooks.finish` called): graded, with what
    /// the timeline measured. `start`: how its encoder was set up, for the record;
    /// `duration_ms`: the run's wall time.
    pub fn graded(
        mut result: CaseResult,
        mut hooks: DriveEncoder,
        scenario: &Scenario,
        duration_ms: f64,
        start: Start,
        cut_short: bool,
    ) -> ScenarioRun {
        let record = ScenarioRecord {
            id: scenario.id.to_string(),
            attempt: 1,
            early: false,
            start,
            facts: result.findings.iter().map(Fact::of).collect(),
            inputs: compact(hooks.take_log()),
            end_us: hooks.timeline.end_us,
            cut_short,
            line_faults: hooks.timeline.line_faults.clone(),
            master_waited: changes_only(&hooks.timeline.master_waited),
            kernel_waited: changes_only(&hooks.timeline.kernel_waited),
            host_paused: changes_only(&hooks.timeline.host_paused),
        };
        let by_operator = start == Start::PowerOnByOperator;
        let disturbed = finish(&mut result, &mut hooks, scenario, duration_ms, by_operator, cut_short);
        let (length_us, real_time) = (hooks.timeline.end_us, hooks.timeline.real_time);
        let uart_faults = hooks.port().map(|_| hooks.timeline.uart_faults);
        ScenarioRun { result, output: None, length_us, disturbed, real_time, uart_faults, record }
    }
}

/// Where the scenarios run: the master under test and the line to it.
pub trait ScenarioLine {
    /// One run of `scenario` (a fresh encoder of `profile`, a fresh power-on).
    fn run(&mut self, profile: Profile, scenario: &Scenario) -> ScenarioRun;
    /// Whether the run was interrupted (Ctrl-C or SIGTERM): the scenario under way
    /// ends, no other starts.
    fn interrupted(&self) -> bool {
        false
    }
}

/// How far a master's run is, as it goes: for a progress bar and the console's lines.
#[derive(Debug)]
pub enum Progress<'a> {
    /// Scenario `index` (1-based) of `total` starts, its `attempt`th run (2 and more: it
    /// is run again because the harness's timing was disturbed).
    Starting { index: usize, total: usize, id: &'static str, attempt: u32 },
    /// Scenario `index` of `total` has its result.
    Done { index: usize, total: usize, result: &'a CaseResult },
}

/// What the scenario loop needs besides the line.
pub struct Catalogue<'a> {
    /// The scenarios chosen, in run order.
    pub chosen: &'a [Scenario],
    /// The encoder's profile (a scenario may make its own of it).
    pub profile: Profile,
    /// The commands the master declares it never sends.
    pub not_used: &'a [CommandId],
}

/// Run `catalogue` on `line` into `report`: its scenarios, summary, record, output,
/// times and notes per scenario. Returns how many scenarios were not run (an interrupt).
pub fn run_catalogue(
    report: &mut DriveReport,
    catalogue: &Catalogue,
    line: &mut dyn ScenarioLine,
    progress: &mut dyn FnMut(Progress),
) -> usize {
    let n = catalogue.chosen.len();
    let mut not_run = 0;
    // Each scenario's result, its runs so far and the length of the run it rests on.
    let mut results: Vec<Option<CaseResult>> = vec![None; n];
    let mut attempts = vec![0u32; n];
    let mut rests_on_ms = vec![0.0f64; n];
    // The scenarios still undecided after their runs (the harness disturbed each run):
    // run again once the others are done, when a busy spell may have passed.
    let mut undecided: Vec<usize> = Vec::new();
    let mut queue: VecDeque<usize> = (0..n).collect();
    let mut at_end = false;
    while let Some(i) = queue.pop_front() {
        let Some(scenario) = catalogue.chosen.get(i) else { continue };
        let profile = scenario.encoder.map_or(catalogue.profile, |make| make(catalogue.profile));
        let result = if let Some(result) = declared_out(scenario, catalogue.not_used) {
            // Left out by the master's declaration: nothing of it runs.
            if let Some(r) = report.record.as_mut() {
                r.runs.push(ScenarioRecord::early_of(&result));
            }
            result
        } else if line.interrupted() && !at_end {
            // Not run: nothing about the master is known from it.
            let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
            result.push(Finding::not_exercised("not run: the run was interrupted"));
            not_run += 1;
            if let Some(r) = report.record.as_mut() {
                r.runs.push(ScenarioRecord::early_of(&result));
            }
            result
        } else if at_end && (line.interrupted() || report.rerun_ms + rests_on_ms[i] > END_BUDGET * report.needed_ms) {
            // Not run again: its result stays the undecided one.
            report.notes_per_scenario.push(format!(
                "{}: not run again at the end: {}",
                scenario.id,
                if line.interrupted() { "the run was interrupted" } else { "the time for runs again was spent" }
            ));
            continue;
        } else {
            let limit = attempts[i] + MAX_ATTEMPTS;
            if at_end {
                // The undecided run is one run again now.
                report.rerun_ms += rests_on_ms[i];
                report.needed_ms -= rests_on_ms[i];
            }
            let run = loop {
                attempts[i] += 1;
                let attempt = attempts[i];
                progress(Progress::Starting { index: i + 1, total: n, id: scenario.id, attempt });
                let run = line.run(profile, scenario);
                if let Some(faults) = run.uart_faults {
                    *report.uart_faults.get_or_insert(0) += faults;
                }
                if let Some(r) = report.record.as_mut() {
                    r.runs.push(ScenarioRecord { attempt, ..run.record.clone() });
                }
                // The harness's own timing was disturbed: run the scenario again, so
                // that the verdict rests on an undisturbed run where one can be had.
                match &run.disturbed {
                    Some(why) if attempt < limit && !line.interrupted() => {
                        report.rerun_ms += ms(run.length_us);
                        report.notes_per_scenario.push(format!("{}: run again: {why}", scenario.id));
                    }
                    Some(_) if !at_end && !line.interrupted() => {
                        undecided.push(i);
                        break run;
                    }
                    _ => break run,
                }
            };
            let ScenarioRun { mut result, output, length_us, real_time, .. } = run;
            result.attempts = attempts[i];
            if !at_end {
                report.real_time_scenarios += usize::from(real_time);
            }
            report.needed_ms += ms(length_us);
            if let Some(slot) = rests_on_ms.get_mut(i) {
                *slot = ms(length_us);
            }
            if let Some(output) = output {
                report.output.insert(scenario.id.to_string(), output);
            }
            result
        };
        progress(Progress::Done { index: i + 1, total: n, result: &result });
        if let Some(slot) = results.get_mut(i) {
            *slot = Some(result);
        }
        if queue.is_empty() && !at_end {
            at_end = true;
            queue.extend(undecided.drain(..));
        }
    }
    for result in results.into_iter().flatten() {
        *report.summary.entry(result.verdict.label().to_string()).or_default() += 1;
        report.scenarios.push(result);
    }
    not_run
}

/// µs as ms.
fn ms(us: u64) -> f64 {
    us as f64 / 1000.0
}
