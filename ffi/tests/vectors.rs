//! The golden vectors graded through the C API as `hiperface vectors verify` grades
//! them: the worked examples of the documents (001 §5.1.4, all 19, and its two errata,
//! both ways; 002's data-field sequence) and every generated vector the C API can set
//! up (a profile, physical inputs, setup requests; not start-up faults or timed
//! power-up sequences, which the C API does not drive).

use hiperface::*;
use hiperface_conformance::vectors::{self, parse_hex, Expected, Vector};
use std::path::Path;
use std::ptr::null;

/// What the C API says of `v`: `None` where it cannot set the vector up, else whether
/// every step got its expected verdict (the last one the vector's result, the others
/// PASS).
fn through_the_c_api(v: &Vector) -> Option<Result<(), String>> {
    let s = &v.setup;
    let plain = !s.power_on && s.init_faults.is_empty() && s.position_faults.is_empty() && !s.i2c_fault;
    if v.steps.is_empty() || !plain || s.counter.is_some() || v.steps.iter().any(|st| st.at_us.is_some()) {
        return None;
    }
    let name = std::ffi::CString::new(v.profile.as_str()).ok()?;
    let mut slave = std::ptr::null_mut();
    assert_eq!(unsafe { hf_slave_new(name.as_ptr(), &mut slave) }, HfStatus::Ok, "{}", v.profile);
    let set = |slave, i: &vectors::Inputs| {
        let mut now = HfInputs { position: 0, speed: 0, temperature_c: 0, led_current_ma: 0 };
        assert_eq!(unsafe { hf_slave_inputs(slave, &mut now) }, HfStatus::Ok);
        now.position = i.position.unwrap_or(now.position);
        now.speed = i.speed.unwrap_or(now.speed);
        now.temperature_c = i.temperature_c.unwrap_or(now.temperature_c);
        now.led_current_ma = i.led_current_ma.unwrap_or(now.led_current_ma);
        assert_eq!(unsafe { hf_slave_set_inputs(slave, &now) }, HfStatus::Ok);
    };
    if let Some(i) = &s.inputs {
        set(slave, i);
    }
    let mut g = HfGrade { verdict: HfVerdict::Pass, clause: [0; HF_CLAUSE_LEN], reason: [0; HF_REASON_LEN] };
    for r in &s.requests {
        let r = parse_hex(r).unwrap();
        // The setup's requests: the model takes them (their replies are not graded).
        unsafe { hf_oracle_grade(slave, r.as_ptr(), r.len(), 0, null(), 0, true, false, &mut g) };
    }
    let mut result = Ok(());
    for (i, step) in v.steps.iter().enumerate() {
        if let Some(inputs) = &step.inputs {
            set(slave, inputs);
        }
        let request = parse_hex(&step.request).unwrap();
        let reply = step.response.as_deref().map(|r| parse_hex(r).unwrap());
        let (ptr, len) = reply.as_ref().map_or((null(), 0), |r| (r.as_ptr(), r.len()));
        let status = unsafe {
            hf_oracle_grade(slave, request.as_ptr(), request.len(), 0, ptr, len, true, step.uart_fault, &mut g)
        };
        assert_eq!(status, HfStatus::Ok);
        let want = match (i + 1 == v.steps.len(), v.result) {
            (false, _) | (true, Expected::Valid) => HfVerdict::Pass,
            (true, Expected::Acceptable) => HfVerdict::NonStrict,
            (true, Expected::Invalid) => HfVerdict::Fail,
        };
        if g.verdict != want {
            let reason = unsafe { std::ffi::CStr::from_ptr(g.reason.as_ptr()) }.to_string_lossy().into_owned();
            result = Err(format!("step {i}: {:?}, expected {want:?}: {reason}", g.verdict));
            break;
        }
    }
    unsafe { hf_slave_free(slave) };
    Some(result)
}

fn file(name: &str) -> Vec<Vector> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../vectors").join(name);
    vectors::load(&path).unwrap_or_else(|e| panic!("{e}")).vectors
}

#[test]
fn the_documents_worked_examples_are_graded_as_vectors_verify_grades_them() {
    let mut graded = Vec::new();
    for v in file("documents.json") {
        let Some(c) = through_the_c_api(&v) else { continue };
        let native = vectors::replay(&v).map_err(|m| format!("{m:?}"));
        assert_eq!(c.is_ok(), native.is_ok(), "{}: C API {c:?}, vectors verify {native:?}", v.id);
        assert!(c.is_ok(), "{}: {c:?}", v.id);
        graded.push(v.id);
    }
    // 001 §5.1.4's 19 examples, its two errata as printed, and 002's sequence.
    assert_eq!(graded.iter().filter(|id| id.starts_with("001-")).count(), 21, "{graded:?}");
    assert!(graded.iter().any(|id| id.starts_with("002-")), "{graded:?}");
}

#[test]
fn the_generated_vectors_are_graded_as_vectors_verify_grades_them() {
    for name in ["generated-current.json", "generated-legacy.json"] {
        let (mut graded, mut skipped) = (0, 0);
        for v in file(name) {
            let Some(c) = through_the_c_api(&v) else {
                skipped += 1;
                continue;
            };
            let native = vectors::replay(&v).map_err(|m| format!("{m:?}"));
            assert_eq!(c.is_ok(), native.is_ok(), "{}: C API {c:?}, vectors verify {native:?}", v.id);
            assert!(c.is_ok(), "{}: {c:?}", v.id);
            graded += 1;
        }
        eprintln!("{name}: {graded} vectors graded through the C API, {skipped} need a setup it does not drive");
        assert!(graded > 100, "{name}: only {graded} graded");
    }
}
