//! The documents' own examples, replayed byte for byte from `vectors/documents.json`,
//! the one place they are written: 000 Table 7, the 19 request/response pairs of 001
//! §5.1.4 (two of them printed wrongly: the printed frame is replayed as an invalid
//! vector, the corrected one as valid), and the data-field example of 002. The
//! conformance crate replays the same file with every vector feature; this test reads
//! the subset the documents use and refuses anything else, so nothing is skipped
//! silently, and adds what only the model's inside shows.

mod common;
use common::*;
use hiperface_model::{checksum, profiles, Slave};
use serde_json::Value;

/// Every test of the file, with its group's profile and setup merged in (the file is
/// in Wycheproof's shape: groups of tests that share a profile and a starting state).
fn documents() -> Vec<Value> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../vectors/documents.json");
    let text = std::fs::read_to_string(path).expect("vectors/documents.json");
    let file: Value = serde_json::from_str(&text).expect("JSON");
    let mut tests = Vec::new();
    for group in file["testGroups"].as_array().expect("testGroups") {
        for test in group["tests"].as_array().expect("tests") {
            let mut t = test.clone();
            t["profile"] = group["profile"].clone();
            t["setup"] = group.get("setup").cloned().unwrap_or(Value::Null);
            tests.push(t);
        }
    }
    assert_eq!(file["numberOfTests"].as_u64(), Some(tests.len() as u64));
    tests
}

fn vector(id: &str) -> Value {
    documents().into_iter().find(|v| v["id"] == id).unwrap_or_else(|| panic!("no vector {id}"))
}

/// The slave in the vector's starting state: the profile, operational, with the
/// setup's inputs and requests.
fn start(v: &Value) -> Slave {
    let name = v["profile"].as_str().expect("profile");
    let mut slave = operational(profiles::builtin(name).unwrap_or_else(|| panic!("profile {name}")));
    let setup = v["setup"].as_object().cloned().unwrap_or_default();
    for key in setup.keys() {
        assert!(["inputs", "requests"].contains(&key.as_str()), "{}: setup `{key}` is not replayed here", v["id"]);
    }
    if let Some(inputs) = setup.get("inputs").and_then(Value::as_object) {
        slave = with_inputs(slave, |i| {
            for (k, value) in inputs {
                match k.as_str() {
                    "position" => i.position = value.as_u64().expect("position"),
                    "temperature_c" => i.temperature_c = value.as_i64().expect("temperature") as i16,
                    other => panic!("{}: input `{other}` is not replayed here", v["id"]),
                }
            }
        });
    }
    for r in setup.get("requests").and_then(Value::as_array).into_iter().flatten() {
        assert!(ask(&mut slave, &hex(r.as_str().expect("hex"))).is_some(), "{}: setup {r}", v["id"]);
    }
    slave
}

/// Replay the steps; the slave afterwards. A `valid` vector's responses are the
/// model's; an `invalid` one's last response is what the document printed wrongly, and
/// the model must not produce it.
fn replay(v: &Value) -> Slave {
    let mut slave = start(v);
    let steps = v["steps"].as_array().expect("steps");
    for (n, step) in steps.iter().enumerate() {
        for key in step.as_object().expect("a step").keys() {
            assert!(["request", "response", "note"].contains(&key.as_str()), "{}: step `{key}`", v["id"]);
        }
        let got = ask(&mut slave, &hex(step["request"].as_str().expect("request")));
        let printed = step["response"].as_str().map(hex);
        match (v["result"].as_str(), n + 1 == steps.len()) {
            (Some("invalid"), true) => assert_ne!(got, printed, "{} step {}", v["id"], n + 1),
            (Some("valid" | "invalid"), _) => assert_eq!(got, printed, "{} step {}", v["id"], n + 1),
            (other, _) => panic!("{}: result {other:?} is not replayed here", v["id"]),
        }
    }
    slave
}

#[test]
fn every_document_example_replays_byte_for_byte() {
    let all = documents();
    for v in &all {
        if let Some(c) = v.get("checksum_example") {
            // 000:T7
            let frame = hex(c["frame"].as_str().expect("frame"));
            assert_eq!(vec![checksum::xor(&frame)], hex(c["checksum"].as_str().expect("checksum")), "{}", v["id"]);
        } else {
            replay(v);
        }
    }
    // 000 Table 7's two examples, all 19 pairs of 001 §5.1.4, and 002's example.
    let sections: std::collections::BTreeSet<&str> = all
        .iter()
        .filter_map(|v| v["id"].as_str()?.strip_prefix("001-5.1.4."))
        .filter_map(|rest| rest.split('-').next())
        .collect();
    assert_eq!(sections.len(), 19, "{sections:?}");
    assert_eq!(all.iter().filter(|v| v.get("checksum_example").is_some()).count(), 2);
    assert!(all.iter().any(|v| v["id"] == "002-data-field-example"));
}

#[test]
fn a_wrong_model_answer_is_caught() {
    // The replay compares bytes: an example whose printed response is altered fails.
    let mut v = vector("001-5.1.4.1-read-position");
    v["steps"][0]["response"] = Value::from("40 42 00 00 00 01 03");
    assert!(std::panic::catch_unwind(|| replay(&v)).is_err());
}

#[test]
fn set_position_with_synchronization_keeps_the_phase() {
    // 001 5.1.4.19: preset 0005D2C7h is answered with 0005D2C1h, so the raw position's
    // five LSBs (the sin/cos phase) are 00001b and the offset keeps a zero phase shift:
    // Read Synchronization Offset would answer 0 (DESIGN:position).
    let slave = replay(&vector("001-5.1.4.19-set-position-with-synchronization"));
    assert_eq!(slave.nonvolatile().offset % 32, 0);
}

#[test]
fn set_serial_interface_as_printed_changes_nothing() {
    // 001 5.1.4.18 prints a request with a wrong checksum: it draws 0Ah and must not
    // reach the EEPROM.
    let slave = replay(&vector("001-5.1.4.18-set-serial-interface-as-printed"));
    assert_eq!(slave.eeprom_writes(), 0);
}

#[test]
fn legacy_data_field_example_leaves_the_fields_it_describes() {
    // 002: fields 0 (32 bytes) and 1 (16 bytes) take 3 of 8 blocks; the data is there.
    let mut slave = replay(&vector("002-data-field-example"));
    assert_eq!(ask(&mut slave, &hex("40 4E 0E")), Some(sealed(&hex("40 4E 05 02"))));
    assert_eq!(ask_sealed(&mut slave, &hex("40 4A 01 05 02 66")), Some(sealed(&hex("40 4A 01 05 02 08 15"))));
}
