//! The `hiperface` command. One file for the whole command line (a little over 400
//! lines): the argument definitions, about half of it, and one function per
//! subcommand, so that `--help` and the code acting on it are read together. The work
//! itself is in the library (`certify`, `port`, `vectors`, `simulate`).

use clap::{Parser, Subcommand, ValueEnum};
use hiperface_conformance::certify::{self, CaseVerdict, Options};
use hiperface_conformance::line::LineKind;
use hiperface_conformance::port::{self, PortSpec};
use hiperface_conformance::simulate;
use hiperface_conformance::verdict::timing::TimingMode;
use hiperface_conformance::world::World;
use hiperface_conformance::{demo, drive, profile_file, report};
use hiperface_model::command::COMMAND_TABLE;
use hiperface_model::slave::inputs::{InitFault, PhysicalInputs};
use hiperface_model::{Grading, Profile};
use serialport::SerialPort as _;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "hiperface", version, about = "HIPERFACE reference model and conformance suite")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Certify a device under test.
    Certify {
        #[command(subcommand)]
        what: CertifyWhat,
    },
    /// Serve the reference model as a virtual encoder on a port or a new pseudo-terminal.
    Simulate {
        /// `pty` for a new pseudo-terminal pair (its path is printed), or a port path.
        #[arg(long, default_value = "pty")]
        port: String,
        #[arg(long, default_value = "SRS50")]
        profile: String,
        /// Log every frame to standard error.
        #[arg(long)]
        log: bool,
        #[command(flatten)]
        world: WorldArgs,
    },
    /// Run a demonstration session against the reference slave in virtual time.
    Demo {
        /// A built-in profile name or a profile TOML file.
        #[arg(long, default_value = "SRS50")]
        profile: String,
    },
    /// List the built-in profiles.
    Profiles,
    /// Load and validate a profile (built-in name or TOML file).
    CheckProfile { profile: String },
    /// Print the command table (000 Table 10 and legacy 63h).
    Commands,
    /// Golden vectors: generate, verify, export.
    Vectors {
        #[command(subcommand)]
        what: VectorsCommand,
    },
    /// Print a profile as TOML, to start a data sheet of your own.
    ExportProfile { profile: String },
    /// The reference master: start-up, cyclic Read Position, fault reaction (000:3.3).
    Master(drive::cli::MasterArgs),
    /// Grade a capture of a bus (a wire log, a logic analyzer's CSV, sigrok-cli's UART
    /// decoder output) without talking: both sides; exit 1 on a FAIL, 3 when nothing
    /// could be graded.
    Decode(hiperface_conformance::listen::cli::DecodeArgs),
    /// Listen to a live bus without talking (the port is opened read-only) and grade
    /// both sides as it goes; Ctrl-C ends the run with a summary and the reports.
    Monitor(hiperface_conformance::listen::monitor::MonitorArgs),
    /// Clause coverage: what cites each clause of the registry (exit 1 when a
    /// normative clause is neither covered nor listed as unobservable).
    Clauses {
        /// Only the normative clauses nothing covers.
        #[arg(long)]
        uncovered: bool,
        #[arg(long, value_enum, default_value = "md")]
        format: ClauseFormat,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum ClauseFormat {
    Md,
    Json,
}

#[derive(Subcommand)]
enum CertifyWhat {
    /// Act as master against a slave (encoder).
    Slave {
        /// `sim` (the reference model on an in-process pseudo-terminal, real time),
        /// `virtual` (the reference model in-process, virtual time), a serial port path,
        /// or `tcp://host:port` (a serial device server such as ser2net).
        #[arg(long)]
        port: PortSpec,
        /// The device's profile: a built-in name or a TOML file.
        #[arg(long, default_value = "SRS50")]
        profile: String,
        /// Allow EEPROM writes (each case restores what it changes). Implied by `--port sim`.
        #[arg(long)]
        allow_writes: bool,
        /// Allow changing the counter, which cannot be restored. Implied by `--port sim`.
        #[arg(long)]
        allow_counter_change: bool,
        /// Cap on EEPROM writes in the run.
        #[arg(long, default_value_t = 200)]
        write_budget: u32,
        /// Run only cases whose id matches (glob with `*` and `?`, comma-separated).
        #[arg(long)]
        cases: Option<String>,
        /// Write report.json, junit.xml, certificate.md and certificate.html here.
        #[arg(long)]
        report: Option<PathBuf>,
        /// How values of the physical world are graded: `exact` or `range` (default: exact
        /// for `sim` and `virtual`, by range otherwise).
        #[arg(long)]
        grading: Option<Grading>,
        /// Timing jitter allowed before a reply's start is graded, ms (default: 2 on a
        /// serial port or pseudo-terminal, 4 over TCP).
        #[arg(long)]
        tolerance_ms: Option<u64>,
        /// How reply timing is graded: strict (FAIL outside the window), lenient
        /// (NON-STRICT, with the figure), off (reported only). Default: strict, lenient
        /// through a USB adapter whose latency timer could not be lowered.
        #[arg(long, value_enum)]
        timing: Option<TimingMode>,
        /// The simulated encoder's world (with `--port sim` or `virtual`).
        #[command(flatten)]
        world: WorldArgs,
    },
    /// Act as encoder against a master (a drive): scenarios with injected faults.
    Master(drive::cli::CertifyMasterArgs),
}

/// The simulated encoder's physical inputs and start-up faults.
#[derive(clap::Args, Clone, Default)]
struct WorldArgs {
    /// Encoder temperature in °C (outside the profile's limits raises warning 1Eh).
    #[arg(long, allow_hyphen_values = true)]
    temperature: Option<i16>,
    /// Raw shaft position in steps.
    #[arg(long)]
    position: Option<u64>,
    /// A fault found at start-up (repeatable): alignment-data, angular-offset,
    /// partition-table, analog-limits, type-code, watchdog, counter, extended-type-label,
    /// multiturn-parameters.
    #[arg(long = "init-fault", value_parser = parse_init_fault)]
    init_faults: Vec<InitFault>,
}

impl WorldArgs {
    fn world(&self) -> World {
        let mut inputs = PhysicalInputs::default();
        let custom = self.temperature.is_some() || self.position.is_some();
        if let Some(t) = self.temperature {
            inputs.temperature_c = t;
        }
        if let Some(p) = self.position {
            inputs.position = p;
        }
        World { inputs: custom.then_some(inputs), init_faults: self.init_faults.clone() }
    }
}

fn parse_init_fault(s: &str) -> Result<InitFault, String> {
    InitFault::from_name(s).ok_or_else(|| format!("unknown start-up fault `{s}`"))
}

#[derive(Subcommand)]
enum VectorsCommand {
    /// Write the generated vector files into DIR (documents.json and master-tables.json
    /// are transcribed from the documents by hand and never generated).
    Generate {
        #[arg(default_value = "vectors")]
        dir: PathBuf,
    },
    /// Re-check every vector file in DIR: schema, checksums, agreement with the model.
    Verify {
        #[arg(default_value = "vectors")]
        dir: PathBuf,
    },
    /// Write documentation tables (one per command) from the vector files in DIR.
    Export {
        #[arg(long, value_enum, default_value = "markdown")]
        format: ExportFormat,
        /// Write vectors.md / vectors-tables.json here instead of standard output.
        #[arg(long)]
        out: Option<PathBuf>,
        #[arg(default_value = "vectors")]
        dir: PathBuf,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum ExportFormat {
    Markdown,
    Json,
}

/// Why a command could not do its job: exit code 2 (bad input, a port that cannot be
/// opened, a report that cannot be written). A device that FAILs is exit code 1.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
struct CliError(String);

impl CliError {
    fn from(e: impl std::fmt::Display) -> CliError {
        CliError(e.to_string())
    }
}

/// `hiperface clauses`: exit 1 when a normative clause is neither covered nor listed.
fn print_clauses(uncovered: bool, format: ClauseFormat) -> Result<ExitCode, CliError> {
    use hiperface_conformance::clauses;
    let all = clauses::coverage().map_err(CliError)?;
    let rows: Vec<&clauses::ClauseCoverage> = all.iter().filter(|c| !uncovered || c.uncovered()).collect();
    let text = match format {
        ClauseFormat::Md => clauses::markdown(&rows, &all),
        ClauseFormat::Json => serde_json::to_string_pretty(&rows).map_err(|e| CliError(e.to_string()))? + "\n",
    };
    print_all(&text)?;
    Ok(if all.iter().any(|c| c.uncovered()) { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Certify { what: CertifyWhat::Master(args) } => drive::cli::certify_master(&args).map_err(CliError),
        Command::Certify { what } => certify_slave(what),
        Command::Master(args) => drive::cli::reference_master(&args).map_err(CliError),
        Command::Simulate { port, profile, log, world } => run_simulator(&port, &profile, log, &world.world()),
        Command::Demo { profile } => profile_file::resolve(&profile)
            .map_err(CliError::from)
            .and_then(|p| print_all(&demo::run(p)).map(|()| ExitCode::SUCCESS)),
        Command::Profiles => {
            for (name, make) in hiperface_model::profiles::BUILTIN {
                let p = make();
                println!("{name:<16} {:?} edition, type {:02X}h, range {} steps", p.edition, p.type_code, p.range());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::CheckProfile { profile } => profile_file::resolve(&profile).map_err(CliError::from).map(|p| {
            println!(
                "{}: valid ({:?} edition, {} commands, range {} steps)",
                p.name,
                p.edition,
                p.commands.iter().count(),
                p.range()
            );
            ExitCode::SUCCESS
        }),
        Command::ExportProfile { profile } => profile_file::resolve(&profile).map_err(CliError::from).map(|p| {
            print!("{}", profile_file::to_toml(&p));
            ExitCode::SUCCESS
        }),
        Command::Vectors { what } => vectors_command(what),
        Command::Decode(args) => hiperface_conformance::listen::cli::decode(&args).map_err(CliError),
        Command::Monitor(args) => {
            let stop = hiperface_conformance::interrupt::flag("\ninterrupted: the summary and the reports follow");
            hiperface_conformance::listen::monitor::monitor(&args, &stop).map_err(CliError)
        }
        Command::Clauses { uncovered, format } => print_clauses(uncovered, format),
        Command::Commands => {
            println!("{:<6} {:<50} {:>8}  master  slave", "cmd", "name", "max ms");
            for s in COMMAND_TABLE {
                let ms = s.max_response_ms.map_or("-".to_string(), |m| m.to_string());
                println!("{:02X}h    {:<50} {:>8}  {:?}  {:?}", s.id.byte(), s.name, ms, s.master_data, s.slave_data);
            }
            Ok(ExitCode::SUCCESS)
        }
    };
    result.unwrap_or_else(|e| {
        eprintln!("error: {e}");
        ExitCode::from(hiperface_conformance::verdict::EXIT_USAGE)
    })
}

fn certify_slave(what: CertifyWhat) -> Result<ExitCode, CliError> {
    let CertifyWhat::Slave {
        port,
        profile,
        allow_writes,
        allow_counter_change,
        write_budget,
        cases,
        report: dir,
        grading,
        tolerance_ms,
        timing,
        world,
    } = what
    else {
        return Err(CliError("not a slave certification".into()));
    };
    let profile = profile_file::resolve(&profile).map_err(CliError::from)?;
    if let Some(dir) = &dir {
        report::prepare_dir(dir).map_err(CliError)?;
    }
    // Nothing selected is nothing graded: refused before the port is touched.
    if let Some(globs) = &cases {
        if certify::select(Some(globs)).is_empty() {
            let mut groups: Vec<String> = certify::cases::catalogue()
                .iter()
                .map(|c| format!("{}.*", c.id.split('.').next().unwrap_or(c.id)))
                .collect();
            groups.sort();
            groups.dedup();
            return Err(CliError(format!("no case matches `{globs}` (the cases: {})", groups.join(", "))));
        }
    }
    let sim = port.is_model();
    let grading = grading.unwrap_or(if sim { Grading::Exact } else { Grading::Range });
    let world = if sim { world.world() } else { World::default() };
    let opened = match port::open_for_slave(&port, profile, &world, tolerance_ms.map(|ms| ms * 1000)) {
        Ok(o) => o,
        Err(e) => {
            if let Some(dir) = &dir {
                let options = Options { grading, timing: timing.unwrap_or(TimingMode::Strict), ..Options::default() };
                let partial =
                    certify::Report::aborted_before_start(&profile, &port.to_string(), &options, &e.to_string());
                if report::write_all(&partial, dir).is_ok() {
                    eprintln!("partial report written to {}", dir.display());
                }
            }
            return Err(CliError::from(e));
        }
    };
    let (default_timing, timing_reason) = opened.default_timing;
    let options = Options {
        allow_writes: allow_writes || sim,
        allow_counter_change: allow_counter_change || sim,
        write_budget,
        cases,
        grading,
        interrupt: Some(hiperface_conformance::interrupt::flag(
            "\ninterrupted: restoring and writing a partial report",
        )),
        world,
        timing: timing.unwrap_or(default_timing),
    };
    if let (None, Some(reason)) = (timing, &timing_reason) {
        eprintln!("note: {reason}");
    }
    // Keep the simulator alive for the whole run.
    let simulator = opened.simulator;
    let line = opened.line;
    eprintln!("certifying {} on {}", profile.name, line.describe());
    // A progress bar on a terminal; plain lines in logs.
    let bar = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
        let b = indicatif::ProgressBar::new(certify::cases::catalogue().len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}") {
            b.set_style(style);
        }
        b
    });
    let report = certify::run(line, profile, &options, |i, n, r| {
        let mut text = format!("[{i:>2}/{n}] {:<16} {}", r.verdict.label(), r.id);
        if r.attempts > 1 {
            text.push_str(&format!(" ({} runs: the harness was disturbed)", r.attempts));
        }
        for f in r.findings.iter().filter(|f| matches!(f.verdict(), CaseVerdict::Fail | CaseVerdict::Error)) {
            text.push_str(&format!("\n          {f}"));
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
    summarize(&report, &profile);
    if let Some(dir) = dir {
        report::write_all(&report, &dir)
            .map_err(|e| CliError(format!("cannot write the report to {}: {e}", dir.display())))?;
        eprintln!("reports written to {}", dir.display());
    }
    Ok(report.outcome().exit())
}

fn summarize(report: &certify::Report, profile: &Profile) {
    let summary: Vec<String> = report.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    println!("{}: {}", profile.name, summary.join(", "));
    if report.line_kind == Some(LineKind::Virtual) {
        println!(
            "virtual time: {:.0} ms of line time run in {:.1} ms; EEPROM writes {}",
            report.physical_minimum_ms, report.wall_time_ms, report.safety.eeprom_writes
        );
    } else if report.physical_minimum_ms > 0.0 {
        println!(
            "wall time {:.0} ms; physical minimum from the wire log {:.0} ms (ratio {:.2}); EEPROM writes {}",
            report.wall_time_ms,
            report.physical_minimum_ms,
            report.wall_time_ms / report.physical_minimum_ms,
            report.safety.eeprom_writes
        );
    } else {
        println!("wall time {:.0} ms; nothing was exchanged", report.wall_time_ms);
    }
    for c in report.rerun_cases() {
        println!("re-run: {c}: the harness's own lateness left a verdict untold");
    }
    if let Some(a) = &report.aborted {
        println!("ABORTED: {a}");
    }
    if report.safety.differs() {
        println!("CHECK THE DEVICE: the run may have left it changed (not a verdict on the device):");
        for c in report.safety.changed.iter().chain(&report.safety.bookkeeping) {
            println!("  {c}");
        }
    }
    if !report.safety.unverified.is_empty() {
        println!("NOT VERIFIED: read before the run, not read back after it (not a verdict on the device):");
        for c in &report.safety.unverified {
            println!("  {c}");
        }
    }
    println!("{}", report.outcome().label());
}

fn run_simulator(port: &str, profile: &str, log: bool, world: &World) -> Result<ExitCode, CliError> {
    let profile = profile_file::resolve(profile).map_err(CliError::from)?;
    let port: Box<dyn serialport::SerialPort> = if port == "pty" {
        let (sim_end, other) =
            serialport::TTYPort::pair().map_err(|e| CliError(format!("cannot create a pseudo-terminal pair: {e}")))?;
        println!("{}", other.name().unwrap_or_default());
        // Keep the other end open so the pseudo-terminal lives until we stop.
        std::mem::forget(other);
        Box::new(sim_end)
    } else {
        serialport::new(port, profile.settings.baud.bits_per_second())
            .open()
            .map_err(|e| CliError(format!("cannot open {port}: {e}")))?
    };
    let stop = hiperface_conformance::interrupt::flag("\ninterrupted: the simulator stops");
    let mut stderr = std::io::stderr();
    let log: Option<&mut dyn std::io::Write> = if log { Some(&mut stderr) } else { None };
    simulate::serve(port, profile, world, stop, log).map_err(CliError::from)?;
    Ok(ExitCode::SUCCESS)
}

/// Print to standard output; a reader that stops early (`| head`) is not an error.
fn print_all(text: &str) -> Result<(), CliError> {
    use std::io::Write as _;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(CliError::from(e)),
        _ => Ok(()),
    }
}

fn vectors_command(what: VectorsCommand) -> Result<ExitCode, CliError> {
    use hiperface_conformance::vectors;
    match what {
        VectorsCommand::Generate { dir } => {
            // documents.json and master-tables.json are written from the documents, by hand.
            for (name, file) in vectors::generate::files() {
                let json = serde_json::to_string_pretty(&file).map_err(CliError::from)? + "\n";
                let path = dir.join(name);
                std::fs::write(&path, json).map_err(|e| CliError(format!("{}: {e}", path.display())))?;
                println!("{}: {} vectors", path.display(), file.vectors.len());
            }
            Ok(ExitCode::SUCCESS)
        }
        VectorsCommand::Verify { dir } => {
            let (count, failures) = vectors::verify_dir(&dir).map_err(CliError::from)?;
            // Nothing verified is not a pass.
            if count == 0 {
                return Err(CliError(format!("{}: no vectors to verify (no *.json vector file)", dir.display())));
            }
            if failures.is_empty() {
                println!("{count} vectors verified: schema, checksums, agreement with the model");
                return Ok(ExitCode::SUCCESS);
            }
            for f in &failures {
                println!("FAIL {f}");
            }
            println!("{} of {count} vectors failed", failures.len());
            Ok(ExitCode::from(1))
        }
        VectorsCommand::Export { format, out, dir } => {
            let mut files = Vec::new();
            for path in vectors::files(&dir).map_err(CliError::from)? {
                files.push(vectors::load(&path).map_err(CliError::from)?);
            }
            let (name, text) = match format {
                ExportFormat::Markdown => ("vectors.md", vectors::export::markdown(&files)),
                ExportFormat::Json => {
                    let json =
                        serde_json::to_string_pretty(&vectors::export::tables(&files)).map_err(CliError::from)?;
                    ("vectors-tables.json", json + "\n")
                }
            };
            match out {
                Some(dir) => {
                    std::fs::create_dir_all(&dir)
                        .and_then(|()| std::fs::write(dir.join(name), text))
                        .map_err(|e| CliError(format!("{}: {e}", dir.display())))?;
                    println!("{}", dir.join(name).display());
                }
                None => print_all(&text)?,
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}
