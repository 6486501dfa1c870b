//! The command table (000 Table 10) as the rest of the model reads it: the command
//! byte's bits, the data lengths, and which commands store to EEPROM.

mod common;
use common::*;
use hiperface_model::command::{CommandByte, DataLength};
use hiperface_model::{profiles, CommandId, COMMAND_TABLE};

/// 000:2.3.2: bit 6 always set, bit 7 the error (or warning) bit, the rest the command.
#[test]
fn the_command_byte_is_its_bits() {
    let warned = CommandByte::decode(0xC2).unwrap();
    assert_eq!((warned.id, warned.error_bit), (CommandId::ReadPosition, true));
    let plain = CommandByte::decode(0x42).unwrap();
    assert_eq!((plain.id, plain.error_bit), (CommandId::ReadPosition, false));
    assert_eq!(CommandByte::decode(0x02), None);
    assert_eq!(CommandByte::decode(0x82), None);
    for b in 0u8..=255 {
        if let Some(c) = CommandByte::decode(b) {
            assert_eq!(c.byte(), b);
        }
    }
}

/// A variable length (Read Data's reply, Store Data's request, 000:T8) is a range
/// with both ends included and nothing outside.
#[test]
fn a_length_range_includes_both_ends_only() {
    let r = DataLength::Range { min: 5, max: 8 };
    assert_eq!((4..=9).map(|n| r.accepts(n)).collect::<Vec<_>>(), [false, true, true, true, true, false]);
    assert!(DataLength::Fixed(2).accepts(2) && !DataLength::Fixed(2).accepts(3));
    assert!(!DataLength::NoFrame.accepts(0));
}

/// The table's EEPROM column is what the model does: a command marked as writing
/// counts an EEPROM write when it succeeds, and no other does (the harness caps
/// writes on a real device by this column).
#[test]
fn the_eeprom_column_is_what_the_model_writes() {
    let requests: [&[u8]; 10] = [
        &[0x40, 0x42],
        &[0x40, 0x43, 0, 0, 0, 5, 0x55],
        &[0x40, 0x46],
        &[0x40, 0x47],
        &[0x40, 0x49, 0x55],
        &[0x40, 0x4D, 0x00, 0x80, 0x55],
        &[0x40, 0x4F, 0x01, 0x55, 0x56],
        &[0x40, 0x52],
        &[0x40, 0x57, 0xE4, 0x55],
        &[0x40, 0x67, 0xE4],
    ];
    for body in requests {
        let mut s = operational(profiles::reference());
        let reply = ask_sealed(&mut s, body).unwrap();
        assert_ne!(reply.get(1), Some(&0x50), "{body:02X?} succeeds: {reply:02X?}");
        let id = CommandId::decode(body[1]);
        let spec = COMMAND_TABLE.iter().find(|s| s.id == id).unwrap();
        assert_eq!(s.eeprom_writes() > 0, spec.writes_eeprom(), "{id}");
    }
}
