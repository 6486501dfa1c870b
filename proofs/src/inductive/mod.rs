//! The slave's invariant is inductive: from **any** state that satisfies it
//! ([`invariant::slave_invariant`]), any frame of a command, at any time, with or
//! without a UART fault, the slave does not panic, the invariant holds afterwards, and
//! the frame-level rules hold ([`rules_hold`]). Together with the factory state of
//! every built-in profile satisfying it, the invariant holds in every state the slave
//! can reach, with no bound on the number of steps.
//!
//! A state is built from [`Parts`], plain values a Kani harness makes symbolic
//! (`kani::any()`) and a property test samples; [`Parts::build`] gives `None` for parts
//! that do not form a state satisfying the invariant, which both then skip (Kani:
//! `kani::assume`). What the parts keep and leave out, and why that is sound, is in
//! docs/src/verification.md, "The invariant is inductive".
//!
//! Here the parts, the frame rules, the command families and the whole step;
//! field_memory.rs the field memory's operations as the whole-step harnesses' stubs
//! take them; stack_and_fields.rs the error stack's and the data field table's parts of
//! the invariant, each inductive on its own.

use crate::invariant::slave_invariant;
use hiperface_model::address::{AddressByte, SlaveAddress};
use hiperface_model::frame::MAX_FIELD_BYTES;
use hiperface_model::slave::fields::DataFields;
use hiperface_model::slave::inputs::{PhysicalInputs, PositionFault};
use hiperface_model::slave::powerup::PowerUp;
use hiperface_model::slave::stack::STACK_DEPTH;
use hiperface_model::slave::{Locks, NonVolatile};
use hiperface_model::{checksum, CommandId, Outcome, Profile, Reply, Silence, Slave, UartSettings};

mod field_memory;
mod stack_and_fields;

pub use field_memory::{
    erased_read_answer, field_memory_contents, field_memory_frees_without_panic, field_memory_reads_as_stubbed,
    field_memory_writes_as_stubbed, memory_holds,
};
use stack_and_fields::stack_of;
pub use stack_and_fields::{fields_step_keeps_invariant, stack_step_keeps_invariant, FieldsStep};

/// The data fields a built state has at most: the addressed field, the last one and
/// one before them are what the data field commands tell apart (the sizes of the
/// others enter only through the free memory, which the parts make any).
pub const MAX_FIELDS: usize = 3;

/// A slave's state as plain values: every part of [`Slave`] that a command reads or
/// writes, the field memory's contents excepted (they read FFh: no command's control
/// flow depends on them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(kani, derive(kani::Arbitrary))]
pub struct Parts {
    pub address: u8,
    /// Stored settings, as of the last reset, and 67h's (when `temporary` is set).
    pub settings: u8,
    pub boot_settings: u8,
    pub temporary: bool,
    pub temporary_settings: u8,
    pub codes: [u8; 4],
    pub offset: u64,
    pub counter: u32,
    pub field_count: u8,
    pub statuses: [u8; MAX_FIELDS],
    pub stack_len: u8,
    pub stack: [u8; STACK_DEPTH],
    /// Powered on long ago (`settled`), or at `since_us`.
    pub settled: bool,
    pub since_us: u64,
    pub kept_default: bool,
    pub locks: [bool; 3],
    pub position: u64,
    pub speed: i32,
    pub temperature_c: i16,
    pub led_current_ma: u16,
    pub i2c_fault: bool,
    /// Each of the position faults (000:T38-T68) present or not.
    pub position_faults: [bool; 7],
}

impl Parts {
    /// The state these parts make on a device of `profile`, if they make one that
    /// satisfies the invariant.
    pub fn build(&self, profile: Profile) -> Option<Slave> {
        let (s, holds) = self.state(profile);
        holds.then_some(s)
    }

    /// The state these parts make on a device of `profile`, and whether they make one
    /// that satisfies the invariant (parts that decode to nothing are replaced by the
    /// factory values and make it false). Straight-line, with no `Option` around the
    /// slave: a bounded model checker merges the paths of an early return, and a field
    /// that is a constant on every path that builds a state (the field count) would be
    /// a symbolic value after the merge, its loops unrolled to the bound.
    pub fn state(&self, profile: Profile) -> (Slave, bool) {
        let address = SlaveAddress::new(self.address);
        let decode = |byte| UartSettings::decode(byte).ok();
        let (settings, boot_settings) = (decode(self.settings), decode(self.boot_settings));
        let temp_settings = decode(self.temporary_settings);
        let decoded = address.is_some()
            && settings.is_some()
            && boot_settings.is_some()
            && (!self.temporary || temp_settings.is_some());
        // As stored, fitting or not: the invariant decides (`from_statuses` would refuse
        // what does not fit, on paths a model checker then has to merge).
        let capacity = profile.user_memory_blocks;
        let fields = DataFields::from_table(capacity, &self.statuses, self.field_count as usize);
        let nv = NonVolatile {
            address: address.unwrap_or(SlaveAddress::DEFAULT),
            settings: settings.unwrap_or(UartSettings::DEFAULT),
            codes: self.codes,
            offset: self.offset,
            counter: self.counter,
            fields,
        };
        let stack = stack_of(self.stack, self.stack_len);
        let power = PowerUp { since_us: (!self.settled).then_some(self.since_us), kept_default: self.kept_default };
        let [position, nonvolatile, data_fields] = self.locks;
        let locks = Locks { position, nonvolatile, data_fields };
        let temp_settings = temp_settings.filter(|_| self.temporary);
        let boot_settings = boot_settings.unwrap_or(UartSettings::DEFAULT);
        let mut s = Slave::from_parts(profile, nv, stack, power, boot_settings, temp_settings, locks);
        s.set_inputs(PhysicalInputs {
            position: self.position,
            speed: self.speed,
            temperature_c: self.temperature_c,
            led_current_ma: self.led_current_ma,
        });
        s.inject_i2c_fault(self.i2c_fault);
        for (fault, on) in PositionFault::ALL.iter().zip(self.position_faults) {
            s.inject_position_fault(*fault, on);
        }
        let holds = decoded && slave_invariant(&s).is_ok();
        (s, holds)
    }
}

/// The frame-level rules of one step, without allocating (so that Kani checks the same
/// function): a slave that does not listen stays silent; one that listens answers a
/// frame addressed to it (or is silent after Encoder Reset) and is silent to any other;
/// a reply's checksum is right, it carries the own address (after 55h the new one,
/// 000:T30) and the warning bit exactly when the error stack is not empty
/// (000:2.3.4). The same rules as `fixpoint::frame_rules`, which also decodes the reply.
pub fn rules_hold(before: &Slave, frame: &[u8], now_us: u64, outcome: &Outcome, after: &Slave) -> bool {
    let listening = before.listening_settings(now_us).is_some();
    let own = before.nonvolatile().address;
    let addressed = frame.first().is_some_and(|b| AddressByte::decode(*b).addresses(own));
    let command = CommandId::of_frame(frame);
    match outcome.reply {
        Reply::Silent(Silence::NotListening) => !listening,
        Reply::Silent(Silence::NotAddressed) => listening && !addressed,
        Reply::Silent(Silence::Reset) => listening && addressed && command == CommandId::EncoderReset,
        Reply::Frame(rf) => {
            let bytes = rf.encode();
            listening
                && addressed
                && checksum::is_valid(bytes.as_bytes())
                && rf.address == after.nonvolatile().address.byte()
                && rf.warning != after.error_stack().is_empty()
        }
    }
}

/// The command families the inductive harnesses take one at a time: each command byte
/// with its number of data bytes (000:T10). Store Data, whose length varies, is a
/// family of its own (`STORE_DATA`, 1 to 4 data bytes).
pub const POSITION: &[(u8, usize)] = &[(0x42, 0), (0x43, 5), (0x44, 1), (0x6A, 5), (0x6B, 2), (0x6C, 0)];
pub const COUNTER: &[(u8, usize)] = &[(0x46, 0), (0x47, 0), (0x49, 1)];
pub const FIELDS: &[(u8, usize)] = &[(0x4A, 4), (0x4C, 1), (0x4D, 3), (0x4E, 0)];
pub const STORE_DATA: &[(u8, usize)] = &[(0x4B, 5), (0x4B, 6), (0x4B, 7), (0x4B, 8)];
pub const SETTINGS: &[(u8, usize)] = &[(0x4F, 3), (0x55, 2), (0x57, 2), (0x67, 1)];
pub const STATUS: &[(u8, usize)] = &[(0x50, 0), (0x52, 0), (0x53, 0), (0x56, 0)];

/// The longest frame a family above sends: Store Data with 4 data bytes.
pub const MAX_FAMILY_FRAME: usize = 3 + 8;

/// Where a Read Data request holds its count byte (000:T21).
pub const READ_DATA_COUNT: usize = 4;

/// The counts the harness `inductive_read_data` leaves out: 17 up to the largest field
/// (128 bytes). It takes 0 to 16, and more than 128 (refused: no field is larger), so
/// that the reply is at most 22 bytes; longer replies need an unwind bound past 130,
/// to which every loop over a count CBMC does not know is then unrolled
/// (proofs/src/harnesses.rs).
pub const READ_DATA_LONG: core::ops::RangeInclusive<u8> = 17..=MAX_FIELD_BYTES as u8;

/// Whether a Read Data request is one the harness `inductive_read_data` takes.
pub fn read_data_counted_short(frame: &[u8]) -> bool {
    frame.get(READ_DATA_COUNT).is_some_and(|c| !READ_DATA_LONG.contains(c))
}

/// A Read Data request made one of the harness's (a long count taken to 0 to 16).
pub fn read_data_short(frame: &mut [u8]) {
    if let Some(c) = frame.get_mut(READ_DATA_COUNT).filter(|c| READ_DATA_LONG.contains(*c)) {
        *c %= READ_DATA_LONG.start();
    }
}

/// A Read Data request made one the harness leaves out (a long count).
pub fn read_data_long(frame: &mut [u8]) {
    let (first, last) = (*READ_DATA_LONG.start(), *READ_DATA_LONG.end());
    if let Some(c) = frame.get_mut(READ_DATA_COUNT) {
        *c = first + *c % (last - first + 1);
    }
}

/// `frame` made a request of `command` with `data` data bytes: the command byte set,
/// the rest as given (any address byte, data and checksum byte).
pub fn request_of(frame: &[u8; MAX_FAMILY_FRAME], command: u8, data: usize) -> [u8; MAX_FAMILY_FRAME] {
    let mut f = *frame;
    f[1] = command;
    if let Some(request) = f.get_mut(..3 + data) {
        count_store_data(request);
    }
    f
}

/// A Store Data request of `frame.len()` bytes made to say so: its count byte (the
/// fifth) is the number of data bytes after its 4 header bytes (000:T22); other
/// requests are left as they are.
pub fn count_store_data(frame: &mut [u8]) {
    let data = frame.len().saturating_sub(7);
    if let [_, 0x4B, _, _, count, _, _, ..] = frame {
        *count = data as u8;
    }
}

/// One step from `state`: no panic, the invariant afterwards, the frame rules.
pub fn step_keeps_invariant(state: &Slave, frame: &[u8], now_us: u64, uart_fault: bool) -> bool {
    let mut after = state.clone();
    let outcome = after.handle(frame, uart_fault, now_us);
    // `scripts/kani.sh --false-assertion`: a claim every command breaks (a frame with
    // the own address and a wrong checksum is answered with an error, whose reply
    // carries the warning bit, 000:2.3.4), so each whole-step harness must FAIL with
    // it: the assertions after the step are reached and can fail.
    #[cfg(false_assertion)]
    assert!(
        !matches!(outcome.reply, Reply::Frame(rf) if rf.warning),
        "false assertion: no reply carries the warning bit"
    );
    slave_invariant(&after).is_ok() && rules_hold(state, frame, now_us, &outcome, &after)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::profiles;

    fn factory() -> Parts {
        Parts {
            address: 0x40,
            settings: 0xE4,
            boot_settings: 0xE4,
            temporary: false,
            temporary_settings: 0,
            codes: [0x55; 4],
            offset: 0,
            counter: 0,
            field_count: 0,
            statuses: [0; MAX_FIELDS],
            stack_len: 0,
            stack: [0; STACK_DEPTH],
            settled: true,
            since_us: 0,
            kept_default: false,
            locks: [false; 3],
            position: 0,
            speed: 0,
            temperature_c: 25,
            led_current_ma: 10,
            i2c_fault: false,
            position_faults: [false; 7],
        }
    }

    #[test]
    fn the_factory_parts_are_the_operational_slave() {
        let built = factory().build(profiles::srs50()).unwrap();
        assert_eq!(built, Slave::operational(profiles::srs50()));
    }

    #[test]
    fn parts_that_break_the_invariant_build_nothing() {
        let p = profiles::srs50();
        assert!(Parts { counter: 0x100_0000, ..factory() }.build(p).is_none());
        assert!(Parts { address: 0x60, ..factory() }.build(p).is_none());
        assert!(Parts { settings: 0xE7, ..factory() }.build(p).is_none());
        assert!(Parts { offset: p.range(), ..factory() }.build(p).is_none());
        // 00h is never stacked (ErrorStack::push ignores it): an empty stack.
        assert!(Parts { stack_len: 1, ..factory() }.build(p).is_some_and(|s| s.error_stack().is_empty()));
        assert!(Parts { settled: true, kept_default: true, ..factory() }.build(p).is_none());
        // Fields that do not fit the memory (8 blocks of 128 bytes on 8 blocks: one fits).
        let legacy = profiles::legacy_srs();
        assert!(Parts { field_count: 1, statuses: [0xC7, 0, 0], ..factory() }.build(legacy).is_some());
        assert!(Parts { field_count: 2, statuses: [0xC7, 0xC0, 0], ..factory() }.build(legacy).is_none());
    }

    /// The twins of Read Data's harness and of the requests it leaves out sample the
    /// two parts of its frames, which together are all of them.
    #[test]
    fn read_data_frames_are_shaped_into_their_part() {
        for c in 0..=255u8 {
            let mut short = [0x40, 0x4A, 0, 0, c, 0, 0];
            let mut long = short;
            read_data_short(&mut short);
            read_data_long(&mut long);
            assert!(read_data_counted_short(&short) && !read_data_counted_short(&long), "{c:02X}");
            assert_eq!(short[READ_DATA_COUNT] == c, read_data_counted_short(&[0x40, 0x4A, 0, 0, c]));
        }
    }

    #[test]
    fn the_rules_fail_a_reply_with_the_wrong_warning_bit() {
        let s = Parts { stack_len: 1, stack: [0x1E, 0, 0, 0], ..factory() }.build(profiles::srs50()).unwrap();
        let frame = [0x40, 0x42, 0x02];
        let mut after = s.clone();
        let mut outcome = after.handle_frame(&frame, 0);
        assert!(rules_hold(&s, &frame, 0, &outcome, &after));
        if let Reply::Frame(rf) = &mut outcome.reply {
            rf.warning = false;
        }
        assert!(!rules_hold(&s, &frame, 0, &outcome, &after));
        // Silent where it must answer.
        outcome.reply = Reply::Silent(Silence::NotAddressed);
        assert!(!rules_hold(&s, &frame, 0, &outcome, &after));
    }
}
