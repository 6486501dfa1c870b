//! Events of several channels into time order. sigrok-cli prints each decoder
//! instance's annotations in chunks, not interleaved by time; within a channel they
//! are in order. A bounded window (memory constant in the capture's length) sorts
//! them; an event older than one already passed on is an error, not a silent reorder.

use super::{Event, ParseError};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Events held back at most.
pub const WINDOW: usize = 1 << 16;

#[derive(Default)]
pub struct Merge {
    heap: BinaryHeap<Reverse<Held>>,
    seq: u64,
    passed_us: u64,
    /// The latest time seen on each channel (by index): a channel's own events come in
    /// order, and one that goes back in time is an error, never sorted into place (a
    /// reply's bytes would be permuted and charged to the device).
    latest_us: Vec<u64>,
}

/// An event in the window, ordered by its time, then by arrival (which keeps a
/// channel's own order for equal times).
struct Held {
    at_us: u64,
    seq: u64,
    event: Event,
}

impl PartialEq for Held {
    fn eq(&self, other: &Held) -> bool {
        (self.at_us, self.seq) == (other.at_us, other.seq)
    }
}
impl Eq for Held {}
impl PartialOrd for Held {
    fn partial_cmp(&self, other: &Held) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Held {
    fn cmp(&self, other: &Held) -> std::cmp::Ordering {
        (self.at_us, self.seq).cmp(&(other.at_us, other.seq))
    }
}

impl Merge {
    /// Hold `e`; pass on the oldest once the window is full.
    pub fn push(&mut self, e: Event, line: u64) -> Result<Option<Event>, ParseError> {
        let channel = usize::from(e.channel);
        if self.latest_us.len() <= channel {
            self.latest_us.resize(channel + 1, 0);
        }
        if let Some(latest) = self.latest_us.get_mut(channel) {
            if e.at_us < *latest {
                return Err(ParseError::at(
                    line,
                    format!(
                        "a time {:.6} s before the one before it on its channel ({:.6} s): expected each channel's \
                         events in time order",
                        (*latest - e.at_us) as f64 / 1e6,
                        *latest as f64 / 1e6
                    ),
                ));
            }
            *latest = e.at_us;
        }
        if e.at_us < self.passed_us {
            return Err(ParseError::at(
                line,
                format!("an event more than {WINDOW} events out of time order: expected a capture sorted by time"),
            ));
        }
        self.seq += 1;
        self.heap.push(Reverse(Held { at_us: e.at_us, seq: self.seq, event: e }));
        Ok(if self.heap.len() > WINDOW { self.pop() } else { None })
    }

    /// The oldest held event.
    pub fn pop(&mut self) -> Option<Event> {
        let Reverse(held) = self.heap.pop()?;
        self.passed_us = held.at_us;
        Some(held.event)
    }
}
