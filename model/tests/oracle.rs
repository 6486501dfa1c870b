//! The oracle grades answers: PASS, NON-STRICT with a reason, FAIL with a reason,
//! each with its clause.

mod common;
use common::*;
use hiperface_model::oracle::Deviation;
use hiperface_model::{profiles, Grading, Oracle, Slave, Verdict};

/// Grade `observed` for `request` on a copy of `slave`.
fn grade(slave: &Slave, request: &[u8], observed: Option<&[u8]>, grading: Grading) -> hiperface_model::Grade {
    let mut model = slave.clone();
    let expected = model.handle_frame(request, 0);
    Oracle::new(grading).grade(slave, request, 0, &expected, observed)
}

#[test]
fn the_preferred_answer_passes() {
    let s = operational(profiles::srs50());
    let g = grade(&s, &hex("40 42 02"), Some(&hex("40 42 00 00 00 00 02")), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Pass);
    assert_eq!(g.clause(), "000:T12");
    let g = grade(&s, &hex("41 42 03"), None, Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Pass);
}

#[test]
fn another_applicable_error_is_non_strict() {
    let s = operational(profiles::srs50());
    // 55h with a bad address and a bad code: 0Dh preferred, 0Fh acceptable.
    let req = sealed(&[0x40, 0x55, 0x60, 0x00]);
    let g = grade(&s, &req, Some(&error(0x40, 0x0F)), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::NonStrict);
    assert_eq!(g.clause(), "DESIGN:order");
    assert!(matches!(g.deviation(), Some(Deviation::OtherApplicableError { .. })));
    // An error whose condition does not hold fails.
    let g = grade(&s, &req, Some(&error(0x40, 0x12)), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Fail);
}

#[test]
fn defects_fail_with_their_clause() {
    let s = operational(profiles::srs50());
    let req = hex("40 42 02");
    let cases: [(Option<Vec<u8>>, &str); 5] = [
        (Some(hex("40 42 00 00 00 00 03")), "000:2.3.3"),       // wrong checksum
        (Some(sealed(&hex("41 42 00 00 00 00"))), "000:2.3.1"), // wrong address
        (None, "000:T12"),                                      // silence
        (Some(sealed(&hex("40 C2 00 00 00 00"))), "000:2.3.4"), // warning bit never cleared
        (Some(sealed(&hex("40 42 00 00 00 01"))), "000:T12"),   // wrong position
    ];
    for (observed, clause) in cases {
        let g = grade(&s, &req, observed.as_deref(), Grading::Exact);
        assert_eq!((g.verdict(), g.clause().id()), (Verdict::Fail, clause), "{observed:02X?}: {g}");
    }
    // Answering a frame for another address.
    let g = grade(&s, &hex("41 42 03"), Some(&sealed(&hex("41 42 00 00 00 00"))), Grading::Exact);
    assert_eq!(g.deviation(), Some(Deviation::UnexpectedReply));
    // A warning bit missing while the stack holds an entry.
    let hot = with_inputs(s.clone(), |i| i.temperature_c = 150);
    let g = grade(&hot, &req, Some(&hex("40 42 00 00 00 00 02")), Grading::Exact);
    assert_eq!(g.deviation(), Some(Deviation::WarningBitMissing));
}

#[test]
fn physical_values_are_graded_by_range_on_real_devices() {
    let s = operational(profiles::sek37()); // 512 steps
    let req = hex("40 42 02");
    let g = grade(&s, &req, Some(&sealed(&hex("40 42 00 00 01 2C"))), Grading::Range);
    assert_eq!(g.verdict(), Verdict::Pass);
    let g = grade(&s, &req, Some(&sealed(&hex("40 42 00 00 02 00"))), Grading::Range);
    assert_eq!(g.verdict(), Verdict::Fail, "512 is outside 0..512");
    // A stacked temperature warning the model cannot see: NON-STRICT; a stacked
    // protocol error (never stacked, 000:T37): FAIL.
    let g = grade(&s, &hex("40 50 10"), Some(&sealed(&hex("40 50 1E"))), Grading::Range);
    assert_eq!(g.verdict(), Verdict::NonStrict, "{g}");
    let g = grade(&s, &hex("40 50 10"), Some(&sealed(&hex("40 50 0A"))), Grading::Range);
    assert_eq!(g.verdict(), Verdict::Fail, "{g}");
    // An unexpected warning on a real device may be a real fault: NON-STRICT.
    let g = grade(&s, &req, Some(&sealed(&hex("40 C2 00 00 01 2C"))), Grading::Range);
    assert_eq!(g.verdict(), Verdict::NonStrict);
}

#[test]
fn documented_latitudes_are_non_strict() {
    // Read Type Label with the active instead of the stored settings.
    let mut s = operational(profiles::srs50());
    ask_sealed(&mut s, &[0x40, 0x57, 0xE5, 0x55]).unwrap();
    let g = grade(&s, &hex("40 52 12"), Some(&sealed(&[0x40, 0x52, 0xE4, 0x22, 0x80, 0x00])), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::NonStrict, "{g}");
    // A legacy device's shorter Read Version.
    let l = operational(profiles::legacy_srs());
    let mut short = vec![0x40, 0x56];
    short.extend_from_slice(b"123456789v1.012.03.99");
    let short = sealed(&short);
    let g = grade(&l, &hex("40 56 16"), Some(&short), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::NonStrict);
    let c = operational(profiles::srs50());
    assert_eq!(grade(&c, &hex("40 56 16"), Some(&short), Grading::Exact).verdict(), Verdict::Fail);
    // Count 0 in Read Data: 11h preferred, 0Dh acceptable.
    let mut f = operational(profiles::srs50());
    ask_sealed(&mut f, &[0x40, 0x4D, 0, 0xC0, 0x55]).unwrap();
    let req = sealed(&[0x40, 0x4A, 0, 0, 0, 0x55]);
    assert_eq!(grade(&f, &req, Some(&error(0x40, 0x0D)), Grading::Exact).verdict(), Verdict::NonStrict);
}

#[test]
fn an_error_response_to_read_encoder_status_is_recognised() {
    // `40 50 0A 1A` answers a 50h request with a bad checksum; as bytes it is also a
    // status reply. Found by `hiperface vectors verify`.
    let s = operational(profiles::srs50());
    let g = grade(&s, &hex("40 50 11"), Some(&hex("40 50 0A 1A")), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Pass, "{g}");
    let g = grade(&s, &hex("40 50 11"), Some(&hex("40 50 0B 1B")), Grading::Exact);
    assert_eq!(g.verdict(), Verdict::Fail, "{g}");
}

/// Silence where the slave must answer is charged to the state machine's rule within
/// the power-up windows (000:T9; 000:T29's "respond to new requests after initialization
/// time" in the legacy edition) and to the command's own clause after them.
#[test]
fn silence_in_the_power_up_windows_breaks_the_state_machine_rule() {
    let request = hex("40 42 02");
    for (profile, within) in [(profiles::srs50(), "000:T9"), (profiles::legacy_srs(), "000:T29")] {
        let s = Slave::new(profile);
        // In the default window (initialization over at 100 ms, the window open until
        // 900 ms): the slave answers Read Position, and silence breaks 000:T9. The rule
        // holds a little past the switch to the stored settings (100 ms: a slave's clock
        // and a master's may differ), and not a microsecond beyond.
        let switch_us = u64::from(profile.user_settings_ms) * 1000;
        let cases = [
            (300_000, within),
            (switch_us + 50_000, within),
            (switch_us + 99_999, within),
            (switch_us + 100_000, "000:T12"),
            (20_000_000, "000:T12"),
        ];
        for (at_us, clause) in cases {
            let mut model = s.clone();
            let expected = model.handle_frame(&request, at_us);
            let g = Oracle::new(Grading::Exact).grade(&s, &request, at_us, &expected, None);
            assert_eq!((g.verdict(), g.clause().id()), (Verdict::Fail, clause), "{} at {at_us} µs: {g}", profile.name);
        }
    }
}

/// An answer while the slave initializes FAILs on the state machine (000:T9) for a
/// current device and on 000:T29 for a legacy one (000:T9 binds current devices only;
/// HX-4's d13); a frame for another address answered stays the address rule's in
/// either edition.
#[test]
fn an_answer_while_initializing_fails_on_the_editions_rule() {
    let reply = sealed(&hex("40 42 00 00 00 00"));
    for (profile, clause) in [(profiles::srs50(), "000:T9"), (profiles::legacy_srs(), "000:T29")] {
        let s = Slave::new(profile);
        let g = grade(&s, &hex("40 42 02"), Some(&reply), Grading::Range);
        assert_eq!(
            (g.verdict(), g.clause().id(), g.deviation()),
            (Verdict::Fail, clause, Some(Deviation::UnexpectedReply))
        );
        let o = operational(profile);
        let g = grade(&o, &hex("41 42 03"), Some(&sealed(&hex("41 42 00 00 00 00"))), Grading::Range);
        assert_eq!((g.deviation(), g.clause().id()), (Some(Deviation::UnexpectedReply), "000:T5"), "{g}");
    }
}
