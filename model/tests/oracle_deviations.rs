//! Each way a device's answer can differ from the model's, graded by the rule that
//! decides it: the deviation named, the verdict, the clause. Complements oracle.rs
//! (the verdict scale and the documents' latitudes) with one test per branch of the
//! oracle, as the mutation run of issue 14 asked for.

mod common;
use common::*;
use hiperface_model::oracle::Deviation;
use hiperface_model::response::{Response, ResponseFrame, Version};
use hiperface_model::{profiles, FaultCode, Grade, Grading, Oracle, Profile, Slave, Verdict};

/// Grade `observed` for the request `body` (checksum added) on a copy of `slave`.
fn grade(slave: &Slave, body: &[u8], observed: &[u8], grading: Grading) -> Grade {
    let request = sealed(body);
    let mut model = slave.clone();
    let expected = model.handle_frame(&request, 0);
    Oracle::new(grading).grade(slave, &request, 0, &expected, Some(observed))
}

/// The bytes of a reply from 40h.
fn reply(response: Response) -> Vec<u8> {
    ResponseFrame { address: 0x40, warning: false, response }.encode().as_bytes().to_vec()
}

fn verdict_and_deviation(g: &Grade) -> (Verdict, Option<Deviation>) {
    (g.verdict(), g.deviation())
}

#[test]
fn a_wrong_error_code_is_named_as_such() {
    // Read Data of a field that does not exist: 12h (000:T56), not 0Dh.
    let s = operational(profiles::srs50());
    let g = grade(&s, &[0x40, 0x4A, 0x07, 0x00, 0x01, 0x55], &error(0x40, 0x0D), Grading::Exact);
    let expected = FaultCode::decode(0x12);
    let found = FaultCode::decode(0x0D);
    assert_eq!(verdict_and_deviation(&g), (Verdict::Fail, Some(Deviation::WrongError { expected, found })), "{g}");
    // The preferred code passes.
    let g = grade(&s, &[0x40, 0x4A, 0x07, 0x00, 0x01, 0x55], &error(0x40, 0x12), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Pass, "{g}");
    // 002 leaves the codes to the data sheet: for a legacy device another error code
    // is NON-STRICT, an error reply is still required.
    let legacy = operational(profiles::legacy_srs());
    let g = grade(&legacy, &[0x40, 0x4A, 0x07, 0x00, 0x01, 0x55], &error(0x40, 0x0D), Grading::Exact);
    assert_eq!(verdict_and_deviation(&g), (Verdict::NonStrict, Some(Deviation::WrongError { expected, found })));
    assert_eq!(g.clause().id(), "002:50h", "{g}");
    let g = grade(&legacy, &[0x40, 0x4A, 0x07, 0x00, 0x01, 0x55], &reply(Response::Position(0)), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Fail, "{g}");
}

#[test]
fn an_error_for_a_request_that_must_succeed_and_a_reply_for_one_that_must_fail() {
    let s = operational(profiles::srs50());
    // Read Position has nothing to refuse: an error is ErrorInsteadOfReply.
    let g = grade(&s, &[0x40, 0x42], &error(0x40, 0x0D), Grading::Range);
    let found = FaultCode::decode(0x0D);
    assert_eq!(verdict_and_deviation(&g), (Verdict::Fail, Some(Deviation::ErrorInsteadOfReply { found })));
    // 55h with a wrong Code0 must be refused (0Fh): an acknowledgement is a FAIL.
    let g = grade(&s, &[0x40, 0x55, 0x41, 0x00], &sealed(&[0x41, 0x55]), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Fail, "{g}");
    let g = grade(&s, &[0x40, 0x46], &reply(Response::Error(FaultCode::decode(0x0F))), Grading::Exact);
    assert!(matches!(g.deviation(), Some(Deviation::ErrorInsteadOfReply { .. })), "{g}");
    let g = grade(&s, &[0x40, 0x49, 0x00], &reply(Response::CounterReset), Grading::Exact);
    let expected = FaultCode::decode(0x0F);
    assert_eq!(verdict_and_deviation(&g), (Verdict::Fail, Some(Deviation::ReplyInsteadOfError { expected })));
}

#[test]
fn the_type_label_with_the_active_settings_is_a_latitude_but_other_fields_are_not() {
    // 57h stored E5h; the device still listens at E4h until reset. // 000:T32
    let mut s = operational(profiles::srs50());
    ask_sealed(&mut s, &[0x40, 0x57, 0xE5, 0x55]).unwrap();
    let label =
        |settings, type_code| reply(Response::TypeLabel { settings, type_code, memory_blocks: 0x80, option: 0 });
    let g = grade(&s, &[0x40, 0x52], &label(0xE4, 0x22), Grading::Exact);
    let active = Deviation::ActiveSettingsInTypeLabel { stored: 0xE5, active: 0xE4 };
    assert_eq!(verdict_and_deviation(&g), (Verdict::NonStrict, Some(active)), "{g}");
    assert_eq!(grade(&s, &[0x40, 0x52], &label(0xE5, 0x22), Grading::Exact).verdict(), Verdict::Pass);
    // Settings that are neither stored nor active, or another type: FAIL.
    assert_eq!(grade(&s, &[0x40, 0x52], &label(0xE6, 0x22), Grading::Exact).verdict(), Verdict::Fail);
    assert_eq!(grade(&s, &[0x40, 0x52], &label(0xE4, 0x23), Grading::Exact).verdict(), Verdict::Fail);
}

/// Read Data: bytes the model knows must match; bytes of a field the device had before
/// the run are its own (PASS); an unwritten field created in the run reads as erased
/// by decision (NON-STRICT when it is not).
#[test]
fn data_field_contents_are_graded_by_what_the_model_knows() {
    let data = |bytes: &[u8]| hiperface_model::frame::FieldBytes::from_bytes(bytes).unwrap();
    let read = [0x40, 0x4A, 0x00, 0x01, 0x02, 0x55];
    let got = |b: &[u8], offset| reply(Response::Data { field: 0, offset, data: data(b) });
    // Adopted: the device had field 0 (16 bytes, no code) before the run.
    let mut adopted = operational(profiles::srs50());
    assert!(adopted.adopt(&[0x80], 4, 0));
    assert_eq!(grade(&adopted, &read, &got(&[0x12, 0x34], 1), Grading::Range).verdict(), Verdict::Pass);
    // The same reply at another offset, or with fewer bytes, is not the reply asked for.
    assert_eq!(grade(&adopted, &read, &got(&[0x12, 0x34], 2), Grading::Range).verdict(), Verdict::Fail);
    assert_eq!(grade(&adopted, &read, &got(&[0x12], 1), Grading::Range).verdict(), Verdict::Fail);
    // Created in the run and never written: FFh expected; other bytes NON-STRICT.
    let mut created = operational(profiles::srs50());
    ask_sealed(&mut created, &[0x40, 0x4D, 0x00, 0xC0, 0x55]).unwrap();
    let g = grade(&created, &read, &got(&[0xFF, 0x00], 1), Grading::Range);
    assert_eq!(verdict_and_deviation(&g), (Verdict::NonStrict, Some(Deviation::UnwrittenContents)), "{g}");
    assert_eq!(grade(&created, &read, &got(&[0xFF, 0xFF], 1), Grading::Range).verdict(), Verdict::Pass);
    // Written in the run: known, so a difference is a FAIL, at any byte.
    ask_sealed(&mut created, &[0x40, 0x4B, 0x00, 0x00, 0x04, 0x55, 1, 2, 3, 4]).unwrap();
    assert_eq!(grade(&created, &read, &got(&[2, 3], 1), Grading::Range).verdict(), Verdict::Pass);
    for wrong in [[2, 4], [3, 3], [1, 2]] {
        let g = grade(&created, &read, &got(&wrong, 1), Grading::Range);
        assert!(matches!(g.deviation(), Some(Deviation::WrongReply { .. })), "{wrong:?}: {g}");
    }
    // Known and unknown bytes in one reply, away from offset 0: byte 3 of the
    // adopted (read-only) field was read in the run, byte 2 is the device's own.
    assert!(adopted.adopt_field_data(0, 3, &[0x77]));
    let read = [0x40, 0x4A, 0x00, 0x02, 0x02, 0x55];
    assert_eq!(grade(&adopted, &read, &got(&[0x12, 0x77], 2), Grading::Range).verdict(), Verdict::Pass);
    let g = grade(&adopted, &read, &got(&[0x12, 0x78], 2), Grading::Range);
    assert!(matches!(g.deviation(), Some(Deviation::WrongReply { .. })), "{g}");
    // The field grown to two blocks, byte 16 written: an erased byte (15) that
    // differs beside a written one that matches is NON-STRICT only.
    ask_sealed(&mut created, &[0x40, 0x4D, 0x00, 0xC1, 0x55]).unwrap();
    ask_sealed(&mut created, &[0x40, 0x4B, 0x00, 0x10, 0x01, 0x55, 0x66]).unwrap();
    let read = [0x40, 0x4A, 0x00, 0x0F, 0x02, 0x55];
    let g = grade(&created, &read, &got(&[0x00, 0x66], 15), Grading::Range);
    assert_eq!(verdict_and_deviation(&g), (Verdict::NonStrict, Some(Deviation::UnwrittenContents)), "{g}");
    // The bytes written before it grew are still known.
    let read = [0x40, 0x4A, 0x00, 0x00, 0x03, 0x55];
    assert_eq!(grade(&created, &read, &got(&[1, 2, 3], 0), Grading::Range).verdict(), Verdict::Pass);
}

/// Values of the physical world on a real device: only what no world allows fails.
#[test]
fn physical_values_fail_only_where_no_world_allows_them() {
    let p = profiles::reference();
    let s = operational(p);
    let range = u32::try_from(p.range()).unwrap();
    let impossible = |g: &Grade| matches!(g.deviation(), Some(Deviation::ImpossibleValue { .. }));
    // Read Analog Value answers the channel asked for; the value is the world's.
    let analog = |channel, value| reply(Response::AnalogValue { channel, value });
    assert_eq!(grade(&s, &[0x40, 0x44, 0x48], &analog(0x48, 0x0019), Grading::Range).verdict(), Verdict::Pass);
    let g = grade(&s, &[0x40, 0x44, 0x48], &analog(0x49, 0x0019), Grading::Range);
    let asked = Deviation::WrongChannel { asked: 0x48, named: 0x49 };
    assert_eq!(verdict_and_deviation(&g), (Verdict::Fail, Some(asked)), "{g}");
    // A temperature outside the data sheet's limits is doubtful without a warning (the
    // harness does not know the temperature), plausible with one (000:T14). 25 degC
    // sent little-endian reads 6400 degC.
    let (min, max) = (p.temperature_min_c, p.temperature_max_c);
    let g = grade(&s, &[0x40, 0x44, 0x48], &analog(0x48, 0x1900), Grading::Range);
    let hot = Deviation::ImplausibleTemperature { celsius: 6400, min, max };
    assert_eq!(verdict_and_deviation(&g), (Verdict::NonStrict, Some(hot)), "{g}");
    let at = |v: i16| analog(0x48, v as u16);
    assert_eq!(grade(&s, &[0x40, 0x44, 0x48], &at(max), Grading::Range).verdict(), Verdict::Pass);
    assert_eq!(grade(&s, &[0x40, 0x44, 0x48], &at(min), Grading::Range).verdict(), Verdict::Pass);
    assert_eq!(grade(&s, &[0x40, 0x44, 0x48], &at(min - 1), Grading::Range).verdict(), Verdict::NonStrict);
    let warned = ResponseFrame {
        address: 0x40,
        warning: true,
        response: Response::AnalogValue { channel: 0x48, value: 0x1900 },
    };
    let g = grade(&s, &[0x40, 0x44, 0x48], warned.encode().as_bytes(), Grading::Range);
    assert_ne!(g.deviation(), Some(hot), "{g}");
    // Read Sync Offset: 0...31. // 000:T36
    let offset = |v| reply(Response::SyncOffset(v));
    assert_eq!(grade(&s, &[0x40, 0x6C], &offset(31), Grading::Range).verdict(), Verdict::Pass);
    assert!(impossible(&grade(&s, &[0x40, 0x6C], &offset(32), Grading::Range)));
    // Set Position with Synchronization: within 16 steps of the preset, either side,
    // across the range's end too; never outside the range.
    let set = |preset: u32| {
        let mut body = vec![0x40, 0x6A];
        body.extend(preset.to_be_bytes());
        body.push(0x55);
        body
    };
    let used = |v| reply(Response::PositionWithSyncSet(v));
    for preset in [1000, 2, range - 3] {
        // The model's own answer (the preset on its synchronisation grid).
        let x = match ResponseFrame::decode(&ask_sealed(&mut s.clone(), &set(preset)).unwrap(), set_cmd()) {
            Ok(ResponseFrame { response: Response::PositionWithSyncSet(x), .. }) => i64::from(x),
            r => panic!("{r:?}"),
        };
        for delta in [-17i64, -16, 0, 16, 17] {
            let v = u32::try_from((x + i64::from(range) + delta) % i64::from(range)).unwrap();
            let g = grade(&s, &set(preset), &used(v), Grading::Range);
            let ok = delta.abs() <= 16;
            assert_eq!(g.verdict() == Verdict::Pass, ok, "preset {preset}, model {x}, used {v}: {g}");
            assert_eq!(impossible(&g), !ok, "preset {preset}, used {v}: {g}");
        }
        assert!(impossible(&grade(&s, &set(preset), &used(range), Grading::Range)));
    }
    // Graded exactly (the built-in encoder), a different value is a wrong reply.
    let g = grade(&s, &[0x40, 0x6C], &offset(31), Grading::Exact);
    assert!(matches!(g.deviation(), Some(Deviation::WrongReply { .. })), "{g}");
}

fn set_cmd() -> hiperface_model::CommandId {
    hiperface_model::CommandId::SetPositionWithSync
}

fn version_of(profile: &Profile) -> Version {
    let mut s = operational(*profile);
    let bytes = ask_sealed(&mut s, &[0x40, 0x56]).unwrap();
    match ResponseFrame::decode(&bytes, hiperface_model::CommandId::ReadVersion).unwrap().response {
        Response::Version(v) => v,
        r => panic!("{r:?}"),
    }
}

/// Read Version of a real device: pinned fields exact, the rest by form (000:T31).
#[test]
fn a_version_is_graded_by_its_pins_and_its_form() {
    let mut p = profiles::srs50();
    let ours = version_of(&p);
    let grade_version =
        |p: &Profile, v: Version| grade(&operational(*p), &[0x40, 0x56], &reply(Response::Version(v)), Grading::Range);
    // Unpinned: another serial number, firmware and date of the right form pass.
    let mut other = ours;
    other.serial = *b"987654321";
    other.firmware = [0; 20];
    other.firmware[..4].copy_from_slice(b"v2.1");
    other.date = *b"31.12.25";
    assert_eq!(grade_version(&p, other).verdict(), Verdict::Pass);
    // Pinned: each field exact, and only the pinned one is checked.
    for (field, pin) in [("serial number", 0), ("firmware version", 1), ("firmware date", 2)] {
        p.version_pins = Default::default();
        match pin {
            0 => p.version_pins.serial = true,
            1 => p.version_pins.firmware = true,
            _ => p.version_pins.date = true,
        }
        let g = grade_version(&p, other);
        assert_eq!(verdict_and_deviation(&g), (Verdict::Fail, Some(Deviation::VersionDiffers { field })), "{g}");
        assert_eq!(grade_version(&p, ours).verdict(), Verdict::Pass, "{field}");
    }
    p.version_pins = Default::default();
    // The built-in encoder is graded exactly: another serial number is a wrong reply.
    let exact = grade(&operational(p), &[0x40, 0x56], &reply(Response::Version(other)), Grading::Exact);
    assert!(matches!(exact.deviation(), Some(Deviation::WrongReply { .. })), "{exact}");
    // Form: NON-STRICT, naming the field and the problem.
    let form = |v: Version| match grade_version(&p, v).deviation() {
        Some(Deviation::VersionForm { field, problem }) => Some((field, problem)),
        _ => None,
    };
    let mut v = other;
    v.serial[3] = 0x07;
    assert_eq!(form(v), Some(("serial number", "is not ASCII text")));
    let mut v = other;
    v.serial[3] = 0xC4;
    assert_eq!(form(v).map(|f| f.0), Some("serial number"));
    let mut v = other;
    v.firmware[1] = 0x1B;
    assert_eq!(form(v), Some(("firmware version", "is not ASCII text")));
    let mut v = other;
    v.firmware[10] = b'x';
    assert_eq!(form(v), Some(("firmware version", "has text after its trailing 00h characters")));
    let mut full = other;
    full.firmware = *b"firmware 20 chars ok";
    assert_eq!(form(full), None, "no padding at all is fine");
    for date in [*b"31-12-25", *b"3a.12.25", *b"31.1x.25", *b"31.12.2x"] {
        let mut v = other;
        v.date = date;
        assert_eq!(form(v).map(|f| f.0), Some("firmware date"), "{}", String::from_utf8_lossy(&date));
    }
}

#[test]
fn an_unexpected_warning_bit_fails_only_when_graded_exactly() {
    let s = operational(profiles::srs50());
    let warned = sealed(&[0x40, 0xC2, 0, 0, 0, 0]);
    let g = grade(&s, &[0x40, 0x42], &warned, Grading::Exact);
    assert_eq!(verdict_and_deviation(&g), (Verdict::Fail, Some(Deviation::WarningBitUnexpected)));
    let g = grade(&s, &[0x40, 0x42], &warned, Grading::Range);
    assert_eq!(verdict_and_deviation(&g), (Verdict::NonStrict, Some(Deviation::WarningBitUnexpected)));
    // A content FAIL is not hidden behind a NON-STRICT warning bit.
    let g = grade(&s, &[0x40, 0x46], &sealed(&[0x40, 0xC6, 0, 0, 9]), Grading::Range);
    assert_eq!(g.verdict(), Verdict::Fail, "{g}");
    // A NON-STRICT content with a missing warning bit: the FAIL wins.
    let hot = with_inputs(operational(profiles::srs50()), |i| i.temperature_c = 150);
    let g = grade(&hot, &[0x40, 0x42], &sealed(&[0x40, 0x42, 0, 0, 0, 1]), Grading::Range);
    assert_eq!(verdict_and_deviation(&g), (Verdict::Fail, Some(Deviation::WarningBitMissing)), "{g}");
}

#[test]
fn names_of_verdicts_gradings_grades_and_deviations() {
    assert_eq!(
        [Verdict::Pass, Verdict::NonStrict, Verdict::Fail].map(|v| v.to_string()),
        ["PASS", "NON-STRICT", "FAIL"]
    );
    assert_eq!("exact".parse::<Grading>(), Ok(Grading::Exact));
    assert_eq!("range".parse::<Grading>(), Ok(Grading::Range));
    let e = "loose".parse::<Grading>().unwrap_err();
    assert!(e.to_string().contains("exact") && e.to_string().contains("range"), "{e}");
    let s = operational(profiles::srs50());
    let g = grade(&s, &[0x40, 0x42], &error(0x40, 0x0D), Grading::Exact);
    let text = g.to_string();
    assert!(text.contains("FAIL") && text.contains("000:T12"), "{text}");
    let d = g.deviation().unwrap().to_string();
    assert!(!d.is_empty() && text.contains(&d), "{text} / {d}");
}
