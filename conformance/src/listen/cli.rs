//! `hiperface decode`: the listener over a capture file, with a live line per
//! exchange, a summary, and reports.

use crate::args::parse_ms;
use crate::command::{CommandError, Ended};
use hiperface_model::UartSettings;
use hiperface_suite::capture::{self, Format, ReadOptions};
use hiperface_suite::listen::decode::{grade_capture, settings_at, DecodeOptions};
use hiperface_suite::listen::{HeardExchange, ListeningReport};
use hiperface_suite::profile_file;
use hiperface_suite::verdict::CaseVerdict;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    Auto,
    Wirelog,
    Csv,
    Sigrok,
}

/// The largest timing uncertainty `decode` grades with, ms (the largest a certify run
/// is documented with: a loaded CI machine's `--tolerance-ms 20`).
pub const MAX_TOLERANCE_MS: f64 = 20.0;

/// `hiperface decode`.
#[derive(clap::Args, Debug, Clone)]
pub struct DecodeArgs {
    /// The capture: a file, or `-` for standard input.
    pub file: PathBuf,
    #[arg(long, value_enum, default_value = "auto")]
    pub format: FormatArg,
    /// The capture's sample rate, Hz (sigrok-cli's sample numbers).
    #[arg(long)]
    pub samplerate: Option<u64>,
    /// The capture's timing uncertainty, ms, at most 20 (default: a certify report's
    /// own tolerance, else one bit time).
    #[arg(long, value_parser = parse_ms)]
    pub tolerance_ms: Option<f64>,
    /// The channel the master talks on (`uart-1`, a CSV channel name), where the
    /// capture has one channel per direction.
    #[arg(long)]
    pub master_channel: Option<String>,
    /// Instead of grading: write the capture's UART waveform as a VCD file.
    #[arg(long)]
    pub vcd: Option<PathBuf>,
    /// A certify report: grade its wire log as a listener on the bus would (both sides,
    /// without what the harness knew), instead of playing back the record of its run.
    #[arg(long)]
    pub listen: bool,
    /// Check the report's signature (report.sig beside it, written by `certify --sign`)
    /// with this Ed25519 public key (PEM) before playing the record back: exit 5 when it
    /// does not hold (another key, or a byte changed in the report, its record or a
    /// signed file beside it).
    #[arg(long, value_name = "PUBKEY", conflicts_with_all = ["listen", "vcd"])]
    pub verify: Option<PathBuf>,
    #[command(flatten)]
    pub listening: ListeningArgs,
}

/// What `decode` and `monitor` are both told.
#[derive(clap::Args, Debug, Clone)]
pub struct ListeningArgs {
    /// The encoder's profile: a built-in name or a TOML file.
    #[arg(long, default_value = "SRS50")]
    pub profile: String,
    /// The bus's data rate, bits per second (8E1).
    #[arg(long, default_value_t = 9600)]
    pub baud: u32,
    /// The application's polling period, ms.
    #[arg(long, default_value_t = hiperface_model::master::obligations::POLLING_PERIOD_MS,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub polling_period_ms: u32,
    /// Write report.json, junit.xml, listening.md and listening.html here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Do not print a line per exchange.
    #[arg(long)]
    pub quiet: bool,
}

/// What decoding a report without `--verify` leaves unchecked beside it, said so that
/// nobody takes the certificate files for checked: they are written from a report, and
/// only a signature covers them.
fn unchecked_beside(report: &Path) -> Vec<String> {
    let Some(dir) = report.parent() else { return Vec::new() };
    let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    let mut notes = Vec::new();
    let written: Vec<&str> =
        ["certificate.md", "certificate.html", "junit.xml"].into_iter().filter(|f| dir.join(f).is_file()).collect();
    if !written.is_empty() {
        notes.push(format!(
            "what is checked is the report against its record; {} beside it {} written from a report and not \
             checked here (a signed run's are, with --verify)",
            written.join(", "),
            if written.len() == 1 { "is" } else { "are" }
        ));
    }
    if dir.join(crate::report::signature::FILE).is_file() {
        notes.push(format!(
            "{} beside it: the run was signed, and the signature is checked only with --verify PUBKEY",
            crate::report::signature::FILE
        ));
    }
    notes
}

/// Run `decode`; exit 0 with no FAIL, 1 with one, an error for input it cannot read.
/// A certify report with the record of its wire is played back to the catalogue
/// instead (`slave::record`): the run's verdicts, graded again, and its exit code.
pub fn decode(args: &DecodeArgs) -> Result<Ended, CommandError> {
    use crate::report::recorded::{self, AnyRecorded};
    if let Some(dir) = &args.listening.report {
        crate::report::refuse_overwriting(&args.file, dir)?;
    }
    if let Some(ms) = args.tolerance_ms.filter(|ms| *ms > MAX_TOLERANCE_MS) {
        return Err(CommandError::Usage(format!(
            "--tolerance-ms {ms}: at most {MAX_TOLERANCE_MS} ms; a larger uncertainty would take replies late by \
             more than their limits (5 to 70 ms) for on time"
        )));
    }
    let recorded = match &args.verify {
        Some(key) => match recorded::read_verified(&args.file, key)? {
            Ok((verified, r)) => {
                say!(
                    "the signature holds: {} as signed by the key given{}",
                    verified.checked.join(", "),
                    if verified.absent.is_empty() {
                        String::new()
                    } else {
                        format!(" ({} signed too, not beside it: not checked)", verified.absent.join(", "))
                    }
                );
                Some(r)
            }
            Err(why) => {
                say!("THE SIGNATURE DOES NOT HOLD: {why}: the report is no evidence of the signer's run");
                return Ok(Ended::Unverified);
            }
        },
        None if args.listen || args.vcd.is_some() => None,
        None => recorded::read_any(&args.file)?,
    };
    let beside = if args.verify.is_some() { Vec::new() } else { unchecked_beside(&args.file) };
    match recorded {
        Some(AnyRecorded::Slave(r)) => {
            return recorded::decode(*r, args.listening.report.as_deref(), args.listening.quiet, &beside)
        }
        Some(AnyRecorded::Master(r)) => return recorded::decode_master(*r, args.listening.quiet, &beside),
        None => {}
    }
    let (profile, _) = bus(&args.listening.profile, args.listening.baud)?;
    let input: capture::Input = if args.file.as_os_str() == "-" {
        Box::new(BufReader::new(std::io::stdin()))
    } else {
        let f = std::fs::File::open(&args.file).map_err(CommandError::file(&args.file))?;
        Box::new(BufReader::with_capacity(1 << 16, f))
    };
    let format = match args.format {
        FormatArg::Auto => None,
        FormatArg::Wirelog => Some(Format::Wirelog),
        FormatArg::Csv => Some(Format::Csv),
        FormatArg::Sigrok => Some(Format::Sigrok),
    };
    let name = args.file.display().to_string();
    if let Some(vcd) = &args.vcd {
        let read = ReadOptions { baud: args.listening.baud, samplerate_hz: args.samplerate };
        let (_, mut capture) = capture::open(input, format, read)
            .map_err(|e| CommandError::Input { name: name.clone(), why: e.to_string() })?;
        return write_vcd(capture.as_mut(), vcd, args.listening.baud, &name).map(|()| Ended::Done);
    }
    if let Some(dir) = &args.listening.report {
        crate::report::prepare_dir(dir)?;
    }
    let run_info = crate::report::run_info(&profile, &[]);
    let options = DecodeOptions {
        profile,
        baud: args.listening.baud,
        format,
        samplerate_hz: args.samplerate,
        tolerance_ms: args.tolerance_ms,
        master_channel: args.master_channel.clone(),
        polling_period_ms: args.listening.polling_period_ms,
    };
    let a_certify_report = || matches!(recorded::read_any(&args.file), Ok(Some(AnyRecorded::Slave(_))));
    if args.listen && args.file.as_os_str() != "-" && a_certify_report() {
        // A newcomer took the harness's own faults for FAILs of the run.
        say!(
            "note: the master on this wire is the harness, whose requests carry faults on purpose (a wrong \
             checksum, a wrong length, the error bit): graded as a listener would, they are the master's FAILs \
             below, not the device's; decode without --listen plays the run back as it was graded"
        );
    }
    let mut view = LiveView::new(args.listening.quiet, false);
    let report = grade_capture(input, &name, &options, &mut |h| view.print(h))?;
    drop(view);
    conclude(report, run_info, args.listening.report.as_deref())
}

/// End a listening run (`decode`, `monitor`): the summary on standard output, the
/// reports, and the exit code of the run's outcome (0 PASSED, 1 FAILED, 3 INCOMPLETE).
pub fn conclude(
    mut report: ListeningReport,
    run_info: hiperface_suite::report::RunInfo,
    report_dir: Option<&std::path::Path>,
) -> Result<Ended, CommandError> {
    report.run_info = Some(run_info);
    print_summary(&report);
    if let Some(dir) = report_dir {
        crate::report::write_all(&report, dir, None)?;
    }
    Ok(Ended::Graded(report.outcome))
}

/// The line per exchange on standard output, coloured by verdict where standard
/// output is a terminal that wants colour (`NO_COLOR`, `CLICOLOR_FORCE` respected).
pub struct LiveView {
    out: Option<Box<dyn Write>>,
    /// Whether lines are coloured: on a terminal that takes colour (anstream's choice,
    /// `NO_COLOR` and the like). Otherwise no escape is written at all, rather than
    /// written and stripped again for every line of a million-exchange capture.
    colour: bool,
    /// Flush after each line (a live bus), or once at the end (a file).
    live: bool,
}

impl LiveView {
    pub fn new(quiet: bool, live: bool) -> LiveView {
        let choice = anstream::AutoStream::choice(&std::io::stdout());
        let colour = choice != anstream::ColorChoice::Never;
        let raw: Box<dyn Write> = Box::new(std::io::BufWriter::new(std::io::stdout()));
        let out: Box<dyn Write> = if colour { Box::new(anstream::AutoStream::new(raw, choice)) } else { raw };
        LiveView { out: (!quiet).then_some(out), colour, live }
    }

    pub fn print(&mut self, h: &HeardExchange) {
        let Some(out) = self.out.as_mut() else { return };
        let _ = if self.colour {
            use anstyle::AnsiColor;
            let colour = match h.verdict {
                CaseVerdict::Pass => AnsiColor::Green,
                CaseVerdict::NonStrict => AnsiColor::Yellow,
                CaseVerdict::Fail => AnsiColor::Red,
                _ => AnsiColor::Cyan,
            };
            let style = anstyle::Style::new().fg_color(Some(colour.into()));
            writeln!(out, "{style}{h}{style:#}")
        } else {
            writeln!(out, "{h}")
        };
        if self.live {
            let _ = out.flush();
        }
    }
}

impl Drop for LiveView {
    fn drop(&mut self) {
        if let Some(out) = self.out.as_mut() {
            let _ = out.flush();
        }
    }
}

fn print_summary(r: &ListeningReport) {
    let s = &r.summary;
    let counts: Vec<String> = s.verdicts.iter().map(|(k, v)| format!("{v} {k}")).collect();
    say!(
        "{}: {} characters ({} with a line error), {} exchanges ({}), {} frames not attributed, {} breaks",
        r.capture,
        s.characters,
        s.flagged,
        s.exchanges,
        counts.join(", "),
        s.unattributed,
        s.breaks
    );
    for m in &s.master {
        say!("master: {} {} ({} times)", m.first.verdict().label(), m.first, m.count);
    }
    for a in &r.assumptions {
        say!("assumed: {a}");
    }
    say!("worst verdict heard: {}", r.verdict.label());
    match &r.incomplete {
        Some(why) => say!("{}: {why}", r.outcome.label()),
        None => say!("{}", r.outcome.label()),
    }
}

/// The profile and the bus's settings at `baud` (000:T7).
pub fn bus(profile: &str, baud: u32) -> Result<(hiperface_model::Profile, UartSettings), CommandError> {
    let profile = profile_file::resolve(profile)?;
    Ok((profile, settings_at(baud).map_err(|e| CommandError::Usage(e.to_string()))?))
}

fn write_vcd(
    capture: &mut dyn capture::Capture,
    path: &std::path::Path,
    baud: u32,
    name: &str,
) -> Result<(), CommandError> {
    // The channels are known once read; a wire log's are fixed.
    let mut events = Vec::new();
    for e in &mut *capture {
        events.push(e.map_err(|e| CommandError::Input { name: name.to_string(), why: e.to_string() })?);
    }
    let f = std::fs::File::create(path).map_err(CommandError::file(path))?;
    let mut w = std::io::BufWriter::new(f);
    capture::vcd::write(events.into_iter(), &capture.channels(), baud, &mut w)
        .and_then(|()| w.flush())
        .map_err(CommandError::file(path))
}
