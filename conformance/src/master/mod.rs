//! Certifying a master (a drive): the harness plays the encoder, one scenario at a
//! time, and grades what the master sends against its obligations
//! (`hiperface_model::master::obligations`). A FAIL needs a normative "must" of 000 that
//! binds the profile's edition; the recommendations of 000 (read the status after
//! power-on, read out the warning's codes, react to faults as Table 74 says) are
//! NON-STRICT at most.

pub mod cli;
pub mod reference;
mod scenario_run;

// The scenarios, the encoder's hooks that observe the master, their grades, the record
// and the report are the core's (`hiperface_suite::master`); the harness serves them on
// lines.
use hiperface_suite::master::{encoder, record, report, scenarios, DriveReport};

use hiperface_model::Profile;
use hiperface_suite::line::echo::{Echo, EchoMode};
use hiperface_suite::line::reply_echo::ReplyEcho;
use hiperface_suite::master::run::{run_catalogue, Catalogue, Progress, ScenarioLine, ScenarioRun};
use hiperface_suite::master::scenario::Scenario;
use hiperface_suite::verdict::{CaseResult, Finding, END_BUDGET, MAX_ATTEMPTS};
use scenario_run::{echo_slack_us, on_port, open_port, run_scenario, Drive, MachineWatch};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Where the master under test is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Attach {
    /// A process started for each scenario on a fresh pseudo-terminal: its command
    /// line, `{port}` standing for the pseudo-terminal's path. Its start is power-on.
    Exec(String),
    /// A drive on a serial port the harness serves as the encoder; `echo`: whether
    /// the port hears the encoder's own replies (a two-wire RS-485 adapter).
    Port { path: String, power_on: PowerOn, echo: EchoMode },
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
    /// The commands the master declares it never sends (`--not-used`): the scenarios
    /// about them are NOT-APPLICABLE.
    pub not_used: Vec<hiperface_model::CommandId>,
    /// Set by Ctrl-C or SIGTERM: the scenario under way ends (its master stopped with
    /// everything it started), no other starts, and the report says so.
    pub interrupt: Option<Arc<AtomicBool>>,
}

/// Run the catalogue against the master `options.attach`, for an encoder of `profile`;
/// with `--power-on prompt` the operator at the console switches the drive.
pub fn run(profile: Profile, options: &Options, progress: impl FnMut(Progress)) -> DriveReport {
    run_with(profile, options, &mut ConsoleOperator, progress)
}

/// As [`run`], with `operator` switching a drive on a port (`--power-on prompt`).
pub fn run_with(
    profile: Profile,
    options: &Options,
    operator: &mut dyn Operator,
    mut progress: impl FnMut(Progress),
) -> DriveReport {
    let started = Instant::now();
    let chosen = scenarios::chosen(options.scenarios.as_deref());
    let mut report =
        DriveReport::new(&profile, options.attach.to_string(), options.polling_period_ms, &options.not_used);
    report.notes.push(match options.attach {
        Attach::Exec(_) => "The master's data rate was read from its pseudo-terminal's settings; parity and character \
                            size cannot be read there (Linux keeps a pseudo-terminal at 8 bits, no parity) and were \
                            not graded."
            .into(),
        Attach::Port { .. } => "The master's data rate was not read: on a port a wrong one shows as characters with \
                                framing errors, or frames that are no requests. Characters read with a parity or \
                                framing error reach the encoder as such, and it answers 09h as an encoder does \
                                (000:T47); they are counted, not charged to the master (noise on the line looks \
                                the same)."
            .into(),
    });
    report.notes.push(format!(
        "A sufficient cyclic request (000:3.2.2) was taken as one at least every {} ms.",
        options.polling_period_ms
    ));
    report.notes.extend(hiperface_suite::master::declaration_note(&options.not_used));
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
    // A master on a pseudo-terminal: the kernel's delivery, measured beside the line
    // for the whole run (the reader at the encoder's real-time priority).
    let delivery = match &options.attach {
        Attach::Exec(_) => match crate::line::delivery::DeliveryProbe::start_with(Instant::now(), true) {
            Ok(p) => Some(std::sync::Arc::new(p)),
            Err(e) => {
                report.notes.push(format!("The pseudo-terminal's delivery could not be measured: {e}."));
                None
            }
        },
        Attach::Port { .. } => None,
    };
    let mut line = HarnessLine {
        options,
        // A drive on a port: the port stays open for the whole run.
        port: match &options.attach {
            Attach::Port { path, .. } => Some(open_port(path)),
            Attach::Exec(_) => None,
        },
        operator,
        reply_echo: None,
        delivery,
        // A master on a pseudo-terminal: the kernel's workers that deliver its
        // characters raised for the run, where permitted (put back when dropped).
        kernel: match &options.attach {
            Attach::Exec(_) => crate::sched::KernelDelivery::raise(),
            Attach::Port { .. } => None,
        },
        // A master process here: the processors' pauses timed, where permitted (a
        // process on a stopped processor stops with it, and its run delay does not
        // count that).
        pauses: match &options.attach {
            Attach::Exec(_) => crate::line::host_pauses::HostPauses::start(),
            Attach::Port { .. } => None,
        },
    };
    let catalogue = Catalogue { chosen: &chosen, profile, not_used: &options.not_used };
    let not_run = run_catalogue(&mut report, &catalogue, &mut line, &mut progress);
    let interrupted = line.interrupted();
    let HarnessLine { reply_echo, delivery, mut kernel, pauses, .. } = line;
    report.echo = reply_echo.map(|e| (e.echo(), e.mode()));
    if let Some(k) = kernel.take() {
        report.notes.push(k.note());
    }
    if let Some(p) = pauses {
        report.notes.push(format!(
            "The processors' pauses were timed on {} processors (a sentinel thread on each, at a real-time priority): \
             a rule a slow master breaks, broken by less than its process waited for a processor and the processors \
             stopped, is never a FAIL.",
            p.processors
        ));
    }
    if let Some(d) = delivery.as_ref().map(|p| p.stats()) {
        report.delivery = Some(d);
        report.notes.push(format!(
            "The pseudo-terminal's own delivery was measured beside the line ({} probe writes, {} more than 1 ms \
             late, the latest {:.3} ms); a character the kernel may have held back is taken to have come that much \
             earlier, and what that could explain is never a FAIL.",
            d.samples,
            d.over_1ms,
            d.max_us as f64 / 1000.0
        ));
    }
    report.wall_time_ms = started.elapsed().as_secs_f64() * 1000.0;
    if interrupted {
        let why = format!("interrupted (Ctrl-C or SIGTERM) with {} of {n} scenarios run", n - not_run);
        report.notes.push(format!("The run was {why}: the master was stopped with everything it started."));
        report.cut_short = Some(why);
        if let Some(r) = report.record.as_mut() {
            r.interrupted = true;
        }
    }
    report.notes.push(format!(
        "The harness's encoder ran at a real-time priority in {} of {} scenarios (where not permitted it runs as any \
         process). A scenario is run again (at most {} times in a row) where the harness's own timing may have \
         changed what the master did: a reply it wrote in two parts or past its limit, or an unplanned pause the \
         master broke a rule after; one still undecided is run again at the end of the run (at most {} times more, \
         while the time for runs again stays within {:.0} % of the scenarios' own). What such a disturbance could \
         explain is UNKNOWN, never charged to the master.",
        report.real_time_scenarios,
        // The scenarios served: a NOT-APPLICABLE one never started an encoder.
        report.scenarios.iter().filter(|s| s.verdict != hiperface_suite::verdict::CaseVerdict::NotApplicable).count(),
        MAX_ATTEMPTS - 1,
        MAX_ATTEMPTS,
        END_BUDGET * 100.0
    ));
    report
}

/// The master under test as `options.attach` gives it, and what its line keeps from
/// one scenario to the next.
struct HarnessLine<'a> {
    options: &'a Options,
    /// A drive's port, open for the whole run.
    port: Option<Result<Box<dyn serialport::SerialPort>, String>>,
    operator: &'a mut dyn Operator,
    /// A drive on a port: the echo of the encoder's replies, found once for the run.
    reply_echo: Option<ReplyEcho>,
    delivery: Option<Arc<crate::line::delivery::DeliveryProbe>>,
    kernel: Option<crate::sched::KernelDelivery>,
    pauses: Option<crate::line::host_pauses::HostPauses>,
}

impl ScenarioLine for HarnessLine<'_> {
    fn run(&mut self, profile: Profile, scenario: &Scenario) -> ScenarioRun {
        if let Some(k) = self.kernel.as_mut() {
            k.refresh();
        }
        let options = self.options;
        let interrupted = || is_set(&options.interrupt);
        let mut run = match (&options.attach, &self.port) {
            (Attach::Exec(exec), _) => {
                let not_used = &options.not_used;
                let watched = MachineWatch { delivery: self.delivery.clone(), pauses: self.pauses.as_ref() };
                run_scenario(profile, scenario, exec, options.polling_period_ms, not_used, watched, &interrupted)
            }
            (Attach::Port { power_on, echo: mode, path }, Some(Ok(port))) => {
                let echo =
                    self.reply_echo.get_or_insert_with(|| ReplyEcho::new(*mode, Echo::Unknown, echo_slack_us(path)));
                let drive = Drive { port: port.as_ref(), power_on: *power_on, operator: &mut *self.operator, echo };
                on_port(profile, scenario, drive, options.polling_period_ms, &options.not_used, &interrupted)
            }
            (Attach::Port { path, .. }, _) => {
                let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
                let why = self.port.as_ref().and_then(|p| p.as_ref().err().cloned()).unwrap_or_default();
                result.push(Finding::error(format!("cannot open {path}: {why}")));
                ScenarioRun::early(result)
            }
        };
        // A master's process prints, if only nothing; a drive's port counts its UART
        // faults, if only none.
        run.output.get_or_insert_with(String::new);
        if matches!(options.attach, Attach::Port { .. }) {
            run.uart_faults.get_or_insert(0);
        }
        run
    }

    fn interrupted(&self) -> bool {
        is_set(&self.options.interrupt)
    }
}

/// Whether an interrupt flag is there and set.
fn is_set(flag: &Option<Arc<AtomicBool>>) -> bool {
    flag.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
}
