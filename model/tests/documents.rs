//! The documents' own examples, replayed byte for byte: 000 Table 7, the 19
//! request/response pairs of 001 §5.1.4, and the data-field example of 002.
//! Frames printed with a wrong checksum draw the bad-checksum answer `40 50 0A 1A`.

mod common;
use common::*;
use hiperface_model::{checksum, profiles, Slave};

#[test]
fn table_7_checksum_examples() {
    // 000:T7
    assert_eq!(checksum::xor(&hex("40 42")), 0x02);
    assert_eq!(checksum::xor(&hex("40 4E 70 00")), 0x7E);
}

/// The S36 of 001 in the state each example shows: position 0, 37 °C, counter 0,
/// no data fields, codes 55h.
fn s36() -> Slave {
    with_inputs(operational(profiles::kuebler_s36()), |i| {
        i.position = 0;
        i.temperature_c = 37;
    })
}

/// (example, setup requests, request, expected response) of 001 §5.1.4.
fn s36_examples() -> Vec<(&'static str, Vec<&'static str>, &'static str, Option<&'static str>)> {
    vec![
        ("5.1.4.1 read position", vec![], "40 42 02", Some("40 42 00 00 00 00 02")),
        ("5.1.4.2 set position 0", vec![], "40 43 00 00 00 00 55 56", Some("40 43 03")),
        ("5.1.4.3 read analog 48h", vec![], "40 44 48 4C", Some("40 44 48 00 25 69")),
        ("5.1.4.4 increment counter", vec![], "40 47 07", Some("40 47 07")),
        ("5.1.4.5 read counter", vec![], "40 46 06", Some("40 46 00 00 00 06")),
        ("5.1.4.6 reset counter", vec![], "40 49 55 5C", Some("40 49 09")),
        (
            "5.1.4.7 read data",
            vec!["40 4D 00 C8 55 90"],
            "40 4A 00 00 10 55 4F",
            Some("40 4A 00 00 10 FF FF FF FF FF FF FF FF FF FF FF FF FF FF FF FF 1A"),
        ),
        (
            "5.1.4.8 store data",
            vec!["40 4D 00 C8 55 90"],
            "40 4B 00 00 08 55 FF 00 FF 00 FF 00 FF 00 56",
            Some("40 4B 00 00 08 03"),
        ),
        // 5.1.4.9 is an erratum in the response; see data_field_status_erratum.
        ("5.1.4.10 create data field", vec![], "40 4D 00 C8 55 90", Some("40 4D 00 C8 C5")),
        ("5.1.4.11 memory status", vec![], "40 4E 0E", Some("40 4E 16 00 18")),
        ("5.1.4.12 read encoder status", vec![], "40 50 10", Some("40 50 00 10")),
        ("5.1.4.13 set access code", vec![], "40 4F 02 55 66 3E", Some("40 4F 02 0D")),
        ("5.1.4.14 read type label", vec![], "40 52 12", Some("40 52 E4 22 16 00 C2")),
        ("5.1.4.15 encoder reset", vec![], "40 53 13", None),
        ("5.1.4.16 set encoder address", vec![], "40 55 41 55 01", Some("41 55 14")),
        (
            "5.1.4.17 read version",
            vec![],
            "40 56 16",
            Some(
                "40 56 31 32 33 34 35 36 37 38 39 76 31 2E 30 2E 38 00 00 00 00 00 00 00 00 00 00 00 00 00 00 \
                 31 32 30 37 32 30 31 39 66",
            ),
        ),
        // 5.1.4.18 is an erratum in the request; see set_serial_interface_erratum.
    ]
}

#[test]
fn kuebler_s36_examples_byte_for_byte() {
    let examples = s36_examples();
    assert_eq!(examples.len(), 16);
    for (name, setup, request, response) in examples {
        let mut slave = s36();
        for s in setup {
            assert!(ask(&mut slave, &hex(s)).is_some(), "{name}: setup {s}");
        }
        let got = ask(&mut slave, &hex(request));
        assert_eq!(got, response.map(hex), "{name}");
    }
}

#[test]
fn set_position_with_synchronization_example() {
    // 001 5.1.4.19: preset 0005D2C7h is answered with 0005D2C1h, so the raw position's
    // five LSBs (the sin/cos phase) are 00001b.
    let mut slave = with_inputs(s36(), |i| i.position = 1);
    assert_eq!(ask(&mut slave, &hex("40 6A 00 05 D2 C7 55 6F")), Some(hex("40 6A 00 05 D2 C1 3C")));
    assert_eq!(ask(&mut slave, &hex("40 42 02")), Some(sealed(&hex("40 42 00 05 D2 C1"))));
    // Zero phase shift: Read Synchronization Offset would answer 0 (DESIGN:position).
    assert_eq!(slave.nonvolatile().offset % 32, 0);
}

#[test]
fn data_field_status_erratum() {
    // 001 5.1.4.9 prints the response `40 4C 00 C8 1E`; its checksum should be C4.
    let printed = hex("40 4C 00 C8 1E");
    assert!(!checksum::is_valid(&printed));
    let mut slave = s36();
    ask(&mut slave, &hex("40 4D 00 C8 55 90")).unwrap();
    assert_eq!(ask(&mut slave, &hex("40 4C 00 0C")), Some(hex("40 4C 00 C8 C4")));
}

#[test]
fn set_serial_interface_erratum() {
    // 001 5.1.4.18 prints the request `40 57 E4 55 5C`; A6 is right. The printed frame
    // must draw the bad-checksum answer, and change nothing.
    let mut slave = s36();
    assert_eq!(ask(&mut slave, &hex("40 57 E4 55 5C")), Some(hex("40 50 0A 1A")));
    assert_eq!(slave.eeprom_writes(), 0);
    assert_eq!(ask(&mut slave, &hex("40 57 E4 55 A6")), Some(hex("40 57 E4 F3")));
}

#[test]
fn all_nineteen_s36_pairs_are_covered() {
    // 16 replayed as printed + 6Ah + the two errata.
    assert_eq!(s36_examples().len() + 3, 19);
}

#[test]
fn legacy_data_field_example() {
    // 002: address 40h, codes 0...3 = 55h, 128 bytes free.
    let mut slave = operational(profiles::legacy_srs());
    let steps = [
        ("40 4E 0E", Some("40 4E 08 00 06")),
        ("40 4D 00 C9 55 91", Some("40 4D 00 C9 C4")),
        // Erratum: the printed checksum 69 is wrong (B9 is right).
        ("40 4D 01 E0 55 69", Some("40 50 0A 1A")),
        ("40 4D 01 E0 55 B9", Some("40 4D 01 E0 EC")),
        ("40 4F 02 55 66 3E", Some("40 4F 02 0D")),
        ("40 4B 01 05 02 66 08 15 76", Some("40 4B 01 05 02 0D")),
    ];
    for (request, response) in steps {
        assert_eq!(ask(&mut slave, &hex(request)), response.map(hex), "{request}");
    }
    // Fields 0 (32 bytes) and 1 (16 bytes) take 3 of 8 blocks; the data is there.
    assert_eq!(ask(&mut slave, &hex("40 4E 0E")), Some(sealed(&hex("40 4E 05 02"))));
    assert_eq!(ask_sealed(&mut slave, &hex("40 4A 01 05 02 66")), Some(sealed(&hex("40 4A 01 05 02 08 15"))));
}
