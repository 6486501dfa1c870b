//! `hiperface monitor`: the listener on a live bus, through a port it cannot write
//! ([`super::tap`]). A line per exchange as it closes, a summary when the run ends
//! (Ctrl-C, `--duration-s`, or the port closing), and the reports.

use super::cli::{conclude, ms_to_us, ListeningArgs, LiveView, Source};
use super::tap::{Got, Marks, Stamps, Tap};
use super::{Listener, Options};
use crate::capture::{Event, Mark};
use crate::port::PortSpec;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// `hiperface monitor`.
#[derive(clap::Args, Debug, Clone)]
pub struct MonitorArgs {
    /// The tap: a serial port or pseudo-terminal path (opened read-only), or
    /// `tcp://HOST:PORT` (a serial device server).
    #[arg(long)]
    pub port: PortSpec,
    /// Timing jitter allowed before a reply's timing is graded, ms (default: the
    /// port's: 2 on a pseudo-terminal or serial port, 4 over TCP, a USB adapter's
    /// latency timer when that is longer).
    #[arg(long)]
    pub tolerance_ms: Option<f64>,
    /// Stop after this many seconds (default: at Ctrl-C, or when the port closes).
    #[arg(long)]
    pub duration_s: Option<f64>,
    /// Also write every character heard, with its time, as a CSV capture that
    /// `hiperface decode` reads (nothing heard is lost).
    #[arg(long)]
    pub capture: Option<PathBuf>,
    #[command(flatten)]
    pub listening: ListeningArgs,
}

/// How far behind the clock the listener is moved while the bus is quiet: bytes
/// still on their way (a USB adapter's latency, a server's chunks, a frame's worth
/// of characters stamped before their arrival) must not arrive in its past.
fn lag_us(tap: &Tap, options: &Options) -> u64 {
    let frame_us = hiperface_model::frame::MAX_FRAME as u64 * options.settings.char_time_us();
    tap.jitter_us + options.tolerance_us + 2 * frame_us
}

/// Listen until `stop` is set, the duration is over, or the port closes.
pub fn monitor(args: &MonitorArgs, stop: &AtomicBool) -> Result<ExitCode, String> {
    let (profile, settings) = super::cli::bus(&args.listening.profile, args.listening.baud)?;
    if let Some(dir) = &args.listening.report {
        crate::report::prepare_dir(dir)?;
    }
    let mut tap = Tap::open(&args.port, settings)?;
    let tolerance_us = args.tolerance_ms.map_or(tap.jitter_us, ms_to_us);
    let options = Options {
        profile,
        settings,
        tolerance_us,
        master_channel: None,
        polling_period_ms: args.listening.polling_period_ms,
    };
    let mut capture = match &args.capture {
        Some(p) => Some(CaptureFile::create(p, settings.char_time_us())?),
        None => None,
    };
    eprintln!("listening on {} at {settings} (read-only); Ctrl-C ends the run with a summary", tap.name);
    let mut listener = Listener::new(options.clone());
    let mut view = LiveView::new(args.listening.quiet, true);
    let mut print = |h: &super::HeardExchange| view.print(h);
    let epoch = Instant::now();
    let now_us = || epoch.elapsed().as_micros() as u64;
    let until_us = args.duration_s.map(|s| ms_to_us(s * 1000.0));
    let lag = lag_us(&tap, &options);
    let mut stamps = Stamps::new(settings.char_time_us());
    let mut marks = Marks::default();
    let mut heard = Vec::new();
    // A thread does nothing but read and note the arrival time, so that grading and
    // printing never delay a timestamp.
    let (tx, rx) = std::sync::mpsc::channel::<Result<(u64, Vec<u8>), String>>();
    let reading = AtomicBool::new(true);
    let mut longest_gap_us = 0;
    let ended_by = std::thread::scope(|scope| {
        let reader = scope.spawn(|| {
            let mut buf = [0u8; 4096];
            let mut last_us = now_us();
            let mut longest = 0;
            while reading.load(Ordering::Relaxed) {
                let got = tap.read(&mut buf);
                let arrival = now_us();
                longest = longest.max(arrival - last_us);
                last_us = arrival;
                let sent = match got {
                    Ok(Got::Bytes(n)) => tx.send(Ok((arrival, buf.get(..n).unwrap_or(&[]).to_vec()))),
                    Ok(Got::Quiet) => Ok(()),
                    Ok(Got::Closed) => break,
                    Err(e) => tx.send(Err(format!("{}: {e}", tap.name))),
                };
                if sent.is_err() {
                    break;
                }
            }
            drop(tx);
            longest
        });
        let ended_by = loop {
            if stop.load(Ordering::Relaxed) {
                break Ok("Ctrl-C");
            }
            if until_us.is_some_and(|u| now_us() >= u) {
                break Ok("the duration");
            }
            match rx.recv_timeout(std::time::Duration::from_millis(50)) {
                Ok(Ok((arrival, bytes))) => {
                    heard.clear();
                    for b in bytes {
                        marks.push(b, &mut |m| heard.push(m));
                    }
                    let events = heard.iter().zip(stamps.chunk(heard.len(), arrival));
                    let events = events.map(|(&mark, at_us)| Event { at_us, channel: 0, role: None, mark });
                    if let Some(c) = capture.as_mut() {
                        let saved = events.clone().try_for_each(|e| c.write(e.at_us, e.mark));
                        if let Err(e) = saved {
                            break Err(format!("{}: {e}", c.path.display()));
                        }
                    }
                    events.for_each(|e| listener.feed(e, &mut print));
                }
                Ok(Err(e)) => break Err(e),
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    listener.idle(now_us().saturating_sub(lag), &mut print)
                }
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break Ok("the port closing"),
            }
        };
        reading.store(false, Ordering::Relaxed);
        longest_gap_us = reader.join().unwrap_or(0);
        ended_by
    })?;
    let end_us = now_us();
    listener.finish(end_us, &mut print);
    drop(view);
    if let Some(c) = capture.as_mut() {
        c.out.flush().map_err(|e| format!("{}: {e}", c.path.display()))?;
    }
    let mut assumptions = vec![
        "one channel: a frame that starts in a request's reply window is its reply".to_string(),
        "bytes that arrive together: the last ended at their arrival, the ones before a character time apart"
            .to_string(),
        format!(
            "the run lasted {:.1} s and was ended by {ended_by}; the monitor read the port at least every {:.1} ms",
            end_us as f64 / 1e6,
            longest_gap_us as f64 / 1000.0
        ),
    ];
    assumptions.extend(tap.notes.iter().cloned());
    if let Some(c) = &capture {
        assumptions.push(format!("every character heard is in {}", c.path.display()));
    }
    let source = Source { capture: tap.name.clone(), format: "live".into(), channels: vec!["bus".into()], assumptions };
    conclude(listener, source, &options, args.listening.report.as_deref())
}

/// The characters heard as a CSV capture (`decode` reads it): the start of each
/// character's start bit, as logic-analyzer exports stamp it. A break is written as
/// 00h with a framing error, as a UART reports one.
struct CaptureFile {
    path: PathBuf,
    out: std::io::BufWriter<std::fs::File>,
    char_us: u64,
}

impl CaptureFile {
    fn create(path: &std::path::Path, char_us: u64) -> Result<CaptureFile, String> {
        let f = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut out = std::io::BufWriter::new(f);
        writeln!(out, "Time [s],Value,Parity Error,Framing Error").map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(CaptureFile { path: path.to_path_buf(), out, char_us })
    }

    fn write(&mut self, at_us: u64, mark: Mark) -> std::io::Result<()> {
        let start = at_us.saturating_sub(self.char_us);
        let (value, parity, framing) = match mark {
            Mark::Byte(b) => (b, "", ""),
            Mark::ParityError(b) => (b, "1", ""),
            Mark::FramingError(b) => (b, "", "1"),
            Mark::Break => (0, "", "1"),
        };
        writeln!(self.out, "{}.{:06},0x{value:02X},{parity},{framing}", start / 1_000_000, start % 1_000_000)
    }
}
