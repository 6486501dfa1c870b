//! Captures of a bus, read as a stream of characters with their times: the input of
//! the passive listener (`hiperface decode`). Each reader streams (one line at a time,
//! memory constant in the capture's length) and rejects malformed input with the line
//! number and what was expected.
//!
//! Long because: what every reader shares (the timed character, the options, the line-
//! numbered error, the format's detection) is one interface; the readers are files of
//! their own (under 430 lines without its tests).
//!
//! Every reader turns its format's notion of time into the one the model uses: the
//! end of a character's stop bit (000:2.2.2, see `hiperface_model::datalink`), in µs
//! from the capture's start. What a format does not carry (the character time, the
//! direction) comes from the options and is stated in the report.

use std::fmt;
use std::io::BufRead;

pub mod csv;
mod merge;
pub mod parmrk;
mod prefetch;
pub mod sigrok;
pub mod vcd;
pub mod wirelog;
pub use prefetch::prefetch;

/// What a reader reads from: a file, standard input, bytes in memory. `Send`, so
/// that a capture can be read on its own thread ([`prefetch`]).
pub type Input<'a> = Box<dyn BufRead + Send + 'a>;

/// Who sent a character, where the capture tells.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum Role {
    Master,
    Slave,
}

/// What the receiver saw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mark {
    Byte(u8),
    /// A character whose parity bit was wrong (its data bits as read). // 000:T47
    ParityError(u8),
    /// A character without its stop bit.
    FramingError(u8),
    /// The line held low for longer than a character.
    Break,
}

impl Mark {
    /// As a receiving UART hands it on: the byte read and its fault. A break reads as
    /// a 00h whose stop bit is missing (a framing error). // 000:T47
    pub fn as_received(self) -> (u8, Option<hiperface_model::UartFault>) {
        use hiperface_model::UartFault;
        match self {
            Mark::Byte(b) => (b, None),
            Mark::ParityError(b) => (b, Some(UartFault::Parity)),
            Mark::FramingError(b) => (b, Some(UartFault::Framing)),
            Mark::Break => (0, Some(UartFault::Framing)),
        }
    }
}

/// One character (or break) on the bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Event {
    /// End of the stop bit, µs from the capture's start.
    pub at_us: u64,
    /// The channel it was captured on: an index into the reader's channel names.
    pub channel: u8,
    /// Who sent it, where the format says (the project's wire logs do).
    pub role: Option<Role>,
    pub mark: Mark,
    /// How much earlier than `at_us` it may have ended: a live tap's read that
    /// returned it after the reader had waited for a processor, µs (0 where the
    /// instrument stamped it).
    pub late_us: u64,
}

/// Characters that follow one another at a steady pace on one channel, handed on
/// together: a frame of a capture that holds whole frames (a wire log's line), or one
/// [`Event`] of any other. The first may be any mark; the others are bytes received
/// whole, each `step_us` after the one before, with the first one's channel, role and
/// lateness. What a run says, its events say one by one ([`Run::events`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Run {
    pub first: Event,
    /// From one character's end to the next one's, µs.
    pub step_us: u64,
    /// The bytes after the first character, `rest_len` of them.
    rest: [u8; Run::REST],
    rest_len: u8,
}

impl Run {
    /// The most bytes a run holds after its first: a longer frame is several runs.
    pub const REST: usize = 15;

    /// A run of `bytes` (at most [`Run::REST`] + 1 of them; `None` for none), the
    /// first ending at `at_us`.
    pub fn of_bytes(at_us: u64, step_us: u64, channel: u8, role: Option<Role>, bytes: &[u8]) -> Option<Run> {
        let (first, more) = bytes.split_first()?;
        let mut rest = [0; Run::REST];
        rest.get_mut(..more.len())?.copy_from_slice(more);
        let first = Event { at_us, channel, role, mark: Mark::Byte(*first), late_us: 0 };
        Some(Run { first, step_us, rest, rest_len: more.len() as u8 })
    }

    /// How many characters it holds.
    pub fn len(&self) -> usize {
        1 + usize::from(self.rest_len)
    }

    /// Never: a run holds its first character at least.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The bytes after the first character.
    pub fn rest(&self) -> &[u8] {
        self.rest.get(..usize::from(self.rest_len)).unwrap_or(&self.rest)
    }

    /// When its last character ended.
    pub fn last_us(&self) -> u64 {
        self.first.at_us + u64::from(self.rest_len) * self.step_us
    }

    /// Its characters from the `n`th on (`None` if that is past its end).
    pub fn from_nth(&self, n: usize) -> Option<Run> {
        let event = self.events().nth(n)?;
        let rest = self.rest().get(n..).unwrap_or_default();
        let mut run = Run { first: event, step_us: self.step_us, rest: [0; Run::REST], rest_len: rest.len() as u8 };
        run.rest.get_mut(..rest.len())?.copy_from_slice(rest);
        Some(run)
    }

    /// Its characters one by one, as events.
    pub fn events(&self) -> impl Iterator<Item = Event> + '_ {
        let first = self.first;
        std::iter::once(first).chain(self.rest().iter().zip(1u64..).map(move |(b, i)| Event {
            at_us: first.at_us + i * self.step_us,
            mark: Mark::Byte(*b),
            ..first
        }))
    }
}

impl From<Event> for Run {
    fn from(first: Event) -> Run {
        Run { first, step_us: 0, rest: [0; Run::REST], rest_len: 0 }
    }
}

/// A capture that cannot be read: where, and what was expected there.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct ParseError {
    pub line: u64,
    pub message: String,
}

impl ParseError {
    pub fn at(line: u64, message: impl Into<String>) -> ParseError {
        ParseError { line, message: message.into() }
    }
}

/// The formats `decode` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The project's wire log: `certify --report` (report.json or the certificate's
    /// text) and `simulate --log`.
    Wirelog,
    /// Timestamped bytes as logic-analyzer software exports them.
    Csv,
    /// sigrok-cli's UART decoder output with `--protocol-decoder-samplenum`.
    Sigrok,
}

impl Format {
    /// Tell the format from the first line that is not blank.
    pub fn detect(first_line: &str) -> Option<Format> {
        let l = first_line.trim();
        if l.starts_with(csv::MONITOR_CAPTURE) {
            Some(Format::Csv)
        } else if l.starts_with('{') || wirelog::is_line(l) {
            Some(Format::Wirelog)
        } else if sigrok::is_line(l) {
            Some(Format::Sigrok)
        } else if l.contains(',') {
            Some(Format::Csv)
        } else {
            None
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Wirelog => "wirelog",
            Format::Csv => "csv",
            Format::Sigrok => "sigrok",
        })
    }
}

/// What a capture does not carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadOptions {
    /// Bits per second on the bus: the character time (11 bits, 8E1, 000:2.2.1).
    pub baud: u32,
    /// Samples per second of the capture (sigrok reports sample numbers).
    pub samplerate_hz: Option<u64>,
}

impl ReadOptions {
    /// The bus's settings at this rate (8E1, the long timeout: 000:2.2.1, 000:T8).
    fn settings(&self) -> hiperface_model::UartSettings {
        let baud = hiperface_model::settings::Baud::from_bits_per_second(self.baud);
        hiperface_model::UartSettings {
            baud: baud.unwrap_or(hiperface_model::settings::Baud::B9600),
            ..Default::default()
        }
    }
    /// One character's time, µs (start, 8 data, parity, stop).
    pub fn char_time_us(&self) -> u64 {
        self.settings().char_time_us()
    }
    /// The inter-character timeout, µs.
    pub fn timeout_us(&self) -> u64 {
        self.settings().timeout_us(hiperface_model::Edition::Current)
    }
    /// One bit's time, µs.
    pub fn bit_time_us(&self) -> u64 {
        self.char_time_us() / 11
    }
}

/// The latest time a capture may state: 10^9 s (31 years) in µs. Anything later is
/// not a capture but a malformed number; bounding it keeps every sum of times and
/// durations far from overflowing.
pub const MAX_TIME_US: u64 = 1_000_000_000_000_000;

/// A time from a capture, µs, checked against [`MAX_TIME_US`].
pub(crate) fn capture_time(t_us: u64, line: u64) -> Result<u64, ParseError> {
    if t_us < MAX_TIME_US {
        Ok(t_us)
    } else {
        Err(ParseError::at(line, format!("a time of {t_us} µs: expected less than 10^9 s")))
    }
}

/// A stream of events, in time order, and the names of its channels.
pub trait Capture: Iterator<Item = Result<Event, ParseError>> + Send {
    /// The channels seen so far, by index.
    fn channels(&self) -> Vec<String>;
    /// What this reader assumed, for the report.
    fn assumptions(&self) -> Vec<String>;
    /// The timing uncertainty the capture states (a certify report's tolerance), µs.
    fn tolerance_us(&self) -> Option<u64> {
        None
    }
    /// The next characters as a run: the next event, where the capture does not
    /// hold whole frames. The same events in the same order as `next`, whichever of
    /// the two hands them out.
    fn next_run(&mut self) -> Option<Result<Run, ParseError>> {
        self.next().map(|e| e.map(Run::from))
    }
}

/// Open `input` in `format` (`None`: detect it from the first line).
pub fn open<'a>(
    mut input: Input<'a>,
    format: Option<Format>,
    options: ReadOptions,
) -> Result<(Format, Box<dyn Capture + 'a>), ParseError> {
    let format = match format {
        Some(f) => f,
        None => {
            let first = peek_first_line(&mut input).map_err(|e| ParseError::at(0, e.to_string()))?;
            // Nothing but blanks: an empty capture (nothing heard, INCOMPLETE as the
            // guide says), whatever format it was meant to be in.
            let empty = first.is_empty().then_some(Format::Wirelog);
            empty.or_else(|| Format::detect(&first)).ok_or_else(|| {
                ParseError::at(
                    1,
                    "cannot tell the format: expected a wire log line (`12.345 ms  M> 40 42 02`), a \
                     report.json, sigrok-cli output (`1104-1938 uart-1: 40`) or a CSV header; use --format",
                )
            })?
        }
    };
    let capture: Box<dyn Capture + 'a> = match format {
        Format::Wirelog => Box::new(wirelog::Reader::new(input, options)?),
        Format::Csv => Box::new(csv::Reader::new(input, options)?),
        Format::Sigrok => Box::new(sigrok::Reader::new(input, options)?),
    };
    Ok((format, capture))
}

/// The first line that is not blank, without consuming it.
fn peek_first_line(input: &mut dyn BufRead) -> std::io::Result<String> {
    loop {
        let buf = input.fill_buf()?;
        if buf.is_empty() {
            return Ok(String::new());
        }
        let blank = buf.iter().take_while(|b| b.is_ascii_whitespace()).count();
        let Some(rest) = buf.get(blank..).filter(|r| !r.is_empty()) else {
            let n = buf.len();
            input.consume(n);
            continue;
        };
        // Only the first line is looked at (the buffer may hold the whole capture).
        let line = rest.split(|b| *b == b'\n').next().unwrap_or(rest);
        let line = line.get(..4096).unwrap_or(line);
        return Ok(String::from_utf8_lossy(line).trim_end().to_string());
    }
}

/// Read one line into `buf` (cleared first), counting lines; `false` at the end.
/// A line of 64 KiB or more is an error, not an allocation without bound.
pub(crate) fn next_line(input: &mut dyn BufRead, buf: &mut String, line: &mut u64) -> Result<bool, ParseError> {
    // The line's buffer is reused: a capture of millions of lines allocates once.
    let mut bytes = std::mem::take(buf).into_bytes();
    if !next_line_bytes(input, &mut bytes, line)? {
        return Ok(false);
    }
    *buf = String::from_utf8(bytes).map_err(|_| ParseError::at(*line, "not UTF-8 text"))?;
    Ok(true)
}

/// [`next_line`] without the check that the line is UTF-8: for a reader that reads
/// the common form from the bytes and checks the text only where it falls back to it.
pub(crate) fn next_line_bytes(
    input: &mut dyn BufRead,
    bytes: &mut Vec<u8>,
    line: &mut u64,
) -> Result<bool, ParseError> {
    next_line_within(input, bytes, line, MAX_LINE)
}

/// The bound on a line's length, its newline aside: 64 KiB.
pub(crate) const MAX_LINE: usize = 64 * 1024;

/// [`next_line_bytes`] with the bound on a line's length (without its newline) as a
/// parameter: the tests try it at a few bytes.
fn next_line_within(
    input: &mut dyn BufRead,
    bytes: &mut Vec<u8>,
    line: &mut u64,
    max_line: usize,
) -> Result<bool, ParseError> {
    *line += 1;
    bytes.clear();
    // Straight from the reader's buffer (a line is most often within it): what
    // `read_until` does, with the bound on the line's length checked as it goes.
    let mut ended = false;
    while !ended {
        let available = input.fill_buf().map_err(|e| ParseError::at(*line, format!("cannot read: {e}")))?;
        if available.is_empty() {
            break;
        }
        let used = match memchr::memchr(b'\n', available) {
            Some(newline) => {
                ended = true;
                newline + 1
            }
            None => available.len(),
        };
        // The line without its newline: shorter than the bound.
        if bytes.len() + used - usize::from(ended) >= max_line {
            return Err(ParseError::at(*line, format!("a line of {max_line} bytes or more")));
        }
        bytes.extend_from_slice(available.get(..used).unwrap_or(available));
        input.consume(used);
    }
    if bytes.is_empty() {
        return Ok(false);
    }
    let kept = without_line_end(bytes).len();
    bytes.truncate(kept);
    Ok(true)
}

/// A line without its end: the newlines and carriage returns it ends with.
pub(crate) fn without_line_end(mut line: &[u8]) -> &[u8] {
    while let [rest @ .., b'\n' | b'\r'] = line {
        line = rest;
    }
    line
}

/// A hex digit's value by its character; 0xFF for any other character.
pub(crate) const HEX_DIGIT: [u8; 256] = {
    let mut t = [0xFF; 256];
    let mut c = 0;
    while c < 256 {
        t[c] = match c as u8 {
            d @ b'0'..=b'9' => d - b'0',
            d @ b'a'..=b'f' => d - b'a' + 10,
            d @ b'A'..=b'F' => d - b'A' + 10,
            _ => 0xFF,
        };
        c += 1;
    }
    t
};

/// A byte written as two hex digits, optionally with `0x`.
pub(crate) fn hex_byte(s: &str) -> Option<u8> {
    // The common form first: a capture holds millions of them.
    if let [h, l] = s.as_bytes() {
        let (h, l) = (HEX_DIGIT[usize::from(*h)], HEX_DIGIT[usize::from(*l)]);
        if (h | l) <= 0x0F {
            return Some(h << 4 | l);
        }
    }
    let s = s.trim();
    let s = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")).unwrap_or(s);
    (!s.is_empty() && s.len() <= 2).then(|| u8::from_str_radix(s, 16).ok()).flatten()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A line is read whole whatever the reader's buffer, and one as long as the
        /// bound (its newline aside) is an error, as `read_until` on a reader limited
        /// to the bound read it: its first `max` bytes without a newline among them.
        #[test]
        fn lines_are_read_within_their_bound(
            text in proptest::collection::vec(prop_oneof![Just(b'a'), Just(b'\n'), Just(b'\r')], 0..60),
            capacity in 1usize..9,
            max in 1usize..12,
        ) {
            let mut fast = std::io::BufReader::with_capacity(capacity, &text[..]);
            let mut reference = &text[..];
            let (mut got, mut line) = (Vec::new(), 0);
            loop {
                let mut want = Vec::new();
                let n = BufRead::read_until(&mut std::io::Read::take(&mut reference, max as u64), b'\n', &mut want).unwrap();
                let expected = match n {
                    0 => Ok(false),
                    n if n == max && want.last() != Some(&b'\n') => Err(()),
                    _ => Ok(true),
                };
                let result = next_line_within(&mut fast, &mut got, &mut line, max);
                prop_assert_eq!(result.as_ref().map(|b| *b).map_err(|_| ()), expected);
                if expected != Ok(true) {
                    break;
                }
                while matches!(want.last(), Some(b'\n' | b'\r')) {
                    want.pop();
                }
                prop_assert_eq!(&got, &want);
            }
        }
    }

    /// 9600 Bd, a sample a µs (sigrok).
    const OPTIONS: ReadOptions = ReadOptions { baud: 9600, samplerate_hz: Some(1_000_000) };

    /// Every event of `text` read as `format` (the readers' own tests).
    pub(crate) fn read(format: Format, text: &str) -> Vec<Result<Event, ParseError>> {
        match open(Box::new(text.as_bytes()), Some(format), OPTIONS) {
            Ok((_, capture)) => capture.collect(),
            Err(e) => panic!("{format} reader refused to start: {e}"),
        }
    }

    proptest! {
        /// The two-digit fast path reads what the general one reads.
        #[test]
        fn a_hex_byte_reads_alike_by_either_path(s in "[ 0-9a-fA-FxX+-]{2}") {
            let s = s.as_str();
            let t = s.trim();
            let t = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")).unwrap_or(t);
            let general = (!t.is_empty() && t.len() <= 2).then(|| u8::from_str_radix(t, 16).ok()).flatten();
            prop_assert_eq!(hex_byte(s), general);
        }
    }

    /// Read everything, stopping at the first error: never a panic.
    fn drain(text: &[u8], format: Option<Format>) {
        if let Ok((_, capture)) = open(Box::new(text), format, OPTIONS) {
            for e in capture {
                if e.is_err() {
                    break;
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        #[test]
        fn no_reader_panics_on_any_input(text in proptest::collection::vec(any::<u8>(), 0..400)) {
            for f in [None, Some(Format::Wirelog), Some(Format::Csv), Some(Format::Sigrok)] {
                drain(&text, f);
            }
        }

        #[test]
        fn no_reader_panics_on_near_valid_lines(
            lines in proptest::collection::vec(
                prop_oneof![
                    "[0-9]{1,6}\\.[0-9]{3} ms  (M>|S<)( [0-9A-F]{2}){1,6}",
                    "[0-9]{1,7}-[0-9]{1,7} uart-[12]: ([0-9a-f]{2}|Parity error|Frame error|Break condition)",
                    "0\\.[0-9]{1,6},0x[0-9A-F]{2},(Error)?,",
                ],
                0..40,
            )
        ) {
            let text = lines.join("\n");
            for f in [None, Some(Format::Wirelog), Some(Format::Sigrok)] {
                drain(text.as_bytes(), f);
            }
            drain(format!("Time [s],Value,Parity Error,Framing Error\n{text}").as_bytes(), Some(Format::Csv));
        }
    }
}
