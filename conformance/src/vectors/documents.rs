//! Vectors taken from the documents' own examples, with errata flagged, never fixed
//! silently: 000 Table 7, the 19 request/response pairs of 001 §5.1.4, and the
//! data-field definition example of 002.

use super::{ChecksumExample, Erratum, Flag, Inputs, Outcome, Step, Vector, VectorFile, SCHEMA_VERSION};

const S36: &str = "001_9b88135b33541945.txt";
const LEGACY: &str = "002_e12c1515b772d61c.txt";

fn step(request: &str, response: Option<&str>) -> Step {
    Step {
        at_us: None,
        inputs: None,
        uart_fault: false,
        request: request.into(),
        response: response.map(Into::into),
        note: None,
    }
}

/// The S36 of 001 in the state its examples show: position 0, 37 °C, no fields.
fn s36(section: &str, id: &str, command: &str, clauses: &[&str], meaning: &str) -> Vector {
    let clauses: Vec<&str> = clauses.iter().copied().chain(["001:5.1.4"]).collect();
    let mut v = Vector::new(
        format!("001-{section}-{id}"),
        format!("{S36} §{section}"),
        &clauses,
        "Kuebler-S36-ST",
        command.into(),
        meaning.into(),
    );
    v.setup.inputs = Some(Inputs { position: Some(0), temperature_c: Some(37), ..Inputs::default() });
    v
}

fn with(mut v: Vector, steps: Vec<Step>) -> Vector {
    v.steps = steps;
    v
}

/// (section, id, command, clauses, meaning, request, response) of one printed example.
type Example = (
    &'static str,
    &'static str,
    &'static str,
    &'static [&'static str],
    &'static str,
    &'static str,
    Option<&'static str>,
);

pub fn file() -> VectorFile {
    let mut v = Vec::new();
    for (n, frame, sum) in [(1, "40 42", "02"), (2, "40 4E 70 00", "7E")] {
        v.push(Vector {
            checksum_example: Some(ChecksumExample { frame: frame.into(), checksum: sum.into() }),
            ..Vector::new(
                format!("000-t7-{n}"),
                "000_a065519ffa299c0b.txt Table 7".into(),
                &["000:2.3.3", "000:T7"],
                "SRS50",
                "checksum".into(),
                "XOR of all frame bytes including the address".into(),
            )
        });
    }
    let create_c8 = "40 4D 00 C8 55 90";
    let simple: [Example; 14] = [
        ("5.1.4.1", "read-position", "42h", &["000:T12"], "Read Position at position 0", "40 42 02", Some("40 42 00 00 00 00 02")),
        ("5.1.4.2", "set-position", "43h", &["000:T13"], "Set Position to 0 with Code0 55h", "40 43 00 00 00 00 55 56", Some("40 43 03")),
        ("5.1.4.3", "read-analog", "44h", &["000:T15", "000:T14"], "Temperature channel 48h at 37 °C", "40 44 48 4C", Some("40 44 48 00 25 69")),
        ("5.1.4.4", "increment-counter", "47h", &["000:T17"], "Increment Counter", "40 47 07", Some("40 47 07")),
        ("5.1.4.5", "read-counter", "46h", &["000:T16"], "Read Counter at 0", "40 46 06", Some("40 46 00 00 00 06")),
        ("5.1.4.6", "reset-counter", "49h", &["000:T18"], "Reset Counter with Code0", "40 49 55 5C", Some("40 49 09")),
        ("5.1.4.10", "create-data-field", "4Dh", &["000:T24"], "Create field 0: 16 bytes, Code0 enabled, writable (C8h)", create_c8, Some("40 4D 00 C8 C5")),
        ("5.1.4.11", "memory-status", "4Eh", &["000:T25"], "16h free blocks, no fields", "40 4E 0E", Some("40 4E 16 00 18")),
        ("5.1.4.12", "read-encoder-status", "50h", &["000:T27"], "Empty stack: status 00h", "40 50 10", Some("40 50 00 10")),
        ("5.1.4.13", "set-access-code", "4Fh", &["000:T26"], "Code2 55h -> 66h", "40 4F 02 55 66 3E", Some("40 4F 02 0D")),
        ("5.1.4.14", "read-type-label", "52h", &["000:T28"], "Settings E4h, type 22h, 16h blocks, option 00h", "40 52 12", Some("40 52 E4 22 16 00 C2")),
        ("5.1.4.15", "encoder-reset", "53h", &["000:T29"], "Encoder Reset: no response", "40 53 13", None),
        ("5.1.4.16", "set-encoder-address", "55h", &["000:T30"], "Address 41h: the reply already comes from 41h", "40 55 41 55 01", Some("41 55 14")),
        (
            "5.1.4.17",
            "read-version",
            "56h",
            &["000:T31"],
            "Serial 123456789, firmware v1.0.8, date 12072019 (no dots, against the stated DD.MM.YY)",
            "40 56 16",
            Some("40 56 31 32 33 34 35 36 37 38 39 76 31 2E 30 2E 38 00 00 00 00 00 00 00 00 00 00 00 00 00 00 31 32 30 37 32 30 31 39 66"),
        ),
    ];
    for (section, id, command, clauses, meaning, request, response) in simple {
        v.push(with(s36(section, id, command, clauses, meaning), vec![step(request, response)]));
    }
    let mut read =
        s36("5.1.4.7", "read-data", "4Ah", &["000:T21", "DESIGN:fields"], "16 bytes of a new field read FFh");
    read.setup.requests = vec![create_c8.into()];
    read.steps =
        vec![step("40 4A 00 00 10 55 4F", Some("40 4A 00 00 10 FF FF FF FF FF FF FF FF FF FF FF FF FF FF FF FF 1A"))];
    v.push(read);
    let mut store = s36("5.1.4.8", "store-data", "4Bh", &["000:T22"], "Store 8 bytes at offset 0 of field 0");
    store.setup.requests = vec![create_c8.into()];
    store.steps = vec![step("40 4B 00 00 08 55 FF 00 FF 00 FF 00 FF 00 56", Some("40 4B 00 00 08 03"))];
    v.push(store);
    // 5.1.4.9: the printed response has a wrong checksum.
    let status_erratum = Erratum {
        printed: "40 4C 00 C8 1E".into(),
        corrected: "40 4C 00 C8 C4".into(),
        reason: "the XOR of 40 4C 00 C8 is C4h, not 1Eh".into(),
    };
    let mut status = s36("5.1.4.9", "data-field-status", "4Ch", &["000:T23"], "Status of field 0 (C8h), as corrected");
    status.setup.requests = vec![create_c8.into()];
    status.steps = vec![step("40 4C 00 0C", Some("40 4C 00 C8 C4"))];
    status.flags = vec![Flag::Erratum];
    status.erratum = Some(status_erratum.clone());
    v.push(status.clone());
    status.id = "001-5.1.4.9-data-field-status-as-printed".into();
    status.steps = vec![step("40 4C 00 0C", Some("40 4C 00 C8 1E"))];
    status.result = Outcome::Invalid;
    status.meaning = "The response as printed: a master must reject it (bad checksum)".into();
    v.push(status);
    // 5.1.4.18: the printed request has a wrong checksum.
    let serial_erratum = Erratum {
        printed: "40 57 E4 55 5C".into(),
        corrected: "40 57 E4 55 A6".into(),
        reason: "the XOR of 40 57 E4 55 is A6h, not 5Ch".into(),
    };
    let mut serial = s36("5.1.4.18", "set-serial-interface", "57h", &["000:T32"], "Store settings E4h, as corrected");
    serial.steps = vec![step("40 57 E4 55 A6", Some("40 57 E4 F3"))];
    serial.flags = vec![Flag::Erratum];
    serial.erratum = Some(serial_erratum.clone());
    v.push(serial.clone());
    serial.id = "001-5.1.4.18-set-serial-interface-as-printed".into();
    serial.clauses.push("000:T48".into());
    serial.steps = vec![step("40 57 E4 55 5C", Some("40 50 0A 1A"))];
    serial.flags = vec![Flag::Erratum, Flag::BadChecksum];
    serial.meaning = "The request as printed draws the checksum error 0Ah and changes nothing".into();
    v.push(serial);
    let mut sync = s36(
        "5.1.4.19",
        "set-position-with-synchronization",
        "6Ah",
        &["000:T34", "DESIGN:position"],
        "Preset 0005D2C7h at a raw phase of 1: the preset used keeps the phase (0005D2C1h)",
    );
    sync.setup.inputs = Some(Inputs { position: Some(1), temperature_c: Some(37), ..Inputs::default() });
    sync.steps = vec![step("40 6A 00 05 D2 C7 55 6F", Some("40 6A 00 05 D2 C1 3C"))];
    v.push(sync);

    // 002: the data-field definition example, one sequence.
    let mut seq = vec![
        step("40 4E 0E", Some("40 4E 08 00 06")),
        step("40 4D 00 C9 55 91", Some("40 4D 00 C9 C4")),
        step("40 4D 01 E0 55 69", Some("40 50 0A 1A")),
        step("40 4D 01 E0 55 B9", Some("40 4D 01 E0 EC")),
        step("40 4F 02 55 66 3E", Some("40 4F 02 0D")),
        step("40 4B 01 05 02 66 08 15 76", Some("40 4B 01 05 02 0D")),
    ];
    seq[0].note = Some("8 x 16 bytes free, no data fields".into());
    seq[1].note = Some("field 0: 32 bytes, Code0, code enabled, writable".into());
    seq[2].note = Some("as printed: wrong checksum, so 0Ah".into());
    seq[3].note = Some("corrected: field 1, 16 bytes, Code2, writable".into());
    seq[4].note = Some("Code2 55h -> 66h".into());
    seq[5].note = Some("store 08h 15h at offset 5 of field 1 with code 66h".into());
    v.push(Vector {
        steps: seq,
        flags: vec![Flag::Erratum, Flag::Legacy, Flag::BadChecksum],
        erratum: Some(Erratum {
            printed: "40 4D 01 E0 55 69".into(),
            corrected: "40 4D 01 E0 55 B9".into(),
            reason: "the XOR of 40 4D 01 E0 55 is B9h, not 69h; the status E0h has bit 3 = 0 although the prose says \
                     \"code must be given\" (that would be E8h)"
                .into(),
        }),
        ..Vector::new(
            "002-data-field-example".into(),
            format!("{LEGACY} Example: Data Field Definition"),
            &["000:T25", "000:T24", "000:T26", "000:T22", "000:T48", "002:example"],
            "Legacy-SRS",
            "4Dh".into(),
            "Starting from address 40h, codes 55h and 128 bytes free: two fields, a code change, a store".into(),
        )
    });
    VectorFile {
        schema_version: SCHEMA_VERSION,
        description: "Examples printed in the documents, replayed byte for byte; errata flagged".into(),
        vectors: v,
    }
}
