//! `hiperface decode`: the listener over a capture file, with a live line per
//! exchange, a summary, and reports.

use super::{HeardExchange, Listener, ListeningReport, Options, Summary};
use crate::args::{ms_to_us, parse_ms};
use crate::capture::{self, Capture, Format, ReadOptions};
use crate::profile_file;
use crate::verdict::CaseVerdict;
use hiperface_model::settings::Baud;
use hiperface_model::UartSettings;
use std::io::{BufReader, Write};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    Auto,
    Wirelog,
    Csv,
    Sigrok,
}

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
    /// The capture's timing uncertainty, ms (default: a certify report's own
    /// tolerance, else one bit time).
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

/// Run `decode`; exit 0 with no FAIL, 1 with one, an error for input it cannot read.
/// A certify report with the record of its wire is played back to the catalogue
/// instead (`crate::record`): the run's verdicts, graded again, and its exit code.
pub fn decode(args: &DecodeArgs) -> Result<ExitCode, String> {
    use crate::report::recorded::{self, AnyRecorded};
    let recorded = if args.listen || args.vcd.is_some() { None } else { recorded::read_any(&args.file)? };
    match recorded {
        Some(AnyRecorded::Slave(r)) => {
            return recorded::decode(*r, args.listening.report.as_deref(), args.listening.quiet)
        }
        Some(AnyRecorded::Master(r)) => return recorded::decode_master(r, args.listening.quiet),
        None => {}
    }
    let (profile, _) = bus(&args.listening.profile, args.listening.baud)?;
    let input: capture::Input = if args.file.as_os_str() == "-" {
        Box::new(BufReader::new(std::io::stdin()))
    } else {
        let f = std::fs::File::open(&args.file).map_err(|e| format!("{}: {e}", args.file.display()))?;
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
        let (_, mut capture) = capture::open(input, format, read).map_err(|e| format!("{name}: {e}"))?;
        return write_vcd(capture.as_mut(), vcd, args.listening.baud, &name).map(|()| ExitCode::SUCCESS);
    }
    if let Some(dir) = &args.listening.report {
        crate::report::prepare_dir(dir)?;
    }
    let options = DecodeOptions {
        profile,
        baud: args.listening.baud,
        format,
        samplerate_hz: args.samplerate,
        tolerance_ms: args.tolerance_ms,
        master_channel: args.master_channel.clone(),
        polling_period_ms: args.listening.polling_period_ms,
    };
    let mut view = LiveView::new(args.listening.quiet, false);
    let report = grade_capture(input, &name, &options, &mut |h| view.print(h))?;
    drop(view);
    conclude(report, args.listening.report.as_deref())
}

/// How to hear a capture file: what `decode`'s options say.
#[derive(Debug, Clone)]
pub struct DecodeOptions {
    /// The encoder's profile.
    pub profile: hiperface_model::Profile,
    /// The bus's data rate, bits per second (8E1).
    pub baud: u32,
    /// `None`: detected from the first line.
    pub format: Option<Format>,
    /// The capture's sample rate (sigrok-cli's sample numbers).
    pub samplerate_hz: Option<u64>,
    /// The capture's timing uncertainty, ms (`None`: a certify report's own
    /// tolerance, else one bit time).
    pub tolerance_ms: Option<f64>,
    /// The channel the master talks on, where the capture has one per direction.
    pub master_channel: Option<String>,
    /// The application's polling period, ms (000:3.2.2).
    pub polling_period_ms: u32,
}

/// Grade a capture: every exchange heard is graded by the listener and given to
/// `heard` as it is, and the run comes back as the report `decode --report` writes.
/// The text is parsed on a thread of its own while the listener grades. An error for
/// input that cannot be read (with the capture's `name` and the line).
pub fn grade_capture(
    input: capture::Input,
    name: &str,
    o: &DecodeOptions,
    heard: &mut dyn FnMut(&HeardExchange),
) -> Result<ListeningReport, String> {
    let settings = settings_at(o.baud)?;
    let read = ReadOptions { baud: o.baud, samplerate_hz: o.samplerate_hz };
    let (format, capture) = capture::open(input, o.format, read).map_err(|e| format!("{name}: {e}"))?;
    // The capture's own statement (a certify report's tolerance), else one bit time.
    let tolerance_us = match o.tolerance_ms {
        Some(ms) => ms_to_us(ms),
        None => capture.tolerance_us().unwrap_or(read.bit_time_us()),
    };
    let mut options = Options {
        profile: o.profile,
        settings,
        tolerance_us,
        master_channel: None,
        polling_period_ms: o.polling_period_ms,
    };
    let (l, channels, assumptions) = std::thread::scope(|s| {
        let mut capture = capture::prefetch(s, capture);
        let mut listener: Option<Listener> = None;
        let mut last_us = 0;
        while let Some(e) = capture.next() {
            let e = e.map_err(|e| format!("{name}: {e}"))?;
            // The master's channel is known once the capture has named it.
            let l = match &mut listener {
                Some(l) => l,
                None => {
                    if let Some(m) = &o.master_channel {
                        let names = capture.channels();
                        options.master_channel = Some(names.iter().position(|n| n == m).ok_or_else(|| {
                            format!(
                                "{name}: no channel `{m}` before the first character (channels: {})",
                                names.join(", ")
                            )
                        })? as u8);
                    }
                    listener.insert(Listener::new(options.clone()))
                }
            };
            last_us = e.at_us;
            l.feed(e, &mut |h| heard(h));
        }
        let mut l = listener.unwrap_or_else(|| Listener::new(options.clone()));
        l.finish(last_us, &mut |h| heard(h));
        Ok::<_, String>((l, capture.channels(), capture.assumptions()))
    })?;
    let source = Source { capture: name.to_string(), format: format.to_string(), channels, assumptions };
    Ok(report(l, source, &options))
}

/// Where a listening run heard its characters, for the report.
pub struct Source {
    pub capture: String,
    pub format: String,
    pub channels: Vec<String>,
    pub assumptions: Vec<String>,
}

/// What a listening run adds up to: the report its `--report` writes.
pub fn report(listener: Listener, source: Source, options: &Options) -> ListeningReport {
    let (outcome, incomplete) = listener.summary.outcome();
    ListeningReport {
        tool: format!("hiperface {}", env!("CARGO_PKG_VERSION")),
        capture: source.capture,
        format: source.format,
        profile: options.profile.name.to_string(),
        baud: options.settings.baud.bits_per_second(),
        tolerance_us: options.tolerance_us,
        channels: source.channels,
        assumptions: source.assumptions,
        verdict: listener.summary.worst(),
        outcome,
        incomplete,
        summary: listener.summary,
    }
}

/// End a listening run (`decode`, `monitor`): the summary on standard output, the
/// reports, and the exit code of the run's outcome (0 PASSED, 1 FAILED, 3 INCOMPLETE).
pub fn conclude(report: ListeningReport, report_dir: Option<&std::path::Path>) -> Result<ExitCode, String> {
    print_summary(&report);
    if let Some(dir) = report_dir {
        crate::report::write_all(&report, dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    Ok(report.outcome.exit())
}

/// The line per exchange on standard output, coloured by verdict where standard
/// output is a terminal that wants colour (`NO_COLOR`, `CLICOLOR_FORCE` respected).
pub struct LiveView {
    out: Option<anstream::AutoStream<Box<dyn Write>>>,
    /// Flush after each line (a live bus), or once at the end (a file).
    live: bool,
}

impl LiveView {
    pub fn new(quiet: bool, live: bool) -> LiveView {
        let choice = anstream::AutoStream::choice(&std::io::stdout());
        let raw: Box<dyn Write> = Box::new(std::io::BufWriter::new(std::io::stdout()));
        LiveView { out: (!quiet).then(|| anstream::AutoStream::new(raw, choice)), live }
    }

    pub fn print(&mut self, h: &HeardExchange) {
        let Some(out) = self.out.as_mut() else { return };
        use anstyle::AnsiColor;
        let colour = match h.verdict {
            CaseVerdict::Pass => AnsiColor::Green,
            CaseVerdict::NonStrict => AnsiColor::Yellow,
            CaseVerdict::Fail => AnsiColor::Red,
            _ => AnsiColor::Cyan,
        };
        let style = anstyle::Style::new().fg_color(Some(colour.into()));
        let _ = writeln!(out, "{style}{h}{style:#}");
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
    println!(
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
        println!("master: {} {} ({} times)", m.first.verdict().label(), m.first, m.count);
    }
    for a in &r.assumptions {
        println!("assumed: {a}");
    }
    println!("worst verdict heard: {}", r.verdict.label());
    match &r.incomplete {
        Some(why) => println!("{}: {why}", r.outcome.label()),
        None => println!("{}", r.outcome.label()),
    }
}

/// The profile and the bus's settings at `baud` (000:T7).
pub fn bus(profile: &str, baud: u32) -> Result<(hiperface_model::Profile, UartSettings), String> {
    let profile = profile_file::resolve(profile).map_err(|e| e.to_string())?;
    Ok((profile, settings_at(baud)?))
}

/// The bus's settings at `baud`, one of 000:T7's data rates (8E1).
fn settings_at(baud: u32) -> Result<UartSettings, String> {
    let baud =
        Baud::from_bits_per_second(baud).ok_or_else(|| format!("{baud} Bd is not a HIPERFACE data rate (000:T7)"))?;
    Ok(UartSettings { baud, ..UartSettings::DEFAULT })
}

fn write_vcd(capture: &mut dyn capture::Capture, path: &std::path::Path, baud: u32, name: &str) -> Result<(), String> {
    // The channels are known once read; a wire log's are fixed.
    let mut events = Vec::new();
    for e in &mut *capture {
        events.push(e.map_err(|e| format!("{name}: {e}"))?);
    }
    let f = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut w = std::io::BufWriter::new(f);
    capture::vcd::write(events.into_iter(), &capture.channels(), baud, &mut w)
        .and_then(|()| w.flush())
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Read a whole capture and listen to it, without printing, the reader on a thread
/// of its own as `decode` does: what the throughput benchmark and the tests run.
/// `format`: `None` detects it.
pub fn listen_to(
    input: &[u8],
    format: Option<crate::capture::Format>,
    read: crate::capture::ReadOptions,
    options: Options,
) -> Result<Summary, crate::capture::ParseError> {
    let (_, capture) = crate::capture::open(Box::new(input), format, read)?;
    std::thread::scope(|s| listen_all(crate::capture::prefetch(s, capture), options))
}

fn listen_all(
    capture: impl Iterator<Item = Result<crate::capture::Event, crate::capture::ParseError>>,
    options: Options,
) -> Result<Summary, crate::capture::ParseError> {
    let mut listener = Listener::new(options);
    let mut last_us = 0;
    for e in capture {
        let e = e?;
        last_us = e.at_us;
        listener.feed(e, &mut |_| {});
    }
    listener.finish(last_us, &mut |_| {});
    Ok(listener.summary)
}

/// The fuzz targets' entry (fuzz/fuzz_targets/capture_*.rs) and their corpus replay:
/// any bytes as a capture of `format` (9600 Bd, sigrok at 1 MHz) through its reader
/// and the listener, on one thread. An error for bad input is fine; a panic or a
/// hang is not.
pub fn fuzz_capture(format: crate::capture::Format, input: &[u8]) {
    let profile = hiperface_model::profiles::srs50();
    let options = Options {
        profile,
        settings: UartSettings::DEFAULT,
        tolerance_us: 1_000,
        master_channel: None,
        polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
    };
    let read = crate::capture::ReadOptions { baud: 9600, samplerate_hz: Some(1_000_000) };
    if let Ok((_, capture)) = crate::capture::open(Box::new(input), Some(format), read) {
        let _ = listen_all(capture, options);
    }
}
