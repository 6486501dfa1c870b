//! What the encoder took in from its serving loop, in order: the inputs a master
//! certification's record keeps (`record.rs` plays them back through a fresh
//! encoder), written by the encoder as it serves (`encoder/hooks.rs`). Apart from
//! both, so that the encoder does not import the record that imports it.

use crate::exchange::Char;
use hiperface_model::UartSettings;
use serde::{Deserialize, Serialize};

/// One input of the encoder, as the serving loop gave it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "in", rename_all = "kebab-case")]
pub enum Input {
    /// The serving thread got a real-time priority, or did not.
    RealTime { granted: bool },
    /// The characters of one read follow; the line had gone unwatched this long.
    Read { unwatched_us: u64 },
    /// A character of the master, and the settings the encoder listened with (hex).
    Received {
        ch: Char,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        listening: Option<String>,
    },
    /// The model was polled at `now_us`, then the hooks told the time.
    Idle { now_us: u64 },
    /// The model's next step was shown to the hooks.
    Frame,
    /// The hooks were asked for the reply to it.
    Reply,
    /// A reply went out as it did (hex frame; its start, pauses the harness did not
    /// plan, the gap it had) and ended at `end_us`.
    Sent {
        frame: String,
        start_us: u64,
        end_us: u64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        gap: Option<(usize, u64)>,
        disturbed_us: u64,
        split_by_harness: bool,
    },
    /// The master's data rate as read from its end of the pseudo-terminal.
    PeerRate {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        bps: Option<u32>,
    },
    /// Turns of the serving loop with nothing read (the line watched), one per time in
    /// `at` (the first in µs, each next as the µs after the one before): a read that
    /// returned nothing, the model polled and the hooks told the time, and where
    /// `rate_read` the master's data rate read as `bps`. The record's short form of
    /// `Read {0}, Idle {t}, PeerRate {bps}`, which a loop repeats every 500 µs.
    Quiet {
        at: String,
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        rate_read: bool,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        bps: Option<u32>,
    },
}

/// The settings byte of `s`, hex, as a record keeps it.
pub fn settings_hex(s: Option<UartSettings>) -> Option<String> {
    s.map(|s| format!("{:02X}", s.byte()))
}
