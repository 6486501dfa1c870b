//! The C API from Rust: what it answers is what the model answers, and no input
//! (null pointers, short buffers, any bytes) makes it misbehave. The same API from C:
//! `scripts/c-examples.sh`.

use hiperface::*;
use hiperface_model::{profiles, RequestFrame, RxChar, Slave};
use proptest::prelude::*;
use std::ptr::{null, null_mut};

/// A transmission to be written by `hf_slave_poll`.
fn no_transmission() -> HfTransmission {
    HfTransmission {
        frame: [0; HF_MAX_FRAME],
        len: 0,
        earliest_start_us: 0,
        latest_start_us: 0,
        settings: HfUartSettings { byte: 0, bits_per_second: 0 },
    }
}

fn new_slave(profile: &str) -> *mut HfSlave {
    let name = std::ffi::CString::new(profile).unwrap();
    let mut s = null_mut();
    assert_eq!(unsafe { hf_slave_new(name.as_ptr(), &mut s) }, HfStatus::Ok);
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Decoding agrees with the model's decoder, byte for byte.
    #[test]
    fn decode_agrees_with_the_model(bytes in proptest::collection::vec(any::<u8>(), 0..140)) {
        let mut out = HfRequest { address: 0, command: 0, data_len: 0, data: [0; HF_MAX_REQUEST_DATA] };
        let mut code = 0u8;
        let status = unsafe { hf_request_decode(bytes.as_ptr(), bytes.len(), &mut out, &mut code) };
        match RequestFrame::decode(&bytes) {
            Ok(rf) => {
                prop_assert_eq!(status, HfStatus::Ok);
                prop_assert_eq!((out.address, out.command), (rf.address.byte(), rf.request.command().byte()));
                prop_assert_eq!(&out.data[..out.data_len], &bytes[2..bytes.len() - 1]);
            }
            Err(_) => {
                prop_assert_eq!(status, HfStatus::Invalid);
                prop_assert!([0x0A, 0x0B, 0x0C].contains(&code), "{:02X}", code);
            }
        }
    }

    /// The slave through the API transmits what the model transmits, when it does.
    #[test]
    fn the_slave_answers_as_the_model(chars in proptest::collection::vec((any::<u8>(), 0u64..20_000, 0u8..5), 1..40)) {
        let s = new_slave("SRS50");
        let mut model = Slave::operational(profiles::srs50());
        let mut t = 0;
        for (byte, gap, fault) in chars {
            t += gap;
            prop_assert_eq!(unsafe { hf_slave_receive(s, byte, t, fault) }, HfStatus::Ok);
            let uart = [None, Some(hiperface_model::UartFault::Parity), Some(hiperface_model::UartFault::Framing),
                        Some(hiperface_model::UartFault::Noise), Some(hiperface_model::UartFault::Overrun)][fault as usize];
            let mut expected = model.receive(RxChar { byte, at_us: t, fault: uart });
            let mut tx = no_transmission();
            let got = unsafe { hf_slave_poll(s, t, &mut tx) };
            if expected.is_none() {
                expected = model.poll(t);
            }
            match expected.and_then(|e| e.transmission) {
                Some(e) => {
                    prop_assert_eq!(got, HfStatus::Ok);
                    prop_assert_eq!(&tx.frame[..tx.len], e.frame.as_bytes());
                    prop_assert_eq!((tx.earliest_start_us, tx.latest_start_us), (e.earliest_start_us, e.latest_start_us));
                    prop_assert_eq!((tx.settings.byte, tx.settings.bits_per_second),
                                    (e.settings.byte(), e.settings.baud.bits_per_second()));
                }
                None => prop_assert_eq!(got, HfStatus::Nothing),
            }
        }
        unsafe { hf_slave_free(s) };
    }

    /// Powered on through the API, the slave keeps the model's power-up sequence
    /// (000:T9): it listens when and how the model listens, its next deadline is the
    /// model's, and it answers as the model does, at any instant a firmware asks.
    #[test]
    fn a_slave_powered_on_keeps_the_model_s_power_up_sequence(
        on_us in 0u64..1_000_000,
        chars in proptest::collection::vec((any::<u8>(), 0u64..400_000), 0..30),
        profile in proptest::sample::select(vec!["SRS50", "SEK37", "Legacy-SRS"]),
    ) {
        let s = new_slave(profile);
        let p = hiperface_model::profiles::builtin(profile).unwrap();
        let mut model = Slave::new(p);
        model.power_cycle(on_us);
        prop_assert_eq!(unsafe { hf_slave_power_on(s, on_us) }, HfStatus::Ok);
        let mut t = on_us;
        for (byte, gap) in chars {
            t += gap;
            // Before the character: the model's settings and deadline at this instant.
            let mut settings = HfUartSettings { byte: 0, bits_per_second: 0 };
            let listening = unsafe { hf_slave_listening(s, t, &mut settings) };
            match model.listening_settings(t) {
                Some(m) => prop_assert_eq!((listening, settings), (HfStatus::Ok, m.into())),
                None => prop_assert_eq!(listening, HfStatus::Nothing),
            }
            let mut due = 0u64;
            let got = unsafe { hf_slave_next_deadline(s, t, &mut due) };
            match model.next_deadline(t) {
                Some(m) => prop_assert_eq!((got, due), (HfStatus::Ok, m)),
                None => prop_assert_eq!(got, HfStatus::Nothing),
            }
            prop_assert_eq!(unsafe { hf_slave_receive(s, byte, t, 0) }, HfStatus::Ok);
            let expected = model.receive(RxChar { byte, at_us: t, fault: None });
            // A character that closed a frame makes the slave due at once.
            if expected.is_some() {
                prop_assert_eq!(unsafe { hf_slave_next_deadline(s, t, &mut due) }, HfStatus::Ok);
                prop_assert_eq!(due, t);
            }
            let mut tx = no_transmission();
            let polled = unsafe { hf_slave_poll(s, t, &mut tx) };
            match expected.or_else(|| model.poll(t)).and_then(|e| e.transmission) {
                Some(e) => {
                    prop_assert_eq!(polled, HfStatus::Ok);
                    prop_assert_eq!(&tx.frame[..tx.len], e.frame.as_bytes());
                }
                None => prop_assert_eq!(polled, HfStatus::Nothing),
            }
        }
        unsafe { hf_slave_free(s) };
    }

    /// Any request and any reply: a grade with a NUL-terminated clause and reason.
    #[test]
    fn any_exchange_is_graded(request in proptest::collection::vec(any::<u8>(), 0..12),
                              reply in proptest::option::of(proptest::collection::vec(any::<u8>(), 0..12)),
                              exact in any::<bool>()) {
        let s = new_slave("SEK37");
        let mut g = HfGrade { verdict: HfVerdict::Pass, clause: [1; HF_CLAUSE_LEN], reason: [1; HF_REASON_LEN] };
        let (ptr, len) = reply.as_ref().map_or((null(), 0), |r| (r.as_ptr(), r.len()));
        let status = unsafe { hf_oracle_grade(s, request.as_ptr(), request.len(), 10_000, ptr, len, exact, false, &mut g) };
        prop_assert_eq!(status, HfStatus::Ok);
        prop_assert!(g.clause.contains(&0) && g.reason.contains(&0));
        unsafe { hf_slave_free(s) };
    }
}

/// A reply the model itself gives PASSes; one with a wrong checksum FAILs on 000:2.3.3.
#[test]
fn the_oracle_passes_the_models_reply_and_fails_a_wrong_checksum() {
    let s = new_slave("SRS50");
    let request = [0x40, 0x50, 0x10];
    let mut model = Slave::operational(profiles::srs50());
    let reply = match model.handle_frame(&request, 10_000).reply {
        hiperface_model::Reply::Frame(f) => f.encode().as_bytes().to_vec(),
        other => panic!("{other:?}"),
    };
    let grade = |reply: &[u8]| {
        let mut g = HfGrade { verdict: HfVerdict::Pass, clause: [0; HF_CLAUSE_LEN], reason: [0; HF_REASON_LEN] };
        assert_eq!(
            unsafe {
                hf_oracle_grade(s, request.as_ptr(), 3, 10_000, reply.as_ptr(), reply.len(), false, false, &mut g)
            },
            HfStatus::Ok
        );
        let text =
            |b: &[std::ffi::c_char]| unsafe { std::ffi::CStr::from_ptr(b.as_ptr()) }.to_string_lossy().into_owned();
        (g.verdict, text(&g.clause), text(&g.reason))
    };
    assert_eq!(grade(&reply).0, HfVerdict::Pass);
    let mut wrong = reply.clone();
    *wrong.last_mut().unwrap() ^= 1;
    let (verdict, clause, reason) = grade(&wrong);
    assert_eq!((verdict, clause.as_str()), (HfVerdict::Fail, "000:2.3.3"), "{reason}");
    unsafe { hf_slave_free(s) };
}

/// Storage given by the caller: too small or misaligned is refused, the right size
/// holds a working slave.
#[test]
fn a_slave_in_the_callers_storage() {
    let name = c"SRS50";
    let mut s = null_mut();
    let mut storage = vec![0u64; hf_slave_size() / 8 + 2];
    let base = storage.as_mut_ptr().cast::<std::ffi::c_void>();
    assert_eq!(unsafe { hf_slave_init(base, 8, name.as_ptr(), &mut s) }, HfStatus::ShortBuffer);
    let odd = unsafe { base.cast::<u8>().add(1) }.cast();
    assert_eq!(unsafe { hf_slave_init(odd, hf_slave_size(), name.as_ptr(), &mut s) }, HfStatus::ShortBuffer);
    assert_eq!(unsafe { hf_slave_init(base, hf_slave_size(), c"nope".as_ptr(), &mut s) }, HfStatus::UnknownProfile);
    assert_eq!(unsafe { hf_slave_init(base, hf_slave_size(), name.as_ptr(), &mut s) }, HfStatus::Ok);
    let mut tx = no_transmission();
    for (i, b) in [0x40u8, 0x50, 0x10].into_iter().enumerate() {
        assert_eq!(unsafe { hf_slave_receive(s, b, 1_000 + i as u64 * 1_146, 0) }, HfStatus::Ok);
    }
    assert_eq!(unsafe { hf_slave_poll(s, 1_000_000, &mut tx) }, HfStatus::Ok);
    assert_eq!(&tx.frame[..2], &[0x40, 0x50], "Read Encoder Status answered");
    assert_eq!(unsafe { hf_slave_receive(s, 0x40, 2_000_000, 9) }, HfStatus::Invalid, "no such UART fault");
}

/// The checksum helpers agree with 000:2.3.3's example (40 42 -> 02).
#[test]
fn frame_helpers() {
    let mut frame = [0x40u8, 0x42, 0];
    let mut n = 0;
    assert_eq!(unsafe { hf_frame_seal(frame.as_mut_ptr(), 2, 3, &mut n) }, HfStatus::Ok);
    assert_eq!((frame, n), ([0x40, 0x42, 0x02], 3));
    assert!(unsafe { hf_frame_is_valid(frame.as_ptr(), 3) });
    assert_eq!(unsafe { hf_frame_seal(frame.as_mut_ptr(), 3, 3, &mut n) }, HfStatus::ShortBuffer);
    let mut sum = 0;
    assert_eq!(unsafe { hf_checksum(frame.as_ptr(), 2, &mut sum) }, HfStatus::Ok);
    assert_eq!(sum, 0x02);
    assert_eq!(unsafe { hf_checksum(null(), 2, &mut sum) }, HfStatus::Null);
}

/// What a slave answers to a few requests, through the C API.
fn answers(s: *mut HfSlave) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let mut t = 1_000_000;
    // Read Position, Read Encoder Status, Read Type, Read Serial Number, Read Data.
    for request in
        [&[0x40u8, 0x42][..], &[0x40, 0x50], &[0x40, 0x52], &[0x40, 0x53], &[0x40, 0x4A, 0x00, 0x00, 0x10, 0x55]]
    {
        let mut frame = request.to_vec();
        frame.push(hiperface_model::checksum::xor(request));
        for b in frame {
            t += 1_146;
            assert_eq!(unsafe { hf_slave_receive(s, b, t, 0) }, HfStatus::Ok);
        }
        t += 1_000_000;
        let mut tx = no_transmission();
        let got = unsafe { hf_slave_poll(s, t, &mut tx) };
        out.push(if got == HfStatus::Ok { tx.frame[..tx.len].to_vec() } else { Vec::new() });
    }
    out
}

/// A copy answers as its source, and is a slave of its own: changing one leaves the
/// other as it was. Storage that is the source itself, too small or null is refused.
#[test]
fn a_copy_of_a_slave() {
    let s = new_slave("SRS50");
    let moved = HfInputs { position: 12_345, speed: 0, temperature_c: 40, led_current_ma: 10 };
    assert_eq!(unsafe { hf_slave_set_inputs(s, &moved) }, HfStatus::Ok);
    let mut storage = vec![0u64; hf_slave_size() / 8 + 1];
    let base = storage.as_mut_ptr().cast::<std::ffi::c_void>();
    let mut c = null_mut();
    assert_eq!(unsafe { hf_slave_copy(s, base, 8, &mut c) }, HfStatus::ShortBuffer);
    assert_eq!(unsafe { hf_slave_copy(s, s.cast(), hf_slave_size(), &mut c) }, HfStatus::Invalid);
    assert_eq!(unsafe { hf_slave_copy(null(), base, hf_slave_size(), &mut c) }, HfStatus::Null);
    assert_eq!(unsafe { hf_slave_copy(s, base, hf_slave_size(), &mut c) }, HfStatus::Ok);
    let mut inputs = HfInputs { position: 0, speed: 0, temperature_c: 0, led_current_ma: 0 };
    assert_eq!(unsafe { hf_slave_inputs(c, &mut inputs) }, HfStatus::Ok);
    assert_eq!(inputs, moved);
    let fresh = new_slave("SRS50");
    let (from_source, from_copy, from_fresh) = (answers(s), answers(c), answers(fresh));
    assert_eq!(from_copy, from_source);
    assert_ne!(from_copy[0], from_fresh[0], "the copy's position is its source's, not a fresh slave's");
    let still = HfInputs { position: 1, ..moved };
    assert_eq!(unsafe { hf_slave_set_inputs(c, &still) }, HfStatus::Ok);
    assert_eq!(unsafe { hf_slave_inputs(s, &mut inputs) }, HfStatus::Ok);
    assert_eq!(inputs.position, moved.position, "the source unchanged");
    unsafe { hf_slave_free(s) };
    unsafe { hf_slave_free(fresh) };
}

/// A slave of a profile's TOML text (as `hiperface export-profile` writes it)
/// answers as the built-in slave of that profile; a text that is not a profile is an
/// error naming the line and the field.
#[test]
fn a_slave_of_a_profiles_toml_text() {
    for (name, make) in profiles::BUILTIN {
        let toml = std::ffi::CString::new(hiperface_suite::profile_file::to_toml(&make())).unwrap();
        let mut s = null_mut();
        let mut error = [0 as std::ffi::c_char; 256];
        let status =
            unsafe { hf_slave_from_toml(toml.as_ptr(), null_mut(), 0, &mut s, error.as_mut_ptr(), error.len()) };
        let why = unsafe { std::ffi::CStr::from_ptr(error.as_ptr()) }.to_string_lossy().into_owned();
        assert_eq!(status, HfStatus::Ok, "{name}: {why}");
        let builtin = new_slave(name);
        assert_eq!(answers(s), answers(builtin), "{name}");
        unsafe { hf_slave_free(s) };
        unsafe { hf_slave_free(builtin) };
    }
    let srs50 = hiperface_suite::profile_file::to_toml(&profiles::srs50());
    let broken = std::ffi::CString::new(srs50.replace("address = 0x40", "address = 0x99")).unwrap();
    assert_ne!(broken.as_bytes(), srs50.as_bytes(), "the test changes the address line");
    let mut storage = vec![0u64; hf_slave_size() / 8 + 1];
    let mut s = null_mut();
    let mut error = [0 as std::ffi::c_char; 256];
    let status = unsafe {
        hf_slave_from_toml(
            broken.as_ptr(),
            storage.as_mut_ptr().cast(),
            hf_slave_size(),
            &mut s,
            error.as_mut_ptr(),
            error.len(),
        )
    };
    let why = unsafe { std::ffi::CStr::from_ptr(error.as_ptr()) }.to_string_lossy().into_owned();
    assert_eq!(status, HfStatus::Invalid);
    assert!(why.contains("address") && why.contains("profile:"), "{why}");
}

#[test]
fn every_enum_has_its_name_and_any_other_value_a_question_mark() {
    use std::ffi::{c_int, CStr};
    let text = |p: *const std::ffi::c_char| unsafe { CStr::from_ptr(p) }.to_str().unwrap().to_string();
    let verdicts: Vec<_> = (0..3).map(|v| text(hf_verdict_name(v))).collect();
    assert_eq!(verdicts, ["PASS", "NON-STRICT", "FAIL"]);
    let statuses: Vec<_> = (0..6).map(|v| text(hf_status_name(v))).collect();
    assert_eq!(statuses, ["OK", "NULL", "SHORT_BUFFER", "INVALID", "UNKNOWN_PROFILE", "NOTHING"]);
    let faults: Vec<_> = (0..5).map(|v| text(hf_fault_name(v))).collect();
    assert_eq!(faults, ["NONE", "PARITY", "FRAMING", "NOISE", "OVERRUN"]);
    let kinds: Vec<_> = (0..3).map(|v| text(hf_vector_kind_name(v))).collect();
    assert_eq!(kinds, ["STEPS", "CHECKSUM_EXAMPLE", "TABLE_CASE"]);
    assert_eq!(text(hf_status_name(HfStatus::ShortBuffer as c_int)), "SHORT_BUFFER");
    for other in [-1, 3, 6, 7, c_int::MAX, c_int::MIN] {
        let names = [hf_verdict_name(other), hf_fault_name(other.max(5)), hf_status_name(other.max(6))];
        assert!(names.iter().all(|&n| text(n) == "?"), "{other}");
    }
    assert_eq!(text(hf_vector_kind_name(-1)), "?");
}
