//! The slave along sequences of events: the error stack and the memory over every
//! short sequence, the invariant and the frame rules along sampled ones, the step in
//! reachable states; and the observer of the master's obligations on sampled streams.

use super::{exhaust, sample};
use crate::targets;
use hiperface_model::slave::stack::{ErrorStack, STACK_DEPTH};
use hiperface_model::{profile::StackOrder, profiles, FaultCode, Slave};
use proptest::prelude::*;

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
pub(super) fn slave_step_reachable() -> Result<u64, String> {
    let states = reachable_states();
    let mut n = 0;
    for s in states.iter().step_by(states.len() / 8) {
        n += exhaust((0..=0xFFFFu32).map(|x| [0x40, (x >> 8) as u8, x as u8]), |f| slave_step_is_total(s, f))?;
    }
    Ok(n)
}

/// Every `n`-operation sequence over `alphabet` operations, as vectors.
pub(super) fn sequences(n: u32, alphabet: u32) -> impl Iterator<Item = Vec<u8>> {
    (0..alphabet.pow(n)).map(move |x| (0..n).map(|i| ((x / alphabet.pow(i)) % alphabet) as u8).collect())
}

/// The observer is told sampled streams of 3 events: times mostly within the
/// first seconds after power-on, now and then anywhere up to `u64::MAX`; it must not
/// panic. Fails if no stream drew an observation (a vacuous run).
pub(super) fn observer_streams() -> Result<u64, String> {
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
