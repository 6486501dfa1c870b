//! The command line of master certification and of the reference master:
//! `hiperface certify master` and `hiperface master`.

use super::{reference, Attach, Options, PowerOn};
use crate::command::{CommandError, Ended};
use crate::port::{self, PortSpec};
use hiperface_suite::exchange::BusMaster;
use hiperface_suite::line::echo::EchoMode;
use hiperface_suite::master::run::Progress;
use hiperface_suite::profile_file;
use hiperface_suite::verdict::CaseVerdict;
use hiperface_suite::world::World;
use std::path::PathBuf;

/// `hiperface certify master`.
#[derive(clap::Args, Debug, Clone)]
pub struct CertifyMasterArgs {
    /// The master under test as a command line; `{port}` is replaced by the path of the
    /// encoder's pseudo-terminal. Its start is the encoder's power-on.
    #[arg(long, conflicts_with = "port", required_unless_present_any = ["port", "list"])]
    pub exec: Option<String>,
    /// Print the catalogue instead of running it: every scenario's id (what
    /// `--scenarios` selects), what it checks and the clauses it grades, as a Markdown
    /// table.
    #[arg(long, conflicts_with_all = ["exec", "port"])]
    pub list: bool,
    /// A drive on a serial port (e.g. a USB-RS-485 adapter wired to the drive's encoder
    /// connector): the harness serves the port as the encoder.
    #[arg(long)]
    pub port: Option<PortSpec>,
    /// With `--port`: how the harness learns the drive's power-on.
    #[arg(long, value_enum, default_value = "unseen")]
    pub power_on: PowerOn,
    /// With `--port`: whether the port hears the encoder's own replies (a two-wire
    /// RS-485 adapter whose receiver stays on). `auto` finds out at the first reply and
    /// takes the echo off the line; `off` reports an echo as a fault of the line.
    #[arg(long, value_enum, requires = "port")]
    pub echo: Option<EchoMode>,
    /// The encoder's profile: a built-in name or a TOML file.
    #[arg(long, default_value = "SRS50")]
    pub profile: String,
    /// Run only scenarios whose id matches: `*` and `?`, comma-separated alternatives,
    /// braces (`'{startup.*,polling.long}'`), `!` to leave out (`'!fault.*'`).
    #[arg(long)]
    pub scenarios: Option<String>,
    /// Commands the master never sends, comma-separated (`4Ah,67h`): the scenarios
    /// about them are NOT-APPLICABLE, "declared not used", and the certificate lists
    /// the declaration. A master seen sending one is UNKNOWN where it did.
    #[arg(long, value_delimiter = ',', value_parser = crate::args::parse_command)]
    pub not_used: Vec<hiperface_model::CommandId>,
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
    /// The application's polling period, ms: a master that sends no request for longer
    /// is NON-STRICT (000:3.2.2 "a sufficient cyclic request should be implemented").
    #[arg(long, default_value_t = hiperface_model::master::obligations::POLLING_PERIOD_MS,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub polling_period_ms: u32,
}

/// `hiperface master`.
#[derive(clap::Args, Debug, Clone)]
pub struct MasterArgs {
    /// A serial port path (a pseudo-terminal path works), `tcp://host:port`,
    /// `rfc2217://host:port`, or `sim`.
    #[arg(long)]
    pub port: PortSpec,
    /// The encoder's profile: a built-in name or a TOML file.
    #[arg(long, default_value = "SRS50")]
    pub profile: String,
    /// Period of Read Position, ms.
    // `--poll-ms`: the old name, kept for one release (docs/src/command-line.md).
    #[arg(long, alias = "poll-ms", default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..))]
    pub polling_period_ms: u32,
    /// Stop after this many ms (default: run until the port fails or Ctrl-C).
    #[arg(long)]
    pub duration_ms: Option<u64>,
}

/// Certify the master; exit code 0 when it passed, 1 when not.
pub fn certify_master(args: &CertifyMasterArgs) -> Result<Ended, CommandError> {
    if args.list {
        crate::say!("{}", hiperface_suite::report::catalogue::master_scenarios().trim_end());
        return Ok(Ended::Done);
    }
    let profile = profile_file::resolve(&args.profile)?;
    let attach = match (&args.exec, &args.port) {
        (Some(exec), _) => Attach::Exec(exec.clone()),
        (None, Some(PortSpec::Path(path))) => {
            Attach::Port { path: path.clone(), power_on: args.power_on, echo: args.echo.unwrap_or_default() }
        }
        (None, Some(other)) => {
            return Err(CommandError::Usage(format!(
                "`--port {other}`: the drive is served on a serial port by path (a pseudo-terminal \
                 path works); to certify a master program give it with --exec"
            )))
        }
        (None, None) => return Err(CommandError::Usage("give the master with --exec or --port".into())),
    };
    let interrupt = Some(crate::interrupt::flag("\ninterrupted: stopping the master, then the partial report"));
    let options = Options {
        attach,
        scenarios: args.scenarios.clone(),
        polling_period_ms: args.polling_period_ms,
        not_used: args.not_used.clone(),
        interrupt,
    };
    if let Some(globs) = &args.scenarios {
        if super::scenarios::chosen(Some(globs)).is_empty() {
            return Err(CommandError::NoScenarioMatches(globs.clone()));
        }
    }
    let signer = args.sign.as_deref().map(crate::report::signature::Signer::load).transpose()?;
    if let Some(dir) = &args.report {
        crate::report::prepare_dir(dir)?;
    }
    let mut run_info = crate::report::run_info(&profile, &args.device);
    let real_time = crate::report::RealTimeRun::start();
    eprintln!("certifying {} against an encoder of profile {}", options.attach, profile.name);
    // On a terminal a bar with the scenario under way and its re-runs as they happen (a
    // scenario takes seconds of real time, a whole run a minute or two); in logs the
    // same lines as before, nothing more.
    let bar = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
        let b = indicatif::ProgressBar::new(super::scenarios::chosen(args.scenarios.as_deref()).len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} ({elapsed})") {
            b.set_style(style);
        }
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    });
    let mut report = super::run(profile, &options, |p| match p {
        Progress::Starting { id, attempt, .. } => {
            if let Some(b) = &bar {
                let again =
                    if attempt > 1 { format!(", run {attempt}: the harness was disturbed") } else { String::new() };
                b.set_message(format!("running {id}{again}"));
            }
        }
        Progress::Done { index, total, result: r } => {
            let again = if r.attempts > 1 {
                format!(" ({} runs: the harness was disturbed)", r.attempts)
            } else {
                String::new()
            };
            let mut text = format!("[{index:>2}/{total}] {:<16} {}{again}", r.verdict.label(), r.id);
            for f in r.findings.iter().filter(|f| f.verdict() != CaseVerdict::Pass) {
                text.push_str(&format!("\n          {} {f}", f.verdict().label()));
            }
            match &bar {
                Some(b) => {
                    b.set_position(index as u64);
                    b.println(text);
                }
                None => eprintln!("{text}"),
            }
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let (held, steal) = real_time.finish();
    report.notes.push(held);
    run_info.steal = steal;
    report.run_info = Some(run_info);
    let summary: Vec<String> = report.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    say!("{}: {}", report.master, summary.join(", "));
    for n in &report.notes {
        say!("note: {n}");
    }
    for line in hiperface_suite::report::NotRun::lines(&report.not_run()) {
        say!("{line}");
    }
    for n in &report.notes_per_scenario {
        say!("re-run: {n}");
    }
    say!("wall time {}", report.wall_time_text());
    crate::report::say_steal(report.run_info.as_ref().and_then(|r| r.steal));
    if let Some(dir) = &args.report {
        let certificate = super::report::MasterCertificate { report: &report, profile: &profile };
        crate::report::write_all(&certificate, dir, signer.as_ref())?;
        eprintln!("reports written to {}", dir.display());
    } else {
        eprintln!("{}", crate::report::NO_REPORT);
    }
    crate::report::say_attention(&report.attention());
    say!("{}", report.outcome().label());
    Ok(Ended::Graded(report.outcome()))
}

/// Run the reference master on a port, printing what it reads.
pub fn reference_master(args: &MasterArgs) -> Result<Ended, CommandError> {
    let profile = profile_file::resolve(&args.profile)?;
    let opened = port::open_for_slave(&args.port, profile, &World::default(), Default::default())
        .map_err(|e| CommandError::Line(e.to_string()))?;
    let _simulator = opened.simulator;
    let mut master = BusMaster::new(opened.line, profile.edition);
    let options = hiperface_model::master::reference::Options {
        polling_period_ms: u64::from(args.polling_period_ms),
        duration_ms: args.duration_ms,
    };
    // A drive's master runs on a processor of its own: be as punctual as permitted (a
    // starved master talks over replies it was too late to hear). Timing does not
    // depend on it.
    if !crate::sched::real_time_priority() {
        eprintln!("note: no real-time priority (not permitted here): on a busy machine requests may be late");
    }
    let mut console = |line: &str| say!("{line}");
    match reference::run(&mut master, profile, options, &mut console) {
        Ok(()) => Ok(Ended::Done),
        Err(e) => Err(CommandError::Line(format!("the line failed: {e}"))),
    }
}
