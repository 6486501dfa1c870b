//! The slave's invariant as one predicate: what holds in every reachable state of
//! [`Slave`], checked by the fuzz targets (`targets::invariants`), the properties and
//! the model checkers (`model_check`, `fixpoint`), and written for a Kani harness too:
//! no allocation, and every loop over a fixed count or over the fields in use.

use hiperface_model::settings::UartSettings;
use hiperface_model::slave::fields::FieldTable;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::slave::stack::{ErrorStack, STACK_DEPTH};
use hiperface_model::{FaultCode, Profile, Slave};

/// The largest counter value: 24 bits. // 000:T16
pub const COUNTER_MAX: u32 = 0xFF_FFFF;

/// What part of the invariant a state violates, with the values that show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Violation {
    /// More than four codes on the error stack. // 000:T27
    StackOverfull { len: usize },
    /// A code twice on the error stack ("each present once"). // 000:T27
    StackDuplicate { code: u8 },
    /// 00h (no fault) on the error stack: it is never stored. // 000:T27
    StackHoldsNoFault,
    /// Free + allocated blocks differ from the total. // 000:2.4.2
    MemoryNotConserved { used: u32, free: u32, capacity: u32 },
    /// The total is not the device's user memory. // 000:2.4.2, 000:T25
    MemoryNotTheDevices { capacity: u8, profile: u8 },
    /// The fields allocate more than the memory holds.
    FieldsBeyondMemory { used: u32, capacity: u32 },
    /// A field number below the count has no field: numbers are not contiguous. // 000:T24
    FieldMissing { number: u8 },
    /// The field numbered by the count exists. // 000:T24
    FieldBeyondCount { number: u8 },
    /// The slave's own address is outside 40h..5Fh. // 000:T5, 000:T30
    AddressOutOfRange { byte: u8 },
    /// Settings that are not a defined settings byte or use a data rate the device
    /// lacks; `which`: stored, as of the last reset, or temporary. // 000:T28
    SettingsInvalid { which: Settings, byte: u8 },
    /// The Set Position offset is outside the measuring range.
    OffsetOutOfRange { offset: u64, range: u64 },
    /// The counter is beyond 24 bits. // 000:T16
    CounterBeyond24Bits { counter: u32 },
    /// The power-up state machine disagrees with itself: a listening state without
    /// settings, settings in a state that does not listen, or the default settings
    /// kept without a power-up window. // 000:T9
    PowerUpInconsistent { state: CommState, listening: bool },
}

/// Which settings a [`Violation::SettingsInvalid`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Settings {
    Stored,
    SinceReset,
    Temporary,
}

impl core::fmt::Display for Violation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Violation::StackOverfull { len } => write!(f, "error stack holds {len} codes, more than 4 (000:T27)"),
            Violation::StackDuplicate { code } => write!(f, "error stack holds {code:02X}h twice (000:T27)"),
            Violation::StackHoldsNoFault => write!(f, "error stack holds 00h (000:T27)"),
            Violation::MemoryNotConserved { used, free, capacity } => {
                write!(f, "memory not conserved: {used} allocated + {free} free blocks != {capacity} (000:2.4.2)")
            }
            Violation::MemoryNotTheDevices { capacity, profile } => {
                write!(f, "user memory of {capacity} blocks, the device has {profile} (000:2.4.2)")
            }
            Violation::FieldsBeyondMemory { used, capacity } => {
                write!(f, "fields allocate {used} blocks of {capacity} (000:2.4.2)")
            }
            Violation::FieldMissing { number } => write!(f, "field {number} missing below the count (000:T24)"),
            Violation::FieldBeyondCount { number } => write!(f, "field {number} exists at the count (000:T24)"),
            Violation::AddressOutOfRange { byte } => write!(f, "own address {byte:02X}h outside 40h..5Fh (000:T5)"),
            Violation::SettingsInvalid { which, byte } => write!(f, "{which:?} settings {byte:02X}h invalid (000:T28)"),
            Violation::OffsetOutOfRange { offset, range } => write!(f, "offset {offset} outside the range {range}"),
            Violation::CounterBeyond24Bits { counter } => write!(f, "counter {counter:X}h beyond 24 bits (000:T16)"),
            Violation::PowerUpInconsistent { state, listening } => {
                write!(f, "power-up state {} inconsistent (listening: {listening}) (000:T9)", state.name())
            }
        }
    }
}

/// The slave's invariant: `Ok` in every reachable state, else the first part violated.
pub fn slave_invariant(s: &Slave) -> Result<(), Violation> {
    error_stack(s)?;
    memory(s)?;
    let nv = s.nonvolatile();
    let profile = s.profile();
    // 000:T5: slave addresses are 40h..5Fh.
    let address = nv.address.byte();
    if !(0x40..=0x5F).contains(&address) {
        return Err(Violation::AddressOutOfRange { byte: address });
    }
    settings_valid(profile, nv.settings, Settings::Stored)?;
    settings_valid(profile, s.boot_settings(), Settings::SinceReset)?;
    if let Some(t) = s.temporary_settings() {
        settings_valid(profile, t, Settings::Temporary)?;
    }
    if nv.offset >= profile.range() {
        return Err(Violation::OffsetOutOfRange { offset: nv.offset, range: profile.range() });
    }
    if nv.counter > COUNTER_MAX {
        return Err(Violation::CounterBeyond24Bits { counter: nv.counter });
    }
    power_up(s)
}

/// At most four codes, none twice, never 00h. Every pair of slots visited: a loop of
/// fixed length. // 000:T27
fn error_stack(s: &Slave) -> Result<(), Violation> {
    stack_invariant(s.error_stack())
}

/// The error stack's part of the invariant, on its own (for the stack's inductive
/// harness). // 000:T27
pub fn stack_invariant(stack: &ErrorStack) -> Result<(), Violation> {
    if stack.len() > STACK_DEPTH {
        return Err(Violation::StackOverfull { len: stack.len() });
    }
    for i in 0..STACK_DEPTH {
        let code = stack.slot(i);
        if code == Some(FaultCode::NoFault) {
            return Err(Violation::StackHoldsNoFault);
        }
        for j in i + 1..STACK_DEPTH {
            if let Some(c) = code.filter(|c| stack.slot(j) == Some(*c)) {
                return Err(Violation::StackDuplicate { code: c.byte() });
            }
        }
    }
    Ok(())
}

/// Free + allocated = total, the total the device's, fields 0..count and no other.
/// // 000:2.4.2, 000:T24
fn memory(s: &Slave) -> Result<(), Violation> {
    fields_invariant(s.nonvolatile().fields.table(), s.profile().user_memory_blocks)
}

/// The data field table's part of the invariant, on its own, for a device with
/// `device_blocks` blocks of user memory (for the table's inductive harness).
/// // 000:2.4.2, 000:T24
pub fn fields_invariant(fields: &FieldTable, device_blocks: u8) -> Result<(), Violation> {
    let (used, free, capacity) = (fields.used_blocks(), fields.free_blocks() as u32, fields.capacity_blocks() as u32);
    if used > capacity {
        return Err(Violation::FieldsBeyondMemory { used, capacity });
    }
    if used + free != capacity {
        return Err(Violation::MemoryNotConserved { used, free, capacity });
    }
    if fields.capacity_blocks() != device_blocks {
        return Err(Violation::MemoryNotTheDevices { capacity: fields.capacity_blocks(), profile: device_blocks });
    }
    for number in 0..fields.count() {
        if !fields.status(number).is_some_and(|st| st.exists()) {
            return Err(Violation::FieldMissing { number });
        }
    }
    if fields.status(fields.count()).is_some() {
        return Err(Violation::FieldBeyondCount { number: fields.count() });
    }
    Ok(())
}

/// A settings byte that decodes to these settings, at a data rate the device has or
/// the default settings (which every device listens with at power-up). // 000:T28, 000:T9
fn settings_valid(profile: &Profile, settings: UartSettings, which: Settings) -> Result<(), Violation> {
    let byte = settings.byte();
    let decodes = UartSettings::decode(byte) == Ok(settings);
    if decodes && (settings == UartSettings::DEFAULT || profile.supports_baud(settings.baud)) {
        Ok(())
    } else {
        Err(Violation::SettingsInvalid { which, byte })
    }
}

/// The power-up state machine at each of its boundaries: it listens exactly in the
/// listening states; the default settings are kept only after a power-up (a slave
/// powered on long ago never saw the default window). // 000:T9
fn power_up(s: &Slave) -> Result<(), Violation> {
    let p = s.profile();
    let up = s.power_up();
    let since = up.since_us.unwrap_or(0);
    let at = |ms: u16| since.saturating_add(ms as u64 * 1000);
    for t in [since, at(p.init_ms), at(p.default_window_ms), at(p.user_settings_ms), u64::MAX] {
        let state = s.state(t);
        let listening = s.listening_settings(t).is_some();
        let listens = matches!(
            state,
            CommState::DefaultCommunication | CommState::OperationalDefault | CommState::OperationalUser
        );
        let kept_unexplained = up.kept_default && up.since_us.is_none();
        if listening != listens || kept_unexplained {
            return Err(Violation::PowerUpInconsistent { state, listening });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::profiles;

    #[test]
    fn every_builtin_profile_starts_in_a_state_that_holds_it() {
        for (name, make) in profiles::BUILTIN {
            assert_eq!(slave_invariant(&Slave::new(make())), Ok(()), "{name}");
            assert_eq!(slave_invariant(&Slave::operational(make())), Ok(()), "{name}");
        }
    }

    /// The predicate can fail: a memory table adopted with a total other than the
    /// device's is caught, and so is a full stack's... (the stack cannot be made
    /// wrong through the public interface; `fixpoint::tests` shows a frame rule fail).
    #[test]
    fn a_violation_is_reported_with_what_is_wrong() {
        let mut s = Slave::operational(profiles::sek37());
        assert!(s.adopt(&[0xC0], 3, 0));
        assert_eq!(slave_invariant(&s), Err(Violation::MemoryNotTheDevices { capacity: 4, profile: 0x70 }));
        let shown = slave_invariant(&s).map_err(|v| v.to_string());
        assert!(shown.is_err_and(|v| v.contains("4 blocks") && v.contains("112")));
    }
}
