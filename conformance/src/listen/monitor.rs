//! `hiperface monitor`: the listener on a live bus, through a port it cannot write
//! ([`super::tap`]). A line per exchange as it closes, a summary when the run ends
//! (Ctrl-C, `--duration-ms`, or the port closing), and the reports.

use super::cli::{conclude, ListeningArgs, LiveView};
use super::tap::{Got, Stamps, Tap};
use crate::args::parse_ms;
use crate::command::{CommandError, Ended};
use crate::port::PortSpec;
use hiperface_suite::capture::parmrk::Marks;
use hiperface_suite::capture::{Event, Mark};
use hiperface_suite::listen::decode::{report, Source};
use hiperface_suite::listen::{Listener, Options};
use hiperface_suite::time::ms_to_us;
use std::io::Write;
use std::path::PathBuf;
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
    #[arg(long, value_parser = parse_ms)]
    pub tolerance_ms: Option<f64>,
    /// Stop after this many ms (default: at Ctrl-C, or when the port closes).
    #[arg(long, value_parser = parse_ms)]
    pub duration_ms: Option<f64>,
    /// The same in seconds: the old name, a hidden alias of one release.
    #[arg(long, hide = true, value_parser = parse_ms, conflicts_with = "duration_ms")]
    pub duration_s: Option<f64>,
    /// Also write every character heard, with its time, as a CSV capture that
    /// `hiperface decode` reads (nothing heard is lost); a new file, never one that
    /// exists.
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
pub fn monitor(args: &MonitorArgs, stop: &AtomicBool) -> Result<Ended, CommandError> {
    let (profile, settings) = super::cli::bus(&args.listening.profile, args.listening.baud)?;
    if let Some(dir) = &args.listening.report {
        crate::report::prepare_dir(dir)?;
    }
    let mut tap = Tap::open(&args.port, settings).map_err(CommandError::Line)?;
    let tolerance_us = args.tolerance_ms.map_or(tap.jitter_us, ms_to_us);
    let options = Options {
        profile,
        settings,
        tolerance_us,
        master_channel: None,
        polling_period_ms: args.listening.polling_period_ms,
    };
    let mut capture = match &args.capture {
        Some(p) => Some(CaptureFile::create(p, settings.char_time_us(), tolerance_us)?),
        None => None,
    };
    eprintln!("listening on {} at {settings} (read-only); Ctrl-C ends the run with a summary", tap.name);
    // A live bus is read in real time: the processors kept awake for the run where
    // permitted, and what the hypervisor took meanwhile recorded (`sched::KeepAwake`).
    let mut run_info = crate::report::run_info(&options.profile, &[]);
    let real_time = crate::report::RealTimeRun::start();
    let mut listener = Listener::new(options.clone());
    let mut view = LiveView::new(args.listening.quiet, true);
    let mut print = |h: &hiperface_suite::listen::HeardExchange| view.print(h);
    let epoch = Instant::now();
    let now_us = || epoch.elapsed().as_micros() as u64;
    let until_us = args.duration_ms.or(args.duration_s.map(|s| s * 1000.0)).map(ms_to_us);
    let lag = lag_us(&tap, &options);
    let mut stamps = Stamps::new(settings.char_time_us());
    let mut marks = Marks::default();
    let mut heard = Vec::new();
    // A thread does nothing but read and note the arrival time, so that grading and
    // printing never delay a timestamp; it says how late each read may have returned.
    let (tx, rx) = std::sync::mpsc::channel::<Result<Chunk, String>>();
    let reading = AtomicBool::new(true);
    let mut reader_log = ReaderLog::default();
    let ended_by = std::thread::scope(|scope| {
        let reader = scope.spawn(|| {
            let mut log = ReaderLog { real_time: crate::sched::real_time_priority(), ..ReaderLog::default() };
            let mut run_delay = crate::run_delay::RunDelay::of_this_thread();
            log.run_delay_counted = run_delay.available();
            let mut buf = [0u8; 4096];
            let mut last_us = now_us();
            // The wait for a processor in a read that returned nothing: what came just
            // after it returned waited that long too.
            let mut quiet_wait_us = 0;
            while reading.load(Ordering::Relaxed) {
                let call_us = now_us();
                let got = tap.read(&mut buf);
                let arrival = now_us();
                // What came may have waited since the last read returned (the reader
                // was elsewhere), and for as long as the reader waited for a processor.
                let waited_us = run_delay.take_us().unwrap_or(0);
                let late_us = (call_us - last_us) + std::mem::replace(&mut quiet_wait_us, 0) + waited_us;
                log.longest_gap_us = log.longest_gap_us.max(arrival - last_us);
                last_us = arrival;
                let sent = match got {
                    Ok(Got::Bytes(n)) => {
                        log.latest_read_us = log.latest_read_us.max(late_us);
                        let bytes = buf.get(..n).unwrap_or(&[]).to_vec();
                        tx.send(Ok(Chunk { arrival_us: arrival, late_us, bytes }))
                    }
                    Ok(Got::Quiet) => {
                        quiet_wait_us = waited_us;
                        Ok(())
                    }
                    Ok(Got::Closed) => break,
                    Err(e) => tx.send(Err(format!("{}: {e}", tap.name))),
                };
                if sent.is_err() {
                    break;
                }
            }
            drop(tx);
            log
        });
        let ended_by = loop {
            if stop.load(Ordering::Relaxed) {
                break Ok("Ctrl-C");
            }
            if until_us.is_some_and(|u| now_us() >= u) {
                break Ok("the duration");
            }
            match rx.recv_timeout(std::time::Duration::from_millis(50)) {
                Ok(Ok(Chunk { arrival_us, late_us, bytes })) => {
                    heard.clear();
                    for b in bytes {
                        marks.push(b, &mut |m| heard.push(m));
                    }
                    let events = heard.iter().zip(stamps.chunk(heard.len(), arrival_us));
                    let events = events.map(|(&mark, at_us)| Event { at_us, channel: 0, role: None, mark, late_us });
                    if let Some(c) = capture.as_mut() {
                        let saved = events.clone().try_for_each(|e| c.write(&e));
                        if let Err(e) = saved {
                            break Err(CommandError::file(&c.path)(e));
                        }
                    }
                    events.for_each(|e| listener.feed(e, &mut print));
                }
                Ok(Err(e)) => break Err(CommandError::Line(e)),
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    listener.idle(now_us().saturating_sub(lag), &mut print)
                }
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break Ok("the port closing"),
            }
        };
        reading.store(false, Ordering::Relaxed);
        reader_log = reader.join().unwrap_or_default();
        ended_by
    })?;
    let end_us = now_us();
    listener.finish(end_us, &mut print);
    drop(view);
    if let Some(c) = capture.as_mut() {
        c.out.flush().map_err(CommandError::file(&c.path))?;
    }
    let mut assumptions = vec![
        "one channel: a frame that starts in a request's reply window is its reply".to_string(),
        "bytes that arrive together: the last ended at their arrival, the ones before a character time apart"
            .to_string(),
        format!(
            "the run lasted {:.1} s and was ended by {ended_by}; the monitor read the port at least every {:.1} ms",
            end_us as f64 / 1e6,
            reader_log.longest_gap_us as f64 / 1000.0
        ),
        reader_log.describe(),
    ];
    assumptions.extend(tap.notes.iter().cloned());
    let (held, steal) = real_time.finish();
    assumptions.push(held);
    if let Some(c) = &capture {
        assumptions.push(format!("every character heard is in {}", c.path.display()));
    }
    let source = Source { capture: tap.name.clone(), format: "live".into(), channels: vec!["bus".into()], assumptions };
    run_info.steal = steal;
    crate::report::say_steal(run_info.steal);
    conclude(report(listener, source, &options), run_info, args.listening.report.as_deref())
}

/// What one read of the tap returned.
struct Chunk {
    arrival_us: u64,
    /// How late the read may have returned it: how long the reader had not been in a
    /// read before, and how long it waited for a processor since the read before.
    late_us: u64,
    bytes: Vec<u8>,
}

/// How punctual the reader was, for the report.
#[derive(Debug, Default)]
struct ReaderLog {
    real_time: bool,
    run_delay_counted: bool,
    longest_gap_us: u64,
    /// The latest any read that returned characters may have been, µs.
    latest_read_us: u64,
}

impl ReaderLog {
    fn describe(&self) -> String {
        let priority = if self.real_time { "at a real-time priority" } else { "at a normal priority" };
        if self.run_delay_counted {
            format!(
                "the reader ran {priority}; its reads returned characters at most {:.1} ms late (waiting for a \
                 processor, measured); a reply's timing that this could change is UNKNOWN",
                self.latest_read_us as f64 / 1000.0
            )
        } else {
            format!(
                "the reader ran {priority}; this kernel does not count how long a thread waits for a processor, \
                 so a read that returned late on a busy machine is not seen"
            )
        }
    }
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
    /// The capture opens with the tolerance the monitor grades with, which `decode`
    /// then grades with too (the same verdicts later, no flag needed).
    fn create(path: &std::path::Path, char_us: u64, tolerance_us: u64) -> Result<CaptureFile, CommandError> {
        // Never over an earlier capture, nor through a link to a file elsewhere.
        let f = std::fs::OpenOptions::new().write(true).create_new(true).open(path).map_err(|e| {
            if e.kind() == std::io::ErrorKind::AlreadyExists {
                CommandError::Input {
                    name: path.display().to_string(),
                    why: "exists already: a capture is never written over; choose another name".into(),
                }
            } else {
                CommandError::file(path)(e)
            }
        })?;
        let mut out = std::io::BufWriter::new(f);
        writeln!(out, "{} tolerance_us={tolerance_us}", hiperface_suite::capture::csv::MONITOR_CAPTURE)
            .and_then(|()| writeln!(out, "Time [s],Value,Parity Error,Framing Error,Read Late [s]"))
            .map_err(CommandError::file(path))?;
        Ok(CaptureFile { path: path.to_path_buf(), out, char_us })
    }

    fn write(&mut self, e: &Event) -> std::io::Result<()> {
        let start = e.at_us.saturating_sub(self.char_us);
        let (value, parity, framing) = match e.mark {
            Mark::Byte(b) => (b, "", ""),
            Mark::ParityError(b) => (b, "1", ""),
            Mark::FramingError(b) => (b, "", "1"),
            Mark::Break => (0, "", "1"),
        };
        let (s, us) = (start / 1_000_000, start % 1_000_000);
        let late = format!("{}.{:06}", e.late_us / 1_000_000, e.late_us % 1_000_000);
        writeln!(self.out, "{s}.{us:06},0x{value:02X},{parity},{framing},{late}")
    }
}
