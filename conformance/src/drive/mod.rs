//! Certifying a master (a drive): the harness plays the encoder, one scenario at a
//! time, and grades what the master sends against its obligations
//! (`hiperface_model::master::obligations`). A FAIL needs a normative "must" of 000 that
//! binds the profile's edition; the recommendations of 000 (read the status after
//! power-on, read out the warning's codes, react to faults as Table 74 says) are
//! NON-STRICT at most.

pub mod cli;
pub mod encoder;
pub mod process;
pub mod reference;
pub mod scenarios;
pub mod timeline;

use crate::simulate::serve_with;
use crate::verdict::{CaseResult, Finding, Outcome};
use encoder::{DriveEncoder, Timeline};
pub use hiperface_model::master::obligations::POLLING_PERIOD_MS;
use hiperface_model::master::obligations::{Observation, Rule};
use hiperface_model::{Profile, Slave, UartSettings};
use process::MasterProcess;
use scenarios::Scenario;
use serde::Serialize;
use serialport::SerialPort;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Where the master under test is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Attach {
    /// A process started for each scenario on a fresh pseudo-terminal: its command
    /// line, `{port}` standing for the pseudo-terminal's path. Its start is power-on.
    Exec(String),
    /// A drive on a serial port the harness serves as the encoder.
    Port { path: String, power_on: PowerOn },
}

impl std::fmt::Display for Attach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Attach::Exec(cmd) => f.write_str(cmd),
            Attach::Port { path, .. } => write!(f, "the drive on {path}"),
        }
    }
}

/// How the harness learns when a drive on a real port powers the encoder on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PowerOn {
    /// The operator switches the drive off and on when asked, then presses Enter.
    Prompt,
    /// Not at all: the encoder is operational from the start, the scenarios about
    /// start-up are not applicable, and the rules about power-on are not graded.
    Unseen,
}

/// The person at the drive with `--power-on prompt`: switches it off and on for each
/// scenario. The harness's encoder powers on when [`Operator::switch_on`] is called,
/// so the drive's power-on is at the same time or later.
pub trait Operator {
    /// Switch the drive off; return when it is off.
    fn switch_off(&mut self, scenario: &str);
    /// Switch the drive on now (return at once).
    fn switch_on(&mut self, scenario: &str);
}

/// The operator at the console: asked on standard error, confirms with Enter.
pub struct ConsoleOperator;

impl Operator for ConsoleOperator {
    fn switch_off(&mut self, scenario: &str) {
        eprintln!("scenario {scenario}: switch the drive OFF, then press Enter");
        let mut line = String::new();
        let _ = std::io::stdin().read_line(&mut line);
    }

    fn switch_on(&mut self, scenario: &str) {
        eprintln!("scenario {scenario}: switch the drive ON now");
    }
}

/// How a master is run.
#[derive(Debug, Clone)]
pub struct Options {
    pub attach: Attach,
    /// Only scenarios whose id matches (globs, comma-separated).
    pub scenarios: Option<String>,
    /// The application's polling period (000:3.2.2 "a sufficient cyclic request").
    pub polling_period_ms: u32,
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
}

/// How often a scenario is run at most when the harness's own timing was disturbed.
pub const MAX_ATTEMPTS: u32 = 3;

/// One run of one scenario.
struct ScenarioRun {
    result: CaseResult,
    /// What the master printed.
    output: String,
    /// From power-on to the scenario's end, ms.
    length_ms: u64,
    /// Why the harness's timing may have decided something in this run.
    disturbed: Option<String>,
    /// The encoder's thread ran at a real-time priority.
    real_time: bool,
}

impl ScenarioRun {
    /// A run that ended before the encoder served (it could not start).
    fn early(result: CaseResult) -> ScenarioRun {
        ScenarioRun { result, output: String::new(), length_ms: 0, disturbed: None, real_time: false }
    }
}

impl DriveReport {
    /// PASSED only when every scenario that ran was exercised and graded, none FAILed.
    pub fn outcome(&self) -> Outcome {
        Outcome::of(self.scenarios.iter().map(|s| s.verdict), true)
    }
}

/// Run the catalogue against the master `options.attach`, for an encoder of `profile`;
/// with `--power-on prompt` the operator at the console switches the drive.
pub fn run(profile: Profile, options: &Options, progress: impl FnMut(usize, usize, &CaseResult)) -> DriveReport {
    run_with(profile, options, &mut ConsoleOperator, progress)
}

/// As [`run`], with `operator` switching a drive on a port (`--power-on prompt`).
pub fn run_with(
    profile: Profile,
    options: &Options,
    operator: &mut dyn Operator,
    mut progress: impl FnMut(usize, usize, &CaseResult),
) -> DriveReport {
    let started = Instant::now();
    let chosen = scenarios::chosen(options.scenarios.as_deref());
    let mut report = DriveReport {
        tool: format!("hiperface {}", env!("CARGO_PKG_VERSION")),
        profile: profile.name.as_str().to_string(),
        edition: format!("{:?}", profile.edition),
        master: options.attach.to_string(),
        scenarios: Vec::new(),
        summary: Default::default(),
        output: Default::default(),
        wall_time_ms: 0.0,
        needed_ms: 0.0,
        rerun_ms: 0.0,
        notes: Vec::new(),
        notes_per_scenario: Vec::new(),
        real_time_scenarios: 0,
    };
    report.notes.push(match options.attach {
        Attach::Exec(_) => "The master's data rate was read from its pseudo-terminal's settings; parity and character \
                            size cannot be read there (Linux keeps a pseudo-terminal at 8 bits, no parity) and were \
                            not graded."
            .into(),
        Attach::Port { .. } => "The master's data rate and parity were not read: on a real port a wrong one shows as \
                                frames that are no requests."
            .into(),
    });
    report.notes.push(format!(
        "A sufficient cyclic request (000:3.2.2) was taken as one at least every {} ms.",
        options.polling_period_ms
    ));
    match options.attach {
        Attach::Port { power_on: PowerOn::Prompt, .. } => report.notes.push(
            "The encoder powered on when the operator was told to switch the drive on; the drive powered on then \
             or later. A request during initialization is graded; one in the settings-change window may be the \
             operator's delay and is NON-STRICT at most."
                .into(),
        ),
        Attach::Port { power_on: PowerOn::Unseen, .. } => report.notes.push(
            "The drive's power-on was not seen: the encoder was operational from the start of each scenario; \
             the rules about initialization, the start-up windows and the status after power-on were not graded."
                .into(),
        ),
        Attach::Exec(_) => {}
    }
    let n = chosen.len();
    // A drive on a port: the port stays open for the whole run.
    let port = match &options.attach {
        Attach::Port { path, .. } => Some(open_port(path)),
        Attach::Exec(_) => None,
    };
    for (i, scenario) in chosen.iter().enumerate() {
        let profile = scenario.encoder.map_or(profile, |make| make(profile));
        let mut attempt = 0;
        let run = loop {
            attempt += 1;
            let run = match (&options.attach, &port) {
                (Attach::Exec(exec), _) => run_scenario(profile, scenario, exec, options.polling_period_ms),
                (Attach::Port { power_on, .. }, Some(Ok(port))) => {
                    let drive = Drive { port: port.as_ref(), power_on: *power_on, operator: &mut *operator };
                    on_port(profile, scenario, drive, options.polling_period_ms)
                }
                (Attach::Port { path, .. }, _) => {
                    let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
                    let why = port.as_ref().and_then(|p| p.as_ref().err().cloned()).unwrap_or_default();
                    result.push(Finding::error(format!("cannot open {path}: {why}")));
                    ScenarioRun::early(result)
                }
            };
            // The harness's own timing was disturbed: run the scenario again, so that
            // the verdict rests on an undisturbed run where one can be had.
            match &run.disturbed {
                Some(why) if attempt < MAX_ATTEMPTS => {
                    report.rerun_ms += run.length_ms as f64;
                    report.notes_per_scenario.push(format!("{}: run again: {why}", scenario.id));
                }
                _ => break run,
            }
        };
        let ScenarioRun { mut result, output, length_ms, real_time, .. } = run;
        result.attempts = attempt;
        report.real_time_scenarios += usize::from(real_time);
        report.needed_ms += length_ms as f64;
        progress(i + 1, n, &result);
        *report.summary.entry(result.verdict.label().to_string()).or_default() += 1;
        report.output.insert(scenario.id.to_string(), output);
        report.scenarios.push(result);
    }
    report.wall_time_ms = started.elapsed().as_secs_f64() * 1000.0;
    report.notes.push(format!(
        "The harness's encoder ran at a real-time priority in {} of {} scenarios (where not permitted it runs as any \
         process); a scenario whose replies the harness wrote with a pause it did not plan is run again (at most {} \
         times), and what such a pause could explain is never a FAIL.",
        report.real_time_scenarios,
        report.scenarios.len(),
        MAX_ATTEMPTS
    ));
    report
}

fn open_port(path: &str) -> Result<Box<dyn SerialPort>, String> {
    serialport::new(path, 9600)
        .data_bits(serialport::DataBits::Eight)
        .parity(serialport::Parity::Even)
        .stop_bits(serialport::StopBits::One)
        .timeout(Duration::from_millis(1))
        .open()
        .map_err(|e| e.to_string())
}

/// A drive on a real port, and how its power-on is known.
struct Drive<'a> {
    port: &'a dyn SerialPort,
    power_on: PowerOn,
    operator: &'a mut dyn Operator,
}

/// One scenario with a drive on a real port: a fresh encoder served on the port.
fn on_port(profile: Profile, scenario: &Scenario, drive: Drive, polling_period_ms: u32) -> ScenarioRun {
    let Drive { port, power_on, operator } = drive;
    let started = Instant::now();
    let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
    if scenario.from_power_on() && power_on == PowerOn::Unseen {
        result.push(Finding::not_applicable(
            "the scenario starts at the drive's power-on, which the harness cannot see on this port (use --power-on prompt)",
        ));
        return ScenarioRun::early(result);
    }
    let port = match port.try_clone() {
        Ok(p) => p,
        Err(e) => {
            result.push(Finding::error(format!("cannot use the port: {e}")));
            return ScenarioRun::early(result);
        }
    };
    let world = (scenario.world)(&profile);
    let mut slave = match power_on {
        PowerOn::Prompt => {
            operator.switch_off(scenario.id);
            // Whatever the drive sent while going off is not this scenario's.
            let _ = port.clear(serialport::ClearBuffer::Input);
            let mut slave = Slave::new(profile);
            world.apply_at_power_on(&mut slave);
            slave
        }
        PowerOn::Unseen => {
            let mut slave = Slave::operational(profile);
            world.apply(&mut slave);
            slave
        }
    };
    let mut hooks = DriveEncoder::new(profile, scenario, power_on == PowerOn::Prompt, None);
    hooks.set_polling_period_ms(polling_period_ms);
    let arisen = hooks.arisen();
    let epoch = Instant::now();
    if power_on == PowerOn::Prompt {
        operator.switch_on(scenario.id);
    }
    let deadline = || epoch + Duration::from_millis(end_ms(scenario, &arisen, polling_period_ms));
    match serve_until(port, &mut slave, &mut hooks, epoch, deadline, || false) {
        Ok(Ok(())) => {}
        Ok(Err(e)) => result.push(Finding::error(format!("the port failed: {e}"))),
        Err(()) => result.push(Finding::error("the encoder thread panicked")),
    }
    hooks.finish(epoch.elapsed().as_micros() as u64);
    let disturbed = finish(&mut result, &mut hooks, scenario, started, power_on == PowerOn::Prompt);
    let (length_ms, real_time) = (hooks.timeline.end_us / 1000, hooks.timeline.real_time);
    ScenarioRun { result, output: String::new(), length_ms, disturbed, real_time }
}

/// One scenario: a fresh encoder on a fresh pseudo-terminal, the master started on it.
fn run_scenario(profile: Profile, scenario: &Scenario, exec: &str, polling_period_ms: u32) -> ScenarioRun {
    let started = Instant::now();
    let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
    let (encoder_end, master_end) = match serialport::TTYPort::pair() {
        Ok(pair) => pair,
        Err(e) => {
            result.push(Finding::error(format!("cannot create a pseudo-terminal pair: {e}")));
            return ScenarioRun::early(result);
        }
    };
    let path = master_end.name().unwrap_or_default();
    let mut slave = Slave::new(profile);
    (scenario.world)(&profile).apply_at_power_on(&mut slave);
    // The master's settings are the pseudo-terminal's: the harness reads them through
    // its own end (on Linux both ends share them).
    let peer = encoder_end.try_clone().ok();
    let mut hooks = DriveEncoder::new(profile, scenario, true, peer);
    hooks.set_polling_period_ms(polling_period_ms);
    let arisen = hooks.arisen();
    // Power-on is the master's start.
    let epoch = Instant::now();
    let mut master = match MasterProcess::start(exec, &path) {
        Ok(m) => m,
        Err(e) => {
            result.push(Finding::error(format!("cannot start the master `{exec}`: {e}")));
            return ScenarioRun::early(result);
        }
    };
    let deadline = || epoch + Duration::from_millis(end_ms(scenario, &arisen, polling_period_ms));
    let mut exited = None;
    let served = serve_until(Box::new(encoder_end), &mut slave, &mut hooks, epoch, deadline, || {
        exited = master.exited();
        exited.is_some()
    });
    let (status, output) = master.stop();
    // The encoder has stopped before its line closes: nothing it writes is lost in a pipe.
    drop(master_end);
    let end_us = epoch.elapsed().as_micros() as u64;
    hooks.finish(end_us);
    match served {
        Ok(Ok(())) => {}
        Ok(Err(e)) => result.push(Finding::error(format!("the encoder's port failed: {e}"))),
        Err(()) => result.push(Finding::error("the encoder thread panicked")),
    }
    if let Some(s) = exited.or(status) {
        let at = end_us as f64 / 1000.0;
        result.push(Finding::error(format!("the master exited after {at:.0} ms ({s}) before the scenario ended")));
    }
    let disturbed = finish(&mut result, &mut hooks, scenario, started, false);
    let (length_ms, real_time) = (hooks.timeline.end_us / 1000, hooks.timeline.real_time);
    ScenarioRun { result, output, length_ms, disturbed, real_time }
}

/// When `scenario` ends (ms since power-on), with its situation as published so far.
fn end_ms(scenario: &Scenario, arisen: &AtomicU64, polling_period_ms: u32) -> u64 {
    let at_us = arisen.load(Ordering::Relaxed);
    scenario.end_ms((at_us != u64::MAX).then_some(at_us / 1000), polling_period_ms)
}

/// Serve `slave` on `port` with `hooks` (time 0 at `epoch`) until `deadline()` (which
/// may move later as the scenario's situation arises), the port goes, or `done()`
/// (asked every 5 ms) says so; then stop the encoder. `Err(())` if the serving thread
/// panicked.
fn serve_until(
    port: Box<dyn SerialPort>,
    slave: &mut Slave,
    hooks: &mut DriveEncoder,
    epoch: Instant,
    deadline: impl Fn() -> Instant,
    mut done: impl FnMut() -> bool,
) -> Result<std::io::Result<()>, ()> {
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let server = scope.spawn(|| serve_with(port, slave, epoch, &stop, hooks));
        while Instant::now() < deadline() && !server.is_finished() && !done() {
            std::thread::sleep(Duration::from_millis(5));
        }
        stop.store(true, Ordering::Relaxed);
        server.join().map_err(drop)
    })
}

/// The verdict, and the timeline with the broken rules on it. `by_operator`: the
/// drive's power-on was the operator's, at the encoder's or later. Returns why the
/// harness's own timing may have decided something, where it may have.
fn finish(
    result: &mut CaseResult,
    hooks: &mut DriveEncoder,
    scenario: &Scenario,
    started: Instant,
    by_operator: bool,
) -> Option<String> {
    let disturbed = grade(result, hooks, scenario, by_operator);
    result.wire.append(&mut hooks.timeline.entries);
    for o in &hooks.timeline.observations {
        result.wire.push(crate::verdict::WireEntry {
            t_us: o.at_us,
            direction: "×",
            bytes: format!("{} ({})", o.rule.text(), o.rule.clause()),
        });
    }
    result.wire.sort_by_key(|w| w.t_us);
    result.duration_ms = started.elapsed().as_secs_f64() * 1000.0;
    disturbed
}

/// Whether the scenario's situation arose (else NOT-EXERCISED: nothing about it was
/// seen), and whether the reaction it expects followed (else graded by the force of
/// the reaction's clause, unless a rule of the observer already judged it).
fn exercised(result: &mut CaseResult, timeline: &Timeline, scenario: &Scenario, edition: hiperface_model::Edition) {
    let Some(at_us) = timeline.situation_us else {
        result.push(Finding::not_exercised(format!("not exercised: {}", scenario.situation.missing(scenario))));
        return;
    };
    let reaction = scenario.reaction;
    let on = scenario.plan.first().map(|p| p.on);
    let seen = timeline.requests_log.iter().any(|(t, r)| *t > at_us && reaction.seen_in(r, on));
    let judged = timeline.observations.iter().any(|o| reaction.judged_by().contains(&o.rule));
    if !seen && !judged {
        let message = format!(
            "the expected reaction, {}, was not seen in the {} ms after the situation arose at {:.3} ms",
            reaction.text(),
            timeline.end_us.saturating_sub(at_us) / 1000,
            at_us as f64 / 1000.0
        );
        result.push(Finding::broken(reaction.clause(), message, edition));
    }
}

/// The scenario's verdict from what the observer saw.
fn grade(result: &mut CaseResult, hooks: &DriveEncoder, scenario: &Scenario, by_operator: bool) -> Option<String> {
    let timeline = &hooks.timeline;
    let edition = hooks.profile().edition;
    if timeline.characters == 0 {
        result.push(Finding::error("the master sent nothing: there is nothing to grade"));
        return None;
    }
    if timeline.characters >= encoder::MAX_CHARACTERS {
        result.push(Finding::error(format!("the master flooded the line ({} characters)", timeline.characters)));
    }
    exercised(result, timeline, scenario, edition);
    // One finding per rule, with the count and the first observation that stands. An
    // observation the harness's own timing may explain is not charged to the master:
    // the rule is then NON-STRICT at most, with the reason. That is one the harness
    // read late by as much as the rule was broken by, and anything after a reply the
    // harness wrote with a pause it did not plan (the master may have heard the reply
    // end there, and all it did after rests on that).
    let timeout = UartSettings::DEFAULT.timeout_us(edition);
    let disturbed_from = timeline.disturbed.first().map(|&(at, _)| at);
    let unproven = |o: &Observation| -> Option<String> {
        if let Some(late) = timeline.unproven(o, timeout, hooks.profile()) {
            return Some(format!(
                "the harness did not read the line for up to {:.1} ms around it (a busy machine): the timing is not proven",
                late as f64 / 1000.0
            ));
        }
        disturbed_from.filter(|&from| o.at_us >= from).map(|from| {
            format!(
                "the harness wrote its reply at {:.3} ms with a pause it did not plan (a busy machine): \
                 what the master did after it is not proven",
                from as f64 / 1000.0
            )
        })
    };
    let mut rules: Vec<Rule> = Vec::new();
    for o in &timeline.observations {
        if !rules.contains(&o.rule) {
            rules.push(o.rule);
        }
    }
    let mut any_unproven = None;
    for rule in rules {
        let all: Vec<&Observation> = timeline.observations.iter().filter(|o| o.rule == rule).collect();
        let count = all.len();
        let standing = all.iter().find(|o| unproven(o).is_none());
        let shown = standing.or(all.first()).copied();
        let Some(&Observation { at_us, measured_us: measured, data_rates: rates, .. }) = shown else { continue };
        let figure = match (measured, rates) {
            (Some(m), _) => format!(", {:.3} ms", m as f64 / 1000.0),
            (None, Some(r)) => format!(", {} Bd, the encoder at {} Bd", r.master_bps, r.encoder_bps),
            (None, None) => String::new(),
        };
        let times = if count > 1 { format!(" ({count} times)") } else { String::new() };
        let message = format!("{} at {:.3} ms{figure}{times}", rule.text(), at_us as f64 / 1000.0);
        let mut finding = Finding::broken(rule.clause(), message, edition);
        if let (None, Some(why)) = (standing, shown.and_then(unproven)) {
            finding = finding.softened(&why);
            any_unproven.get_or_insert(why);
        }
        // A request in the settings-change window by the encoder's clock may be in the
        // default window by the drive's, which powered on later.
        result.push(match (rule, by_operator) {
            (Rule::DuringSettingsChange, true) => {
                finding.softened("the drive powered on when the operator switched it, perhaps after the encoder")
            }
            _ => finding,
        });
    }
    // Why this run may not be the master's own: a disturbed reply, or a rule that only
    // a late read broke.
    let worst = timeline.disturbed.iter().map(|&(_, pause)| pause).max();
    match (disturbed_from, worst) {
        (Some(from), Some(pause)) => Some(format!(
            "{} replies written with an unplanned pause (up to {:.3} ms), the first at {:.3} ms",
            timeline.disturbed.len(),
            pause as f64 / 1000.0,
            from as f64 / 1000.0
        )),
        _ => any_unproven,
    }
}
