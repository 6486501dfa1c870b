//! Slave behaviour beyond single commands: addressing, the check order, warning bit
//! and error stack, faults and locks, data fields and access codes, positions.
//!
//! Long because: each test is a short scenario through the same slave, grouped by the
//! behaviour of 000 chapter 2 it checks; split, the groups would lose the one fixture
//! they share.

mod common;
use common::*;
use hiperface_model::response::{Response, ResponseFrame};
use hiperface_model::slave::inputs::{InitFault, PositionFault};
use hiperface_model::{profiles, FaultCode, Reply, Silence, Slave};

#[test]
fn addressing_and_broadcast() {
    let mut s = operational(profiles::srs50());
    // 000:2.3.1: another address: silent. Broadcast: answered with the own address.
    assert_eq!(ask_sealed(&mut s, &[0x41, 0x42]), None);
    assert_eq!(ask_sealed(&mut s, &[0x60, 0x42]), None);
    assert_eq!(ask_sealed(&mut s, &[0xFF, 0x42]), Some(sealed(&[0x40, 0x42, 0, 0, 0, 0])));
    // Even an unaddressed frame with a bad checksum stays unanswered (check 1 first).
    assert_eq!(ask(&mut s, &[0x41, 0x42, 0x00]), None);
    let silent = s.handle_frame(&sealed(&[0x41, 0x42]), 0);
    assert_eq!(silent.reply, Reply::Silent(Silence::NotAddressed));
    // After 55h the slave answers the new address only, broadcast still with its own.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x5F, 0x55]), Some(sealed(&[0x5F, 0x55])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), None);
    assert_eq!(ask_sealed(&mut s, &[0xFF, 0x4E]), Some(sealed(&[0x5F, 0x4E, 0x70, 0x00])));
}

#[test]
fn order_of_checks_and_alternatives() {
    let mut s = operational(profiles::srs50());
    // UART fault beats everything: 09h; the bad checksum is an acceptable alternative.
    let o = s.handle_faulty_frame(&[0x40, 0x42, 0x00], 0);
    assert_eq!(reply_bytes(&o), Some(error(0x40, 0x09)));
    assert!(o.also.contains(FaultCode::Checksum));
    // Fewer than 3 bytes: 0Ch.
    assert_eq!(ask(&mut s, &[0x40]), Some(error(0x40, 0x0C)));
    assert_eq!(ask(&mut s, &[0x40, 0x42]), Some(error(0x40, 0x0C)));
    // Checksum before command and length.
    assert_eq!(ask(&mut s, &[0x40, 0x45, 0x00]), Some(error(0x40, 0x0A)));
    // Unknown command (not in the table, not in the profile, bit 6 clear, bit 7 set).
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x45]), Some(error(0x40, 0x0B)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x6C]), Some(error(0x40, 0x0B)), "SRS50 lacks optional 6Ch");
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x02]), Some(error(0x40, 0x0B)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0xC2]), Some(error(0x40, 0x0B)));
    // Length before argument before access code.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x60]), Some(error(0x40, 0x0C)));
    let o = s.handle_frame(&sealed(&[0x40, 0x55, 0x60, 0x00]), 0);
    assert_eq!(reply_bytes(&o), Some(error(0x40, 0x0D)));
    assert!(o.also.contains(FaultCode::WrongAccessCode));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x41, 0x00]), Some(error(0x40, 0x0F)));
    // Too many characters (more than any frame): 0Ch.
    let mut long = vec![0x40, 0x4B];
    long.extend([0u8; 200]);
    assert_eq!(ask_sealed(&mut s, &long), Some(error(0x40, 0x0C)));
    // Nothing changed.
    assert_eq!(s.eeprom_writes(), 0);
    assert_eq!(s.nonvolatile().address.byte(), 0x40);
}

#[test]
fn warning_bit_and_error_stack() {
    let mut s = with_inputs(operational(profiles::srs50()), |i| i.temperature_c = 130);
    // 000:T59: temperature is checked before every response and stacked: warning bit.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0xCE, 0x70, 0x00])));
    // An error response with a warning in parallel: D0h. // 000:2.3.4
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x45]), Some(sealed(&[0x40, 0xD0, 0x0B])));
    // The condition persists: reading the stack clears the warning for this reply only.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x50]), Some(sealed(&[0x40, 0xD0, 0x1E])));
    s = with_inputs(s, |i| i.temperature_c = 25);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x50]), Some(sealed(&[0x40, 0x50, 0x1E])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x50]), Some(sealed(&[0x40, 0x50, 0x00])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 0x70, 0x00])));
}

/// An Others condition that holds when 50h comes is active then (000:T58, T59: "checked
/// prior to every Slave response message"): 50h reports it, never 00h with the warning
/// bit, which says nothing is active and that something is (000:T27).
#[test]
fn read_encoder_status_reports_a_condition_that_holds_even_on_an_empty_stack() {
    // Hot, and 50h the very first request: nothing stacked yet.
    let mut s = with_inputs(operational(profiles::srs50()), |i| i.temperature_c = 130);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x50]), Some(sealed(&[0x40, 0xD0, 0x1E])));
    // The LED current over its limit: a position request answers 1Dh, not stacked; 50h
    // then finds it active.
    let mut s = with_inputs(operational(profiles::srs50()), |i| i.led_current_ma = 500);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(error(0x40, 0x1D)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x50]), Some(sealed(&[0x40, 0xD0, 0x1D])));
    // The current back within its limit: the code read once more, then nothing.
    s = with_inputs(s, |i| i.led_current_ma = 10);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x50]), Some(sealed(&[0x40, 0x50, 0x1D])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x50]), Some(sealed(&[0x40, 0x50, 0x00])));
}

#[test]
fn stack_overflow_drops_the_oldest_and_reset_clears() {
    let mut s = operational(profiles::srm50());
    for f in [InitFault::Watchdog, InitFault::AngularOffset, InitFault::PartitionTable] {
        s.inject_init_fault(f, true);
    }
    s.power_cycle(0);
    s.settle();
    // Stacked at start-up in table order: 06h + 02h, 03h (06h once), 07h.
    let stack: Vec<_> = s.error_stack().entries().collect();
    assert_eq!(
        stack,
        [FaultCode::InternalChecksum, FaultCode::AngularOffset, FaultCode::PartitionTable, FaultCode::Watchdog]
    );
    // A fifth distinct code drops the oldest (07h).
    s = with_inputs(s, |i| i.temperature_c = -60);
    let reply = ask_sealed(&mut s, &[0x40, 0x42]).unwrap();
    assert_eq!(reply, sealed(&[0x40, 0xD0, 0x02]), "position locked, warning set");
    let stack: Vec<_> = s.error_stack().entries().collect();
    assert_eq!(stack[0], FaultCode::AngularOffset, "06h dropped");
    assert_eq!(stack[3], FaultCode::Temperature);
    // Encoder Reset clears the stack; the injected faults are found again at init.
    s.inject_init_fault(InitFault::Watchdog, false);
    s.inject_init_fault(InitFault::AngularOffset, false);
    s.inject_init_fault(InitFault::PartitionTable, false);
    s = with_inputs(s, |i| i.temperature_c = 20);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x53]), None);
    s.settle();
    assert!(s.error_stack().is_empty());
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0x42, 0, 0, 0, 0])), "lock gone after reset");
}

#[test]
fn position_faults_lock_until_reset() {
    let mut s = operational(profiles::srm50());
    s.inject_position_fault(PositionFault::MultiturnSync, true);
    s.inject_position_fault(PositionFault::MultiturnVectorLength, true);
    // The first fault is answered, the other stacked. // 000:T37 position group
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0xD0, 0x22])));
    assert!(s.error_stack().contains(FaultCode::MultiturnVectorLength));
    s.inject_position_fault(PositionFault::MultiturnSync, false);
    s.inject_position_fault(PositionFault::MultiturnVectorLength, false);
    // 22h locks position output: 02h until reset. // 000:T65
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0xD0, 0x02])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 0, 0x55]), Some(sealed(&[0x40, 0xD0, 0x02])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x53]), None);
    s.settle();
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0x42, 0, 0, 0, 0])));
    // 23h alone does not lock.
    s.inject_position_fault(PositionFault::MultiturnVectorLength, true);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0x50, 0x23])));
    s.inject_position_fault(PositionFault::MultiturnVectorLength, false);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0x42, 0, 0, 0, 0])));
}

#[test]
fn set_position_keeps_the_offset_over_the_measuring_range() {
    let mut s = with_inputs(operational(profiles::sek37()), |i| i.position = 500);
    // SEK37: 512 steps. Preset 10 at raw 500: offset 22.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 10, 0x55]), Some(sealed(&[0x40, 0x43])));
    assert_eq!(s.nonvolatile().offset, 22);
    s = with_inputs(s, |i| i.position = 511);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0x42, 0, 0, 0, 21])));
    s = with_inputs(s, |i| i.position = 512 + 489);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0x42, 0, 0, 0x01, 0xFF])), "wraps at 512");
    // Preset outside the range: 0Dh. Shaft moving: 1Fh and nothing stored. // 000:T60
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 2, 0, 0x55]), Some(error(0x40, 0x0D)));
    s = with_inputs(s, |i| i.speed = 1);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 0, 0x55]), Some(error(0x40, 0x1F)));
    assert_eq!(s.nonvolatile().offset, 22);
    // Reading at speed is fine up to the data sheet's limit.
    assert!(ask_sealed(&mut s, &[0x40, 0x42]).is_some_and(|r| r[1] == 0x42));
}

#[test]
fn read_synchronization_offset_completes_the_position() {
    let mut p = profiles::sks36();
    p.commands.insert(hiperface_model::CommandId::ReadSyncOffset);
    let mut s = with_inputs(operational(p), |i| i.position = 1000);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x6C]), Some(sealed(&[0x40, 0x6C, 0])));
    // Set Position 7 at raw 1000 (phase 8): offset 4096 + 7 - 1000.
    assert!(ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 7, 0x55]).is_some());
    let reply = ask_sealed(&mut s, &[0x40, 0x6C]).unwrap();
    let shift = reply[2] as u64;
    // DESIGN:position: position + value = raw (mod 32).
    assert_eq!((7 + shift) % 32, 1000 % 32);
}

#[test]
fn analog_channels_and_encodings() {
    let mut s = with_inputs(operational(profiles::sek37()), |i| i.temperature_c = -5);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x44, 0x48]), Some(sealed(&[0x40, 0x44, 0x48, 0xFF, 0xFB])));
    // F0h: (T + 40) / 2.048 = 17.09 -> 17. // 000:T14
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x44, 0xF0]), Some(sealed(&[0x40, 0x44, 0xF0, 0x00, 17])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x44, 0x49]), Some(error(0x40, 0x0D)));
}

#[test]
fn counter_overflow_current_edition() {
    let mut s = operational(profiles::srs50());
    s.set_counter(0xFF_FFFE);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x47]), Some(sealed(&[0x40, 0x47])));
    // 000:T46: at FFFFFFh the counter stays and increment answers 08h.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x47]), Some(error(0x40, 0x08)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x46]), Some(sealed(&[0x40, 0x46, 0xFF, 0xFF, 0xFF])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x49, 0x55]), Some(sealed(&[0x40, 0x49])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x46]), Some(sealed(&[0x40, 0x46, 0, 0, 0])));
}

#[test]
fn data_fields_lifecycle_and_access_codes() {
    let mut s = operational(profiles::kuebler_s36()); // 22 blocks
    let create =
        |s: &mut hiperface_model::Slave, n: u8, status: u8, code: u8| ask_sealed(s, &[0x40, 0x4D, n, status, code]);
    // New number must be the count. // 000:T24
    assert_eq!(create(&mut s, 1, 0xC0, 0x55), Some(error(0x40, 0x12)));
    // Create with the delete bit: 12h.
    assert_eq!(create(&mut s, 0, 0x40, 0x55), Some(error(0x40, 0x12)));
    // Field 0: 128 bytes, Code1 enabled, writable; the code byte is Code1's value.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4F, 1, 0x55, 0x11]), Some(sealed(&[0x40, 0x4F, 1])));
    assert_eq!(create(&mut s, 0, 0xDF, 0x55), Some(error(0x40, 0x0F)));
    assert_eq!(create(&mut s, 0, 0xDF, 0x11), Some(sealed(&[0x40, 0x4D, 0, 0xDF])));
    // Field 1 with Code3 disabled still needs Code3's value at creation.
    assert_eq!(create(&mut s, 1, 0xF7, 0x55), Some(sealed(&[0x40, 0x4D, 1, 0xF7])));
    // 8 + 8 blocks used, 6 free; 7 more do not fit. // 000:T54
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 6, 2])));
    assert_eq!(create(&mut s, 2, 0xC6, 0x55), Some(error(0x40, 0x10)));
    // Resizing field 0 (not the last): 12h. Shrinking the last frees blocks.
    assert_eq!(create(&mut s, 0, 0xD8, 0x11), Some(error(0x40, 0x12)));
    assert_eq!(create(&mut s, 1, 0xB0, 0x55), Some(sealed(&[0x40, 0x4D, 1, 0xB0])), "16 bytes, read-only");
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 13, 2])));
    // Read/store with the field's code: enabled code checked, disabled code ignored.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4B, 0, 126, 2, 0x55, 1, 2]), Some(error(0x40, 0x0F)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4B, 0, 126, 2, 0x11, 1, 2]), Some(sealed(&[0x40, 0x4B, 0, 126, 2])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4B, 0, 127, 2, 0x11, 1, 2]), Some(error(0x40, 0x11)), "off by one");
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 0, 126, 2, 0x11]), Some(sealed(&[0x40, 0x4A, 0, 126, 2, 1, 2])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 0, 127, 2, 0x11]), Some(error(0x40, 0x11)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 0, 0, 0, 0x11]), Some(error(0x40, 0x11)), "count 0");
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 1, 0, 1, 0x00]), Some(sealed(&[0x40, 0x4A, 1, 0, 1, 0xFF])));
    // Read-only field: 0Eh; making it writable needs the field's code.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4B, 1, 0, 1, 0x55, 9]), Some(error(0x40, 0x0E)));
    assert_eq!(create(&mut s, 1, 0xF0, 0x55), Some(sealed(&[0x40, 0x4D, 1, 0xF0])), "now writable");
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4B, 1, 0, 1, 0x00, 9]), Some(sealed(&[0x40, 0x4B, 1, 0, 1])));
    // Delete: only the last, all other bits as stored.
    assert_eq!(create(&mut s, 0, 0x5F, 0x11), Some(error(0x40, 0x12)));
    assert_eq!(create(&mut s, 1, 0x71, 0x55), Some(error(0x40, 0x12)), "bits differ");
    assert_eq!(create(&mut s, 1, 0x70, 0x66), Some(error(0x40, 0x0F)), "Code3 is 55h");
    assert_eq!(create(&mut s, 1, 0x70, 0x55), Some(sealed(&[0x40, 0x4D, 1, 0x70])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4C, 1]), Some(error(0x40, 0x12)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 14, 1])));
}

#[test]
fn extended_type_label_is_field_ff() {
    let mut s = operational(profiles::skm36());
    let label = s.profile().extended_type_label.unwrap();
    let reply = ask_sealed(&mut s, &[0x40, 0x4A, 0xFF, 0, 64, 0x00]).unwrap();
    assert_eq!(&reply[5..69], &label[..]);
    assert_eq!(hiperface_model::checksum::xor(&reply[5..69]), 0, "000:T20 checksum at offset 0");
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 0xFF, 60, 5, 0x00]), Some(error(0x40, 0x11)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4B, 0xFF, 0, 1, 0x55, 0]), Some(error(0x40, 0x0E)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4D, 0xFF, 0xC0, 0x55]), Some(error(0x40, 0x10)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4C, 0xFF]), Some(sealed(&[0x40, 0x4C, 0xFF, 0x83])));
    // Not counted as a data field. // 000:2.4.2
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 0x70, 0x00])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x52]), Some(sealed(&[0x40, 0x52, 0xE4, 0xFF, 0x80, 0x00])));
    // A device without one: 12h.
    let mut t = operational(profiles::srs50());
    assert_eq!(ask_sealed(&mut t, &[0x40, 0x4A, 0xFF, 0, 1, 0x00]), Some(error(0x40, 0x12)));
}

#[test]
fn settings_commands() {
    let mut s = operational(profiles::srs50());
    // 57h stores; 52h reports the stored byte (DESIGN:52h); active only after reset.
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x57, 0xE5, 0x55]), Some(sealed(&[0x40, 0x57, 0xE5])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x52]), Some(sealed(&[0x40, 0x52, 0xE5, 0x22, 0x80, 0])));
    assert_eq!(s.listening_settings(0).map(|x| x.byte()), Some(0xE4));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x53]), None);
    s.settle();
    assert_eq!(s.listening_settings(0).map(|x| x.byte()), Some(0xE5));
    // Undefined bytes and unsupported rates: 0Dh. SRS50 has no 600 Bd.
    for bad in [0xE7, 0xD4, 0xEC, 0xE0] {
        assert_eq!(ask_sealed(&mut s, &[0x40, 0x57, bad, 0x55]), Some(error(0x40, 0x0D)), "{bad:02X}");
    }
}

/// A listener learns Code0 from a request the device accepted: the model then accepts
/// what the device accepted, and still refuses another code. Nothing is written.
#[test]
fn an_adopted_access_code_is_the_one_checked() {
    let mut s = operational(profiles::srs50());
    // 55h with 3Ch while Code0 is the factory 55h: 0Fh, wrong access code. // 000:T26
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x5F, 0x3C]), Some(error(0x40, 0x0F)));
    assert!(s.adopt_access_code(0, 0x3C));
    assert!(!s.adopt_access_code(4, 0x3C), "there is no Code4");
    let writes = s.eeprom_writes();
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x5F, 0x55]), Some(error(0x40, 0x0F)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x55, 0x5F, 0x3C]), Some(sealed(&[0x5F, 0x55])));
    assert_eq!(s.nonvolatile().codes, [0x3C, 0x55, 0x55, 0x55]);
    assert_eq!(s.eeprom_writes(), writes + 1, "only the accepted 55h wrote");
}

/// What a real device's reply says of its world is taken into the model (positions,
/// the preset a synchronised Set Position used), and nothing else; a value outside the
/// range is refused. Nothing is written.
#[test]
fn a_device_s_reply_is_adopted_and_nothing_more() {
    use hiperface_model::response::Response;
    let profile = profiles::srs50();
    let mut s = operational(profile);
    assert!(s.adopt_reply(&Response::Position(0x1234)));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x42]), Some(sealed(&[0x40, 0x42, 0x00, 0x00, 0x12, 0x34])));
    let range = u32::try_from(profile.range()).unwrap();
    assert!(!s.adopt_reply(&Response::Position(range)));
    assert!(s.adopt_reply(&Response::Position(range - 1)));
    assert_eq!(s.position(), u64::from(range - 1));
    assert!(s.adopt_reply(&Response::PositionWithSyncSet(0x50)));
    assert_eq!(s.position(), 0x50);
    assert!(!s.adopt_reply(&Response::PositionWithSyncSet(range)));
    // Read Data's bytes, in a field the device had.
    assert!(s.adopt(&[0x80], 4, 0));
    let data = hiperface_model::frame::FieldBytes::from_bytes(&[9, 8]).unwrap();
    assert!(s.adopt_reply(&Response::Data { field: 0, offset: 2, data }));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 0, 2, 2, 0x55]), Some(sealed(&[0x40, 0x4A, 0, 2, 2, 9, 8])));
    assert!(!s.adopt_reply(&Response::Data { field: 1, offset: 0, data }), "no field 1");
    let before = s.clone();
    assert!(!s.adopt_reply(&Response::EncoderStatus(FaultCode::NoFault)));
    assert!(!s.adopt_reply(&Response::Counter(7)));
    assert_eq!(s, before);
    assert_eq!(s.eeprom_writes(), 0);
}

/// Others-group monitoring before every reply (000:T58, 000:T59): a temperature
/// outside the profile's limits or an LED current above its maximum goes onto the
/// stack (the warning bit of the reply); the limits themselves are inside.
#[test]
fn monitoring_limits_are_inclusive() {
    let p = profiles::srs50();
    let warned = |f: &dyn Fn(&mut hiperface_model::slave::inputs::PhysicalInputs)| {
        let mut s = with_inputs(operational(p), f);
        let reply = ask_sealed(&mut s, &[0x40, 0x46]).unwrap();
        reply[1] & 0x80 != 0
    };
    assert!(!warned(&|i| i.temperature_c = p.temperature_max_c));
    assert!(warned(&|i| i.temperature_c = p.temperature_max_c + 1));
    assert!(!warned(&|i| i.temperature_c = p.temperature_min_c));
    assert!(warned(&|i| i.temperature_c = p.temperature_min_c - 1));
    assert!(!warned(&|i| i.led_current_ma = p.led_current_max_ma));
    assert!(warned(&|i| i.led_current_ma = p.led_current_max_ma + 1));
    // A position command answers the LED current fault, and the speed fault above
    // the data sheet's reading speed, from one past the limit (000:T57, 000:T60).
    let position = |f: &dyn Fn(&mut hiperface_model::slave::inputs::PhysicalInputs)| {
        let mut s = with_inputs(operational(p), f);
        let reply = ask_sealed(&mut s, &[0x40, 0x42]).unwrap();
        (reply[1] & 0x7F == 0x50).then(|| reply[2])
    };
    assert_eq!(position(&|i| i.led_current_ma = p.led_current_max_ma), None);
    let led = FaultCode::LedCurrent.byte();
    assert_eq!(position(&|i| i.led_current_ma = p.led_current_max_ma + 1), Some(led));
    let max = i32::try_from(p.max_read_speed).unwrap();
    assert_eq!(position(&|i| i.speed = max), None);
    assert_eq!(position(&|i| i.speed = -max), None);
    assert_eq!(position(&|i| i.speed = max + 1), Some(FaultCode::Speed.byte()));
    assert_eq!(position(&|i| i.speed = -max - 1), Some(FaultCode::Speed.byte()));
}

/// After an internal checksum error at start-up the commands that list 06h answer it
/// (000:T44, and 57h which T44 names); 05h is acceptable for those that also list it
/// (000:T43). Others are not locked, and without the lock nothing is tolerated.
#[test]
fn the_nonvolatile_lock_answers_06h_where_the_tables_list_it() {
    let locked = || {
        let mut s = Slave::new(profiles::srs50());
        s.power_up_with([hiperface_model::slave::inputs::InitFault::MultiturnParameters], true);
        s
    };
    for body in [&[0x40, 0x55, 0x41, 0x55][..], &[0x40, 0x57, 0xE4, 0x55]] {
        let o = locked().handle_frame(&sealed(body), 0);
        assert_eq!(reply_bytes(&o).map(|r| r[2]), Some(0x06), "{body:02X?}");
        assert!(o.also.contains(FaultCode::I2cBus), "{body:02X?}: 05h acceptable");
    }
    // Read Counter lists 06h but not 05h.
    let o = locked().handle_frame(&sealed(&[0x40, 0x46]), 0);
    assert_eq!(reply_bytes(&o).map(|r| r[2]), Some(0x06));
    assert!(!o.also.contains(FaultCode::I2cBus));
    // Read Type Label lists neither: not locked.
    let o = locked().handle_frame(&sealed(&[0x40, 0x52]), 0);
    assert_eq!(reply_bytes(&o).map(|r| r[1] & 0x7F), Some(0x52));
    let o = operational(profiles::srs50()).handle_frame(&sealed(&[0x40, 0x55, 0x41, 0x55]), 0);
    assert_eq!(reply_bytes(&o), Some(sealed(&[0x41, 0x55])));
    assert!(o.also.is_empty(), "{:?}", o.also);
}

/// An alternative code is never the preferred one itself, and a frame too short to
/// hold a command is not also an unknown command. Exhaustive over the command byte
/// with up to two data bytes from a small set.
#[test]
fn alternatives_exclude_the_preferred_code() {
    let o = operational(profiles::reference()).handle_frame(&[0x40], 0);
    assert_eq!(reply_bytes(&o), Some(error(0x40, 0x0C)));
    assert!(o.also.is_empty(), "{:?}", o.also);
    let data = [0x00, 0x55, 0xFF];
    for command in 0u8..=255 {
        let mut bodies = vec![vec![0x40, command]];
        for a in data {
            bodies.push(vec![0x40, command, a]);
            for b in data {
                bodies.push(vec![0x40, command, a, b]);
            }
        }
        for body in bodies {
            for frame in [sealed(&body), body.clone()] {
                let o = operational(profiles::reference()).handle_frame(&frame, 0);
                match o.reply {
                    Reply::Frame(ResponseFrame { response: Response::Error(code), .. }) => {
                        assert!(!o.also.contains(code), "{frame:02X?}: {code} preferred and also allowed");
                    }
                    // Alternatives are other errors: a request that succeeds has none.
                    _ => assert!(o.also.is_empty(), "{frame:02X?}: {:?}", o.also),
                }
            }
        }
    }
}

/// A condition that holds twice names its code once: deleting a field that is not
/// the last, with other attributes, is 12h for both reasons, and 1Ch is the other
/// applicable code (000:T24, 000:T56).
#[test]
fn a_code_whose_conditions_hold_twice_is_no_alternative_to_itself() {
    let mut s = operational(profiles::kuebler_s36());
    ask_sealed(&mut s, &[0x40, 0x4D, 0, 0xC0, 0x55]).unwrap();
    ask_sealed(&mut s, &[0x40, 0x4D, 1, 0xC0, 0x55]).unwrap();
    let o = s.handle_frame(&sealed(&[0x40, 0x4D, 0, 0x41, 0x55]), 0);
    assert_eq!(reply_bytes(&o), Some(error(0x40, 0x12)));
    assert_eq!(o.also.iter().collect::<Vec<_>>(), vec![FaultCode::WrongArgument]);
}

/// Field FFh is the Extended Type Label only on a device that has one; the numbered
/// fields are ordinary on both (000:T20, 000:2.4.2).
#[test]
fn field_ff_is_the_label_only_where_there_is_one() {
    let mut s = operational(profiles::skm36());
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4D, 0, 0xC0, 0x55]), Some(sealed(&[0x40, 0x4D, 0, 0xC0])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4B, 0, 0, 2, 0x55, 7, 8]), Some(sealed(&[0x40, 0x4B, 0, 0, 2])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4A, 0, 0, 2, 0x55]), Some(sealed(&[0x40, 0x4A, 0, 0, 2, 7, 8])));
    let mut t = operational(profiles::srs50());
    assert_eq!(ask_sealed(&mut t, &[0x40, 0x4C, 0xFF]), Some(error(0x40, 0x12)));
    assert_eq!(ask_sealed(&mut t, &[0x40, 0x4B, 0xFF, 0, 1, 0x55, 0]), Some(error(0x40, 0x12)));
}

/// Growing the last field needs the free blocks: one more than there are is 10h,
/// as many as there are is fine (000:T24, 000:T54).
#[test]
fn the_last_field_grows_into_free_memory_only() {
    let mut s = operational(profiles::kuebler_s36()); // 22 blocks
    let create = |s: &mut hiperface_model::Slave, n: u8, status: u8| ask_sealed(s, &[0x40, 0x4D, n, status, 0x55]);
    assert_eq!(create(&mut s, 0, 0xC7), Some(sealed(&[0x40, 0x4D, 0, 0xC7])));
    assert_eq!(create(&mut s, 1, 0xC7), Some(sealed(&[0x40, 0x4D, 1, 0xC7])));
    assert_eq!(create(&mut s, 2, 0xC0), Some(sealed(&[0x40, 0x4D, 2, 0xC0])));
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 5, 3])));
    assert_eq!(create(&mut s, 2, 0xC6), Some(error(0x40, 0x10)), "7 blocks: 6 more, 5 free");
    assert_eq!(create(&mut s, 2, 0xC5), Some(sealed(&[0x40, 0x4D, 2, 0xC5])), "6 blocks: 5 more");
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4E]), Some(sealed(&[0x40, 0x4E, 0, 3])));
}

/// Sensor Adjustment (6Bh) with an option of the profile answers the option and its
/// status from the data sheet (000:T35).
#[test]
fn sensor_adjustment_answers_the_profile_s_option() {
    let mut s = operational(profiles::reference());
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x6B, 0x01, 0x55]), Some(sealed(&[0x40, 0x6B, 0x01, 0x00])));
    assert_eq!(s.eeprom_writes(), 1);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x6B, 0x02, 0x55]), Some(error(0x40, 0x0D)));
}

/// The counter at FFFFFFh: the current edition refuses to increment it (08h,
/// 000:T46); a legacy device answers and shows the overflow by the warning bit
/// (002:47h).
#[test]
fn an_increment_at_the_counter_s_end() {
    let mut current = operational(profiles::srs50());
    current.set_counter(0xFF_FFFF);
    assert_eq!(ask_sealed(&mut current, &[0x40, 0x47]), Some(error(0x40, 0x08)));
    let mut legacy = operational(profiles::legacy_srs());
    legacy.set_counter(0xFF_FFFF);
    let reply = ask_sealed(&mut legacy, &[0x40, 0x47]).unwrap();
    assert_eq!(reply[..2], [0x40, 0xC7], "{reply:02X?}");
    legacy.set_counter(0xFF_FFFE);
    let mut fresh = operational(profiles::legacy_srs());
    fresh.set_counter(0xFF_FFFE);
    assert_eq!(ask_sealed(&mut fresh, &[0x40, 0x47]).map(|r| r[1]), Some(0x47), "not yet full");
}
