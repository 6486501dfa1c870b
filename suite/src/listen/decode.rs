//! Grading a capture file as `hiperface decode` does, without the command line: the
//! capture read by its format's reader on a thread of its own, every exchange heard
//! graded by the listener and handed over as it is, and the listening run's report.
//! The C and Python libraries and the command share it.

use super::{HeardExchange, Listener, ListeningReport, Options, Summary};
use crate::capture::{self, Capture, Format, ParseError, ReadOptions};
use crate::time::ms_to_us;
use hiperface_model::settings::Baud;
use hiperface_model::UartSettings;

/// Why a capture could not be graded: the input, not a verdict.
#[derive(Debug, thiserror::Error)]
pub enum DecodeError {
    #[error("{0} Bd is not a HIPERFACE data rate (000:T7)")]
    Rate(u32),
    /// The capture cannot be read (with its name and the line).
    #[error("{name}: {error}")]
    Capture { name: String, error: ParseError },
    #[error("{name}: no channel `{channel}` before the first character (channels: {channels})")]
    NoChannel { name: String, channel: String, channels: String },
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
) -> Result<ListeningReport, DecodeError> {
    let settings = settings_at(o.baud)?;
    let read = ReadOptions { baud: o.baud, samplerate_hz: o.samplerate_hz };
    let unreadable = |error| DecodeError::Capture { name: name.to_string(), error };
    let (format, capture) = capture::open(input, o.format, read).map_err(unreadable)?;
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
        while let Some(run) = capture.next_run() {
            let run = run.map_err(unreadable)?;
            // The master's channel is known once the capture has named it.
            let l = match &mut listener {
                Some(l) => l,
                None => {
                    if let Some(m) = &o.master_channel {
                        let names = capture.channels();
                        options.master_channel =
                            Some(names.iter().position(|n| n == m).ok_or_else(|| DecodeError::NoChannel {
                                name: name.to_string(),
                                channel: m.clone(),
                                channels: names.join(", "),
                            })? as u8);
                    }
                    listener.insert(Listener::new(options.clone()))
                }
            };
            last_us = run.last_us();
            l.feed_run(&run, &mut |h| heard(h));
        }
        let mut l = listener.unwrap_or_else(|| Listener::new(options.clone()));
        l.finish(last_us, &mut |h| heard(h));
        Ok::<_, DecodeError>((l, capture.channels(), capture.assumptions()))
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
        run_info: None,
    }
}

/// The bus's settings at `baud`, one of 000:T7's data rates (8E1).
pub fn settings_at(baud: u32) -> Result<UartSettings, DecodeError> {
    let baud = Baud::from_bits_per_second(baud).ok_or(DecodeError::Rate(baud))?;
    Ok(UartSettings { baud, ..UartSettings::DEFAULT })
}

/// Read a whole capture and listen to it, without printing, the reader on a thread
/// of its own as `decode` does: what the throughput benchmark and the tests run.
/// `format`: `None` detects it.
pub fn listen_to(
    input: &[u8],
    format: Option<capture::Format>,
    read: capture::ReadOptions,
    options: Options,
) -> Result<Summary, capture::ParseError> {
    let (_, capture) = capture::open(Box::new(input), format, read)?;
    std::thread::scope(|s| listen_all(&mut capture::prefetch(s, capture), options))
}

fn listen_all<C: Capture + ?Sized>(capture: &mut C, options: Options) -> Result<Summary, capture::ParseError> {
    let mut listener = Listener::new(options);
    let mut last_us = 0;
    while let Some(run) = capture.next_run() {
        let run = run?;
        last_us = run.last_us();
        listener.feed_run(&run, &mut |_| {});
    }
    listener.finish(last_us, &mut |_| {});
    Ok(listener.summary)
}

/// The fuzz targets' entry (fuzz/fuzz_targets/capture_*.rs) and their corpus replay:
/// any bytes as a capture of `format` (9600 Bd, sigrok at 1 MHz) through its reader
/// and the listener, on one thread. An error for bad input is fine; a panic or a
/// hang is not.
pub fn fuzz_capture(format: capture::Format, input: &[u8]) {
    let profile = hiperface_model::profiles::srs50();
    let options = Options {
        profile,
        settings: UartSettings::DEFAULT,
        tolerance_us: 1_000,
        master_channel: None,
        polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
    };
    let read = capture::ReadOptions { baud: 9600, samplerate_hz: Some(1_000_000) };
    if let Ok((_, mut capture)) = capture::open(Box::new(input), Some(format), read) {
        let _ = listen_all(capture.as_mut(), options);
    }
}
