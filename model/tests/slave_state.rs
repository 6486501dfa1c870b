//! The slave's state seen from outside: what a black-box run adopts from a real
//! device, start-up faults and their locks, the I2C fault, the next deadline. Each
//! checked at the wire where the spec says what it changes.

mod common;
use common::*;
use hiperface_model::datalink::RxChar;
use hiperface_model::slave::inputs::{InitFault, PositionFault};
use hiperface_model::slave::Locks;
use hiperface_model::{profiles, Slave};

/// A device's field statuses and counter, adopted: Memory Status (4Eh) and Read
/// Counter (46h) answer them; statuses that do not fit change nothing.
#[test]
fn adopted_fields_and_counter_are_what_the_device_answers() {
    let mut s = operational(profiles::srs50());
    // Field 0: 32 bytes (2 blocks), field 1: 16 bytes; 5 blocks free.
    assert!(s.adopt(&[0x81, 0x80], 5, 0x01_0203));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 5, 2])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x46]), Some(sealed(&[0x40, 0x46, 0x01, 0x02, 0x03])));
    // 32 bytes in field 0: offset 31 can be read, offset 32 cannot (000:T53).
    assert!(ask_sealed(&mut s, &[0x40, 0x4A, 0x00, 0x1F, 0x01, 0x55]).is_some_and(|r| r.len() == 7));
    let before = s.clone();
    // 250 blocks used + 10 free: more than any memory.
    let big = [0x87; 32];
    assert!(!s.adopt(&big[..], 10, 7));
    assert!(!s.adopt(&[0x87, 0x87, 0x87, 0x87, 0x87, 0x87, 0x87, 0x87], 250, 7));
    assert_eq!(s, before, "nothing changed");
}

/// A position a device reported is where the model's shaft is, whatever the offset a
/// Set Position left; the preset a device used becomes the offset.
#[test]
fn adopted_positions_hold_with_any_offset() {
    let p = profiles::srs50();
    let range = p.range();
    let mut s = operational(p);
    s.set_inputs(hiperface_model::slave::inputs::PhysicalInputs { position: 12345, ..Default::default() });
    // Set Position to 100: offset = 100 - 12345 (mod range).
    ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 100, 0x55]).unwrap();
    assert_eq!(s.position(), 100);
    let offset = (100 + range - 12345) % range;
    for reported in [0, 1, 99, 101, range / 2, range - 1] {
        assert!(s.adopt_position(reported));
        assert_eq!(s.position(), reported);
        assert_eq!(s.nonvolatile().offset, offset, "the offset stays");
        // The shaft is where the position says, within the range.
        assert_eq!(s.inputs().position, (reported + range - offset) % range);
    }
    assert!(!s.adopt_position(range));
    assert_eq!(s.position(), range - 1, "a refused value changes nothing");
    let raw = s.inputs().position;
    for used in [0, 7, range - 1] {
        assert!(s.adopt_preset(used));
        assert_eq!(s.position(), used);
        // The offset the device stored is one Set Position could have stored.
        assert_eq!(s.nonvolatile().offset, (used + range - raw) % range);
    }
    assert!(!s.adopt_preset(range));
    assert_eq!(s.position(), range - 1);
}

/// The raw position input is taken modulo the range, whatever its value (the world
/// may hand the model any count): the position, Read Position and an adopted preset
/// stay within the range.
#[test]
fn any_raw_position_input_is_within_the_range() {
    let p = profiles::srs50();
    let range = p.range();
    let mut s = operational(p);
    ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 100, 0x55]).unwrap();
    s.set_inputs(hiperface_model::slave::inputs::PhysicalInputs { position: u64::MAX, ..Default::default() });
    assert_eq!(s.position(), (u64::MAX % range + 100) % range);
    assert!(s.adopt_preset(5));
    assert_eq!(s.position(), 5);
    assert_eq!(s.nonvolatile().offset, (5 + range - u64::MAX % range) % range);
}

/// Clearing one injected start-up fault leaves the others: the next power-up finds
/// exactly them.
#[test]
fn clearing_one_start_up_fault_keeps_the_others() {
    let found = |inject: &[InitFault], clear: &[InitFault]| {
        let mut s = operational(profiles::srs50());
        for f in inject {
            s.inject_init_fault(*f, true);
        }
        for f in clear {
            s.inject_init_fault(*f, false);
        }
        s.power_cycle(0);
        s.settle();
        s.error_stack().entries().collect::<Vec<_>>()
    };
    let analog = found(&[InitFault::AnalogLimits], &[]);
    assert!(!analog.is_empty());
    assert_eq!(found(&[InitFault::Watchdog, InitFault::AnalogLimits], &[InitFault::Watchdog]), analog);
    assert_eq!(found(&[InitFault::Watchdog, InitFault::AnalogLimits], &[InitFault::AnalogLimits]).len(), 1);
}

/// 20h locks the position of a linear encoder ("sensor not adjusted") until reset,
/// not of a rotary one ("singleturn position unreliable") (000:T62).
#[test]
fn the_singleturn_fault_locks_a_linear_encoder_only() {
    let after_20h = |p: hiperface_model::Profile| {
        let mut s = operational(p);
        s.inject_position_fault(PositionFault::Singleturn, true);
        assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]).map(|r| r[2]), Some(0x20));
        s.inject_position_fault(PositionFault::Singleturn, false);
        ask_sealed(&mut s, &[0x40, 0x42]).map(|r| r[1] & 0x7F)
    };
    assert_eq!(after_20h(profiles::ttk70()), Some(0x50), "locked: an error");
    assert_eq!(after_20h(profiles::srs50()), Some(0x42), "a position again");
    assert!(PositionFault::Singleturn.locks(true) && !PositionFault::Singleturn.locks(false));
}

/// Bytes a device returned are adopted into an existing field, within it.
#[test]
fn adopted_field_data_is_read_back() {
    let mut s = operational(profiles::srs50());
    assert!(s.adopt(&[0x80], 4, 0));
    assert!(s.adopt_field_data(0, 14, &[0xAB, 0xCD]));
    assert_eq!(
        ask_sealed(&mut s, &[0x40, 0x4A, 0x00, 0x0E, 0x02, 0x55]),
        Some(sealed(&[0x40, 0x4A, 0x00, 0x0E, 0x02, 0xAB, 0xCD]))
    );
    assert!(!s.adopt_field_data(0, 15, &[1, 2]), "beyond the field's 16 bytes");
    assert!(!s.adopt_field_data(1, 0, &[1]), "no field 1");
    assert_eq!(s.eeprom_writes(), 0, "adopting is not writing");
}

/// Start-up faults found at power-up: each stacked with the internal checksum error
/// where 000:T38-T46 say so, and the locks of all of them together.
#[test]
fn start_up_faults_lock_what_each_of_them_locks() {
    let mut s = Slave::new(profiles::srs50());
    // Alignment data locks the position; the partition table the data fields.
    s.power_up_with([InitFault::AlignmentData, InitFault::PartitionTable], true);
    assert_eq!(s.locks(), Locks { position: true, nonvolatile: true, data_fields: true });
    // Read Position answers 02h, with the warning bit for the stacked faults. // 000:2.3.4
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0xD0, 0x02])));
    // The watchdog alone locks nothing and is no checksum error.
    let mut w = Slave::new(profiles::srs50());
    w.power_up_with([InitFault::Watchdog], true);
    assert_eq!(w.locks(), Locks::default());
    assert_eq!(w.error_stack().len(), 1);
    // Unsettled, the slave is initialising after power-up: silent.
    let mut u = Slave::new(profiles::srs50());
    u.power_up_with([], false);
    assert_eq!(u.listening_settings(0), None);
    assert!(u.listening_settings(2_000_000).is_some());
}

/// The I2C fault answers 05h where a command lists it (55h, 000:T30) until cleared.
#[test]
fn an_i2c_fault_is_reported_by_the_commands_that_list_it() {
    let mut s = operational(profiles::srs50());
    s.inject_i2c_fault(true);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x41, 0x55]), Some(error(0x40, 0x05)));
    s.inject_i2c_fault(false);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x41, 0x55]), Some(sealed(&[0x41, 0x55])));
}

/// The next deadline: the power-up's next state change, or a frame's timeout if
/// sooner. // 000:T9, 000:2.2.2
#[test]
fn the_next_deadline_is_the_sooner_of_timeout_and_state_change() {
    let mut s = Slave::new(profiles::srs50());
    s.power_cycle(0);
    assert_eq!(s.next_deadline(0), Some(100_000), "end of initialization");
    assert_eq!(s.next_deadline(100_000), Some(900_000), "end of the default window");
    assert_eq!(s.next_deadline(900_000), Some(1_100_000));
    assert_eq!(s.next_deadline(1_100_000), None);
    // A character at 150 ms: its timeout ends first.
    let _ = s.receive(RxChar::ok(0x40, 150_000));
    assert_eq!(s.next_deadline(150_000), Some(150_000 + 5_730));
    let o = operational(profiles::srs50());
    assert_eq!(o.next_deadline(0), None, "settled: nothing to wait for");
}

/// The memory size byte counts 16-byte blocks, so up to 255 blocks (4080 bytes) can be
/// adopted and read to their last byte. // 000:T28
#[test]
fn the_largest_memory_is_255_blocks() {
    let mut s = operational(profiles::srs50());
    // 31 fields of 128 bytes (8 blocks) and 7 blocks free: 255 blocks.
    assert!(s.adopt(&[0x87; 31], 7, 0));
    assert!(s.adopt_field_data(30, 127, &[0x5A]));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 30, 127, 1, 0x55]), Some(sealed(&[0x40, 0x4A, 30, 127, 1, 0x5A])));
    assert!(!s.adopt(&[0x87; 31], 8, 0), "256 blocks");
}
