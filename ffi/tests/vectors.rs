//! The golden vectors read and graded through the C API (hf_vectors_load,
//! hf_vector_start, hf_vector_step, hf_oracle_grade, hf_checksum, hf_table_evaluate)
//! as `hiperface vectors verify` grades them: the worked examples of the documents
//! (001 §5.1.4, all 19, and its two errata, both ways; 002's data-field sequence), every
//! generated vector, with power-on, start-up faults and timed steps, and the printed
//! rows of the master-side tables. The same replay in C: `examples/c/vectors.c`.

use hiperface::*;
use hiperface_suite::vectors;
use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};
use std::ptr::{null, null_mut};

fn path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../vectors").join(name)
}

fn text(chars: &[std::ffi::c_char]) -> String {
    unsafe { CStr::from_ptr(chars.as_ptr()) }.to_string_lossy().into_owned()
}

fn verdict(v: HfVerdict) -> &'static str {
    match v {
        HfVerdict::Pass => "PASS",
        HfVerdict::NonStrict => "NON-STRICT",
        HfVerdict::Fail => "FAIL",
    }
}

/// The header of vector `i` of `set`.
fn header(set: *const HfVectors, i: usize) -> HfVector {
    let mut v = HfVector {
        id: [0; HF_ID_LEN],
        profile: [0; HF_NAME_LEN],
        kind: HfVectorKind::Steps,
        steps: 0,
        expected: HfVerdict::Pass,
    };
    assert_eq!(unsafe { hf_vector_get(set, i, &mut v) }, HfStatus::Ok);
    v
}

/// Vector `i` of `set` replayed through the C API: `Ok` if each step (checksum
/// example, table row) got the verdict the vector expects.
fn through_the_c_api(set: *const HfVectors, i: usize) -> Result<HfVector, String> {
    let v = header(set, i);
    let id = text(&v.id);
    match v.kind {
        HfVectorKind::Steps => {
            let mut slave = null_mut();
            let status = unsafe { hf_vector_start(set, i, null_mut(), 0, &mut slave) };
            if status != HfStatus::Ok {
                return Err(format!("{id}: its setup: {status:?}"));
            }
            let mut result = Ok(v);
            for n in 0..v.steps {
                let mut st = HfVectorStep {
                    at_us: 0,
                    inputs_set: 0,
                    inputs: HfInputs { position: 0, speed: 0, temperature_c: 0, led_current_ma: 0 },
                    uart_fault: false,
                    request: [0; HF_MAX_FRAME],
                    request_len: 0,
                    has_reply: false,
                    reply: [0; HF_MAX_FRAME],
                    reply_len: 0,
                };
                assert_eq!(unsafe { hf_vector_step(set, i, n, &mut st) }, HfStatus::Ok, "{id} step {n}");
                if st.inputs_set != 0 {
                    let mut now = HfInputs { position: 0, speed: 0, temperature_c: 0, led_current_ma: 0 };
                    assert_eq!(unsafe { hf_slave_inputs(slave, &mut now) }, HfStatus::Ok);
                    let set_bit = |b| st.inputs_set & b != 0;
                    if set_bit(HF_INPUT_POSITION) {
                        now.position = st.inputs.position;
                    }
                    if set_bit(HF_INPUT_SPEED) {
                        now.speed = st.inputs.speed;
                    }
                    if set_bit(HF_INPUT_TEMPERATURE) {
                        now.temperature_c = st.inputs.temperature_c;
                    }
                    if set_bit(HF_INPUT_LED_CURRENT) {
                        now.led_current_ma = st.inputs.led_current_ma;
                    }
                    assert_eq!(unsafe { hf_slave_set_inputs(slave, &now) }, HfStatus::Ok);
                }
                let mut g =
                    HfGrade { verdict: HfVerdict::Pass, clause: [0; HF_CLAUSE_LEN], reason: [0; HF_REASON_LEN] };
                let reply = if st.has_reply { st.reply.as_ptr() } else { null() };
                let status = unsafe {
                    hf_oracle_grade(
                        slave,
                        st.request.as_ptr(),
                        st.request_len,
                        st.at_us,
                        reply,
                        st.reply_len,
                        true,
                        st.uart_fault,
                        &mut g,
                    )
                };
                assert_eq!(status, HfStatus::Ok);
                let want = if n + 1 == v.steps { v.expected } else { HfVerdict::Pass };
                if g.verdict != want {
                    result = Err(format!(
                        "{id} step {}: {} [{}] {}; expected {}",
                        n + 1,
                        verdict(g.verdict),
                        text(&g.clause),
                        text(&g.reason),
                        verdict(want)
                    ));
                    break;
                }
            }
            unsafe { hf_slave_free(slave) };
            result
        }
        HfVectorKind::ChecksumExample => {
            let mut c = HfChecksumExample { frame: [0; HF_MAX_FRAME], frame_len: 0, printed: 0 };
            assert_eq!(unsafe { hf_vector_checksum_example(set, i, &mut c) }, HfStatus::Ok);
            let mut sum = 0;
            assert_eq!(unsafe { hf_checksum(c.frame.as_ptr(), c.frame_len, &mut sum) }, HfStatus::Ok);
            let got = if sum == c.printed { HfVerdict::Pass } else { HfVerdict::Fail };
            match got == v.expected {
                true => Ok(v),
                false => Err(format!("{id}: XOR {sum:02X}h, printed {:02X}h", c.printed)),
            }
        }
        HfVectorKind::TableCase => {
            let mut t = HfTableCase { table: [0; HF_NAME_LEN], input: [0; HF_TEXT_LEN], output: [0; HF_TEXT_LEN] };
            assert_eq!(unsafe { hf_vector_table_case(set, i, &mut t) }, HfStatus::Ok);
            let mut answer = [0; HF_TEXT_LEN];
            let status =
                unsafe { hf_table_evaluate(t.table.as_ptr(), t.input.as_ptr(), answer.as_mut_ptr(), answer.len()) };
            let got = if status == HfStatus::Ok && text(&answer) == text(&t.output) {
                HfVerdict::Pass
            } else {
                HfVerdict::Fail
            };
            match got == v.expected {
                true => Ok(v),
                false => Err(format!("{id}: {} `{}` gives `{}`", text(&t.table), text(&t.input), text(&answer))),
            }
        }
    }
}

/// Every vector of the file `name` through the C API and through `vectors verify`'s
/// replay: the same outcome, and every one as the vector says. Returns the ids.
fn replay_file(name: &str) -> Vec<String> {
    let native = vectors::load(&path(name)).unwrap_or_else(|e| panic!("{e}")).vectors;
    let c_path = CString::new(path(name).to_str().unwrap()).unwrap();
    let mut set = null_mut();
    let mut error = [0; 256];
    let status = unsafe { hf_vectors_load(c_path.as_ptr(), &mut set, error.as_mut_ptr(), error.len()) };
    assert_eq!(status, HfStatus::Ok, "{}", text(&error));
    assert_eq!(unsafe { hf_vectors_count(set) }, native.len(), "{name}");
    let mut ids = Vec::new();
    for (i, v) in native.iter().enumerate() {
        let c = through_the_c_api(set, i);
        let n = vectors::replay(v).map_err(|m| m.to_string());
        assert_eq!(c.is_ok(), n.is_ok(), "{}: C API {c:?}, vectors verify {n:?}", v.id);
        let c = c.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(text(&c.id), v.id);
        ids.push(v.id.clone());
    }
    unsafe { hf_vectors_free(set) };
    ids
}

#[test]
fn the_documents_worked_examples_are_graded_as_vectors_verify_grades_them() {
    let ids = replay_file("documents.json");
    // 001 §5.1.4's 19 examples, its two errata as printed, and 002's sequence.
    assert_eq!(ids.iter().filter(|id| id.starts_with("001-")).count(), 21, "{ids:?}");
    assert!(ids.iter().any(|id| id.starts_with("002-")), "{ids:?}");
}

#[test]
fn every_generated_vector_and_table_row_is_graded_as_vectors_verify_grades_it() {
    for name in ["generated-current.json", "generated-legacy.json", "master-tables.json"] {
        let ids = replay_file(name);
        assert!(ids.len() > 100, "{name}: only {} vectors", ids.len());
    }
}

/// The replay catches a vector that is wrong: a reply with one value changed (and its
/// checksum kept right) is not what the vector says, and a printed table answer
/// changed is not the model's.
#[test]
fn a_changed_reply_or_table_answer_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    for (name, change) in [("documents.json", "steps"), ("master-tables.json", "table_case")] {
        let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path(name)).unwrap()).unwrap();
        let test = doc["testGroups"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .flat_map(|g| g["tests"].as_array_mut().unwrap().iter_mut())
            .find(|t| t.get(change).is_some() && t["result"] == "valid")
            .unwrap();
        let id = test["id"].as_str().unwrap().to_string();
        if change == "steps" {
            let last = test["steps"].as_array_mut().unwrap().last_mut().unwrap();
            let mut reply = vectors::parse_hex(last["response"].as_str().unwrap()).unwrap();
            let n = reply.len();
            reply[n - 2] ^= 1;
            reply[n - 1] ^= 1;
            last["response"] = vectors::hex(&reply).into();
        } else {
            test["table_case"]["output"] = "+1 (changed)".into();
        }
        let file = dir.path().join(name);
        std::fs::write(&file, doc.to_string()).unwrap();
        let c_path = CString::new(file.to_str().unwrap()).unwrap();
        let mut set = null_mut();
        assert_eq!(unsafe { hf_vectors_load(c_path.as_ptr(), &mut set, null_mut(), 0) }, HfStatus::Ok);
        let index = (0..unsafe { hf_vectors_count(set) }).find(|&i| text(&header(set, i).id) == id).unwrap();
        let got = through_the_c_api(set, index);
        assert!(got.is_err(), "{name}: {id} changed, still graded as the vector says");
        unsafe { hf_vectors_free(set) };
    }
}

#[test]
fn a_file_that_is_not_a_vector_file_is_an_error_with_the_reason() {
    let mut set = null_mut();
    let mut error = [0; 256];
    let schema = CString::new(path("schema.json").to_str().unwrap()).unwrap();
    let status = unsafe { hf_vectors_load(schema.as_ptr(), &mut set, error.as_mut_ptr(), error.len()) };
    assert_eq!(status, HfStatus::Invalid);
    assert!(text(&error).contains("schema.json"), "{}", text(&error));
    assert!(set.is_null());
    let missing = c"/no/such/vectors.json";
    let status = unsafe { hf_vectors_load(missing.as_ptr(), &mut set, error.as_mut_ptr(), error.len()) };
    assert_eq!(status, HfStatus::Invalid);
    assert!(text(&error).contains("/no/such/vectors.json"), "{}", text(&error));
}
