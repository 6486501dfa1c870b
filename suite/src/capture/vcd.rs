//! Write a capture as the UART waveform a logic analyzer would have recorded: a VCD
//! (IEEE 1364 value change dump) at 1 µs resolution, one wire per channel, idle high,
//! 8E1 (000:2.2.1). A character with a parity error gets the wrong parity bit, one
//! with a framing error a low stop bit, and a break holds the line low for two
//! character times. So a session can be turned into a capture without hardware, and
//! read back by sigrok-cli's VCD input.

use super::{Event, Mark};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::io::{self, Write};

/// The wire name of a channel: what sigrok-cli's `rx=` option names.
pub fn wire_name(channel: &str) -> String {
    match channel {
        "M>" => "master".into(),
        "S<" => "slave".into(),
        c => {
            let s: String = c.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
            if s.is_empty() {
                "line".into()
            } else {
                s
            }
        }
    }
}

/// Write `events` (in time order) of `channels` at `baud` to `out`.
pub fn write(
    events: impl Iterator<Item = Event>,
    channels: &[String],
    baud: u32,
    out: &mut dyn Write,
) -> io::Result<()> {
    let ids: Vec<char> = (0..channels.len()).map(|i| (b'!' + i as u8) as char).collect();
    writeln!(out, "$timescale 1 us $end\n$scope module hiperface $end")?;
    for (name, id) in channels.iter().zip(&ids) {
        writeln!(out, "$var wire 1 {id} {} $end", wire_name(name))?;
    }
    writeln!(out, "$upscope $end\n$enddefinitions $end\n#0")?;
    for id in &ids {
        writeln!(out, "1{id}")?;
    }
    let bit_ns = 1_000_000_000 / baud.max(1) as u64;
    let char_ns = 11 * bit_ns;
    // Edges (time µs, sequence, channel, level) not yet written.
    let mut edges: BinaryHeap<Reverse<(u64, u64, u8, u8)>> = BinaryHeap::new();
    let mut seq = 0u64;
    let mut now = 0u64;
    let mut level = vec![1u8; channels.len()];
    let mut flush = |edges: &mut BinaryHeap<Reverse<(u64, u64, u8, u8)>>, until: u64, out: &mut dyn Write| {
        while let Some(Reverse((t, _, ch, v))) = edges.peek().copied() {
            if t > until {
                break;
            }
            edges.pop();
            let Some(l) = level.get_mut(ch as usize) else { continue };
            if *l == v {
                continue;
            }
            *l = v;
            if t > now {
                writeln!(out, "#{t}")?;
                now = t;
            }
            writeln!(out, "{v}{}", ids.get(ch as usize).copied().unwrap_or('!'))?;
        }
        Ok::<(), io::Error>(())
    };
    let mut end_us = 0;
    for e in events {
        let end_ns = e.at_us * 1000;
        let start_ns = end_ns.saturating_sub(if e.mark == Mark::Break { 2 * char_ns } else { char_ns });
        flush(&mut edges, start_ns / 1000, out)?;
        let bits: [u8; 11] = match e.mark {
            Mark::Break => [0; 11],
            Mark::Byte(b) | Mark::ParityError(b) | Mark::FramingError(b) => {
                let mut bits = [0u8; 11];
                for (i, bit) in bits.iter_mut().enumerate().skip(1).take(8) {
                    *bit = (b >> (i - 1)) & 1;
                }
                let even = (b.count_ones() % 2) as u8;
                bits[9] = if matches!(e.mark, Mark::ParityError(_)) { even ^ 1 } else { even };
                bits[10] = u8::from(!matches!(e.mark, Mark::FramingError(_)));
                bits
            }
        };
        let bit_len = if e.mark == Mark::Break { 2 * char_ns / 11 } else { bit_ns };
        for (i, v) in bits.iter().enumerate() {
            seq += 1;
            edges.push(Reverse(((start_ns + i as u64 * bit_len) / 1000, seq, e.channel, *v)));
        }
        seq += 1;
        // Back to idle at the end (a no-op after a good stop bit).
        edges.push(Reverse((end_ns / 1000, seq, e.channel, 1)));
        end_us = end_us.max(e.at_us);
    }
    flush(&mut edges, u64::MAX, out)?;
    writeln!(out, "#{}", end_us + 1000)?;
    Ok(())
}
