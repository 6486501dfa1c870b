//! sigrok-cli's UART decoder output with sample numbers, e.g.
//!
//! ```text
//! sigrok-cli -i capture.sr -P uart:baudrate=9600:parity=even:rx=A -P uart:baudrate=9600:parity=even:rx=B \
//!     -A uart=rx-data:rx-parity-err:rx-warnings:rx-break --protocol-decoder-samplenum
//! 1104-1938 uart-1: 40
//! 17667-17772 uart-2: Parity error
//! ```
//!
//! Each decoder instance (`uart-1`, `uart-2`) is one channel. A data annotation spans
//! the data bits, so the character's stop bit ends two bits after it (parity, stop:
//! 8E1, 000:2.2.1). "Parity error" and "Frame error" mark the character before them
//! on their channel; "Break condition" is a break. The bit-level annotations (`0`,
//! `1`, "Start bit", ...) are skipped; anything else is an error.

use super::merge::Merge;
use super::{next_line, Capture, Event, Input, Mark, ParseError, ReadOptions};

/// A line of sigrok-cli's decoder output.
pub fn is_line(l: &str) -> bool {
    parse_line(l).is_some()
}

/// `(start sample, end sample, instance, text)`.
fn parse_line(l: &str) -> Option<(u64, u64, &str, &str)> {
    let (span, rest) = l.split_once(' ')?;
    let (s, e) = span.split_once('-')?;
    let (instance, text) = rest.split_once(": ")?;
    let (s, e) = (s.parse().ok()?, e.parse().ok()?);
    (e >= s && !instance.is_empty() && !instance.contains(' ')).then_some((s, e, instance, text.trim()))
}

pub struct Reader<'a> {
    input: Input<'a>,
    buf: String,
    line: u64,
    options: ReadOptions,
    samplerate: u64,
    names: Vec<String>,
    /// The last character of each channel, held until the next annotation tells
    /// whether it had a parity or framing error.
    held: Vec<Option<Event>>,
    merge: Merge,
    ended: bool,
}

impl<'a> Reader<'a> {
    pub fn new(input: Input<'a>, options: ReadOptions) -> Result<Reader<'a>, ParseError> {
        let samplerate = options.samplerate_hz.filter(|r| *r > 0).ok_or_else(|| {
            ParseError::at(0, "sigrok-cli prints sample numbers: give the capture's sample rate (--samplerate)")
        })?;
        Ok(Reader {
            input,
            buf: String::new(),
            line: 0,
            options,
            samplerate,
            names: Vec::new(),
            held: Vec::new(),
            merge: Merge::default(),
            ended: false,
        })
    }

    fn us(&self, sample: u64) -> u64 {
        u64::try_from(sample as u128 * 1_000_000 / self.samplerate as u128).unwrap_or(u64::MAX)
    }

    fn channel(&mut self, name: &str) -> Result<u8, ParseError> {
        if let Some(i) = self.names.iter().position(|n| n == name) {
            return Ok(i as u8);
        }
        if self.names.len() >= 16 {
            return Err(ParseError::at(self.line, "more than 16 decoder instances"));
        }
        self.names.push(name.to_string());
        self.held.push(None);
        Ok((self.names.len() - 1) as u8)
    }

    /// Read lines until an event can be passed on.
    fn step(&mut self) -> Result<Option<Event>, ParseError> {
        while !self.ended {
            if !next_line(self.input.as_mut(), &mut self.buf, &mut self.line)? {
                self.ended = true;
                for i in 0..self.held.len() {
                    if let Some(e) = self.held[i].take() {
                        if let Some(out) = self.merge.push(e, self.line)? {
                            return Ok(Some(out));
                        }
                    }
                }
                break;
            }
            let line = std::mem::take(&mut self.buf);
            let out = self.annotation(&line);
            self.buf = line;
            if let Some(e) = out? {
                return Ok(Some(e));
            }
        }
        Ok(self.merge.pop())
    }

    fn annotation(&mut self, l: &str) -> Result<Option<Event>, ParseError> {
        let l = l.trim();
        if l.is_empty() {
            return Ok(None);
        }
        let (start, end, instance, text) = parse_line(l).ok_or_else(|| {
            ParseError::at(self.line, format!("expected `<start>-<end> <decoder>: <annotation>`, found `{l}`"))
        })?;
        let ch = self.channel(instance)?;
        let end_us = super::capture_time(self.us(end), self.line)?;
        let bit = self.options.bit_time_us();
        let held = &mut self.held[ch as usize];
        let new = match text {
            "Parity error" | "Frame error" => {
                let Some(e) = held.as_mut() else {
                    return Err(ParseError::at(self.line, format!("`{text}` with no character before it")));
                };
                e.mark = match (text, e.mark) {
                    ("Parity error", Mark::Byte(b)) => Mark::ParityError(b),
                    (_, Mark::Byte(b) | Mark::ParityError(b)) => Mark::FramingError(b),
                    (_, m) => m,
                };
                return Ok(None);
            }
            "Break condition" => Event { at_us: end_us, channel: ch, role: None, mark: Mark::Break, late_us: 0 },
            "Start bit" | "Stop bit" | "Parity bit" | "0" | "1" => return Ok(None),
            t => match super::hex_byte(t).filter(|_| t.len() == 2) {
                // The data bits end where the parity bit begins: two bits to the stop bit's end.
                Some(b) => Event { at_us: end_us + 2 * bit, channel: ch, role: None, mark: Mark::Byte(b), late_us: 0 },
                None => {
                    return Err(ParseError::at(
                        self.line,
                        format!(
                            "annotation `{t}`: expected a data byte in hex (the uart decoder's default format), \
                             a parity or frame error, or a break"
                        ),
                    ))
                }
            },
        };
        let _ = start;
        match self.held[ch as usize].replace(new) {
            Some(e) => self.merge.push(e, self.line),
            None => Ok(None),
        }
    }
}

impl Iterator for Reader<'_> {
    type Item = Result<Event, ParseError>;
    fn next(&mut self) -> Option<Self::Item> {
        self.step().transpose()
    }
}

impl Capture for Reader<'_> {
    fn channels(&self) -> Vec<String> {
        self.names.clone()
    }
    fn assumptions(&self) -> Vec<String> {
        vec![format!(
            "sigrok: {} samples/s; a character's stop bit ends two bits after its data bits ({} Bd, 8E1)",
            self.samplerate, self.options.baud
        )]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Vec<Result<Event, ParseError>> {
        crate::capture::tests::read(super::super::Format::Sigrok, text)
    }

    #[test]
    fn two_instances_are_merged_by_time_and_errors_mark_their_character() {
        let text = "1104-1938 uart-1: 40\n27562-28396 uart-1: 00\n28500-28605 uart-1: Frame error\n\
                    27458-30458 uart-1: Break condition\n16833-17667 uart-2: 00\n17667-17772 uart-2: Parity error\n";
        let ev: Vec<Event> = read(text).into_iter().map(Result::unwrap).collect();
        let marks: Vec<(u64, u8, Mark)> = ev.iter().map(|e| (e.at_us, e.channel, e.mark)).collect();
        assert_eq!(
            marks,
            vec![
                (1938 + 208, 0, Mark::Byte(0x40)),
                (17667 + 208, 1, Mark::ParityError(0)),
                (28396 + 208, 0, Mark::FramingError(0)),
                (30458, 0, Mark::Break),
            ]
        );
    }

    #[test]
    fn an_unknown_annotation_is_rejected_with_its_line() {
        let err = read("1104-1938 uart-1: 40\n1-2 uart-1: 64\n3-4 uart-1: hello\n").into_iter().find_map(Result::err);
        assert_eq!(err.map(|e| e.line), Some(3));
    }

    #[test]
    fn the_sample_rate_is_required() {
        let opts = ReadOptions { baud: 9600, samplerate_hz: None };
        assert!(Reader::new(Box::new(&b""[..]), opts).is_err());
    }
}
