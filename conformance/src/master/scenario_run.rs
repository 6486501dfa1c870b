//! One scenario run against the master: a fresh encoder served on a fresh
//! pseudo-terminal (the master started on it) or on the drive's port, until the
//! scenario's end, the master's exit or an interrupt.

use super::encoder::{DriveEncoder, MasterSettings, OnPort};
use super::record::Start;
use super::{Operator, PowerOn};
use crate::process::MasterProcess;
use crate::simulate::serve_with;
use hiperface_model::{CommandId, Profile, Slave};
use hiperface_suite::line::reply_echo::ReplyEcho;
use hiperface_suite::master::run::ScenarioRun;
use hiperface_suite::master::scenario::Scenario;
use hiperface_suite::serve::Session;
use hiperface_suite::verdict::{CaseResult, Finding};
use serialport::SerialPort;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The master's end of a pseudo-terminal: its settings are the master's (on Linux both
/// ends share them), read through the encoder's end.
struct PtySettings(Box<dyn SerialPort>);

impl MasterSettings for PtySettings {
    fn data_rate(&self) -> Option<u32> {
        self.0.baud_rate().ok()
    }
}

/// The drive's port at the encoder's delivery settings (000:T7, 9600 8E1), marking
/// UART faults.
pub(super) fn open_port(path: &str) -> Result<Box<dyn SerialPort>, String> {
    crate::line::serial::open_marking_port(path, hiperface_model::UartSettings::DEFAULT).map_err(|e| e.to_string())
}

/// How much later than a reply's end its echo may be read on the drive's port: the
/// encoder's timeout (000:2.2.2), and the port's own latency (a USB adapter's timer).
pub(super) fn echo_slack_us(path: &str) -> u64 {
    let latency =
        crate::line::adapter::Adapter::detect(path, std::path::Path::new("/sys")).map_or(0, |a| a.input_latency_us());
    let timeout = hiperface_model::UartSettings::DEFAULT.timeout_us(hiperface_model::Edition::Current);
    timeout + latency.max(crate::line::serial::DEFAULT_TOLERANCE_US)
}

/// A drive on a real port, and how its power-on is known.
pub(super) struct Drive<'a> {
    pub(super) port: &'a dyn SerialPort,
    pub(super) power_on: PowerOn,
    pub(super) operator: &'a mut dyn Operator,
    /// The echo of the encoder's replies on the port, as the scenarios before left it.
    pub(super) echo: &'a mut ReplyEcho,
}

/// One scenario with a drive on a real port: a fresh encoder served on the port.
pub(super) fn on_port(
    profile: Profile,
    scenario: &Scenario,
    drive: Drive,
    polling_period_ms: u32,
    not_used: &[CommandId],
    interrupted: &dyn Fn() -> bool,
) -> ScenarioRun {
    let Drive { port, power_on, operator, echo } = drive;
    let started = Instant::now();
    let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
    if scenario.from_power_on() && power_on == PowerOn::Unseen {
        result.push(Finding::not_applicable(
            "the scenario starts at the drive's power-on, which the harness cannot see on this port (use --power-on prompt)",
        ));
        return ScenarioRun::early(result);
    }
    let mut port = match port.try_clone() {
        Ok(p) => p,
        Err(e) => {
            result.push(Finding::error(format!("cannot use the port: {e}")));
            return ScenarioRun::early(result);
        }
    };
    let world = (scenario.world)(&profile);
    let slave = match power_on {
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
    let mut on_port = OnPort { echo: echo.clone().carried_over() };
    if power_on == PowerOn::Unseen {
        // The drive talks on from one scenario to the next: the scenario starts at a
        // pause of the timeout, so that a request begun before it is not cut in two
        // and its tail charged to this scenario as a frame that is no request. What
        // comes meanwhile is the last reply's echo, if one is owed, or the drive's.
        let timeout = Duration::from_micros(profile.settings.timeout_us(profile.edition));
        wait_for_quiet(port.as_mut(), &mut on_port.echo, timeout, Duration::from_secs(1));
    }
    let mut hooks = DriveEncoder::new(profile, scenario, power_on == PowerOn::Prompt, None)
        .on_port(on_port)
        .declared_not_used(not_used);
    hooks.set_polling_period_ms(polling_period_ms);
    let arisen = hooks.arisen();
    let mut session = Session::new(slave, hooks);
    let epoch = Instant::now();
    if power_on == PowerOn::Prompt {
        operator.switch_on(scenario.id);
    }
    let deadline = || epoch + Duration::from_millis(end_ms(scenario, &arisen, polling_period_ms));
    let served = serve_until(port, &mut session, None, epoch, deadline, interrupted);
    let cut_short = interrupted();
    let mut hooks = session.into_hooks();
    hooks.finish(epoch.elapsed().as_micros() as u64);
    if let Some(p) = hooks.port() {
        *echo = p.echo.clone();
    }
    if let Some(f) = served_finding(served) {
        result.push(f);
    }
    let start = if power_on == PowerOn::Prompt { Start::PowerOnByOperator } else { Start::Operational };
    let duration_ms = started.elapsed().as_secs_f64() * 1000.0;
    ScenarioRun::graded(result, hooks, scenario, duration_ms, start, cut_short)
}

/// Read what arrives until the line has been quiet for `quiet` (at most `limit`: a
/// master that never pauses starts its scenario talking, and is graded on it): an
/// owed echo is taken off by `echo` (its faults stay the line's), the rest dropped.
fn wait_for_quiet(port: &mut dyn SerialPort, echo: &mut ReplyEcho, quiet: Duration, limit: Duration) {
    let before = port.timeout();
    let _ = port.set_timeout(Duration::from_millis(1));
    let started = Instant::now();
    let mut last = Instant::now();
    let mut buf = [0u8; 64];
    let mut dropped = Vec::new();
    while last.elapsed() < quiet && started.elapsed() < limit {
        if let Ok(n) = std::io::Read::read(port, &mut buf) {
            for &byte in buf.get(..n).unwrap_or_default() {
                echo.take(hiperface_model::datalink::RxChar { byte, at_us: 0, fault: None }, &mut dropped);
                last = Instant::now();
            }
        }
    }
    let _ = port.set_timeout(before);
}

/// What the run watches of the machine beside a master process's line: the
/// pseudo-terminal's delivery, and the processors' pauses. `None` where not measured.
pub(super) struct MachineWatch<'a> {
    pub delivery: Option<std::sync::Arc<crate::line::delivery::DeliveryProbe>>,
    pub pauses: Option<&'a crate::line::host_pauses::HostPauses>,
}

/// One scenario: a fresh encoder on a fresh pseudo-terminal, the master started on it.
pub(super) fn run_scenario(
    profile: Profile,
    scenario: &Scenario,
    exec: &str,
    polling_period_ms: u32,
    not_used: &[CommandId],
    watched: MachineWatch,
    interrupted: &dyn Fn() -> bool,
) -> ScenarioRun {
    let MachineWatch { delivery, pauses } = watched;
    let started = Instant::now();
    let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
    let (encoder_end, master_end) = match crate::line::pty_pair() {
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
    let peer = encoder_end.try_clone().ok().map(|p| Box::new(PtySettings(p)) as Box<dyn MasterSettings>);
    let mut hooks = DriveEncoder::new(profile, scenario, true, peer).declared_not_used(not_used);
    hooks.set_polling_period_ms(polling_period_ms);
    let arisen = hooks.arisen();
    let mut session = Session::new(slave, hooks);
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
    // How long the master's process has waited for a processor, every 5 ms: what a
    // busy machine did to its timing.
    let mut waited = Vec::new();
    // And how long the kernel's workers, which carry the line's characters both ways
    // on a pseudo-terminal, waited: a reply they held back may reach the master in
    // parts, which the harness never wrote.
    let mut kernel = crate::run_delay::KernelWorkersWait::default();
    let mut kernel_waited = Vec::new();
    // And how long the processors stopped: at each sample, the longest pause of any
    // one that ended since the sample before, added up (a pause of the hypervisor's
    // stops the master's process without its waiting for a processor).
    let (mut paused, mut paused_us, mut paused_since) = (Vec::new(), 0u64, epoch);
    let served = serve_until(Box::new(encoder_end), &mut session, delivery, epoch, deadline, || {
        if let Some(us) = crate::run_delay::process_run_delay_us(master.id()) {
            waited.push((epoch.elapsed().as_micros() as u64, us));
        }
        if let Some(us) = kernel.total_us() {
            kernel_waited.push((epoch.elapsed().as_micros() as u64, us));
        }
        if let Some(p) = pauses {
            let now = Instant::now();
            paused_us += p.longest_ending_within(paused_since, now).as_micros() as u64;
            paused_since = now;
            paused.push((now.duration_since(epoch).as_micros() as u64, paused_us));
        }
        exited = master.exited();
        exited.is_some() || interrupted()
    });
    let mut hooks = session.into_hooks();
    hooks.waited(waited, kernel_waited, paused);
    let cut_short = interrupted();
    let (status, output) = master.stop();
    // The encoder has stopped before its line closes: nothing it writes is lost in a pipe.
    drop(master_end);
    let end_us = epoch.elapsed().as_micros() as u64;
    hooks.finish(end_us);
    if let Some(f) = served_finding(served) {
        result.push(f);
    }
    if let Some(s) = exited.or(status).filter(|_| !cut_short) {
        let at = end_us as f64 / 1000.0;
        // What it said last is most often why (a command not found, a usage error).
        let said = last_lines(&output, 3);
        let said = if said.is_empty() { String::new() } else { format!("; it printed: {said}") };
        result
            .push(Finding::error(format!("the master exited after {at:.0} ms ({s}) before the scenario ended{said}")));
    }
    let duration_ms = started.elapsed().as_secs_f64() * 1000.0;
    let run = ScenarioRun::graded(result, hooks, scenario, duration_ms, Start::PowerOnAtStart, cut_short);
    ScenarioRun { output: Some(output), ..run }
}

/// What ended the encoder's serving, where it was not the scenario's end.
fn served_finding(served: Result<std::io::Result<()>, ()>) -> Option<Finding> {
    match served {
        Ok(Ok(())) => None,
        Ok(Err(e)) => Some(Finding::error(format!("the encoder's port failed: {e}"))),
        Err(()) => Some(Finding::error("the encoder thread panicked")),
    }
}

/// The last `n` non-empty lines of `text`, joined with " / ".
fn last_lines(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    lines[lines.len().saturating_sub(n)..].join(" / ")
}

/// When `scenario` ends (ms since power-on), with its situation as published so far.
fn end_ms(scenario: &Scenario, arisen: &AtomicU64, polling_period_ms: u32) -> u64 {
    let at_us = arisen.load(Ordering::Relaxed);
    scenario.end_ms((at_us != u64::MAX).then_some(at_us / 1000), polling_period_ms)
}

/// Serve `session` on `port` (time 0 at `epoch`) until `deadline()` (which
/// may move later as the scenario's situation arises), the port goes, or `done()`
/// (asked every 5 ms) says so; then stop the encoder. `delivery`: the probe of the
/// pseudo-terminal's delivery, where the master is on one. `Err(())` if the serving thread
/// panicked.
fn serve_until(
    port: Box<dyn SerialPort>,
    session: &mut Session<DriveEncoder>,
    delivery: Option<std::sync::Arc<crate::line::delivery::DeliveryProbe>>,
    epoch: Instant,
    deadline: impl Fn() -> Instant,
    mut done: impl FnMut() -> bool,
) -> Result<std::io::Result<()>, ()> {
    let stop = AtomicBool::new(false);
    let serving = session.hooks().serving();
    std::thread::scope(|scope| {
        let server = scope.spawn(|| serve_with(port, session, serving, epoch, &stop, delivery));
        while Instant::now() < deadline() && !server.is_finished() && !done() {
            std::thread::sleep(Duration::from_millis(5));
        }
        stop.store(true, Ordering::Relaxed);
        server.join().map_err(drop)
    })
}
