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
    heap: BinaryHeap<Reverse<(u64, u64, Key)>>,
    seq: u64,
    passed_us: u64,
}

/// An event as a sortable key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Key(u64, u8, u16);

fn key(e: &Event) -> Key {
    use super::Mark::*;
    let (kind, byte) = match e.mark {
        Byte(b) => (0, b),
        ParityError(b) => (1, b),
        FramingError(b) => (2, b),
        Break => (3, 0),
    };
    let role = match e.role {
        None => 0,
        Some(super::Role::Master) => 1,
        Some(super::Role::Slave) => 2,
    };
    Key(e.at_us, e.channel, (role << 12) | (kind << 8) | byte as u16)
}

fn event(k: Key) -> Event {
    use super::Mark::*;
    let byte = (k.2 & 0xFF) as u8;
    let mark = match (k.2 >> 8) & 0xF {
        0 => Byte(byte),
        1 => ParityError(byte),
        2 => FramingError(byte),
        _ => Break,
    };
    let role = match k.2 >> 12 {
        1 => Some(super::Role::Master),
        2 => Some(super::Role::Slave),
        _ => None,
    };
    Event { at_us: k.0, channel: k.1, role, mark }
}

impl Merge {
    /// Hold `e`; pass on the oldest once the window is full.
    pub fn push(&mut self, e: Event, line: u64) -> Result<Option<Event>, ParseError> {
        if e.at_us < self.passed_us {
            return Err(ParseError::at(
                line,
                format!("an event more than {WINDOW} events out of time order: expected a capture sorted by time"),
            ));
        }
        self.seq += 1;
        self.heap.push(Reverse((e.at_us, self.seq, key(&e))));
        Ok(if self.heap.len() > WINDOW { self.pop() } else { None })
    }

    /// The oldest held event.
    pub fn pop(&mut self) -> Option<Event> {
        let Reverse((at, _, k)) = self.heap.pop()?;
        self.passed_us = at;
        Some(event(k))
    }
}
