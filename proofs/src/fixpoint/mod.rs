//! Model checking of the slave to a fixpoint: a breadth-first search over abstract
//! states that ends because no new abstract state appears, not at a depth
//! (docs/src/verification.md, "Model checking to a fixpoint").
//!
//! What makes the concrete state space infinite or too large is abstracted:
//!
//! - the counter (24 bits, 000:T16) as the classes the slave tells apart: 0, 1, 2 to
//!   FFFFFDh, FFFFFEh and FFFFFFh (Increment Counter compares it with FFFFFFh only;
//!   Read Counter copies it into the reply); each class has representatives at its
//!   ends, so that one Increment Counter from the class reaches every class it can;
//! - the Set Position offset as 0, the last step of the range, and the steps between
//!   (no command branches on it; Read Position and Read Synchronization Offset copy
//!   it, Set Position overwrites it);
//! - time as the power-up phases of 000:T9: the slave's clock is the power-up's, a
//!   state is taken at the start of its phase, and a reset at any time is the same
//!   reset at 0;
//! - the count of EEPROM writes, the model's bookkeeping, left out.
//!
//! The field contents stay concrete: the alphabet writes one value, so they take
//! finitely many values; no command branches on them.
//!
//! The slave under check is a [`StepFn`]: the model, or a deliberately defective
//! [`mutant`] that shows what the search catches that a depth-bounded one misses.
//!
//! Here the events, the world and its step, the frame rules; canonical.rs the
//! abstraction (the counter's classes, the offset's, the power-up phases),
//! fingerprint.rs the hash of a state the search keeps, search.rs the search.

use crate::invariant::COUNTER_MAX;
use crate::model_check::{addressed, FIELDS_TO_SETTINGS};
use hiperface_model::{checksum, AddressByte, CommandId, Outcome, Profile, Reply, ResponseFrame, Silence, Slave};

mod canonical;
mod fingerprint;
mod search;

pub use canonical::{abstraction, representatives, CounterClass};
pub(crate) use fingerprint::Fingerprint;
pub use search::{search, Bound, Counterexample, Report};

/// What the environment does: the master's frames, time, power and the sensor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {
    /// A request (body without checksum), its checksum appended.
    Request(Vec<u8>),
    /// A request whose checksum is wrong (the right one with its low bit flipped).
    BadChecksum(Vec<u8>),
    /// Time passes to the power-up state's next change (000:T9), if it has one.
    Advance,
    /// Power off and on: EEPROM contents survive, the clock starts again.
    PowerCycle,
    /// The temperature the slave measures from now on, °C.
    Temperature(i16),
}

/// The slave and the time of the next event, µs since power-on.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct World {
    pub slave: Slave,
    pub now_us: u64,
}

/// How a slave handles a whole frame at a time: the model's [`model_step`], or a
/// mutant's.
pub type StepFn = fn(&mut Slave, &[u8], u64) -> Outcome;

/// The model itself.
pub fn model_step(s: &mut Slave, frame: &[u8], at_us: u64) -> Outcome {
    s.handle_frame(frame, at_us)
}

/// The alphabet for a profile: every command of either edition with boundary
/// arguments, codes, field numbers and sizes, sent broadcast (FFh, so that address
/// changes do not hide the slave) or to 40h and 41h; a corrupted checksum; the passing
/// of the power-up windows; a power cycle; a normal and an out-of-range temperature.
pub fn alphabet(profile: &Profile) -> Vec<Event> {
    let b = 0xFF;
    let range = profile.range();
    let preset = |command: u8, value: u64, code0: u8| {
        let v = (value as u32).to_be_bytes();
        Event::Request(vec![b, command, v[0], v[1], v[2], v[3], code0])
    };
    let req = |body: &[u8]| Event::Request(body.to_vec());
    vec![
        req(&[b, 0x42]),
        req(&[0x40, 0x42]), // to the factory address
        req(&[0x41, 0x42]), // to the address 55h sets
        Event::BadChecksum(vec![b, 0x42]),
        preset(0x43, 0, 0x55),
        preset(0x43, range / 2, 0x55),
        preset(0x43, range - 1, 0x55), // the last position of the range
        preset(0x43, range, 0x55),     // one past it: 0Dh
        preset(0x43, 0, 0x54),         // wrong Code0
        preset(0x63, range - 1, 0x55), // legacy edition only // 002:63h
        preset(0x6A, range / 2, 0x55), // optional, current edition
        req(&[b, 0x44, 0x48]),
        req(&[b, 0x44, 0xF0]),
        req(&[b, 0x46]),
        req(&[b, 0x47]),
        req(&[b, 0x49, 0x55]),
        req(&[b, 0x49, 0x54]), // wrong Code0
    ]
    .into_iter()
    .chain(FIELDS_TO_SETTINGS.iter().map(|r| Event::Request(addressed(b, r))))
    .chain([
        req(&[b, 0x67, 0xE5]), // optional, current edition
        req(&[b, 0x45]),       // unknown command
        Event::Advance,
        Event::PowerCycle,
        Event::Temperature(25),
        Event::Temperature(130),
    ])
    .collect()
}

/// Apply an event; the outcome of a frame, if the event was one.
pub fn apply(step: StepFn, w: &mut World, e: &Event) -> Option<Outcome> {
    match e {
        Event::Request(_) | Event::BadChecksum(_) => frame_of(e).map(|f| apply_frame(step, w, &f)),
        Event::Advance => {
            if let Some(t) = w.slave.next_deadline(w.now_us) {
                w.now_us = t;
            }
            None
        }
        Event::PowerCycle => {
            w.slave.power_cycle(0);
            w.now_us = 0;
            None
        }
        Event::Temperature(c) => {
            let mut inputs = w.slave.inputs();
            inputs.temperature_c = *c;
            w.slave.set_inputs(inputs);
            None
        }
    }
}

/// A whole frame (checksum included) at the world's time.
pub fn apply_frame(step: StepFn, w: &mut World, frame: &[u8]) -> Outcome {
    let outcome = step(&mut w.slave, frame, w.now_us);
    if outcome.reply == Reply::Silent(Silence::Reset) {
        // The state after a reset at any time is the state after the same reset at 0
        // with the clock at 0: only the time since the reset counts (000:T9).
        w.slave.power_cycle(0);
        w.now_us = 0;
    }
    outcome
}

/// The frame an event sends, checksum included, if it sends one.
pub fn frame_of(e: &Event) -> Option<Vec<u8>> {
    let (Event::Request(body) | Event::BadChecksum(body)) = e else { return None };
    let sum = checksum::xor(body);
    let mut f = body.clone();
    f.push(if matches!(e, Event::BadChecksum(_)) { sum ^ 1 } else { sum });
    Some(f)
}

/// The frame-level rules for `frame`'s outcome, from `before` to `after`: silent
/// exactly when not listening (000:T9), not addressed (000:2.3.1) or reset (53h);
/// otherwise a well-formed reply (its checksum; it decodes as a reply to the request's
/// command and encodes back to the same bytes) that carries
/// the own address (after 55h the new one, 000:T30) and the warning bit exactly when
/// the error stack is not empty (000:2.3.4).
pub fn frame_rules(before: &World, frame: &[u8], outcome: &Outcome, after: &Slave) -> Result<(), String> {
    let listening = before.slave.listening_settings(before.now_us).is_some();
    let own = before.slave.nonvolatile().address;
    let addressed = frame.first().is_some_and(|b| AddressByte::decode(*b).addresses(own));
    let command = CommandId::of_frame(frame);
    match outcome.reply {
        Reply::Silent(Silence::NotListening) if !listening => Ok(()),
        Reply::Silent(Silence::NotAddressed) if listening && !addressed => Ok(()),
        Reply::Silent(Silence::Reset) if listening && addressed && command == CommandId::EncoderReset => Ok(()),
        Reply::Silent(why) => Err(format!("silent ({why:?}): listening {listening}, addressed {addressed}")),
        Reply::Frame(_) if !listening || !addressed => {
            Err(format!("a reply while listening {listening}, addressed {addressed}"))
        }
        Reply::Frame(rf) => {
            let bytes = rf.encode();
            let bytes = bytes.as_bytes();
            if !checksum::is_valid(bytes) {
                return Err(format!("reply {bytes:02X?} with a bad checksum"));
            }
            // The master decodes it as a reply to its command, to the same bytes (an
            // error reply to 50h reads as an Encoder Status: the same bytes, 000:T27).
            let decoded = ResponseFrame::decode(bytes, command).map(|d| d.encode());
            if decoded.as_ref().map(|d| d.as_bytes()) != Ok(bytes) {
                return Err(format!("reply {bytes:02X?} to {command:?} does not decode to itself: {decoded:?}"));
            }
            if rf.address != after.nonvolatile().address.byte() {
                return Err(format!("reply from {:02X}h, own address {:?}", rf.address, after.nonvolatile().address));
            }
            if rf.warning == after.error_stack().is_empty() {
                return Err(format!("warning bit {} with the stack {:?}", rf.warning, after.error_stack()));
            }
            Ok(())
        }
    }
}

/// A factory-state slave of `profile`, powered on long ago, at a normal temperature.
pub fn start(profile: Profile) -> World {
    World { slave: Slave::operational(profile), now_us: 0 }
}

/// Deliberate defects, for showing what a search catches. Never the model's own
/// behaviour: only a [`StepFn`] passed to [`search`] runs them.
pub mod mutant {
    use super::*;

    /// Increment Counter at the top of the counter (the legacy edition shows the
    /// overflow by the warning bit, 002:47h) answers with the warning bit of the stack
    /// as it was before the overflow's code was stored: the bit is computed too early.
    /// It shows only after 16 777 215 increments.
    pub fn overflow_warning_too_early(s: &mut Slave, frame: &[u8], at_us: u64) -> Outcome {
        let (was_empty, full) = (s.error_stack().is_empty(), s.nonvolatile().counter >= COUNTER_MAX);
        let mut outcome = s.handle_frame(frame, at_us);
        if let Reply::Frame(rf) = &mut outcome.reply {
            if full && CommandId::of_frame(frame) == CommandId::IncrementCounter {
                rf.warning = !was_empty;
            }
        }
        outcome
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::profiles;
    use hiperface_model::slave::powerup::CommState;

    fn run(profile: Profile, step: StepFn, bound: Bound) -> Result<Report, Counterexample> {
        let t = std::time::Instant::now();
        let alphabet = alphabet(&profile);
        let r = search(start(profile), &alphabet, step, bound);
        match &r {
            Ok(r) => eprintln!("{r}, {} events, {:.1} s", alphabet.len(), t.elapsed().as_secs_f64()),
            Err(c) => eprintln!("counterexample in {:.1} s: {c}", t.elapsed().as_secs_f64()),
        }
        r
    }

    /// The current edition (SEK37) to a fixpoint: no state or frame breaks a rule, and
    /// the search ends because no new abstract state appears.
    #[test]
    fn fixpoint_of_the_current_edition() {
        reaches_a_fixpoint(profiles::sek37());
    }

    /// The legacy edition (002) to a fixpoint.
    #[test]
    fn fixpoint_of_the_legacy_edition() {
        reaches_a_fixpoint(profiles::legacy_srs());
    }

    fn reaches_a_fixpoint(profile: Profile) {
        let r = run(profile, model_step, Bound::Fixpoint { max_states: 1_000_000 }).unwrap_or_else(|c| panic!("{c}"));
        assert!(r.fixpoint, "{r}");
        assert!(r.to_string().contains("fixpoint reached"), "{r}");
        // The counter's five classes were all reached: its top takes 16 777 215 events.
        assert!(r.depth > 8 && r.states > 10_000, "{r}");
        // The book's table says what this search finds (docs/src/verification.md).
        let edition = if profile.edition == hiperface_model::Edition::Legacy { "legacy" } else { "current" };
        let row = format!("{edition} ({})", profile.name);
        let documented = crate::documented::figures("Model checking to a fixpoint", &row).unwrap();
        let found = [r.states as u64, r.transitions, r.checked, r.depth as u64];
        assert_eq!(
            documented, found,
            "the book's figures for {row} (states, transitions, checked, levels) against {r}"
        );
    }

    /// Every counter class is reached in the abstract state space, and each class's
    /// representatives are in it.
    #[test]
    fn the_counter_classes_and_their_representatives() {
        for c in [0, 1, 2, 0x1234, COUNTER_MAX - 2, COUNTER_MAX - 1, COUNTER_MAX, COUNTER_MAX + 1] {
            let class = CounterClass::of(c);
            let reps = class.representatives();
            assert!(reps.iter().all(|r| CounterClass::of(*r) == class), "{c:X}");
            assert_eq!(reps.is_empty(), c > COUNTER_MAX, "{c:X}");
        }
        // The abstraction keeps a class and forgets the value inside it.
        let mut w = start(profiles::sek37());
        w.slave.set_counter(0x12_3456);
        let a = abstraction(&w);
        assert_eq!(a.slave.nonvolatile().counter, 2);
        assert_eq!(
            representatives(&a).iter().map(|r| r.slave.nonvolatile().counter).collect::<Vec<_>>(),
            [2, COUNTER_MAX - 2]
        );
    }

    /// A reset at any time is the same abstract state as a reset at 0, and a state is
    /// taken at the start of its power-up phase.
    #[test]
    fn time_is_abstracted_to_the_power_up_phases() {
        let p = profiles::sek37();
        let mut w = start(p);
        apply(model_step, &mut w, &Event::PowerCycle);
        let mut later = w.clone();
        later.now_us = 50_000; // still Initialization (100 ms)
        assert_eq!(abstraction(&later), abstraction(&w));
        apply(model_step, &mut w, &Event::Advance);
        assert_eq!(w.now_us, 100_000);
        assert_eq!(w.slave.state(w.now_us), CommState::DefaultCommunication);
        let mut w2 = w.clone();
        w2.now_us = 500_000;
        assert_eq!(abstraction(&w2), abstraction(&w));
        assert_ne!(abstraction(&w2), abstraction(&later));
    }

    /// The long-sequence defect: the warning bit of Increment Counter at the counter's
    /// top computed before the overflow is stored (legacy edition). The depth-8
    /// search passes it; the fixpoint search finds it.
    #[test]
    fn the_fixpoint_catches_what_depth_8_misses() {
        let mutant = mutant::overflow_warning_too_early;
        let bounded = run(profiles::legacy_srs(), mutant, Bound::Depth(8)).unwrap_or_else(|c| panic!("{c}"));
        assert!(!bounded.fixpoint && bounded.depth == 8, "{bounded}");
        let found = run(profiles::legacy_srs(), mutant, Bound::Fixpoint { max_states: 1_000_000 })
            .expect_err("the fixpoint search finds the defect");
        assert!(found.what.contains("frame rule: warning bit false"), "{found}");
        // Found where the counter is at its top, past any depth a bounded search reaches.
        assert!(found.what.contains("from counter FFFFFFh"), "{found}");
        assert_eq!(found.trace.last(), Some(&Event::Request(vec![0xFF, 0x47])), "{found}");
        // The model itself passes the same search (`fixpoint_of_the_legacy_edition`).
    }
}
