//! The master's obligations (`master::obligations`), checked in virtual time: a master
//! that follows 000 gets no observation, and each way of breaking a rule gets exactly
//! the observation of that rule.

use hiperface_model::datalink::RxChar;
use hiperface_model::master::obligations::{Observation, Observer, Rule, REACTION_REQUESTS, RETRY_BOUND};
use hiperface_model::response::{Response, ResponseFrame};
use hiperface_model::{profiles, FaultCode};

#[path = "../common/mod.rs"]
mod common;

mod bus;
mod limits;
mod rebase;

use bus::{conformant_start, Bus, CT, MS, POSITION, TIMEOUT};

#[test]
fn a_conformant_master_gets_no_observation() {
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    // A warning: the codes are read out, then polling goes on.
    bus.send(&[0x40, 0x42]).reply(true, POSITION);
    bus.ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::Temperature));
    bus.ask(&[0x40, 0x42], POSITION);
    // A protocol error: the same request again.
    bus.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::Checksum));
    bus.ask(&[0x40, 0x42], POSITION);
    // Type FFh: the Extended Type Label (field FFh) is read before the position.
    bus.ask(&[0x40, 0x52], Response::TypeLabel { settings: 0xE4, type_code: 0xFF, memory_blocks: 0x70, option: 0 });
    bus.ask(&[0x40, 0x4A, 0xFF, 0x00, 0x40, 0x00], Response::Error(FaultCode::WrongOffset));
    bus.ask(&[0x40, 0x42], POSITION);
    // 06h read with 08h from the stack: "06h + 08h", Minor, no action (000:T74); the
    // master goes on without a reset.
    bus.ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::InternalChecksum));
    bus.ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::CounterOverflow));
    bus.ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault));
    for _ in 0..4 {
        bus.ask(&[0x40, 0x42], POSITION);
    }
    // Encoder Reset, then the timeout plus the initialization time.
    bus.send(&[0x40, 0x53]).wait_ms(6 + 100);
    bus.ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault)).ask(&[0x40, 0x42], POSITION);
    assert_eq!(bus.rules(), vec![]);
}

#[test]
fn each_broken_rule_is_observed() {
    /// (what the master does wrong, the rule, the session)
    type Case = (&'static str, Rule, fn(&mut Bus));
    let cases: Vec<Case> = vec![
        ("talks during initialization", Rule::DuringInitialization, |b| {
            b.at(40 * MS).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault));
        }),
        ("first request in the settings change", Rule::DuringSettingsChange, |b| {
            b.at(950 * MS).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault));
        }),
        ("no pause between requests", Rule::NoPause, |b| {
            conformant_start(b);
            b.send_raw(&[0x40, 0x42, 0x02, 0x40, 0x42, 0x02], &[]);
        }),
        ("gap inside a request", Rule::GapInRequest, |b| {
            conformant_start(b);
            b.send_raw(&[0x40, 0x42, 0x02], &[(2, 8 * MS)]);
        }),
        ("wrong checksum", Rule::Malformed, |b| {
            conformant_start(b);
            b.send_raw(&[0x40, 0x42, 0x03], &[]);
        }),
        ("error bit set", Rule::ErrorBit, |b| {
            conformant_start(b);
            b.send(&[0x40, 0xC2]);
        }),
        ("address byte with a fixed bit wrong", Rule::AddressFormat, |b| {
            conformant_start(b);
            b.send(&[0xC0, 0x42]);
        }),
        ("talks over the reply", Rule::TalksOverReply, |b| {
            conformant_start(b);
            b.send(&[0x40, 0x42]);
            let start = b.now + TIMEOUT + 300;
            let rf = ResponseFrame { address: 0x40, warning: false, response: POSITION };
            b.at(start).observer.encoder_reply(start, start + 7 * CT, Some(&rf));
            b.now = start + CT;
            b.send(&[0x40, 0x42]);
        }),
        ("does not wait for the reply window", Rule::ReplyWindow, |b| {
            conformant_start(b);
            b.send(&[0x40, 0x42]).wait_ms(8).send(&[0x40, 0x42]);
        }),
        ("no wait after Encoder Reset", Rule::TooSoonAfterReset, |b| {
            conformant_start(b);
            b.send(&[0x40, 0x53]).wait_ms(30).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault));
        }),
        ("position before the status", Rule::StatusNotRead, |b| {
            b.at(120 * MS).ask(&[0x40, 0x42], POSITION);
        }),
        ("never reads the warning codes", Rule::WarningIgnored, |b| {
            conformant_start(b);
            for _ in 0..6 {
                b.send(&[0x40, 0x42]).reply(true, POSITION);
            }
        }),
        ("no retry after a protocol error", Rule::NoRetry, |b| {
            conformant_start(b);
            b.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::WrongLength));
            b.ask(&[0x40, 0x46], Response::Counter(0));
        }),
        ("retries without bound", Rule::UnboundedRetry, |b| {
            conformant_start(b);
            for _ in 0..RETRY_BOUND + 4 {
                b.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::Checksum));
            }
        }),
        ("keeps reading position after 22h", Rule::PositionAfterSyncFault, |b| {
            conformant_start(b);
            b.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::MultiturnSync));
            b.ask(&[0x40, 0x42], POSITION);
        }),
        ("no reset after a critical start-up fault", Rule::NoResetAfterCriticalFault, |b| {
            b.at(120 * MS).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::AnalogLimits));
            for _ in 0..4 {
                b.ask(&[0x40, 0x42], POSITION);
            }
        }),
        (
            "no reset after 06h read with 04h (\"06h + 04h\": Critical, SW reset)",
            Rule::NoResetAfterCriticalFault,
            |b| {
                b.at(120 * MS).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::AnalogLimits));
                b.ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::InternalChecksum));
                for _ in 0..4 {
                    b.ask(&[0x40, 0x42], POSITION);
                }
            },
        ),
        ("stops polling for two seconds", Rule::NoCyclicRequest, |b| {
            conformant_start(b);
            b.wait_ms(2000);
            b.ask(&[0x40, 0x42], POSITION);
        }),
        ("type FFh and no Extended Type Label", Rule::ExtendedTypeLabelNotRead, |b| {
            b.at(120 * MS)
                .ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault))
                .ask(
                    &[0x40, 0x52],
                    Response::TypeLabel { settings: 0xE4, type_code: 0xFF, memory_blocks: 0x70, option: 0 },
                )
                .ask(&[0x40, 0x42], POSITION);
        }),
        ("ignores an unknown fault code", Rule::UnknownCodeIgnored, |b| {
            conformant_start(b);
            b.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::Unknown(0x3A)));
            b.ask(&[0x40, 0x42], POSITION);
        }),
    ];
    let mut problems = Vec::new();
    for (name, rule, run) in cases {
        let mut bus = Bus::new(profiles::srs50());
        run(&mut bus);
        let rules = bus.rules();
        if rules != vec![rule] {
            problems.push(format!("{name}: expected [{rule:?}], observed {rules:?}"));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn three_requests_back_to_back_are_two_missing_pauses() {
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    bus.wait_ms(10);
    // 42h, 50h, 42h with no pause between them: one frame of nine characters.
    bus.send_raw(&[0x40, 0x42, 0x02, 0x40, 0x50, 0x10, 0x40, 0x42, 0x02], &[]);
    assert_eq!(bus.rules(), vec![Rule::NoPause, Rule::NoPause], "{:?}", bus.seen);
    assert!(bus.seen.iter().all(|o| o.measured_us == Some(0)));
}

#[test]
fn timing_observations_carry_the_measured_figure() {
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    bus.send_raw(&[0x40, 0x42, 0x02], &[(2, 8 * MS)]);
    bus.rules();
    let gap = bus.seen.iter().find(|o| o.rule == Rule::GapInRequest).and_then(|o| o.measured_us);
    assert_eq!(gap, Some(8 * MS), "the gap between the second and third character");
}

#[test]
fn the_data_rate_is_the_one_the_encoder_listens_at() {
    use hiperface_model::master::obligations::DataRates;
    use hiperface_model::settings::Baud;
    let mut bus = Bus::new(profiles::srs50());
    // Default communication: 9600 Bd is right, 38400 Bd is not (000:3.3.1, 000:T9).
    bus.observer.master_data_rate(150 * MS, 9600, &mut |o| bus.seen.push(o));
    assert!(bus.seen.is_empty(), "{:?}", bus.seen);
    bus.observer.master_data_rate(160 * MS, 38400, &mut |o| bus.seen.push(o));
    assert_eq!(bus.rules(), vec![Rule::DataRate]);
    assert_eq!(
        bus.seen[0].data_rates,
        Some(DataRates { master_bps: 38400, encoder_bps: 9600, changed_from_bps: None })
    );
    // The encoder has gone over to its stored 38400 Bd: now 9600 Bd is wrong.
    let mut stored = hiperface_model::UartSettings::DEFAULT;
    stored.baud = Baud::B38400;
    bus.observer.encoder_listens(stored);
    bus.seen.clear();
    bus.observer.master_data_rate(1200 * MS, 38400, &mut |o| bus.seen.push(o));
    bus.observer.master_data_rate(1300 * MS, 9600, &mut |o| bus.seen.push(o));
    assert_eq!(bus.rules(), vec![Rule::DataRate]);
    assert_eq!(bus.seen[0].at_us, 1300 * MS);
}

#[test]
fn a_gap_in_the_polling_counts_once_and_also_when_it_is_still_open() {
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    let last = bus.now;
    bus.at(last + 900 * MS);
    assert!(bus.seen.is_empty(), "within the period: {:?}", bus.seen);
    // The master falls silent: the observation ends with the gap still open.
    bus.observer.end(last + 3000 * MS, &mut |o| bus.seen.push(o));
    assert_eq!(bus.seen.iter().map(|o| o.rule).collect::<Vec<_>>(), vec![Rule::NoCyclicRequest]);
    assert!(bus.seen[0].measured_us.is_some_and(|g| g > 2900 * MS), "{:?}", bus.seen[0]);
    // The application's own period.
    let mut bus = Bus::new(profiles::srs50());
    bus.observer.set_polling_period_ms(5000);
    conformant_start(&mut bus);
    let last = bus.now;
    bus.observer.end(last + 3000 * MS, &mut |o| bus.seen.push(o));
    assert!(bus.seen.is_empty(), "{:?}", bus.seen);
}

#[test]
fn every_rule_is_in_the_list_of_rules() {
    // An exhaustive match: a new rule does not compile until it has a place here, and
    // the assertion then asks for it in `Rule::ALL`.
    let place = |r: Rule| match r {
        Rule::Malformed => 0,
        Rule::ErrorBit => 1,
        Rule::AddressFormat => 2,
        Rule::GapInRequest => 3,
        Rule::NoPause => 4,
        Rule::TalksOverReply => 5,
        Rule::ReplyWindow => 6,
        Rule::DuringInitialization => 7,
        Rule::TooSoonAfterReset => 8,
        Rule::DuringSettingsChange => 9,
        Rule::StatusNotRead => 10,
        Rule::WarningIgnored => 11,
        Rule::NoRetry => 12,
        Rule::UnboundedRetry => 13,
        Rule::NoResetAfterCriticalFault => 14,
        Rule::PositionAfterSyncFault => 15,
        Rule::UnknownCodeIgnored => 16,
        Rule::ExtendedTypeLabelNotRead => 17,
        Rule::NoCyclicRequest => 18,
        Rule::DataRate => 19,
        Rule::ReadOutsideField => 20,
        Rule::StoreOutsideField => 21,
    };
    for (i, r) in Rule::ALL.iter().enumerate() {
        assert_eq!(place(*r), i, "{r:?}");
    }
}

#[test]
fn must_rules_are_normative_and_should_rules_are_not() {
    use hiperface_model::clause::Force;
    for (rule, normative) in [
        (Rule::Malformed, true),
        (Rule::GapInRequest, true),
        (Rule::NoPause, true),
        (Rule::DuringInitialization, true),
        (Rule::TooSoonAfterReset, true),
        (Rule::DataRate, true),
        (Rule::ReadOutsideField, true),
        (Rule::StoreOutsideField, true),
        (Rule::ReplyWindow, false),
        (Rule::StatusNotRead, false),
        (Rule::WarningIgnored, false),
        (Rule::NoRetry, false),
        (Rule::UnknownCodeIgnored, false),
        (Rule::NoCyclicRequest, false),
    ] {
        assert_eq!(rule.clause().force() == Force::Normative, normative, "{rule:?}");
    }
}

proptest::proptest! {
    /// Any stream of characters, gaps and replies: no panic, and never more
    /// observations than events (each frame start or completion reports a bounded few).
    #[test]
    fn any_master_and_any_encoder(events in proptest::collection::vec((0u8..4, proptest::num::u8::ANY, 0u64..20_000), 0..300)) {
        let mut observer = Observer::new(profiles::srs50());
        let mut seen = 0usize;
        let mut t = 0u64;
        for (kind, byte, gap) in &events {
            t += gap;
            let mut sink = |_: Observation| seen += 1;
            match kind {
                0 => observer.power_on(t),
                1 => {
                    let rf = ResponseFrame { address: 0x40, warning: byte & 1 == 1, response: Response::Error(FaultCode::decode(*byte)) };
                    observer.encoder_reply(t, t + 4 * CT, (byte & 2 == 0).then_some(&rf));
                }
                2 => observer.poll(t, &mut sink),
                _ => observer.master_char(RxChar::ok(*byte, t), &mut sink),
            }
        }
        proptest::prop_assert!(seen <= 4 * events.len() + 4, "{seen} observations for {} events", events.len());
    }
}

#[test]
fn without_a_seen_power_on_the_start_up_rules_are_not_graded() {
    // A drive on a real port: the harness did not see the power-on.
    let mut observer = Observer::new(profiles::srs50());
    let mut seen = Vec::new();
    let mut t = 5 * MS;
    for b in [0x40, 0x42, 0x02] {
        t += CT;
        observer.master_char(RxChar::ok(b, t), &mut |o| seen.push(o));
    }
    observer.poll(t + 100 * MS, &mut |o| seen.push(o));
    assert_eq!(seen, vec![], "no initialization, no status-after-power-on rule");
}

/// The reply window is kept for requests to the encoder's address, which 55h moves:
/// before the observer is told, a request to 5Fh right after another is no breach (5Fh
/// is someone else); after, the same is one, and the old address is someone else's.
/// // 000:T30, 000:2.3.1
#[test]
fn the_reply_window_follows_the_address_the_encoder_answers_at() {
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    bus.send(&[0x5F, 0x42]).wait_ms(8).send(&[0x5F, 0x42]);
    assert_eq!(bus.rules(), vec![]);
    bus.observer.encoder_at(hiperface_model::address::SlaveAddress::new(0x5F).unwrap());
    bus.send(&[0x5F, 0x42]).wait_ms(8).send(&[0x5F, 0x42]);
    assert_eq!(bus.rules(), vec![Rule::ReplyWindow]);
    bus.seen.clear();
    bus.send(&[0x40, 0x42]).wait_ms(8).send(&[0x40, 0x42]);
    assert_eq!(bus.rules(), vec![]);
}

/// Codes read from the stack are judged together: 06h read with 08h is the row
/// "06h + 08h" (Minor, no action, 000:T74), so no reset is due; 06h alone would be
/// Critical with a SW reset.
#[test]
fn a_stacked_pair_is_judged_by_its_own_row() {
    let mut bus = Bus::new(profiles::srs50());
    bus.at(120 * MS)
        .ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::CounterOverflow))
        .ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::InternalChecksum));
    for _ in 0..6 {
        bus.ask(&[0x40, 0x42], POSITION);
    }
    assert_eq!(bus.rules(), vec![]);
    let mut alone = Bus::new(profiles::srs50());
    alone.at(120 * MS).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::InternalChecksum));
    for _ in 0..6 {
        alone.ask(&[0x40, 0x42], POSITION);
    }
    assert_eq!(alone.rules(), vec![Rule::NoResetAfterCriticalFault]);
}

/// An Encoder Reset is the reaction to everything pending: a warning not yet read
/// is not "ignored" after it. // 000:3.3.1, 000:T29
#[test]
fn a_reset_clears_what_was_pending() {
    let run = |reset: bool| {
        let mut bus = Bus::new(profiles::srs50());
        conformant_start(&mut bus);
        bus.send(&[0x40, 0x42]).reply(true, POSITION);
        if reset {
            bus.send(&[0x40, 0x53]).wait_ms(200);
        }
        for _ in 0..6 {
            bus.ask(&[0x40, 0x42], POSITION);
        }
        bus.rules()
    };
    assert_eq!(run(false), vec![Rule::WarningIgnored]);
    assert_eq!(run(true), vec![]);
}

#[test]
fn every_rule_says_what_it_asks_in_its_own_words() {
    let texts: std::collections::BTreeSet<&str> = Rule::ALL.iter().map(|r| r.text()).collect();
    assert_eq!(texts.len(), Rule::ALL.len(), "distinct");
    assert!(texts.iter().all(|t| t.len() > 10 && t.chars().all(|c| c.is_ascii_graphic() || c == ' ' || !c.is_ascii())));
    assert_eq!(Rule::Malformed.text(), "a frame that is no request");
}

/// What the encoder itself answered (`served_reply`, a harness that serves the model):
/// 11h to a Read Data or a Store Data is a request outside its field, on 000:T21 or
/// 000:T22; 11h to another command, or another error to these, is nothing of the kind.
#[test]
fn a_data_field_request_the_encoder_refuses_for_its_offset_is_outside_the_field() {
    use hiperface_model::CommandId;
    let reply = |code| ResponseFrame { address: 0x40, warning: false, response: Response::Error(code) };
    let seen = |command, code| {
        let mut observer = Observer::new(profiles::sek37());
        let mut rules = Vec::new();
        observer.served_reply(command, &reply(code), 7_000, &mut |o: Observation| rules.push((o.rule, o.at_us)));
        rules
    };
    assert_eq!(seen(CommandId::ReadData, FaultCode::WrongOffset), vec![(Rule::ReadOutsideField, 7_000)]);
    assert_eq!(seen(CommandId::StoreData, FaultCode::WrongOffset), vec![(Rule::StoreOutsideField, 7_000)]);
    assert_eq!(Rule::ReadOutsideField.clause().id(), "000:T21");
    assert_eq!(Rule::StoreOutsideField.clause().id(), "000:T22");
    for (command, code) in [
        (CommandId::ReadData, FaultCode::WrongFieldNumber),
        (CommandId::StoreData, FaultCode::WrongAccessCode),
        (CommandId::ReadPosition, FaultCode::WrongOffset),
    ] {
        assert_eq!(seen(command, code), vec![], "{command:?} {code:?}");
    }
}

/// A request sent a character at a time, each after a 10 ms tick (HX-M4's d04): one
/// gap inside a request, not three frames that are no request; and a Store Data in
/// three parts the same. A fragment that cannot grow into a request (its command
/// byte names none) stands alone as before.
#[test]
fn a_request_sent_in_more_than_two_parts_is_a_gap_inside_it() {
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    bus.send_raw(&[0x40, 0x42, 0x02], &[(1, 10 * MS), (2, 10 * MS)]);
    assert_eq!(bus.rules(), vec![Rule::GapInRequest]);
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    let store = common::sealed(&[0x40, 0x4B, 0x01, 0x00, 0x02, 0x55, 0x12, 0x34]);
    bus.send_raw(&store, &[(2, 7 * MS), (5, 7 * MS)]);
    assert_eq!(bus.rules(), vec![Rule::GapInRequest]);
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    bus.send_raw(&[0x40, 0x01], &[]).wait_ms(10).send_raw(&[0x02], &[]);
    assert_eq!(bus.rules(), vec![Rule::Malformed, Rule::Malformed]);
    // Parts as long as the command's request, with a wrong checksum: no longer held.
    let mut bus = Bus::new(profiles::srs50());
    conformant_start(&mut bus);
    bus.send_raw(&[0x40, 0x42], &[]).wait_ms(10).send_raw(&[0x03], &[]);
    assert_eq!(bus.rules(), vec![Rule::Malformed, Rule::Malformed]);
}
