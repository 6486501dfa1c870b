//! The master's frames as the observer sees them: characters framed by the pause on
//! the line, each with its receive time.
//!
//! Why not the model's data link (`crate::datalink`): the data link frames as a slave's
//! UART interrupts see the line, by the time between two characters' ends; the master's
//! rules are about the pause it leaves on the line, from one character's stop bit to
//! the next one's start bit (000:2.2.2, "gap"), and measuring the pauses between
//! requests run together needs every character's time, which a slave does not keep.

use super::{Observation, Rule};
use crate::command::CommandByte;
use crate::frame::{Frame, MAX_FRAME};
use crate::request::{RequestChecks, RequestFrame};

/// The master's characters of the frame in progress, with their receive times. Only
/// the times of the characters it holds are its state (`complete` clears the bytes and
/// leaves the times of the frame before: equality and hashing, which the model checker
/// counts states by, look at the live ones alone).
#[derive(Debug, Clone)]
pub(super) struct Framer {
    pub(super) bytes: Frame,
    pub(super) ends_us: [u64; MAX_FRAME],
}

impl PartialEq for Framer {
    fn eq(&self, other: &Framer) -> bool {
        self.bytes == other.bytes && self.live_ends() == other.live_ends()
    }
}

impl Eq for Framer {}

impl core::hash::Hash for Framer {
    fn hash<H: core::hash::Hasher>(&self, state: &mut H) {
        self.bytes.hash(state);
        self.live_ends().hash(state);
    }
}

impl Framer {
    /// The receive times of the characters held.
    fn live_ends(&self) -> &[u64] {
        self.ends_us.get(..self.bytes.len()).unwrap_or(&self.ends_us)
    }

    pub(super) fn new() -> Framer {
        Framer { bytes: Frame::new(), ends_us: [0; MAX_FRAME] }
    }

    pub(super) fn push(&mut self, byte: u8, end_us: u64) {
        let n = self.bytes.len();
        if self.bytes.push(byte).is_ok() {
            if let Some(t) = self.ends_us.get_mut(n) {
                *t = end_us;
            }
        }
    }

    pub(super) fn last_us(&self) -> Option<u64> {
        self.bytes.len().checked_sub(1).and_then(|i| self.ends_us.get(i).copied())
    }
}

/// A completed frame that was no request, held to see what follows.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(super) struct Held {
    pub(super) framer: Framer,
    pub(super) start_us: u64,
}

/// Whether `bytes`, parts joined that are no request, may be the start of one:
/// shorter than the longest request of the command its second byte names.
fn may_grow(bytes: &[u8]) -> bool {
    use crate::command::DataLength;
    let spec = bytes.get(1).and_then(|b| CommandByte::decode(*b)).filter(|c| !c.error_bit).and_then(|c| c.id.spec());
    let longest = spec.map_or(0, |spec| match spec.master_data {
        DataLength::Fixed(n) | DataLength::Range { max: n, .. } => 3 + usize::from(n),
        DataLength::NoFrame => 0,
    });
    bytes.len() < longest
}

/// Where the requests of a frame end, last first: at most one per three bytes.
pub(super) struct Ends {
    at: [usize; MAX_FRAME / 3 + 1],
    len: usize,
}

impl Ends {
    /// In frame order.
    pub(super) fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.at.iter().take(self.len).rev().copied()
    }
}

/// Where the requests end, if `bytes` is two or more requests back to back. The
/// caller has found that `bytes` is not one request.
pub(super) fn requests_in(bytes: &[u8]) -> Option<Ends> {
    const NONE: usize = usize::MAX;
    let n = bytes.len();
    // from[j]: where a request ending at j begins, if the bytes up to j split.
    let mut from = [NONE; MAX_FRAME + 1];
    *from.get_mut(0)? = 0;
    for i in 0..n {
        if from.get(i) == Some(&NONE) {
            continue;
        }
        for j in (i + 3)..=n {
            let open = from.get(j) == Some(&NONE);
            if open && bytes.get(i..j).is_some_and(|r| RequestFrame::decode(r).is_ok()) {
                *from.get_mut(j)? = i;
            }
        }
    }
    let mut ends = Ends { at: [0; MAX_FRAME / 3 + 1], len: 0 };
    let mut j = n;
    while j > 0 {
        *ends.at.get_mut(ends.len)? = j;
        ends.len += 1;
        j = *from.get(j).filter(|&&f| f != NONE)?;
    }
    (ends.len >= 2).then_some(ends)
}

impl super::Observer {
    /// The frame in progress is complete.
    pub(super) fn complete(&mut self, out: &mut impl FnMut(Observation)) {
        let first_end = self.framer.ends_us.first().copied().unwrap_or(0);
        let start = first_end.saturating_sub(self.char_time_us());
        let decoded = RequestFrame::decode(self.framer.bytes.as_bytes()).ok();
        self.memo.answered = decoded.map(|r| r.request.command());
        if let Some(rf) = decoded {
            // The common case: the frame is a request. Its characters' times need not
            // be kept (a listener completes a frame per request heard: no copy of them).
            let end = self.framer.last_us().unwrap_or(start);
            self.framer.bytes = Frame::new();
            // A valid request right after a held fragment that completes it is not
            // possible (the fragment would be part of it); the fragment stands alone.
            self.release_held(out);
            self.request(rf, end, start, out);
            return;
        }
        let framer = core::mem::replace(&mut self.framer, Framer::new());
        let bytes = framer.bytes.as_bytes();
        // Fragments of one request: a gap inside it.
        if let Some(h) = self.held.take() {
            let mut joined = h.framer.bytes;
            let joins = bytes.iter().all(|b| joined.push(*b).is_ok());
            if let Some(whole) = RequestFrame::decode(joined.as_bytes()).ok().filter(|_| joins) {
                let gap = start.saturating_sub(h.framer.last_us().unwrap_or(start));
                let command = Some(whole.request.command());
                out(Observation {
                    rule: Rule::GapInRequest,
                    at_us: h.start_us,
                    measured_us: Some(gap),
                    command,
                    data_rates: None,
                });
                return;
            }
            // A request sent in more than two parts (a character at a time on a slow
            // tick): the parts so far are held together while they may still become
            // one, too short for the command they name.
            if joins && may_grow(joined.as_bytes()) {
                let mut parts = h.framer;
                for (i, b) in bytes.iter().enumerate() {
                    parts.push(*b, framer.ends_us.get(i).copied().unwrap_or(0));
                }
                self.held = Some(Held { framer: parts, start_us: h.start_us });
                return;
            }
            self.held = Some(h);
            self.release_held(out);
        }
        // One frame that is several requests (a reader that looked late sees them
        // together, too): no pause between them.
        if let Some(ends) = requests_in(bytes) {
            let ct = self.char_time_us();
            let mut from = 0;
            for end in ends.iter().take_while(|&e| e < bytes.len()) {
                let command =
                    bytes.get(from..end).and_then(|a| RequestFrame::decode(a).ok()).map(|r| r.request.command());
                let end_a = framer.ends_us.get(end - 1).copied().unwrap_or(0);
                let start_b = framer.ends_us.get(end).copied().unwrap_or(0).saturating_sub(ct);
                out(Observation {
                    rule: Rule::NoPause,
                    at_us: start_b,
                    measured_us: Some(start_b.saturating_sub(end_a)),
                    command,
                    data_rates: None,
                });
                from = end;
            }
            return;
        }
        self.held = Some(Held { framer, start_us: start });
    }

    /// A held fragment stands alone: say why it is no request.
    pub(super) fn release_held(&mut self, out: &mut impl FnMut(Observation)) {
        let Some(h) = self.held.take() else { return };
        let bytes = h.framer.bytes.as_bytes();
        let rule = match bytes.get(1).and_then(|b| CommandByte::decode(*b)) {
            Some(CommandByte { error_bit: true, .. }) if RequestChecks::of(bytes).bad_checksum.is_none() => {
                Rule::ErrorBit
            }
            _ => Rule::Malformed,
        };
        out(Observation { rule, at_us: h.start_us, measured_us: None, command: None, data_rates: None });
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::Framer;
    use core::hash::{Hash, Hasher};

    fn hash(f: &Framer) -> u64 {
        let mut h = std::hash::DefaultHasher::new();
        f.hash(&mut h);
        h.finish()
    }

    fn framer(chars: &[(u8, u64)]) -> Framer {
        let mut f = Framer::new();
        for (byte, end_us) in chars {
            f.push(*byte, *end_us);
        }
        f
    }

    /// The model checker counts the observer's states by equality and hash: a framer is
    /// the characters it holds with their times, whatever an earlier frame left behind.
    #[test]
    fn a_framer_is_its_characters_and_their_times_only() {
        let fresh = framer(&[(0x40, 1_000)]);
        let mut reused = framer(&[(0x40, 5_000), (0x42, 6_000), (0x02, 7_000)]);
        reused.bytes = crate::frame::Frame::new();
        reused.push(0x40, 1_000);
        assert!(reused == fresh && hash(&reused) == hash(&fresh), "a stale time beyond the held characters");
        let other_byte = framer(&[(0x41, 1_000)]);
        let other_time = framer(&[(0x40, 1_001)]);
        for different in [&other_byte, &other_time] {
            assert!(*different != fresh, "{different:?}");
            assert_ne!(hash(different), hash(&fresh), "{different:?}");
        }
    }
}
