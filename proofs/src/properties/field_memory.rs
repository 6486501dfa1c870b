//! The field memory: its operations on erased memory and from any memory state, and
//! the data field commands blind to its contents (the sampled twins of the
//! `field_memory_*` and `contents_blind_*` harnesses).

use super::induction::parts_strategy;
use super::sample;
use crate::{contents, inductive};
use hiperface_model::profiles;
use proptest::prelude::*;

/// Positions near the memory's start, near its end, anywhere and near `usize::MAX`.
fn memory_position() -> impl Strategy<Value = usize> {
    use hiperface_model::slave::fields::MAX_MEMORY;
    prop_oneof![
        2 => 0usize..64,
        3 => MAX_MEMORY - 160..MAX_MEMORY + 16,
        1 => any::<usize>(),
        1 => usize::MAX - 16..=usize::MAX,
    ]
}

/// Where a free starts: mostly a block boundary (the fields end on one), else anywhere.
fn free_start() -> impl Strategy<Value = usize> {
    use hiperface_model::slave::fields::BLOCK;
    prop_oneof![3 => memory_position().prop_map(|p| p / BLOCK * BLOCK), 1 => memory_position()]
}

/// Reads mostly of up to 128 bytes, probed mostly within them.
pub(super) fn field_memory_reads() -> Result<u64, String> {
    let count = prop_oneof![3 => 0usize..=128, 1 => any::<usize>()];
    let strategy = (memory_position(), count, 0usize..130, any::<usize>());
    sample(strategy, 50_000, |(start, count, at, anywhere)| {
        let probe = if at % 8 == 0 { *anywhere } else { *at };
        inductive::field_memory_reads_as_stubbed(*start, *count, probe)
    })
}

/// Writes of 0 to 8 bytes.
pub(super) fn field_memory_writes() -> Result<u64, String> {
    let data = prop::collection::vec(any::<u8>(), 0..=8);
    sample((memory_position(), data), 50_000, |(start, data)| inductive::field_memory_writes_as_stubbed(*start, data))
}

/// Frees from anywhere (mostly a block boundary) to anywhere.
pub(super) fn field_memory_frees() -> Result<u64, String> {
    sample((free_start(), memory_position()), 50_000, |(from, to)| {
        inductive::field_memory_frees_without_panic(*from, *to)
    })
}

/// Writes of 0 to 8 bytes, frees mostly from a block boundary, the byte probed mostly
/// near the write or the free.
pub(super) fn field_memory_contents() -> Result<u64, String> {
    let data = prop::collection::vec(any::<u8>(), 0..=8);
    let strategy = (memory_position(), data, free_start(), memory_position(), (0u8..3, 0usize..160, memory_position()));
    sample(strategy, 50_000, |(start, data, from, to, (near, delta, anywhere))| {
        let probe = match near {
            0 => start.saturating_add(*delta).saturating_sub(4),
            1 => from.saturating_add(*delta),
            _ => *anywhere,
        };
        inductive::field_memory_contents(*start, data, *from, *to, probe)
    })
}

/// Memory states of the field memory from any state: contents from a seed (xorshift,
/// so that a case costs microseconds, not 4 591 draws of proptest), and a bitmap of
/// known bytes all clear, all set, any, or byte by byte one of the three.
fn memory_state() -> impl Strategy<Value = contents::MemoryState> {
    (any::<u64>(), 0u8..4).prop_map(|(seed, bitmap)| {
        let mut x = seed | 1;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        };
        let bytes = core::array::from_fn(|_| next());
        let known = core::array::from_fn(|_| match (bitmap, next() % 3) {
            (0, _) | (3, 0) => 0,
            (1, _) | (3, 1) => 0xFF,
            _ => next(),
        });
        contents::MemoryState { bytes, known }
    })
}

/// An operation of `kind` at any position (mostly a block boundary, as fields start),
/// a read's count or a free's end mostly near its start, else anywhere.
fn memory_op(kind: impl Strategy<Value = u8>) -> impl Strategy<Value = contents::MemoryOp> {
    let extent = (prop_oneof![3 => Just(true), 1 => Just(false)], 0usize..=160, memory_position());
    (kind, free_start(), extent, any::<[u8; 8]>(), 0usize..=8).prop_map(
        |(kind, at, (near, small, anywhere), data, len)| {
            let extent = match (near, kind % 3) {
                (false, _) => anywhere,
                (true, contents::READ) | (true, contents::WRITE) => small,
                (true, _) => at.saturating_add(small),
            };
            contents::MemoryOp { kind, at, extent, data, len }
        },
    )
}

/// `ops` operations of `kind` from sampled memory states, the byte probed mostly near
/// an operation's start (before or in it), else anywhere.
pub(super) fn field_memory_from_any(kind: impl Strategy<Value = u8> + Clone, ops: usize) -> Result<u64, String> {
    field_memory_from_any_at(kind, ops, None, 8)
}

/// [`field_memory_from_any`], every operation at `at` where given, a write of at most
/// `max_len` bytes.
pub(super) fn field_memory_from_any_at(
    kind: impl Strategy<Value = u8> + Clone,
    ops: usize,
    at: Option<usize>,
    max_len: usize,
) -> Result<u64, String> {
    let probe = (0usize..2, 0usize..140, memory_position());
    let strategy = (
        memory_state(),
        prop::collection::vec(memory_op(kind), ops),
        prop_oneof![3 => Just(true), 1 => Just(false)],
        probe,
    );
    sample(strategy, 20_000, |(state, ops, near, (which, delta, anywhere))| {
        let mut ops = ops.clone();
        for op in ops.iter_mut() {
            op.at = at.unwrap_or(op.at);
            op.len = op.len.min(max_len);
        }
        let probe = match ops.get(*which % ops.len().max(1)) {
            Some(op) if *near => op.at.saturating_add(*delta).saturating_sub(4),
            _ => *anywhere,
        };
        contents::memory_ops_from_any(state, &ops, probe, true)
    })
}

/// One frame of `command` from a sampled state of SEK37 (`parts_strategy`) on two
/// sampled memories; a sampled twin of the `contents_blind_*` harnesses (most frames
/// to the own address with the checksum right and the field number mostly 0 to 3, so
/// that the command's own code runs on a field). Fails if fewer than half the samples
/// build a state.
pub fn contents_blind_sampled(family: &[(u8, usize)], cases: u32, shape: fn(&mut [u8])) -> Result<u64, String> {
    use std::sync::atomic::{AtomicU64, Ordering};
    let built = AtomicU64::new(0);
    let frame = any::<[u8; inductive::MAX_FAMILY_FRAME]>();
    let memories = (memory_state(), memory_state(), 0u8..4);
    let strategy = (
        parts_strategy(),
        frame,
        any::<bool>(),
        memories,
        0u64..3_000_000,
        prop_oneof![4 => Just(false), 1 => Just(true)],
    );
    let n = sample(strategy, cases, |(parts, frame, sealed, (first, second, field), now, fault)| {
        let Some(state) = parts.build(profiles::sek37()) else { return true };
        built.fetch_add(1, Ordering::Relaxed);
        family.iter().all(|&(command, data)| {
            let mut frame = inductive::request_of(frame, command, data);
            frame[0] = state.nonvolatile().address.byte();
            frame[2] = *field;
            let frame = &mut frame[..3 + data];
            shape(frame);
            if *sealed || *field < 2 {
                let (sum, body) = frame.split_last_mut().expect("3 bytes or more");
                *sum = hiperface_model::checksum::xor(body);
            }
            contents::step_blind_to_contents(&state, first.memory(), second.memory(), frame, *now, *fault)
        })
    })?;
    let built = built.load(Ordering::Relaxed);
    if built * 2 < n {
        return Err(format!("only {built} of {n} samples built a state satisfying the invariant"));
    }
    Ok(built)
}
