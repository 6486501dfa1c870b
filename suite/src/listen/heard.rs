//! What the listener heard: one exchange graded ([`HeardExchange`]), and the
//! characters of one frame as the listener heard them, with how late each may
//! have been heard: a live tap's read that returned it after its reader had waited
//! for a processor (the harness measures its own run delay). A capture file's times are its instrument's:
//! heard on time.

use super::summary;
use crate::verdict::{CaseVerdict, Finding};
use hiperface_model::command::CommandId;
use hiperface_model::datalink::RxChar;
use hiperface_model::frame::Hex;
use serde::Serialize;
use std::fmt;

#[derive(Debug, Default)]
pub(super) struct Heard {
    pub chars: Vec<RxChar>,
    /// How late each character may have been heard, µs; empty while every one was
    /// heard on time (a capture file's are: no second buffer per frame).
    late_us: Vec<u64>,
}

impl Heard {
    /// An empty frame in a buffer kept from an earlier one.
    pub fn in_buffer(chars: Vec<RxChar>) -> Heard {
        Heard { chars, late_us: Vec::new() }
    }

    #[inline]
    pub fn push(&mut self, c: RxChar, late_us: u64) {
        if late_us != 0 && self.late_us.is_empty() {
            self.late_us.resize(self.chars.len(), 0);
        }
        self.chars.push(c);
        if !self.late_us.is_empty() || late_us != 0 {
            self.late_us.push(late_us);
        }
    }

    pub fn len(&self) -> usize {
        self.chars.len()
    }

    pub fn is_empty(&self) -> bool {
        self.chars.is_empty()
    }

    pub fn bytes(&self) -> Vec<u8> {
        self.chars.iter().map(|c| c.byte).collect()
    }

    /// The bytes into `buffer` (emptied first): a buffer kept from an earlier frame.
    pub fn bytes_into(&self, mut buffer: Vec<u8>) -> Vec<u8> {
        buffer.clear();
        buffer.extend(self.chars.iter().map(|c| c.byte));
        buffer
    }

    /// The characters from `n` on; these keep the first `n`.
    pub fn split_off(&mut self, n: usize) -> Heard {
        let n = n.min(self.chars.len());
        let late_us = if self.late_us.is_empty() { Vec::new() } else { self.late_us.split_off(n) };
        Heard { chars: self.chars.split_off(n), late_us }
    }

    /// How late the first character may have been heard, µs.
    pub fn first_late_us(&self) -> u64 {
        self.late_us.first().copied().unwrap_or(0)
    }

    /// How late the last character may have been heard, µs.
    pub fn last_late_us(&self) -> u64 {
        self.late_us.last().copied().unwrap_or(0)
    }
}

/// Buffers kept from frame to frame, so that a capture of millions of frames
/// allocates a few: each frame's characters, and the bytes of a request and its reply.
#[derive(Debug, Default)]
pub(super) struct Spare {
    chars: Vec<Vec<RxChar>>,
    bytes: Vec<Vec<u8>>,
}

impl Spare {
    /// Buffers kept of each kind, and the largest kept (a frame cut at four times the
    /// longest valid one).
    const KEEP: usize = 4;
    const LARGEST: usize = 4 * hiperface_model::frame::MAX_FRAME;

    pub fn chars(&mut self) -> Vec<RxChar> {
        Self::take(&mut self.chars)
    }

    pub fn bytes(&mut self) -> Vec<u8> {
        Self::take(&mut self.bytes)
    }

    pub fn keep_chars(&mut self, chars: Vec<RxChar>) {
        Self::keep(&mut self.chars, chars);
    }

    pub fn keep_bytes(&mut self, bytes: Vec<u8>) {
        Self::keep(&mut self.bytes, bytes);
    }

    fn take<T>(kept: &mut Vec<Vec<T>>) -> Vec<T> {
        // Most frames are short (a request 3–7 bytes, a reply up to 11 but Read
        // Version and Read Data): a small first allocation, grown for the long ones.
        kept.pop().unwrap_or_else(|| Vec::with_capacity(16))
    }

    fn keep<T>(kept: &mut Vec<Vec<T>>, mut buffer: Vec<T>) {
        if kept.len() < Self::KEEP && buffer.capacity() <= Self::LARGEST {
            buffer.clear();
            kept.push(buffer);
        }
    }
}

/// One exchange as heard: what the live view prints and the report counts.
#[derive(Debug, Clone, Serialize)]
pub struct HeardExchange {
    /// End of the request, ms from the capture's start.
    pub t_ms: f64,
    #[serde(serialize_with = "summary::command_name")]
    pub command: CommandId,
    #[serde(serialize_with = "summary::hex")]
    pub request: Vec<u8>,
    #[serde(serialize_with = "summary::hex_or_silence")]
    pub reply: Option<Vec<u8>>,
    /// From the end of the request's timeout to the reply's first start bit, ms.
    pub response_ms: Option<f64>,
    pub verdict: CaseVerdict,
    pub findings: Vec<Finding>,
}

/// One exchange as a line: time, command, bytes, response time, verdict, and a line
/// per finding (the live view, the reports).
impl fmt::Display for HeardExchange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Written straight to the formatter: the live view prints one per exchange.
        write!(
            f,
            "{:>12.3} ms  {:<10} {}  M> {}  S< ",
            self.t_ms,
            self.verdict.label(),
            self.command,
            Hex(&self.request)
        )?;
        match self.reply.as_deref() {
            Some(bytes) => write!(f, "{}", Hex(bytes))?,
            None => f.write_str("(silence)")?,
        }
        if let Some(t) = self.response_ms {
            write!(f, " {t:+.3} ms")?;
        }
        for finding in &self.findings {
            write!(f, "\n{:>27} {finding}", finding.verdict().label())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_split_keeps_each_characters_lateness() {
        let mut h = Heard::default();
        for (i, late) in [0u64, 0, 9_000, 4_000].into_iter().enumerate() {
            h.push(RxChar::ok(0x40 + i as u8, 1_000 * i as u64), late);
        }
        let reply = h.split_off(2);
        assert_eq!((h.bytes(), h.first_late_us(), h.last_late_us()), (vec![0x40, 0x41], 0, 0));
        assert_eq!((reply.bytes(), reply.first_late_us(), reply.last_late_us()), (vec![0x42, 0x43], 9_000, 4_000));
        assert_eq!(Heard::default().split_off(3).len(), 0);
        // Lateness after characters heard on time, and on time after late ones.
        let mut h = Heard::default();
        for (i, late) in [0u64, 0, 7_000, 0].into_iter().enumerate() {
            h.push(RxChar::ok(0x40 + i as u8, 1_000 * i as u64), late);
        }
        assert_eq!((h.first_late_us(), h.last_late_us()), (0, 0));
        let tail = h.split_off(2);
        assert_eq!((tail.first_late_us(), tail.last_late_us(), h.last_late_us()), (7_000, 0, 0));
        let mut h = Heard::default();
        h.push(RxChar::ok(0x40, 1_000), 0);
        h.push(RxChar::ok(0x41, 2_000), 3_000);
        assert_eq!((h.first_late_us(), h.last_late_us()), (0, 3_000));
    }

    #[test]
    fn kept_buffers_come_back_empty_and_are_few() {
        let mut spare = Spare::default();
        let mut chars = spare.chars();
        chars.push(RxChar::ok(0x40, 1));
        let at = chars.as_ptr();
        spare.keep_chars(chars);
        let again = spare.chars();
        assert!(again.is_empty() && again.as_ptr() == at, "the same buffer, emptied");
        for _ in 0..10 {
            spare.keep_bytes(vec![1, 2, 3]);
        }
        assert_eq!(spare.bytes.len(), Spare::KEEP);
        assert!(spare.bytes().is_empty());
        spare.keep_bytes(Vec::with_capacity(Spare::LARGEST + 1));
        assert!(spare.bytes.iter().all(|b| b.capacity() <= Spare::LARGEST), "a huge buffer is not kept");
    }
}
