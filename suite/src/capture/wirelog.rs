//! The project's own wire logs: the text of `simulate --log` and of a certificate
//! (`   171.465 ms  M> 40 42 02`), and `certify --report`'s report.json.
//!
//! A line holds a whole frame with one time: for a request (`M>`) the end of its last
//! character's stop bit, for a reply (`S<`) the start of its first start bit. The
//! characters between are taken as sent back to back at the bus's rate: the log does
//! not keep them apart, so a gap inside a frame is not in it.

use super::{next_line, Capture, Event, Input, Mark, ParseError, ReadOptions, Role};
use std::collections::VecDeque;

/// A line of the text form.
pub fn is_line(l: &str) -> bool {
    parse_line(l).is_some()
}

/// `(t_us, role, bytes)` of one text line.
fn parse_line(l: &str) -> Option<(u64, Role, Vec<u8>)> {
    let mut words = l.split_ascii_whitespace();
    let t_us = ms_as_us(words.next()?)?;
    if words.next()? != "ms" {
        return None;
    }
    let role = match words.next()? {
        "M>" => Role::Master,
        "S<" => Role::Slave,
        _ => return None,
    };
    let mut bytes = Vec::with_capacity(hiperface_model::frame::MAX_FRAME);
    for w in words {
        bytes.push(super::hex_byte(w)?);
    }
    (!bytes.is_empty()).then_some((t_us, role, bytes))
}

/// A time written in ms (`171.465`), in µs. The logs' own form (at most three
/// decimals) is read exactly; any other number is rounded to the µs.
fn ms_as_us(word: &str) -> Option<u64> {
    let (int, frac) = word.split_once('.').unwrap_or((word, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if !int.is_empty() && int.len() <= 12 && frac.len() <= 3 && digits(int) && digits(frac) {
        let int: u64 = int.parse().ok()?;
        let frac = frac.bytes().chain(std::iter::repeat(b'0')).take(3).fold(0, |us, d| us * 10 + u64::from(d - b'0'));
        return Some(int * 1000 + frac);
    }
    let t_ms: f64 = word.parse().ok()?;
    (t_ms.is_finite() && t_ms >= 0.0).then(|| (t_ms * 1000.0).round() as u64)
}

pub struct Reader<'a> {
    source: Source<'a>,
    options: ReadOptions,
    pending: VecDeque<Event>,
    last_us: u64,
    line: u64,
    ahead: Option<(u64, Role, Vec<u8>)>,
    /// The lines of the look-ahead frame and of the frame being expanded.
    ahead_line: u64,
    frame_line: u64,
    /// Replies whose characters did not fit at the bus's rate.
    compressed: u64,
    /// The run's timing tolerance, where a report states it.
    tolerance_us: Option<u64>,
}

enum Source<'a> {
    Text {
        input: Input<'a>,
        buf: String,
    },
    /// The frames of a report.json, case after case.
    Report(std::vec::IntoIter<(u64, Role, Vec<u8>)>),
}

#[derive(serde::Deserialize)]
struct Report {
    cases: Vec<ReportCase>,
    #[serde(default)]
    tolerance_us: Option<u64>,
}

#[derive(serde::Deserialize)]
struct ReportCase {
    wire: Vec<ReportWire>,
}

#[derive(serde::Deserialize)]
struct ReportWire {
    t_us: u64,
    direction: String,
    bytes: String,
}

impl<'a> Reader<'a> {
    pub fn new(mut input: Input<'a>, options: ReadOptions) -> Result<Reader<'a>, ParseError> {
        let first = super::peek_first_line(&mut input).map_err(|e| ParseError::at(0, e.to_string()))?;
        let mut tolerance_us = None;
        let source = if first.trim_start().starts_with('{') {
            // A report is small (the cases' wire logs); it is read whole.
            let report: Report = serde_json::from_reader(input)
                .map_err(|e| ParseError::at(e.line() as u64, format!("expected a certify report.json: {e}")))?;
            let mut frames = Vec::new();
            for w in report.cases.iter().flat_map(|c| &c.wire) {
                let role = match w.direction.as_str() {
                    "M>" => Role::Master,
                    "S<" => Role::Slave,
                    d => return Err(ParseError::at(0, format!("a wire entry's direction `{d}`: expected M> or S<"))),
                };
                let bytes: Option<Vec<u8>> = w.bytes.split_whitespace().map(super::hex_byte).collect();
                let bytes = bytes
                    .filter(|b| !b.is_empty())
                    .ok_or_else(|| ParseError::at(0, format!("a wire entry's bytes `{}`: expected hex", w.bytes)))?;
                frames.push((super::capture_time(w.t_us, 0)?, role, bytes));
            }
            tolerance_us = report.tolerance_us;
            Source::Report(frames.into_iter())
        } else {
            Source::Text { input, buf: String::new() }
        };
        Ok(Reader {
            source,
            options,
            pending: VecDeque::new(),
            last_us: 0,
            line: 0,
            ahead: None,
            ahead_line: 0,
            frame_line: 0,
            compressed: 0,
            tolerance_us,
        })
    }

    fn next_frame(&mut self) -> Result<Option<(u64, Role, Vec<u8>)>, ParseError> {
        match &mut self.source {
            Source::Report(frames) => {
                self.line += 1;
                Ok(frames.next())
            }
            Source::Text { input, buf } => loop {
                if !next_line(input.as_mut(), buf, &mut self.line)? {
                    return Ok(None);
                }
                let l = buf.trim();
                if l.is_empty() || l.starts_with('#') {
                    continue;
                }
                let (t_us, role, bytes) = parse_line(l).ok_or_else(|| {
                    ParseError::at(self.line, format!("expected `<time> ms M>|S< <hex bytes>`, found `{l}`"))
                })?;
                return Ok(Some((super::capture_time(t_us, self.line)?, role, bytes)));
            },
        }
    }

    /// The frame's characters, each stamped at the end of its stop bit. A reply
    /// whose characters back to back would run into the next frame (a log of a line
    /// that does not pace characters, such as `--port sim`) ends the timeout before
    /// that frame instead: its start is as logged, its length is not in the log.
    ///
    /// Likewise a request written at once on such a line, whose characters back to back
    /// would begin before the frame before it ended (a long Store Data, or one at a
    /// data rate the log does not say): its end is as logged, its characters share the
    /// time since that frame.
    fn expand(&mut self, t_us: u64, role: Role, bytes: &[u8], next_start: Option<u64>) -> Result<(), ParseError> {
        let ct = self.options.char_time_us();
        let n = bytes.len() as u64;
        let mut step = ct;
        let first_end = match role {
            Role::Master => match t_us.checked_sub((n - 1) * ct) {
                Some(t) if t >= self.last_us => Some(t),
                _ if n > 1 && t_us > self.last_us => {
                    step = (t_us - self.last_us) / n;
                    self.compressed += 1;
                    Some(t_us - (n - 1) * step)
                }
                _ => None,
            },
            Role::Slave => t_us.checked_add(ct),
        };
        let first_end = first_end.filter(|t| *t >= self.last_us).ok_or_else(|| {
            ParseError::at(
                self.frame_line,
                "a frame that starts before the one before it ended: expected times in order",
            )
        })?;
        if let (Role::Slave, Some(next)) = (role, next_start) {
            let room = next.saturating_sub(self.options.timeout_us()).saturating_sub(first_end);
            if n > 1 && (n - 1) * ct > room {
                step = room / (n - 1);
                self.compressed += 1;
            }
        }
        let channel = role as u8;
        for (i, b) in bytes.iter().enumerate() {
            let at_us = first_end + i as u64 * step;
            self.pending.push_back(Event { at_us, channel, role: Some(role), mark: Mark::Byte(*b), late_us: 0 });
        }
        self.last_us = first_end + (n - 1) * step;
        Ok(())
    }

    /// When a frame's first start bit began.
    fn start_of(&self, (t_us, role, bytes): &(u64, Role, Vec<u8>)) -> u64 {
        match role {
            Role::Master => t_us.saturating_sub(bytes.len() as u64 * self.options.char_time_us()),
            Role::Slave => *t_us,
        }
    }
}

impl Iterator for Reader<'_> {
    type Item = Result<Event, ParseError>;
    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(e) = self.pending.pop_front() {
                return Some(Ok(e));
            }
            // One frame of look-ahead: where the next one starts bounds this one.
            let (frame, line) = match self.ahead.take() {
                Some(f) => (f, self.ahead_line),
                None => match self.next_frame() {
                    Ok(Some(f)) => (f, self.line),
                    Ok(None) => return None,
                    Err(e) => return Some(Err(e)),
                },
            };
            let ahead = match self.next_frame() {
                Ok(f) => f,
                Err(e) => return Some(Err(e)),
            };
            self.ahead_line = self.line;
            self.frame_line = line;
            let next_start = ahead.as_ref().map(|f| self.start_of(f));
            self.ahead = ahead;
            if let Err(e) = self.expand(frame.0, frame.1, &frame.2, next_start) {
                return Some(Err(e));
            }
        }
    }
}

impl Capture for Reader<'_> {
    fn tolerance_us(&self) -> Option<u64> {
        self.tolerance_us
    }
    fn channels(&self) -> Vec<String> {
        vec!["M>".into(), "S<".into()]
    }
    fn assumptions(&self) -> Vec<String> {
        let mut a = vec![format!(
            "wire log: each frame's characters back to back at {} Bd ({} µs each); a gap inside a frame is not in the log",
            self.options.baud,
            self.options.char_time_us()
        )];
        if self.compressed > 0 {
            a.push(format!(
                "{} replies did not fit at that rate before the next frame (a line that does not pace characters): \
                 they were taken to end the timeout before it; their start is as logged",
                self.compressed
            ));
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Vec<Result<Event, ParseError>> {
        crate::capture::tests::read(super::super::Format::Wirelog, text)
    }

    #[test]
    fn a_request_ends_at_its_time_and_a_reply_starts_at_its_time() {
        let ev = read("      10.000 ms  M> 40 42 02\n      16.000 ms  S< 40 42 00 00 00 00 02\n");
        let ev: Vec<Event> = ev.into_iter().map(Result::unwrap).collect();
        assert_eq!(ev.len(), 10);
        assert_eq!((ev[0].at_us, ev[2].at_us), (10_000 - 2 * 1146, 10_000));
        assert_eq!((ev[3].at_us, ev[3].role), (16_000 + 1146, Some(Role::Slave)));
        assert_eq!(ev[9].at_us, 16_000 + 7 * 1146);
    }

    #[test]
    fn a_malformed_line_is_rejected_with_its_number() {
        let ev = read("10.000 ms  M> 40 42 02\n\nhello\n");
        let err = ev.into_iter().find_map(Result::err).unwrap();
        assert_eq!(err.line, 3);
        assert!(err.message.contains("expected"), "{err}");
    }

    proptest::proptest! {
        /// The exact reading of a logged time is the float reading, rounded to the µs.
        #[test]
        fn a_time_reads_as_its_rounded_value(us in 0u64..1_000_000_000_000, decimals in 0usize..=3) {
            let text = format!("{}.{:03}", us / 1000, us % 1000);
            let text = &text[..text.len() - (3 - decimals)];
            let text = text.trim_end_matches('.');
            let float = (text.parse::<f64>().unwrap() * 1000.0).round() as u64;
            proptest::prop_assert_eq!(ms_as_us(text), Some(float));
        }
    }

    #[test]
    fn odd_times_are_read_or_refused() {
        assert_eq!(ms_as_us("1.2345"), Some(1235));
        assert_eq!(ms_as_us("1e3"), Some(1_000_000));
        assert_eq!(ms_as_us(".5"), Some(500));
        assert_eq!(ms_as_us("-1.000"), None);
        assert_eq!(ms_as_us("inf"), None);
        assert_eq!(ms_as_us("1.x"), None);
    }

    #[test]
    fn times_must_not_go_back() {
        let ev = read("20.000 ms  M> 40 42 02\n10.000 ms  S< 40 42 00 00 00 00 02\n");
        assert_eq!(ev.into_iter().find_map(Result::err).map(|e| e.line), Some(2));
    }

    /// Found by fuzzing: a time near u64::MAX overflowed the listener's sums.
    #[test]
    fn a_time_beyond_a_billion_seconds_is_an_error() {
        let ev = read("10.000 ms  M> 40 42 02\n18446744073709551 ms  S< 40 42 00 00 00 00 02\n");
        let err = ev.into_iter().find_map(Result::err).unwrap();
        assert_eq!(err.line, 2);
        assert!(err.message.contains("10^9 s"), "{err}");
    }
}
