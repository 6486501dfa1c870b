//! The command line of slave certification: `hiperface certify slave`.

use crate::args::{parse_ms, WorldArgs};
use crate::command::{CommandError, Ended};
use crate::line::rs485::{Rs485Mode, Rs485Settings};
use crate::port::{self, PortSpec};
use crate::report;
use hiperface_model::{Grading, Profile};
use hiperface_suite::line::echo::{EchoLine, EchoMode};
use hiperface_suite::line::{Line, LineKind};
use hiperface_suite::profile_file;
use hiperface_suite::time::ms_to_us;
use hiperface_suite::verdict::timing::TimingMode;
use hiperface_suite::verdict::CaseVerdict;
use hiperface_suite::world::World;
use std::path::PathBuf;

use hiperface_suite::slave::Options;

/// `hiperface certify slave`: act as master against a slave (encoder).
#[derive(clap::Args, Debug, Clone)]
pub struct CertifySlaveArgs {
    /// `sim` (the reference model on an in-process pseudo-terminal, real time),
    /// `virtual` (the reference model in-process, virtual time), a serial port path,
    /// `tcp://host:port` (a serial device server such as ser2net, raw) or
    /// `rfc2217://host:port` (one that takes the line's settings, RFC 2217).
    #[arg(long, value_name = "sim|virtual|PATH|tcp://HOST:PORT|rfc2217://HOST:PORT", required_unless_present = "list")]
    pub port: Option<PortSpec>,
    /// Print the catalogue instead of running it: every case's id (what `--cases`
    /// selects), what it checks and the clauses it grades, as a Markdown table.
    #[arg(long, conflicts_with = "port")]
    pub list: bool,
    /// The device's profile: a built-in name or a TOML file.
    #[arg(long, default_value = "SRS50")]
    pub profile: String,
    /// Allow EEPROM writes (each case restores what it changes). Implied by `--port sim`
    /// and `--port virtual` (the reference model).
    #[arg(long)]
    pub allow_writes: bool,
    /// Allow changing the counter, which cannot be restored. Implied by `--port sim` and
    /// `--port virtual` (the reference model).
    #[arg(long)]
    pub allow_counter_change: bool,
    /// Allow Sensor Adjustment (6Bh) with the profile's options: it may recalibrate the
    /// sensor, and no request undoes it. Implied by `--port sim` and `--port virtual`.
    #[arg(long)]
    pub allow_adjustment: bool,
    /// Cap on EEPROM writes in the run.
    #[arg(long, default_value_t = 200)]
    pub write_budget: u32,
    /// Run only cases whose id matches: `*` and `?`, comma-separated alternatives,
    /// braces (`'{powerup.reset,timing.*}'`), `!` to leave out (`'!fields.*'`).
    #[arg(long)]
    pub cases: Option<String>,
    /// Write report.json, junit.xml, certificate.md and certificate.html here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// What is certified, for the certificate (repeatable): a model and serial number,
    /// a firmware image and its digest. Recorded in report.json, signed with it.
    #[arg(long, value_name = "TEXT")]
    pub device: Vec<String>,
    /// Sign the reports with this Ed25519 private key (PKCS#8 PEM, made by `hiperface
    /// keygen`): report.sig beside them, which `decode report.json --verify PUBKEY` checks.
    #[arg(long, value_name = "KEY", requires = "report")]
    pub sign: Option<PathBuf>,
    /// How values of the physical world are graded: `exact` or `range` (default: exact
    /// for `sim` and `virtual`, by range otherwise).
    #[arg(long)]
    pub grading: Option<Grading>,
    /// Timing jitter allowed before a reply's start is graded, ms (default: 2 on a
    /// serial port or pseudo-terminal, 4 over TCP).
    #[arg(long, value_parser = parse_ms)]
    pub tolerance_ms: Option<f64>,
    /// The line may deliver received characters up to this late, ms: a latency timer
    /// the harness cannot read or lower (an adapter behind a hub or a device server's
    /// buffering). Reply windows are widened by it, above 3 ms timing is graded
    /// leniently by default, and the certificate says so.
    #[arg(long, value_parser = parse_ms)]
    pub latency_ms: Option<f64>,
    /// How reply timing is graded: strict (FAIL outside the window), lenient
    /// (NON-STRICT, with the figure), off (reported only). Default: strict, lenient
    /// through a USB adapter whose latency timer could not be lowered.
    #[arg(long, value_enum)]
    pub timing: Option<TimingMode>,
    /// Whether the line returns the harness's own requests (a two-wire RS-485
    /// adapter whose receiver stays on): `auto` finds out at the first request and
    /// takes the echo off the line; `on` always expects it; `off` reports an echo as a
    /// line fault.
    #[arg(long, value_enum, default_value_t = EchoMode::Auto)]
    pub echo: EchoMode,
    /// The kernel's RS-485 mode for a native UART that keys its transceiver with RTS:
    /// `leave` the port as it is, `on` for the run (put back after it), `off`.
    #[arg(long, value_enum, default_value_t = Rs485Mode::Leave)]
    pub rs485: Rs485Mode,
    /// With `--rs485 on`: RTS low, not high, while sending (a transceiver whose DE is
    /// active low).
    #[arg(long, requires = "rs485")]
    pub rs485_rts_low: bool,
    /// With `--rs485 on`: delay from RTS to the first character, ms.
    #[arg(long, value_parser = parse_ms, default_value = "0", requires = "rs485")]
    pub rs485_delay_before_ms: f64,
    /// With `--rs485 on`: delay from the last character to RTS released, ms.
    #[arg(long, value_parser = parse_ms, default_value = "0", requires = "rs485")]
    pub rs485_delay_after_ms: f64,
    /// The simulated encoder's world (with `--port sim` or `virtual`).
    #[command(flatten)]
    pub world: WorldArgs,
}

/// Certify the slave; exit code 0 when it passed, 1 when it failed, 3 when incomplete.
/// Run policy lives here, where tests reach it: the grading and the writes a model
/// port implies, nothing selected refused before the port is touched, and a partial
/// report when the port cannot be opened.
pub fn certify_slave(args: CertifySlaveArgs) -> Result<Ended, CommandError> {
    if args.list {
        crate::say!("{}", hiperface_suite::report::catalogue::slave_cases().trim_end());
        return Ok(Ended::Done);
    }
    let CertifySlaveArgs {
        port,
        list: _,
        profile,
        allow_writes,
        allow_counter_change,
        allow_adjustment,
        write_budget,
        cases,
        report: dir,
        device,
        sign,
        grading,
        tolerance_ms,
        latency_ms,
        timing,
        echo,
        rs485,
        rs485_rts_low,
        rs485_delay_before_ms,
        rs485_delay_after_ms,
        world,
    } = args;
    let rs485 = Rs485Settings {
        mode: rs485,
        rts_low_while_sending: rs485_rts_low,
        delay_before_ms: rs485_delay_before_ms,
        delay_after_ms: rs485_delay_after_ms,
    };
    let Some(port) = port else { return Err(CommandError::Usage("give the device with --port".into())) };
    let profile = profile_file::resolve(&profile)?;
    let signer = sign.as_deref().map(report::signature::Signer::load).transpose()?;
    let mut run_info = report::run_info(&profile, &device);
    if let Some(dir) = &dir {
        report::prepare_dir(dir)?;
    }
    // Nothing selected is nothing graded: refused before the port is touched.
    if let Some(globs) = &cases {
        hiperface_suite::slave::check_selection(globs)?;
    }
    let sim = port.is_model();
    let grading = grading.unwrap_or(if sim { Grading::Exact } else { Grading::Range });
    let world = if sim { world.world() } else { World::default() };
    if latency_ms.is_some() && !matches!(port, PortSpec::Path(_)) {
        return Err(CommandError::Usage(format!(
            "--latency-ms applies to a serial port or pseudo-terminal path, not `{port}`"
        )));
    }
    // The RS-485 mode is set before the run opens the port, and put back when the guard
    // goes at the end of this function.
    let rs485_guard = match (&port, rs485.mode) {
        (_, Rs485Mode::Leave) => None,
        (PortSpec::Path(path), _) => rs485.apply(path).map_err(|e| CommandError::Line(e.to_string()))?,
        (other, _) => return Err(CommandError::Usage(format!("--rs485 needs a serial port, not `{other}`"))),
    };
    let opened = match port::open_for_slave(
        &port,
        profile,
        &world,
        port::LineOptions { tolerance_us: tolerance_ms.map(ms_to_us), latency_us: latency_ms.map(ms_to_us) },
    ) {
        Ok(o) => o,
        Err(e) => {
            if let Some(dir) = &dir {
                let options = Options { grading, timing: timing.unwrap_or(TimingMode::Strict), ..Options::default() };
                let mut partial = hiperface_suite::slave::Report::aborted_before_start(
                    &profile,
                    &port.to_string(),
                    &options,
                    &e.to_string(),
                );
                partial.run_info = Some(run_info.clone());
                if report::write_all(&partial, dir, signer.as_ref()).is_ok() {
                    eprintln!("partial report written to {}", dir.display());
                }
            }
            return Err(CommandError::Line(e.to_string()));
        }
    };
    let (default_timing, timing_reason) = opened.default_timing;
    let options = Options {
        allow_writes: allow_writes || sim,
        allow_counter_change: allow_counter_change || sim,
        allow_adjustment: allow_adjustment || sim,
        write_budget,
        cases,
        grading,
        interrupt: Some(crate::interrupt::flag("\ninterrupted: restoring and writing a partial report")),
        world,
        timing: timing.unwrap_or(default_timing),
    };
    if let (None, Some(reason)) = (timing, &timing_reason) {
        eprintln!("note: {reason}");
    }
    // Keep the simulator alive for the whole run.
    let simulator = opened.simulator;
    let line: Box<dyn Line> = Box::new(EchoLine::new(opened.line, echo));
    // On a pseudo-terminal the kernel's workers deliver both ways: raised for the run
    // where permitted, as `certify master` does (`sched::KernelDelivery`).
    let kernel = (line.kind() == hiperface_suite::line::LineKind::PseudoTerminal)
        .then(crate::sched::KernelDelivery::raise)
        .flatten();
    // A line in real time: the processors kept awake for the run, where permitted
    // (`sched::KeepAwake`, released when dropped), and what the host took meanwhile
    // recorded; in virtual time the host's pauses change nothing.
    let real_time = line.kind() != LineKind::Virtual;
    let real_time = real_time.then(report::RealTimeRun::start);
    eprintln!("certifying {} on {}", profile.name, line.describe());
    // A progress bar on a terminal; plain lines in logs.
    let bar = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
        let b = indicatif::ProgressBar::new(hiperface_suite::slave::cases::catalogue().len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}") {
            b.set_style(style);
        }
        b
    });
    // A reason the run gives every case after it was aborted is said once, not per case.
    let mut said_before: Vec<String> = Vec::new();
    let mut report = hiperface_suite::slave::run(line, profile, &options, |i, n, r| {
        let mut text = format!("[{i:>2}/{n}] {:<16} {}", r.verdict.label(), r.id);
        if r.attempts > 1 {
            text.push_str(&format!(" ({} runs: the harness was disturbed)", r.attempts));
        }
        for f in r.findings.iter().filter(|f| matches!(f.verdict(), CaseVerdict::Fail | CaseVerdict::Error)) {
            let line = f.to_string();
            if !line.contains("not run: ") {
                text.push_str(&format!("\n          {line}"));
            } else if said_before.contains(&line) {
                text.push_str(" (not run, as above)");
            } else {
                text.push_str(&format!("\n          {line}"));
                said_before.push(line);
            }
        }
        match &bar {
            Some(b) => {
                b.set_length(n as u64);
                b.set_position(i as u64);
                b.set_message(r.id);
                b.println(text);
            }
            None => eprintln!("{text}"),
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    drop(simulator);
    let (held, steal) = real_time.map(report::RealTimeRun::finish).unzip();
    run_info.steal = steal.flatten();
    report.run_info = Some(run_info);
    if let Some(k) = kernel {
        report.line_notes.push(k.note());
    }
    report.line_notes.extend(held);
    if let Some(g) = &rs485_guard {
        report.line_notes.push(format!("The port ran in the kernel's {} (--rs485), put back afterwards.", g.in_force));
    }
    summarize(&report, &profile);
    match dir {
        Some(dir) => {
            report::write_all(&report, &dir, signer.as_ref())?;
            eprintln!("reports written to {}", dir.display());
        }
        None => eprintln!("{}", report::NO_REPORT),
    }
    Ok(Ended::Graded(report.outcome()))
}

fn summarize(report: &hiperface_suite::slave::Report, profile: &Profile) {
    let summary: Vec<String> = report.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    say!("{}: {}", profile.name, summary.join(", "));
    if report.line_kind == Some(LineKind::Virtual) {
        say!(
            "virtual time: {:.0} ms of line time run in {:.1} ms; EEPROM writes {}",
            report.line_time_ms,
            report.wall_time_ms,
            report.safety.eeprom_writes
        );
    } else if let (Some(_), true) = (&report.aborted, report.line_time_ms > 0.0) {
        // A run cut short has no ratio worth the name (its waits for a silent device).
        say!(
            "wall time {:.0} ms; the run ended early, after {:.0} ms of exchanges; EEPROM writes {}",
            report.wall_time_ms,
            report.line_time_ms,
            report.safety.eeprom_writes
        );
    } else if report.line_time_ms > 0.0 {
        say!(
            "wall time {:.0} ms; the same exchanges on a real line {:.0} ms (ratio {:.2}); EEPROM writes {}",
            report.wall_time_ms,
            report.line_time_ms,
            report.wall_time_ms / report.line_time_ms,
            report.safety.eeprom_writes
        );
    } else {
        say!("wall time {:.0} ms; nothing was exchanged", report.wall_time_ms);
    }
    for line in hiperface_suite::report::NotRun::lines(&report.not_run) {
        say!("{line}");
    }
    for c in report.rerun_cases() {
        say!("re-run: {c}: the harness's own lateness left a verdict untold");
    }
    crate::report::say_steal(report.run_info.as_ref().and_then(|r| r.steal));
    if let Some(a) = &report.aborted {
        say!("ABORTED: {a}");
    }
    if report.safety.differs() {
        say!("CHECK THE DEVICE: the run may have left it changed (not a verdict on the device):");
        for c in report.safety.changed.iter().chain(&report.safety.bookkeeping) {
            say!("  {c}");
        }
    }
    if !report.safety.unverified.is_empty() {
        say!("NOT VERIFIED: read before the run, not read back after it (not a verdict on the device):");
        for c in &report.safety.unverified {
            say!("  {c}");
        }
    }
    crate::report::say_attention(&report.attention());
    say!("{}", report.outcome().label());
}
