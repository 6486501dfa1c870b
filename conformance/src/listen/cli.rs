//! `hiperface decode`: the listener over a capture file, with a live line per
//! exchange, a summary, and reports.

use super::{Heard, HeardExchange, Listener, Options, Summary};
use crate::capture::{self, Format, ReadOptions};
use crate::profile_file;
use hiperface_model::settings::Baud;
use hiperface_model::UartSettings;
use std::io::{BufRead, BufReader, Write};
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
    /// The encoder's profile: a built-in name or a TOML file.
    #[arg(long, default_value = "SRS50")]
    pub profile: String,
    /// The bus's data rate, bits per second (8E1).
    #[arg(long, default_value_t = 9600)]
    pub baud: u32,
    /// The capture's sample rate, Hz (sigrok-cli's sample numbers).
    #[arg(long)]
    pub samplerate: Option<u64>,
    /// The capture's timing uncertainty, ms (default: a certify report's own
    /// tolerance, else one bit time).
    #[arg(long)]
    pub tolerance_ms: Option<f64>,
    /// The channel the master talks on (`uart-1`, a CSV channel name), where the
    /// capture has one channel per direction.
    #[arg(long)]
    pub master_channel: Option<String>,
    /// The application's polling period, ms.
    #[arg(long, default_value_t = hiperface_model::master::obligations::POLLING_PERIOD_MS,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub polling_period_ms: u32,
    /// Write report.json and listening.md here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Do not print a line per exchange.
    #[arg(long)]
    pub quiet: bool,
    /// Instead of grading: write the capture's UART waveform as a VCD file.
    #[arg(long)]
    pub vcd: Option<PathBuf>,
}

/// The report of a listening run.
#[derive(Debug, serde::Serialize)]
pub struct ListeningReport {
    pub tool: String,
    pub capture: String,
    pub format: String,
    pub profile: String,
    pub baud: u32,
    pub tolerance_us: u64,
    pub channels: Vec<String>,
    pub assumptions: Vec<String>,
    pub verdict: Heard,
    pub summary: Summary,
}

/// Run `decode`; exit 0 with no FAIL, 1 with one, an error for input it cannot read.
pub fn decode(args: &DecodeArgs) -> Result<ExitCode, String> {
    let profile = profile_file::resolve(&args.profile).map_err(|e| e.to_string())?;
    let baud = Baud::from_bits_per_second(args.baud)
        .ok_or_else(|| format!("{} Bd is not a HIPERFACE data rate (000:T7)", args.baud))?;
    let settings = UartSettings { baud, ..UartSettings::DEFAULT };
    let read = ReadOptions { baud: args.baud, samplerate_hz: args.samplerate };
    let input: Box<dyn BufRead> = if args.file.as_os_str() == "-" {
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
    let (format, mut capture) = capture::open(input, format, read).map_err(|e| format!("{name}: {e}"))?;
    if let Some(vcd) = &args.vcd {
        return write_vcd(capture.as_mut(), vcd, args.baud, &name).map(|()| ExitCode::SUCCESS);
    }
    // The capture's own statement (a certify report's tolerance), else one bit time.
    let tolerance_us = match args.tolerance_ms {
        Some(ms) => (ms * 1000.0).round().max(0.0) as u64,
        None => capture.tolerance_us().unwrap_or(read.bit_time_us()),
    };
    let mut listener: Option<Listener> = None;
    let mut options =
        Options { profile, settings, tolerance_us, master_channel: None, polling_period_ms: args.polling_period_ms };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let quiet = args.quiet;
    let mut print = |h: &HeardExchange| {
        if !quiet {
            let _ = writeln!(out, "{}", line(h));
        }
    };
    let mut last_us = 0;
    while let Some(e) = capture.next() {
        let e = e.map_err(|e| format!("{name}: {e}"))?;
        // The master's channel is known once the capture has named it.
        let l = match &mut listener {
            Some(l) => l,
            None => {
                if let Some(m) = &args.master_channel {
                    let names = capture.channels();
                    options.master_channel = Some(names.iter().position(|n| n == m).ok_or_else(|| {
                        format!("{name}: no channel `{m}` before the first character (channels: {})", names.join(", "))
                    })? as u8);
                }
                listener.insert(Listener::new(options.clone()))
            }
        };
        last_us = e.at_us;
        l.feed(e, &mut print);
    }
    let mut l = listener.unwrap_or_else(|| Listener::new(options.clone()));
    l.finish(last_us, &mut print);
    let _ = out.flush();
    drop(out);
    let report = ListeningReport {
        tool: format!("hiperface {}", env!("CARGO_PKG_VERSION")),
        capture: name,
        format: format.to_string(),
        profile: profile.name.to_string(),
        baud: args.baud,
        tolerance_us,
        channels: capture.channels(),
        assumptions: capture.assumptions(),
        verdict: l.summary.worst(),
        summary: l.summary,
    };
    print_summary(&report);
    if let Some(dir) = &args.report {
        write_report(&report, dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    Ok(if report.verdict == Heard::Fail { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// One exchange as a line: time, command, bytes, response time, verdict.
pub fn line(h: &HeardExchange) -> String {
    let reply = h.reply.as_deref().unwrap_or("(silence)");
    let rt = h.response_ms.map_or(String::new(), |t| format!(" +{t:.3} ms"));
    let mut s =
        format!("{:>12.3} ms  {:<10} {}  M> {}  S< {reply}{rt}", h.t_ms, h.verdict.label(), h.command, h.request);
    for f in &h.findings {
        s.push_str(&format!("\n{:>27} {f}", f.verdict().label()));
    }
    s
}

fn print_summary(r: &ListeningReport) {
    let s = &r.summary;
    let counts: Vec<String> = s.verdicts.iter().map(|(k, v)| format!("{v} {k}")).collect();
    println!(
        "{}: {} characters, {} exchanges ({}), {} frames not attributed, {} breaks",
        r.capture,
        s.characters,
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
    println!("verdict: {}", r.verdict.label());
}

fn write_report(r: &ListeningReport, dir: &std::path::Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let json = serde_json::to_string_pretty(r).map_err(std::io::Error::other)?;
    std::fs::write(dir.join("report.json"), json + "\n")?;
    std::fs::write(dir.join("listening.md"), markdown(r))
}

/// The report for people.
pub fn markdown(r: &ListeningReport) -> String {
    use std::fmt::Write as _;
    let s = &r.summary;
    let mut m = String::new();
    let _ = writeln!(m, "# Listening report: {}\n", r.capture);
    let _ = writeln!(m, "- Verdict: **{}**", r.verdict.label());
    let _ = writeln!(m, "- Format: {}; channels: {}", r.format, r.channels.join(", "));
    let _ = writeln!(m, "- Profile: {}; {} Bd; timing tolerance {} µs", r.profile, r.baud, r.tolerance_us);
    let _ = writeln!(
        m,
        "- {} characters, {} exchanges, {} frames not attributed, {} breaks",
        s.characters, s.exchanges, s.unattributed, s.breaks
    );
    for (k, v) in &s.verdicts {
        let _ = writeln!(m, "  - {k}: {v}");
    }
    for a in &r.assumptions {
        let _ = writeln!(m, "- Assumed: {a}");
    }
    let _ = writeln!(
        m,
        "\nUNKNOWN is what a listener cannot tell (the encoder's stored state, a corrupted capture), never a charge.\n"
    );
    if !s.master.is_empty() {
        let _ = writeln!(m, "## The master\n\n| verdict | rule | times | first |\n|---|---|---|---|");
        for x in &s.master {
            let _ = writeln!(m, "| {} | {} | {} | {} |", x.first.verdict().label(), x.rule, x.count, x.first);
        }
    }
    let _ = writeln!(m, "\n## Response times per command (ms)\n");
    let head: Vec<String> = super::summary::BUCKETS_MS.iter().map(|b| format!("≤{b}")).collect();
    let _ = writeln!(m, "| command | n | min | mean | max | {} | more |", head.join(" | "));
    let _ = writeln!(m, "|---|---|---|---|---|{}---|", "---|".repeat(head.len()));
    for (c, t) in &s.response_times {
        let h: Vec<String> = t.histogram.iter().map(|n| n.to_string()).collect();
        let _ = writeln!(
            m,
            "| {c} | {} | {:.3} | {:.3} | {:.3} | {} |",
            t.count,
            t.min_ms,
            t.mean_ms,
            t.max_ms,
            h.join(" | ")
        );
    }
    if !s.exchanges_kept.is_empty() {
        let _ = writeln!(m, "\n## Exchanges not PASS (the first {})\n\n```", s.exchanges_kept.len());
        for h in &s.exchanges_kept {
            let _ = writeln!(m, "{}", line(h));
        }
        let _ = writeln!(m, "```");
    }
    if !s.notes.is_empty() {
        let _ = writeln!(m, "\n## Notes\n");
        for n in &s.notes {
            let _ = writeln!(m, "- {n}");
        }
    }
    m
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
