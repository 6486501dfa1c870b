//! Timestamped bytes as logic-analyzer software exports them: a CSV with a header
//! naming the columns, e.g. Saleae Logic's async serial export
//! (`Time [s],Value,Parity Error,Framing Error`) or Logic 2's
//! (`name,type,start_time,duration,data,error`).
//!
//! Columns, by header name (case-insensitive): the time in seconds (`time`,
//! `time [s]`, `start_time`, `timestamp`), the byte in hex (`value`, `data`;
//! `0x40` or `40`), optionally the channel (`channel`, `name`) and error flags
//! (`parity error`, `framing error`: any text but empty, `0` or `false`; `error`:
//! text containing "parity" or "fram"), and how late a live tap may have heard the
//! character (`read late [s]`, what `hiperface monitor --capture` writes). The time
//! is the start of the character's start bit, as those exports stamp it; its stop bit
//! ends a character time later.
//!
//! Lines starting with `#` are comments. The monitor's capture opens with one that
//! states its timing tolerance (`# hiperface monitor capture: tolerance_us=2000`), so
//! that `decode` grades it with the tolerance the live run had.

use super::merge::Merge;
use super::{Capture, Event, Input, Mark, ParseError, ReadOptions};

pub struct Reader<'a> {
    /// The tolerance the capture states (the monitor's own), µs.
    tolerance_us: Option<u64>,
    records: csv::StringRecordsIntoIter<Input<'a>>,
    columns: Columns,
    options: ReadOptions,
    names: Vec<String>,
    merge: Merge,
    ended: bool,
}

struct Columns {
    time: usize,
    value: usize,
    channel: Option<usize>,
    parity: Option<usize>,
    framing: Option<usize>,
    error: Option<usize>,
    read_late: Option<usize>,
}

impl Columns {
    fn of(header: &csv::StringRecord) -> Result<Columns, ParseError> {
        let find = |names: &[&str]| header.iter().position(|h| names.contains(&h.trim().to_lowercase().as_str()));
        let missing = |what: &str| {
            ParseError::at(
                1,
                format!("a CSV header with a {what} column; found `{}`", header.iter().collect::<Vec<_>>().join(",")),
            )
        };
        Ok(Columns {
            time: find(&["time", "time [s]", "start_time", "timestamp"]).ok_or_else(|| missing("time (`time [s]`)"))?,
            value: find(&["value", "data"]).ok_or_else(|| missing("value (`value` or `data`)"))?,
            channel: find(&["channel", "name"]),
            parity: find(&["parity error"]),
            framing: find(&["framing error"]),
            error: find(&["error"]),
            read_late: find(&["read late [s]", "read late"]),
        })
    }
}

fn flag(s: Option<&str>) -> bool {
    s.map(str::trim).is_some_and(|s| !s.is_empty() && s != "0" && !s.eq_ignore_ascii_case("false"))
}

impl<'a> Reader<'a> {
    pub fn new(mut input: Input<'a>, options: ReadOptions) -> Result<Reader<'a>, ParseError> {
        let first = super::peek_first_line(&mut input).map_err(|e| ParseError::at(0, e.to_string()))?;
        let tolerance_us = stated_tolerance_us(&first);
        let mut reader =
            csv::ReaderBuilder::new().has_headers(true).flexible(true).comment(Some(b'#')).from_reader(input);
        let header = reader.headers().map_err(|e| ParseError::at(1, format!("expected a CSV header: {e}")))?.clone();
        let columns = Columns::of(&header)?;
        Ok(Reader {
            tolerance_us,
            records: reader.into_records(),
            columns,
            options,
            names: Vec::new(),
            merge: Merge::default(),
            ended: false,
        })
    }

    fn event(&mut self, r: &csv::StringRecord) -> Result<Event, ParseError> {
        let line = r.position().map_or(0, |p| p.line());
        let c = &self.columns;
        let field = |i: usize, what: &str| {
            r.get(i).ok_or_else(|| ParseError::at(line, format!("expected a {what} in column {}", i + 1)))
        };
        let t = field(c.time, "time")?;
        let seconds: f64 = t
            .trim()
            .parse()
            .ok()
            .filter(|s: &f64| s.is_finite() && *s >= 0.0 && *s * 1e6 < super::MAX_TIME_US as f64)
            .ok_or_else(|| ParseError::at(line, format!("time `{t}`: expected seconds, a number ≥ 0")))?;
        let v = field(c.value, "value")?;
        let byte = super::hex_byte(v)
            .ok_or_else(|| ParseError::at(line, format!("value `{v}`: expected a byte in hex (`0x40` or `40`)")))?;
        let error = c.error.and_then(|i| r.get(i)).unwrap_or("").to_lowercase();
        let mark = if flag(c.framing.and_then(|i| r.get(i))) || error.contains("fram") {
            Mark::FramingError(byte)
        } else if flag(c.parity.and_then(|i| r.get(i))) || error.contains("parity") {
            Mark::ParityError(byte)
        } else {
            Mark::Byte(byte)
        };
        let name = c.channel.and_then(|i| r.get(i)).unwrap_or("").trim().to_string();
        let channel = match self.names.iter().position(|n| *n == name) {
            Some(i) => i,
            None if self.names.len() < 16 => {
                self.names.push(name);
                self.names.len() - 1
            }
            None => return Err(ParseError::at(line, "more than 16 channels")),
        };
        let late = c.read_late.and_then(|i| r.get(i)).map(str::trim).filter(|l| !l.is_empty());
        let late_us = match late {
            None => 0,
            Some(l) => l
                .parse::<f64>()
                .ok()
                .filter(|s| s.is_finite() && *s >= 0.0 && *s < 3600.0)
                .map(|s| (s * 1e6).round() as u64)
                .ok_or_else(|| ParseError::at(line, format!("read late `{l}`: expected seconds, a number ≥ 0")))?,
        };
        let at_us = (seconds * 1e6).round() as u64 + self.options.char_time_us();
        Ok(Event { at_us, channel: channel as u8, role: None, mark, late_us })
    }
}

impl Iterator for Reader<'_> {
    type Item = Result<Event, ParseError>;
    fn next(&mut self) -> Option<Self::Item> {
        while !self.ended {
            match self.records.next() {
                None => self.ended = true,
                Some(Err(e)) => {
                    let line = e.position().map_or(0, |p| p.line());
                    return Some(Err(ParseError::at(line, format!("not CSV: {e}"))));
                }
                Some(Ok(r)) => {
                    let line = r.position().map_or(0, |p| p.line());
                    match self.event(&r).and_then(|e| self.merge.push(e, line)) {
                        Ok(Some(e)) => return Some(Ok(e)),
                        Ok(None) => {}
                        Err(e) => return Some(Err(e)),
                    }
                }
            }
        }
        self.merge.pop().map(Ok)
    }
}

/// The marker of the monitor's capture, on its first line.
pub const MONITOR_CAPTURE: &str = "# hiperface monitor capture:";

/// The tolerance a capture's first line states (`tolerance_us=N`), where it does.
fn stated_tolerance_us(first_line: &str) -> Option<u64> {
    let rest = first_line.strip_prefix(MONITOR_CAPTURE)?;
    rest.split_whitespace().find_map(|w| w.strip_prefix("tolerance_us=")?.parse().ok())
}

impl Capture for Reader<'_> {
    fn tolerance_us(&self) -> Option<u64> {
        self.tolerance_us
    }
    fn channels(&self) -> Vec<String> {
        self.names.clone()
    }
    fn assumptions(&self) -> Vec<String> {
        vec![format!(
            "CSV: each time is the start of a character's start bit; its stop bit ends {} µs later ({} Bd, 8E1)",
            self.options.char_time_us(),
            self.options.baud
        )]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Vec<Result<Event, ParseError>> {
        crate::capture::tests::read(super::super::Format::Csv, text)
    }

    #[test]
    fn the_monitors_capture_states_its_tolerance() {
        assert_eq!(stated_tolerance_us("# hiperface monitor capture: tolerance_us=2000 baud=9600"), Some(2000));
        assert_eq!(stated_tolerance_us("# hiperface monitor capture: baud=9600"), None);
        assert_eq!(stated_tolerance_us("Time [s],Value"), None);
        let text = "# hiperface monitor capture: tolerance_us=4000\nTime [s],Value\n0.001,0x40\n";
        let ev: Vec<Event> = read(text).into_iter().map(Result::unwrap).collect();
        assert_eq!(ev.len(), 1);
        assert_eq!(
            super::super::Format::detect("# hiperface monitor capture: tolerance_us=4000"),
            Some(super::super::Format::Csv)
        );
    }

    #[test]
    fn saleae_async_serial_export() {
        let ev = read("Time [s],Value,Parity Error,Framing Error\n0.001,0x40,,\n0.002146,0x42,Error,\n");
        let ev: Vec<Event> = ev.into_iter().map(Result::unwrap).collect();
        assert_eq!(ev[0].at_us, 1000 + 1146);
        assert_eq!(ev[1].mark, Mark::ParityError(0x42));
    }

    #[test]
    fn the_monitors_capture_keeps_how_late_it_heard() {
        let ev =
            read("Time [s],Value,Parity Error,Framing Error,Read Late [s]\n0.001,0x40,,,0.011000\n0.002,0x42,,,\n");
        let late: Vec<u64> = ev.into_iter().map(|e| e.unwrap().late_us).collect();
        assert_eq!(late, vec![11_000, 0]);
        let err = read("time,value,read late [s]\n0.001,0x40,-1\n").into_iter().find_map(Result::err).unwrap();
        assert!(err.message.contains("read late `-1`"), "{err}");
    }

    /// Times that go back on a channel are an error at their line, not sorted into place
    /// (issue 55: a reply's bytes permuted, and a "malformed reply" FAIL charged).
    #[test]
    fn times_that_go_back_are_rejected_with_their_line() {
        let err = read("time,value\n0.003,0x40\n0.001,0x42\n").into_iter().find_map(Result::err).unwrap();
        assert_eq!(err.line, 3);
        assert!(err.message.contains("before the one before it on its channel"), "{err}");
        // Two channels each in order, interleaved out of order between them: merged.
        let two = "time,value,channel\n0.003,0x40,a\n0.001,0x42,b\n0.004,0x43,a\n";
        let ev: Vec<u64> = read(two).into_iter().map(|e| e.unwrap().at_us).collect();
        assert_eq!(ev, vec![1000 + 1146, 3000 + 1146, 4000 + 1146]);
    }

    #[test]
    fn a_bad_value_is_rejected_with_its_line() {
        let err = read("time,value\n0.001,0x40\n0.002,zz\n").into_iter().find_map(Result::err).unwrap();
        assert_eq!(err.line, 3);
        assert!(err.message.contains("expected a byte"), "{err}");
    }

    #[test]
    fn a_header_without_a_time_is_rejected() {
        let opts = ReadOptions { baud: 9600, samplerate_hz: None };
        assert!(Reader::new(Box::new(&b"when,value\n1,40\n"[..]), opts).is_err());
    }
}
