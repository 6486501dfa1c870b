//! The one mechanism: every property is a function of its input, registered once
//! with the domain `cargo test` checks (exhausted or sampled with proptest); the Kani
//! harnesses in `lib.rs` call the same functions on symbolic inputs.

use crate::{contents, inductive, targets};
use hiperface_model::command::CommandByte;
use hiperface_model::slave::stack::{ErrorStack, STACK_DEPTH};
use hiperface_model::{profile::StackOrder, profiles, FaultCode, RequestFrame, Slave};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// A registered property.
pub struct Property {
    pub name: &'static str,
    /// What it proves, with the clause.
    pub claim: &'static str,
    /// The domain `cargo test` checks.
    pub domain: &'static str,
    pub exhaustive: bool,
    /// The Kani harness that proves the same property (`lib.rs`), where one does.
    pub harness: Option<&'static str>,
    /// Cases checked, or a counterexample.
    pub run: fn() -> Result<u64, String>,
}

/// Check `prop` for every value of `domain`.
pub fn exhaust<T: std::fmt::Debug>(domain: impl Iterator<Item = T>, prop: impl Fn(&T) -> bool) -> Result<u64, String> {
    let mut n = 0;
    for v in domain {
        let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| prop(&v))).unwrap_or(false);
        if !ok {
            return Err(format!("counterexample: {v:?}"));
        }
        n += 1;
    }
    Ok(n)
}

/// Check `prop` on `cases` values sampled from `strategy` (proptest, with shrinking).
pub fn sample<S: Strategy>(strategy: S, cases: u32, prop: impl Fn(&S::Value) -> bool) -> Result<u64, String>
where
    S::Value: std::fmt::Debug,
{
    let mut runner = TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
    runner
        .run(&strategy, |v| {
            let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| prop(&v))).unwrap_or(false);
            prop_assert!(ok);
            Ok(())
        })
        .map(|()| cases as u64)
        .map_err(|e| e.to_string())
}

// ---- the properties ----

/// Decoding never panics, and what decodes re-encodes to the same bytes.
pub fn request_decoder_is_total(frame: &[u8]) -> bool {
    match RequestFrame::decode(frame) {
        Ok(r) => r.encode().as_bytes() == frame,
        Err(_) => true,
    }
}

pub fn decoders_are_total(data: &[u8]) -> bool {
    targets::decode(data);
    true
}

pub fn command_byte_round_trips(b: u8) -> bool {
    match CommandByte::decode(b) {
        Some(c) => c.byte() == b,
        None => b & 0x40 == 0,
    }
}

/// Any sequence of stack operations: at most 4 entries, no duplicates. // 000:T27
pub fn stack_invariants(ops: &[u8]) -> bool {
    let codes = [
        FaultCode::Temperature,
        FaultCode::LedCurrent,
        FaultCode::Watchdog,
        FaultCode::InternalChecksum,
        FaultCode::Speed,
    ];
    let mut s = ErrorStack::new();
    for op in ops {
        match codes.get(*op as usize) {
            Some(c) => s.push(*c),
            None => {
                s.pop(StackOrder::OldestFirst);
            }
        }
        // At most four entries, each present once (no allocation: Kani checks this too).
        if s.len() > STACK_DEPTH || !targets::holds_each_code_once(&s) {
            return false;
        }
    }
    true
}

/// Create/modify/delete sequences keep free + allocated = total and numbers contiguous.
pub fn memory_is_conserved(ops: &[u8]) -> bool {
    let requests: [&[u8]; 6] = [
        &[0x40, 0x4D, 0, 0xC3, 0x55],
        &[0x40, 0x4D, 1, 0xC7, 0x55],
        &[0x40, 0x4D, 1, 0x47, 0x55],
        &[0x40, 0x4D, 0, 0x43, 0x55],
        &[0x40, 0x4D, 0, 0xC1, 0x55],
        &[0x40, 0x4D, 2, 0xC0, 0x55],
    ];
    let mut s = Slave::operational(profiles::kuebler_s36()); // 22 blocks
    for op in ops {
        let body = requests[*op as usize % requests.len()];
        let mut f = body.to_vec();
        f.push(hiperface_model::checksum::xor(body));
        s.handle_frame(&f, 0);
        if std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| targets::invariants(&s))).is_err() {
            return false;
        }
        // What freeing only the blocks given up relies on (`DataFields::rest_is_free`).
        if !s.nonvolatile().fields.rest_is_free() {
            return false;
        }
    }
    true
}

/// An event of a sampled sequence: one of the fixpoint alphabet's (its index modulo
/// the alphabet's length), or any frame's bytes, sent as they are.
#[derive(Debug, Clone)]
pub enum SequenceEvent {
    Alphabet(usize),
    Frame(Vec<u8>),
}

/// From the factory state of SEK37 or (`legacy`) the legacy SRS: after every event
/// the invariant holds, and every frame's outcome keeps the frame rules.
pub fn invariant_holds_along(legacy: bool, events: &[SequenceEvent]) -> bool {
    use crate::fixpoint;
    let profile = if legacy { profiles::legacy_srs() } else { profiles::sek37() };
    let alphabet = fixpoint::alphabet(&profile);
    let mut w = fixpoint::start(profile);
    for e in events {
        let before = w.clone();
        let (outcome, frame) = match e {
            SequenceEvent::Alphabet(i) => {
                let e = &alphabet[i % alphabet.len()];
                (fixpoint::apply(fixpoint::model_step, &mut w, e), fixpoint::frame_of(e))
            }
            SequenceEvent::Frame(bytes) => {
                (Some(fixpoint::apply_frame(fixpoint::model_step, &mut w, bytes)), Some(bytes.clone()))
            }
        };
        if let (Some(o), Some(f)) = (outcome, frame) {
            if fixpoint::frame_rules(&before, &f, &o, &w.slave).is_err() {
                return false;
            }
        }
        if crate::invariant::slave_invariant(&w.slave).is_err() {
            return false;
        }
    }
    true
}

/// The data link never merges characters a timeout apart, loses none, never panics.
pub fn datalink_frames(timeout: u16, chars: &[(u8, u16)]) -> bool {
    targets::datalink_of(timeout, chars.iter().map(|(b, g)| (*b, *g, None)));
    true
}

/// The slave's step never panics for any frame in a reachable state, and the
/// invariants hold after it.
pub fn slave_step_is_total(state: &Slave, frame: &[u8]) -> bool {
    let mut s = state.clone();
    for faulty in [false, true] {
        let outcome = if faulty { s.handle_faulty_frame(frame, 0) } else { s.handle_frame(frame, 0) };
        // 000:2.3.4: the warning bit is set exactly when the stack is not empty.
        if let hiperface_model::Reply::Frame(f) = outcome.reply {
            if f.warning == s.error_stack().is_empty() {
                return false;
            }
        }
        targets::invariants(&s);
    }
    true
}

/// The longest request frame: Store Data with 128 data bytes after its 4 header
/// bytes, with address, command and checksum. // 000:T22
pub const MAX_REQUEST: usize = 2 + 132 + 1;

/// Store Data's row of the command table.
pub const STORE_DATA_ROW: u8 = {
    let table = hiperface_model::COMMAND_TABLE;
    let mut row = 0;
    while row < table.len() && table[row].id.byte() != hiperface_model::CommandId::StoreData.byte() {
        row += 1;
    }
    row as u8
};

/// A well-formed request decodes as its command and encodes back to the same bytes.
/// The command is row `row` of the command table (modulo its length); its data bytes
/// are the first of `data` (as many as the command takes; Store Data takes all of
/// `data`, 5 to 132 bytes, and its count byte is set to match). Allocation-free, so
/// that Kani checks this same function.
pub fn request_round_trips(row: u8, data: &[u8]) -> bool {
    use hiperface_model::command::DataLength;
    let table = hiperface_model::COMMAND_TABLE;
    let Some(spec) = table.get(row as usize % table.len()) else {
        return false;
    };
    let n = match spec.master_data {
        DataLength::Fixed(n) => n as usize,
        DataLength::Range { .. } => data.len(),
        DataLength::NoFrame => 0,
    };
    let mut frame = [0u8; MAX_REQUEST];
    let (Some(d), true) = (data.get(..n), spec.master_data.accepts(n)) else {
        return false; // outside the domain: the caller gave too few bytes
    };
    frame[0] = 0x40;
    frame[1] = spec.id.byte();
    let Some(slot) = frame.get_mut(2..2 + n) else { return false };
    slot.copy_from_slice(d);
    if spec.id == hiperface_model::CommandId::StoreData {
        frame[4] = (n - 4) as u8; // 000:T22: the count byte matches the data bytes
    }
    frame[2 + n] = hiperface_model::checksum::xor(&frame[..2 + n]);
    let body = &frame[..3 + n];
    match RequestFrame::decode(body) {
        Ok(r) => r.request.command() == spec.id && r.encode().as_bytes() == body,
        Err(_) => false,
    }
}

fn reachable_states() -> Vec<Slave> {
    // Depth 2 of the model checker's alphabet: a few hundred distinct states.
    let mut out = vec![Slave::operational(profiles::sek37())];
    let alphabet = crate::model_check::alphabet();
    for a in &alphabet {
        let mut s = out[0].clone();
        crate::model_check::apply(&mut s, a);
        for b in alphabet.iter().step_by(3) {
            let mut t = s.clone();
            crate::model_check::apply(&mut t, b);
            out.push(t);
        }
    }
    out
}

/// Every 3-byte frame to 40h, in each of 8 reachable states, the first the factory
/// state (every command without data with every checksum byte among them: what the
/// properties `slave_step` and `slave_step_no_data`, removed, checked on that state).
fn slave_step_reachable() -> Result<u64, String> {
    let states = reachable_states();
    let mut n = 0;
    for s in states.iter().step_by(states.len() / 8) {
        n += exhaust((0..=0xFFFFu32).map(|x| [0x40, (x >> 8) as u8, x as u8]), |f| slave_step_is_total(s, f))?;
    }
    Ok(n)
}

/// Every frame of 0 to 3 bytes, exhaustively, and `samples` frames of 4 to `max` bytes.
fn short_exhaustive_then_sampled(max: usize, samples: u32, prop: impl Fn(&[u8]) -> bool) -> Result<u64, String> {
    let short = (0..=0xFFu32).map(|a| vec![a as u8]).chain((0..=0xFFFFu32).map(|x| vec![(x >> 8) as u8, x as u8]));
    let three = (0..=0xFF_FFFFu32).map(|x| vec![(x >> 16) as u8, (x >> 8) as u8, x as u8]);
    let n = 1 + exhaust(short.chain(three), |f| prop(f))?;
    Ok(n + sample(prop::collection::vec(any::<u8>(), 4..=max), samples, |f| prop(f))?)
}

/// Every `n`-operation sequence over `alphabet` operations, as vectors.
fn sequences(n: u32, alphabet: u32) -> impl Iterator<Item = Vec<u8>> {
    (0..alphabet.pow(n)).map(move |x| (0..n).map(|i| ((x / alphabet.pow(i)) % alphabet) as u8).collect())
}

/// Every property, with its domain. A property with a harness checks the harness's
/// domain, named by the same words as the harness's `Domain:` line (a test compares
/// the two); one without checks a further domain only `cargo test` reaches.
/// [`inductive::Parts`] as proptest samples them: biased towards parts that make a
/// state satisfying the invariant (valid address and settings bytes, codes of the fault
/// table on the stack, fields that exist), with any value among them now and then.
pub fn parts_strategy() -> impl Strategy<Value = inductive::Parts> {
    let settings = || {
        prop_oneof![
            // Data rates mostly from 1200 Bd up: a SEK37 has no 600 Bd.
            19 => (prop_oneof![29 => 1u8..7, 1 => Just(0u8)], prop::sample::select(vec![0x00u8, 0x20, 0x30]), any::<bool>(), any::<bool>())
                .prop_map(|(baud, parity, long, standard)| baud | parity | u8::from(long) << 6 | u8::from(standard) << 7),
            1 => any::<u8>(),
        ]
    };
    let codes: Vec<u8> = FaultCode::ALL.iter().map(|c| c.byte()).filter(|b| *b != 0).collect();
    let nv = (
        prop_oneof![19 => 0x40u8..=0x5F, 1 => any::<u8>()],
        settings(),
        settings(),
        any::<bool>(),
        settings(),
        any::<[u8; 4]>(),
        // Offsets below the range of a SEK37 (512 steps) and of larger devices.
        prop_oneof![16 => 0u64..512, 1 => 0u64..32_768, 1 => any::<u64>()],
        prop_oneof![6 => 0u32..=0xFF_FFFF, 2 => Just(0xFF_FFFF), 1 => Just(0xFF_FFFE), 1 => any::<u32>()],
    );
    // Field sizes mostly small, so that three fields fit a legacy device's 8 blocks too.
    let status =
        prop_oneof![3 => any::<u8>().prop_map(|b| (b | 0x80) & !0x06), 1 => any::<u8>().prop_map(|b| b | 0x80)];
    let fields = (0u8..=inductive::MAX_FIELDS as u8, prop::array::uniform3(status));
    let stack = (0u8..=STACK_DEPTH as u8, prop::array::uniform4(prop::sample::select(codes)));
    let power = (any::<bool>(), 0u64..2_000_000, any::<bool>(), any::<[bool; 3]>());
    let inputs = (
        any::<u64>(),
        -20_000i32..20_000,
        -60i16..150,
        0u16..100,
        any::<bool>(),
        prop::array::uniform7(prop_oneof![5 => Just(false), 1 => Just(true)]),
    );
    (nv, fields, stack, power, inputs).prop_map(
        |(
            (address, settings, boot_settings, temporary, temporary_settings, codes, offset, counter),
            (field_count, statuses),
            (stack_len, stack),
            (settled, since_us, kept_default, locks),
            (position, speed, temperature_c, led_current_ma, i2c_fault, position_faults),
        )| inductive::Parts {
            address,
            settings,
            boot_settings,
            temporary,
            temporary_settings,
            codes,
            offset,
            counter,
            field_count,
            statuses,
            stack_len,
            stack,
            settled,
            since_us,
            // Kept default settings only after a power-up (else the invariant rejects
            // the parts: kept once in ten samples, to check that it does).
            kept_default: kept_default && (!settled || since_us % 10 == 0),
            locks,
            position,
            speed,
            temperature_c,
            led_current_ma,
            i2c_fault,
            position_faults,
        },
    )
}

/// The twin of an inductive harness: sampled parts (those that build a state
/// satisfying the invariant), each command of the family with sampled bytes, time and
/// UART fault. Fails when fewer than half the samples build a state (a vacuous run).
pub fn inductive_sampled(profile: hiperface_model::Profile, family: &[(u8, usize)], cases: u32) -> Result<u64, String> {
    inductive_sampled_shaped(profile, family, cases, |_| {})
}

/// [`inductive_sampled`] with each frame first made one of a part of the command's
/// frames by `shape` (a harness whose domain is that part has this twin).
pub fn inductive_sampled_shaped(
    profile: hiperface_model::Profile,
    family: &[(u8, usize)],
    cases: u32,
    shape: fn(&mut [u8]),
) -> Result<u64, String> {
    use std::sync::atomic::{AtomicU64, Ordering};
    let built = AtomicU64::new(0);
    let frame = any::<[u8; inductive::MAX_FAMILY_FRAME]>();
    // Most frames to the own address or broadcast with their checksum right, so that the
    // command's own code runs (Kani takes every byte).
    let to = prop_oneof![6 => Just(0u8), 2 => Just(1u8), 1 => Just(2u8)];
    let sealed = prop_oneof![4 => Just(true), 1 => Just(false)];
    let strategy =
        (parts_strategy(), frame, to, sealed, 0u64..3_000_000, prop_oneof![4 => Just(false), 1 => Just(true)]);
    let n = sample(strategy, cases, |(parts, frame, to, sealed, now, fault)| {
        let Some(state) = parts.build(profile) else { return true };
        built.fetch_add(1, Ordering::Relaxed);
        family.iter().all(|&(command, data)| {
            let mut frame = inductive::request_of(frame, command, data);
            match to {
                0 => frame[0] = state.nonvolatile().address.byte(),
                1 => frame[0] = 0xFF,
                _ => {}
            }
            let frame = &mut frame[..3 + data];
            shape(frame);
            if *sealed {
                let (sum, body) = frame.split_last_mut().expect("3 bytes or more");
                *sum = hiperface_model::checksum::xor(body);
            }
            inductive::step_keeps_invariant(&state, frame, *now, *fault)
        })
    })?;
    let built = built.load(Ordering::Relaxed);
    if built * 2 < n {
        return Err(format!("only {built} of {n} samples built a state satisfying the invariant"));
    }
    Ok(built)
}

/// The observer is told sampled streams of 3 events: times mostly within the
/// first seconds after power-on, now and then anywhere up to `u64::MAX`; it must not
/// panic. Fails if no stream drew an observation (a vacuous run).
fn observer_streams() -> Result<u64, String> {
    use crate::observer::{observe, LineEvent, KINDS};
    use std::sync::atomic::{AtomicU64, Ordering};
    let reported = AtomicU64::new(0);
    let time = || prop_oneof![8 => 0u64..3_000_000, 1 => any::<u64>(), 1 => (u64::MAX - 1_000_000)..=u64::MAX];
    let event = (0..KINDS, any::<u8>(), any::<u8>(), time(), time())
        .prop_map(|(kind, byte, code, at_us, until_us)| LineEvent { kind, byte, code, at_us, until_us });
    let streams = prop::collection::vec(event, 3);
    let n = sample(streams, 20_000, |events| {
        let seen = observe(profiles::sek37(), events);
        reported.fetch_add(u64::from(seen > 0), Ordering::Relaxed);
        true
    })?;
    match reported.load(Ordering::Relaxed) {
        0 => Err("no stream drew an observation".into()),
        _ => Ok(n),
    }
}

/// The stack's inductive step on sampled stacks and operations: codes mostly from a
/// few (so that duplicates and full stacks occur), now and then any byte.
fn stack_steps() -> Result<u64, String> {
    let code = || prop_oneof![4 => prop::sample::select(vec![0x00u8, 0x01, 0x07, 0x1E, 0x22, 0xFF]), 1 => any::<u8>()];
    let strategy = (prop::array::uniform4(code()), 0u8..=4, any::<u8>(), code());
    sample(strategy, 50_000, |(codes, len, op, c)| inductive::stack_step_keeps_invariant(*codes, *len, *op, *c))
}

/// The data field table's inductive step on sampled tables and operations: sizes
/// mostly small and memories mostly tight, so that tables fill up, resizes are
/// refused and the last field is deleted.
fn fields_steps() -> Result<u64, String> {
    let step = (
        prop::array::uniform3(any::<u8>()),
        0u8..=3,
        prop_oneof![3 => 0u8..12, 1 => any::<u8>()],
        any::<u8>(),
        prop_oneof![3 => 0u8..4, 1 => any::<u8>()],
        any::<u8>(),
    )
        .prop_map(|(statuses, count, capacity, op, number, status)| inductive::FieldsStep {
            statuses,
            count,
            capacity,
            op,
            number,
            status,
        });
    sample(step, 50_000, inductive::fields_step_keeps_invariant)
}

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
fn field_memory_reads() -> Result<u64, String> {
    let count = prop_oneof![3 => 0usize..=128, 1 => any::<usize>()];
    let strategy = (memory_position(), count, 0usize..130, any::<usize>());
    sample(strategy, 50_000, |(start, count, at, anywhere)| {
        let probe = if at % 8 == 0 { *anywhere } else { *at };
        inductive::field_memory_reads_as_stubbed(*start, *count, probe)
    })
}

/// Writes of 0 to 8 bytes.
fn field_memory_writes() -> Result<u64, String> {
    let data = prop::collection::vec(any::<u8>(), 0..=8);
    sample((memory_position(), data), 50_000, |(start, data)| inductive::field_memory_writes_as_stubbed(*start, data))
}

/// Frees from anywhere (mostly a block boundary) to anywhere.
fn field_memory_frees() -> Result<u64, String> {
    sample((free_start(), memory_position()), 50_000, |(from, to)| {
        inductive::field_memory_frees_without_panic(*from, *to)
    })
}

/// Writes of 0 to 8 bytes, frees mostly from a block boundary, the byte probed mostly
/// near the write or the free.
fn field_memory_contents() -> Result<u64, String> {
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
fn field_memory_from_any(kind: impl Strategy<Value = u8> + Clone, ops: usize) -> Result<u64, String> {
    field_memory_from_any_at(kind, ops, None, 8)
}

/// [`field_memory_from_any`], every operation at `at` where given, a write of at most
/// `max_len` bytes.
fn field_memory_from_any_at(
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

/// The claim of each whole-step harness, one command each (its domain names it).
const ONE_COMMAND_CLAIM: &str = "the invariant is inductive for one command: from any state satisfying it, one frame of it keeps it and the frame rules hold (000:2.3.4, 000:T9, 000:T27, 000:2.4.2)";

pub const PROPERTIES: &[Property] = &[
    Property {
        name: "checksum",
        claim: "a frame with its checksum XORs to 0; every single-bit flip is detected (000:2.3.3)",
        domain: "every 3-byte body, every bit of the 4-byte frame",
        exhaustive: false,
        harness: Some("checksum"),
        run: || sample(any::<[u8; 3]>(), 20_000, |b| (0..32).all(|bit| crate::checksum_detects_single_bit_flips(*b, bit))),
    },
    Property {
        name: "checksum_two_byte_bodies",
        claim: "the same, exhaustively on shorter frames",
        domain: "every 2-byte body x every bit of the 3-byte frame (1 572 864)",
        exhaustive: true,
        harness: None,
        run: || exhaust((0..=0xFFFFu32).flat_map(|b| (0..24).map(move |bit| (b, bit))), |(b, bit)| crate::checksum_detects_single_bit_flips([(*b >> 8) as u8, *b as u8], *bit)),
    },
    Property {
        name: "address_codec",
        claim: "address bytes round-trip; slave addresses are exactly 40h...5Fh (000:T5)",
        domain: "all 256 address bytes",
        exhaustive: true,
        harness: Some("address_codec"),
        run: || exhaust(0..=255u8, |b| crate::address_codec_round_trips(*b)),
    },
    Property {
        name: "command_byte_codec",
        claim: "command bytes round-trip; bit 6 clear is refused (000:T6)",
        domain: "all 256 command bytes",
        exhaustive: true,
        harness: Some("command_byte_codec"),
        run: || exhaust(0..=255u8, |b| command_byte_round_trips(*b)),
    },
    Property {
        name: "settings_codec",
        claim: "the settings byte decodes exactly when defined and round-trips (000:T28)",
        domain: "all 256 settings bytes",
        exhaustive: true,
        harness: Some("settings_codec"),
        run: || exhaust(0..=255u8, |b| crate::settings_codec_round_trips(*b)),
    },
    Property {
        name: "request_decoder",
        claim: "the request decoder never panics; decoded frames re-encode identically",
        domain: "every frame of 0 to 6 bytes",
        exhaustive: false,
        harness: Some("request_decoder"),
        run: || short_exhaustive_then_sampled(6, 20_000, request_decoder_is_total),
    },
    Property {
        name: "response_decoder",
        claim: "the response decoder never panics; decoded replies re-encode identically",
        domain: "a command byte and 0 to 6 reply bytes",
        exhaustive: false,
        harness: Some("response_decoder"),
        run: || short_exhaustive_then_sampled(7, 20_000, |d| {
            targets::response(d);
            true
        }),
    },
    Property {
        name: "decoders_long_frames",
        claim: "request and response decoders never panic and round-trip on any bytes",
        domain: "20 000 byte strings of 0..140 bytes (proptest)",
        exhaustive: false,
        harness: None,
        run: || sample(prop::collection::vec(any::<u8>(), 0..140), 20_000, |d| decoders_are_total(d)),
    },
    Property {
        name: "request_round_trip_fixed",
        claim: "a well-formed request of every command of fixed length decodes and re-encodes identically",
        domain: "every command of fixed length, any data bytes",
        exhaustive: false,
        harness: Some("request_round_trip_fixed"),
        run: || {
            let rows = (0..hiperface_model::COMMAND_TABLE.len() as u8).filter(|r| *r != STORE_DATA_ROW).collect::<Vec<_>>();
            sample((prop::sample::select(rows), any::<[u8; 5]>()), 20_000, |(r, d)| request_round_trips(*r, d))
        },
    },
    Property {
        name: "request_round_trip_store_data",
        claim: "a well-formed Store Data request of any length decodes and re-encodes identically (000:T22)",
        domain: "Store Data with 1 to 128 data bytes, any header and data bytes",
        exhaustive: false,
        harness: Some("request_round_trip_store_data"),
        run: || sample(prop::collection::vec(any::<u8>(), 5..=132), 20_000, |d| request_round_trips(STORE_DATA_ROW, d)),
    },
    Property {
        name: "datalink",
        claim: "the data link frames any character sequence, never merges characters a timeout apart, loses none (000:2.2.2)",
        domain: "any timeout, 4 characters with any bytes and gaps",
        exhaustive: false,
        harness: Some("datalink"),
        run: || sample((any::<u16>(), any::<[(u8, u16); 4]>()), 20_000, |(t, c)| datalink_frames(*t, c)),
    },
    Property {
        name: "datalink_long",
        claim: "the same on longer sequences",
        domain: "5 000 sequences of up to 64 characters with any gaps (proptest)",
        exhaustive: false,
        harness: None,
        run: || sample((1u16..20_000, prop::collection::vec((any::<u8>(), any::<u16>()), 0..64)), 5000, |(t, c)| datalink_frames(*t, c)),
    },
    Property {
        name: "stack",
        claim: "at most 4 entries, no duplicates, after every step of any push/pop sequence (000:T27)",
        domain: "every sequence of 6 operations over 5 codes and pop",
        exhaustive: true,
        harness: Some("stack"),
        run: || exhaust(sequences(6, 6), |ops| stack_invariants(ops)),
    },
    Property {
        name: "memory",
        claim: "free + allocated = total and field numbers contiguous after any create/resize/delete sequence (DESIGN:fields)",
        domain: "every sequence of up to 5 requests over 6 (9 331)",
        exhaustive: true,
        harness: None,
        run: || exhaust((0..=5u32).flat_map(|len| sequences(len, 6)), |ops| memory_is_conserved(ops)),
    },
    Property {
        name: "slave_step_reachable",
        claim: "the slave's step never panics for any frame of up to 3 bytes in reachable states; invariants hold",
        domain: "every 3-byte frame to 40h x 8 reachable states, with and without a UART fault",
        exhaustive: true,
        harness: None,
        run: slave_step_reachable,
    },
    Property {
        name: "observer",
        claim: "the master obligations' observer never panics, whatever it is told in whatever order (000:2.2.2, 000:3.3.1)",
        domain: "(no harness: over the Kani budget) 3 events of any kind (the master's characters with and without a UART fault, replies, polls, power-on, settings, address, data rate, end) at any times, SEK37",
        exhaustive: false,
        harness: None,
        run: observer_streams,
    },
    Property {
        name: "inductive_stack",
        claim: "the error stack's part of the invariant is inductive: from any stack satisfying it, a push, pop or clear keeps it; a code pushed is on it (000:T27, 000:2.3.4)",
        domain: "every error stack satisfying the invariant (any 4 codes, the first 0 to 4 pushed), then one push of any code, pop (either order) or clear",
        exhaustive: false,
        harness: Some("inductive_stack"),
        run: stack_steps,
    },
    Property {
        name: "inductive_data_fields",
        claim: "the data field table's part of the invariant is inductive: from any table satisfying it, a create, change or delete keeps it; one refused changes nothing (000:2.4.2, 000:T24)",
        domain: "every data field table of at most 3 fields satisfying the invariant, on any memory size, then one create, change or delete of a field with any status",
        exhaustive: false,
        harness: Some("inductive_data_fields"),
        run: fields_steps,
    },
    Property {
        name: "field_memory_read",
        claim: "on erased field memory a read of up to 128 bytes gives FFh for each byte where they all lie in the memory, else nothing; no panic (the stub of Read Data's harness; DESIGN:fields)",
        domain: "erased memory, any position, any count, any byte probed",
        exhaustive: false,
        harness: Some("field_memory_read"),
        run: field_memory_reads,
    },
    Property {
        name: "field_memory_write",
        claim: "a write to the field memory answers whether its bytes lie in the memory; no panic (the stub of Store Data's harness; DESIGN:fields)",
        domain: "erased memory, 0 to 8 bytes written at any position",
        exhaustive: false,
        harness: Some("field_memory_write"),
        run: field_memory_writes,
    },
    Property {
        name: "field_memory_free",
        claim: "freeing field memory never panics, from anywhere to anywhere (the stub of Create Data Field's harness; DESIGN:fields)",
        domain: "erased memory, any range freed",
        exhaustive: false,
        harness: Some("field_memory_free"),
        run: field_memory_frees,
    },
    Property {
        name: "field_memory_contents",
        claim: "a write reads back and is known, no other byte changes; freeing from a block boundary erases the blocks freed and forgets them (DESIGN:fields)",
        domain: "(no harness: over the Kani budget) erased memory, 0 to 8 bytes written at any position, then any range freed, any byte probed",
        exhaustive: false,
        harness: None,
        run: field_memory_contents,
    },
    Property {
        name: "field_memory_any_read",
        claim: "from any memory state a read answers exactly when its bytes lie in the memory, with the memory's own bytes and, up to 128 bytes, the stub's length; it changes nothing; no panic (DESIGN:fields, 000:T21)",
        domain: "any memory state (any contents, any bitmap of known bytes), a read of any count at any position, any byte probed",
        exhaustive: false,
        harness: Some("field_memory_any_read"),
        run: || field_memory_from_any(Just(contents::READ), 1),
    },
    Property {
        name: "field_memory_any_write",
        claim: "from any memory state a write answers whether its bytes lie in the memory; a byte written holds its value and is known, every other byte and bit stays; no panic (DESIGN:fields, 000:T22)",
        domain: "any memory state (any contents, any bitmap of known bytes), 0 to 8 bytes written at any position, any byte probed",
        exhaustive: false,
        harness: Some("field_memory_any_write"),
        run: || field_memory_from_any(Just(contents::WRITE), 1),
    },
    Property {
        name: "field_memory_any_free",
        claim: "from any memory state freeing erases and forgets the bytes freed (at most 8 blocks from its start, below its end), every other byte and bit stays; no panic (DESIGN:fields, 000:T24)",
        domain: "any memory state (any contents, any bitmap of known bytes), any range freed, any byte probed",
        exhaustive: false,
        harness: Some("field_memory_any_free"),
        run: || field_memory_from_any(Just(2u8), 1),
    },
    Property {
        name: "field_memory_any_write_block",
        claim: "the same for a write at a block boundary where a field starts (DESIGN:fields, 000:T22)",
        domain: "any memory state (any contents, any bitmap of known bytes), 0 to 8 bytes written at the second block (byte 16), any byte probed",
        exhaustive: false,
        harness: Some("field_memory_any_write_block"),
        run: || field_memory_from_any_at(Just(contents::WRITE), 1, Some(contents::FREE_BLOCK), 8),
    },
    Property {
        name: "field_memory_any_free_block",
        claim: "the same for a free from a block boundary where a field starts, read back (DESIGN:fields, 000:T24)",
        domain: "any memory state (any contents, any bitmap of known bytes), a free from the second block (byte 16) to any end, any byte probed",
        exhaustive: false,
        harness: Some("field_memory_any_free_block"),
        run: || field_memory_from_any_at(Just(2u8), 1, Some(contents::FREE_BLOCK), 8),
    },
    Property {
        name: "field_memory_any_two",
        claim: "the same for two operations in a row, each a read or a write (DESIGN:fields)",
        domain: "any memory state (any contents, any bitmap of known bytes), two operations in a row (each a read or a write of 0 to 2 bytes, at any position), any byte probed",
        exhaustive: false,
        harness: Some("field_memory_any_two"),
        run: || field_memory_from_any_at(0u8..2, 2, None, 2),
    },
    Property {
        name: "contents_blind_read_data",
        claim: "no control flow of Read Data depends on the field memory's contents or bitmap: on two memories one frame leaves the same state but the contents and the same reply but its data bytes (DESIGN:fields, 000:T21)",
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields) on two memories in any states, every frame of Read Data (4Ah) asking for 0 to 16 or more than 128 bytes at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("contents_blind_read_data"),
        run: || contents_blind_sampled(&[(0x4A, 4)], 3000, inductive::read_data_short),
    },
    Property {
        name: "contents_blind_store_data_one_byte",
        claim: "no control flow of Store Data depends on the field memory's contents or bitmap: on two memories one frame leaves the same state but the contents and the same reply (DESIGN:fields, 000:T22)",
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields) on two memories in any states, every frame of Store Data (4Bh) with 1 data byte at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("contents_blind_store_data_one_byte"),
        run: || contents_blind_sampled(&[(0x4B, 5)], 3000, |_| {}),
    },
    Property {
        name: "contents_blind_create_data_field",
        claim: "no control flow of Create Data Field depends on the field memory's contents or bitmap: on two memories one frame leaves the same state but the contents and the same reply (DESIGN:fields, 000:T24)",
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields) on two memories in any states, every frame of Create Data Field (4Dh) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("contents_blind_create_data_field"),
        run: || contents_blind_sampled(&[(0x4D, 3)], 3000, |_| {}),
    },
    Property {
        name: "contents_blind",
        claim: "no control flow of any command depends on the field memory's contents or bitmap but Read Data's reply, which copies them (DESIGN:fields)",
        domain: "(no harness: the data field commands have theirs) every state of SEK37 satisfying the invariant (at most 3 data fields) on two memories in any states, one frame of every command of the current edition and of Store Data with 1 to 4 data bytes, at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || {
            let families = [inductive::POSITION, inductive::COUNTER, inductive::FIELDS, inductive::STORE_DATA, inductive::SETTINGS, inductive::STATUS];
            contents_blind_sampled(&families.concat(), 1000, |_| {})
        },
    },
    Property {
        name: "inductive_read_counter",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Counter (46h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_counter"),
        run: || inductive_sampled(profiles::sek37(), &[(0x46, 0)], 3000),
    },
    Property {
        name: "inductive_increment_counter",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Increment Counter (47h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_increment_counter"),
        run: || inductive_sampled(profiles::sek37(), &[(0x47, 0)], 3000),
    },
    Property {
        name: "inductive_reset_counter",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Reset Counter (49h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_reset_counter"),
        run: || inductive_sampled(profiles::sek37(), &[(0x49, 1)], 3000),
    },
    Property {
        name: "inductive_read_position",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Position (42h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_position"),
        run: || inductive_sampled(profiles::sek37(), &[(0x42, 0)], 3000),
    },
    Property {
        name: "inductive_set_position",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Position (43h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_set_position"),
        run: || inductive_sampled(profiles::sek37(), &[(0x43, 5)], 3000),
    },
    Property {
        name: "inductive_read_analog_value",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Analog Value (44h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_analog_value"),
        run: || inductive_sampled(profiles::sek37(), &[(0x44, 1)], 3000),
    },
    Property {
        name: "inductive_read_data",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Data (4Ah) asking for 0 to 16 or more than 128 bytes at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_data"),
        run: || inductive_sampled_shaped(profiles::sek37(), &[(0x4A, 4)], 3000, inductive::read_data_short),
    },
    Property {
        name: "inductive_read_data_long",
        claim: ONE_COMMAND_CLAIM,
        domain: "(no harness: over the Kani budget) every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Data (4Ah) asking for 17 to 128 bytes at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || inductive_sampled_shaped(profiles::sek37(), &[(0x4A, 4)], 3000, inductive::read_data_long),
    },
    Property {
        name: "inductive_store_data_one_byte",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Store Data (4Bh) with 1 data byte at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_store_data_one_byte"),
        run: || inductive_sampled(profiles::sek37(), &[(0x4B, 5)], 3000),
    },
    Property {
        name: "inductive_data_field_status",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Data Field Status (4Ch) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_data_field_status"),
        run: || inductive_sampled(profiles::sek37(), &[(0x4C, 1)], 3000),
    },
    Property {
        name: "inductive_create_data_field",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Create Data Field (4Dh) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_create_data_field"),
        run: || inductive_sampled(profiles::sek37(), &[(0x4D, 3)], 3000),
    },
    Property {
        name: "inductive_memory_status",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Memory Status (4Eh) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_memory_status"),
        run: || inductive_sampled(profiles::sek37(), &[(0x4E, 0)], 3000),
    },
    Property {
        name: "inductive_set_access_code",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Access Code (4Fh) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_set_access_code"),
        run: || inductive_sampled(profiles::sek37(), &[(0x4F, 3)], 3000),
    },
    Property {
        name: "inductive_read_encoder_status",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Encoder Status (50h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_encoder_status"),
        run: || inductive_sampled(profiles::sek37(), &[(0x50, 0)], 3000),
    },
    Property {
        name: "inductive_read_type_label",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Type Label (52h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_type_label"),
        run: || inductive_sampled(profiles::sek37(), &[(0x52, 0)], 3000),
    },
    Property {
        name: "inductive_encoder_reset",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Encoder Reset (53h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_encoder_reset"),
        run: || inductive_sampled(profiles::sek37(), &[(0x53, 0)], 3000),
    },
    Property {
        name: "inductive_set_encoder_address",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Encoder Address (55h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_set_encoder_address"),
        run: || inductive_sampled(profiles::sek37(), &[(0x55, 2)], 3000),
    },
    Property {
        name: "inductive_read_version",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Version (56h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_version"),
        run: || inductive_sampled(profiles::sek37(), &[(0x56, 0)], 3000),
    },
    Property {
        name: "inductive_set_serial_interface",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Serial Interface (57h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_set_serial_interface"),
        run: || inductive_sampled(profiles::sek37(), &[(0x57, 2)], 3000),
    },
    Property {
        name: "inductive_temporarily_set_serial_interface",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Temporarily Set Serial Interface (67h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_temporarily_set_serial_interface"),
        run: || inductive_sampled(profiles::sek37(), &[(0x67, 1)], 3000),
    },
    Property {
        name: "inductive_set_position_with_sync",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Position with Synchronization (6Ah) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_set_position_with_sync"),
        run: || inductive_sampled(profiles::sek37(), &[(0x6A, 5)], 3000),
    },
    Property {
        name: "inductive_sensor_adjustment",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Sensor Adjustment (6Bh) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_sensor_adjustment"),
        run: || inductive_sampled(profiles::sek37(), &[(0x6B, 2)], 3000),
    },
    Property {
        name: "inductive_read_sync_offset",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Synchronization Offset (6Ch) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_read_sync_offset"),
        run: || inductive_sampled(profiles::sek37(), &[(0x6C, 0)], 3000),
    },
    Property {
        name: "inductive_position",
        claim: "the invariant is inductive: from any state satisfying it, one frame of the family keeps it and the frame rules hold (000:2.3.4, 000:T9, 000:T27, 000:2.4.2)",
        domain: "(no harness: over the Kani budget) every state of the Reference profile satisfying the invariant (at most 3 data fields), every frame of 42h, 43h, 44h, 6Ah, 6Bh, 6Ch at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || inductive_sampled(profiles::reference(), inductive::POSITION, 3000),
    },
    Property {
        name: "inductive_counter",
        claim: "the invariant is inductive: from any state satisfying it, one frame of the family keeps it and the frame rules hold (000:2.3.4, 000:T9, 000:T27, 000:2.4.2)",
        domain: "(no harness: over the Kani budget) every state of the Reference profile satisfying the invariant (at most 3 data fields), every frame of 46h, 47h, 49h at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || inductive_sampled(profiles::reference(), inductive::COUNTER, 3000),
    },
    Property {
        name: "inductive_fields",
        claim: "the invariant is inductive: from any state satisfying it, one frame of the family keeps it and the frame rules hold (000:2.3.4, 000:T9, 000:T27, 000:2.4.2)",
        domain: "(no harness: over the Kani budget) every state of the Reference profile satisfying the invariant (at most 3 data fields), every frame of 4Ah, 4Ch, 4Dh, 4Eh at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || inductive_sampled(profiles::reference(), inductive::FIELDS, 3000),
    },
    Property {
        name: "inductive_store_data",
        claim: "the invariant is inductive: from any state satisfying it, one frame of the family keeps it and the frame rules hold (000:2.3.4, 000:T9, 000:T27, 000:2.4.2)",
        domain: "(no harness: over the Kani budget) every state of the Reference profile satisfying the invariant (at most 3 data fields), every Store Data frame with 1 to 4 data bytes at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || inductive_sampled(profiles::reference(), inductive::STORE_DATA, 3000),
    },
    Property {
        name: "inductive_settings",
        claim: "the invariant is inductive: from any state satisfying it, one frame of the family keeps it and the frame rules hold (000:2.3.4, 000:T9, 000:T27, 000:2.4.2)",
        domain: "(no harness: over the Kani budget) every state of the Reference profile satisfying the invariant (at most 3 data fields), every frame of 4Fh, 55h, 57h, 67h at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || inductive_sampled(profiles::reference(), inductive::SETTINGS, 3000),
    },
    Property {
        name: "inductive_status",
        claim: "the invariant is inductive: from any state satisfying it, one frame of the family keeps it and the frame rules hold (000:2.3.4, 000:T9, 000:T27, 000:2.4.2)",
        domain: "(no harness: over the Kani budget) every state of the Reference profile satisfying the invariant (at most 3 data fields), every frame of 50h, 52h, 53h, 56h at any time, with and without a UART fault",
        exhaustive: false,
        harness: None,
        run: || inductive_sampled(profiles::reference(), inductive::STATUS, 3000),
    },
    Property {
        name: "inductive_legacy_set_position_internal_sync",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of Legacy-SRS satisfying the invariant (at most 3 data fields), every frame of Set Position with Internal Track Synchronisation (63h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_legacy_set_position_internal_sync"),
        run: || inductive_sampled(profiles::legacy_srs(), &[(0x63, 5)], 3000),
    },
    Property {
        name: "inductive_legacy_increment_counter",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of Legacy-SRS satisfying the invariant (at most 3 data fields), every frame of Increment Counter (47h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_legacy_increment_counter"),
        run: || inductive_sampled(profiles::legacy_srs(), &[(0x47, 0)], 3000),
    },
    Property {
        name: "inductive_legacy_set_serial_interface",
        claim: ONE_COMMAND_CLAIM,
        domain: "every state of Legacy-SRS satisfying the invariant (at most 3 data fields), every frame of Set Serial Interface (57h) at any time, with and without a UART fault",
        exhaustive: false,
        harness: Some("inductive_legacy_set_serial_interface"),
        run: || inductive_sampled(profiles::legacy_srs(), &[(0x57, 2)], 3000),
    },
    Property {
        name: "slave_invariant",
        claim: "the slave's invariant (invariant::slave_invariant) and the frame rules hold after every event of any sequence",
        domain: "2 000 sequences of up to 64 events (the fixpoint alphabet and any frame of up to 8 bytes), both editions (proptest)",
        exhaustive: false,
        harness: None,
        run: || {
            let event = prop_oneof![
                (0usize..64).prop_map(SequenceEvent::Alphabet),
                prop::collection::vec(any::<u8>(), 0..8).prop_map(SequenceEvent::Frame),
            ];
            sample((any::<bool>(), prop::collection::vec(event, 0..64)), 2000, |(legacy, events)| {
                invariant_holds_along(*legacy, events)
            })
        },
    },
    Property {
        name: "quadrature_table",
        claim: "the quadrature step equals 000 Table 72",
        domain: "the 16 rows of 000 Table 72",
        exhaustive: true,
        harness: Some("quadrature_table"),
        run: || exhaust(0..16u8, |r| crate::quadrature_equals_table_72(*r)),
    },
    Property {
        name: "sync_table",
        claim: "the synchronisation correction equals 000:3.2.5's table",
        domain: "the 16 rows of 000:3.2.5's table",
        exhaustive: true,
        harness: Some("sync_table"),
        run: || exhaust((0..16u8).map(|x| (x >> 2, x & 3)), |(f, a)| crate::sync_equals_table(*f, *a)),
    },
    Property {
        name: "octants",
        claim: "octant transformation and retransformation are sound for every sign combination (000:3.2.4)",
        domain: "sin and cos in -128..=127",
        exhaustive: true,
        harness: Some("octants"),
        run: || exhaust((-128..=127i32).flat_map(|s| (-128..=127i32).map(move |c| (s, c))), |(s, c)| crate::octant_transformation_is_sound(*s, *c)),
    },
    Property {
        name: "octants_wide",
        claim: "the same over larger magnitudes",
        domain: "sin, cos in -1024..=1024 (4 198 401)",
        exhaustive: true,
        harness: None,
        run: || exhaust((-1024..=1024i32).flat_map(|s| (-1024..=1024i32).map(move |c| (s, c))), |(s, c)| crate::octant_transformation_is_sound(*s, *c)),
    },
];
