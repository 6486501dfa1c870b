//! The master's obligations (`master::obligations`), checked in virtual time: a master
//! that follows 000 gets no observation, and each way of breaking a rule gets exactly
//! the observation of that rule.

use hiperface_model::datalink::RxChar;
use hiperface_model::master::obligations::{Observation, Observer, Rule, REACTION_REQUESTS, RETRY_BOUND};
use hiperface_model::response::{Response, ResponseFrame};
use hiperface_model::{profiles, FaultCode, Profile};

mod common;
use common::sealed;

const CT: u64 = 1146; // 9600 Bd, 11 bits
const TIMEOUT: u64 = 5730;
const MS: u64 = 1000;

/// A master talking to an encoder, in virtual time.
struct Bus {
    observer: Observer,
    now: u64,
    seen: Vec<Observation>,
}

impl Bus {
    fn new(profile: Profile) -> Bus {
        let mut observer = Observer::new(profile);
        observer.power_on(0);
        Bus { observer, now: 0, seen: Vec::new() }
    }

    fn at(&mut self, t_us: u64) -> &mut Bus {
        self.observer.poll(t_us, &mut |o| self.seen.push(o));
        self.now = self.now.max(t_us);
        self
    }

    /// The master sends `body` (checksum appended unless `raw`) from `now`, characters
    /// back to back with `gaps` (index, extra µs) inserted.
    fn send_raw(&mut self, bytes: &[u8], gaps: &[(usize, u64)]) -> &mut Bus {
        let mut t = self.now;
        for (i, b) in bytes.iter().enumerate() {
            t += CT + gaps.iter().filter(|(at, _)| *at == i).map(|(_, g)| g).sum::<u64>();
            self.observer.master_char(RxChar::ok(*b, t), &mut |o| self.seen.push(o));
        }
        self.now = t;
        self
    }

    fn send(&mut self, body: &[u8]) -> &mut Bus {
        self.send_raw(&sealed(body), &[])
    }

    /// The encoder answers after the timeout (+300 µs), and the master waits for the
    /// reply's end and the timeout.
    fn reply(&mut self, warning: bool, response: Response) -> &mut Bus {
        let start = self.now + TIMEOUT + 300;
        self.at(start);
        let rf = ResponseFrame { address: 0x40, warning, response };
        let end = start + rf.encode().len() as u64 * CT;
        self.observer.encoder_reply(start, end, Some(&rf));
        self.at(end + TIMEOUT)
    }

    /// Request and reply: what a conformant master does each cycle.
    fn ask(&mut self, body: &[u8], response: Response) -> &mut Bus {
        self.send(body).reply(false, response)
    }

    fn wait_ms(&mut self, ms: u64) -> &mut Bus {
        let t = self.now + ms * MS;
        self.at(t)
    }

    fn rules(&mut self) -> Vec<Rule> {
        let t = self.now + 100 * MS;
        self.at(t);
        self.seen.iter().map(|o| o.rule).collect()
    }
}

const POSITION: Response = Response::Position(1234);

/// The start-up flow of 000:3.3.1 and cyclic Read Position.
fn conformant_start(bus: &mut Bus) {
    bus.at(120 * MS)
        .ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault))
        .ask(&[0x40, 0x52], Response::TypeLabel { settings: 0xE4, type_code: 0x22, memory_blocks: 0x70, option: 0 });
    for _ in 0..5 {
        bus.ask(&[0x40, 0x42], POSITION).wait_ms(2);
    }
}

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
    assert_eq!(bus.seen[0].data_rates, Some(DataRates { master_bps: 38400, encoder_bps: 9600 }));
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

/// Where each timing rule's limit lies: at the limit is allowed, a microsecond past it
/// is not, and the figure reported is the measured one.
mod limits {
    use super::*;

    fn observed(run: impl Fn(&mut Bus)) -> Vec<Observation> {
        let mut bus = Bus::new(profiles::srs50());
        run(&mut bus);
        bus.rules();
        bus.seen
    }

    fn rules(run: impl Fn(&mut Bus)) -> Vec<Rule> {
        observed(run).iter().map(|o| o.rule).collect()
    }

    /// The rules broken, each with the figure measured.
    fn figures(run: impl Fn(&mut Bus)) -> Vec<(Rule, Option<u64>)> {
        observed(run).iter().map(|o| (o.rule, o.measured_us)).collect()
    }

    /// The rules broken by Read Encoder Status requests at `times` after power-up.
    fn status_requests_at(times: &[u64]) -> Vec<Rule> {
        rules(|b| {
            for &t in times {
                b.at(t).send(&[0x40, 0x50]);
            }
        })
    }

    /// "Initialization: 100 ms" (000:T9): a request may begin at 100 ms, not before.
    #[test]
    fn initialization() {
        assert_eq!(status_requests_at(&[100 * MS]), vec![]);
        assert_eq!(status_requests_at(&[100 * MS - 1]), vec![Rule::DuringInitialization]);
    }

    /// The settings change (000:T9): quiet from 900 ms to 1100 ms unless a request in
    /// the default window (before 900 ms) kept the defaults.
    #[test]
    fn settings_change_window() {
        assert_eq!(status_requests_at(&[1100 * MS]), vec![]);
        assert_eq!(status_requests_at(&[1100 * MS - 1]), vec![Rule::DuringSettingsChange]);
        // Kept by a request just inside the default window: later ones are fine.
        assert_eq!(status_requests_at(&[900 * MS - 1, 1000 * MS]), vec![]);
        // At 900 ms the window is over: that request and the next are in the change.
        assert_eq!(
            status_requests_at(&[900 * MS, 1000 * MS]),
            vec![Rule::DuringSettingsChange, Rule::DuringSettingsChange]
        );
    }

    /// The reply window: the limit of 42h (10 ms, 000:T10/T12) after the request's
    /// timeout. A request at its end is fine; one earlier breaks it by the difference.
    #[test]
    fn reply_window() {
        let until = |b: &Bus| b.now + TIMEOUT + 10 * MS;
        assert_eq!(
            rules(|b| {
                conformant_start(b);
                b.send(&[0x40, 0x42]);
                b.now = until(b);
                b.send(&[0x40, 0x42]);
            }),
            vec![]
        );
        for early in [1, 500] {
            let seen = figures(|b| {
                conformant_start(b);
                b.send(&[0x40, 0x42]);
                b.now = until(b) - early;
                b.send(&[0x40, 0x42]);
            });
            assert_eq!(seen, vec![(Rule::ReplyWindow, Some(early))]);
        }
    }

    /// Talking over a reply: from its first start bit to its last stop bit. A reply
    /// that began after its window closed may be talked over (the master gave up).
    #[test]
    fn talking_over_a_reply() {
        let reply = |b: &mut Bus, delay: u64| {
            let start = b.now + TIMEOUT + delay;
            let end = start + 7 * CT;
            b.at(start);
            let rf = ResponseFrame { address: 0x40, warning: false, response: POSITION };
            b.observer.encoder_reply(start, end, Some(&rf));
            (start, end)
        };
        assert_eq!(
            rules(|b| {
                conformant_start(b);
                b.send(&[0x40, 0x42]);
                let (_, end) = reply(b, 300);
                b.now = end;
                b.send(&[0x40, 0x42]);
            }),
            vec![]
        );
        let talks = figures(|b| {
            conformant_start(b);
            b.send(&[0x40, 0x42]);
            let (start, _) = reply(b, 300);
            b.now = start + 2 * CT;
            b.send(&[0x40, 0x42]);
        });
        assert_eq!(talks, vec![(Rule::TalksOverReply, Some(2 * CT))]);
        // A reply starting exactly at the window's end is on time: talking over it counts.
        assert_eq!(
            rules(|b| {
                conformant_start(b);
                b.send(&[0x40, 0x42]);
                let (start, _) = reply(b, 10 * MS);
                b.now = start + CT;
                b.send(&[0x40, 0x42]);
            }),
            vec![Rule::TalksOverReply]
        );
        // One microsecond later it is late, and the master may have moved on.
        assert_eq!(
            rules(|b| {
                conformant_start(b);
                b.send(&[0x40, 0x42]);
                let (start, _) = reply(b, 10 * MS + 1);
                b.now = start + CT;
                b.send(&[0x40, 0x42]);
            }),
            vec![]
        );
    }

    /// Cyclic requests: a gap of exactly the polling period between frames' starts is
    /// cyclic; one microsecond more is not. // 000:3.2.2
    #[test]
    fn polling_period() {
        let gap = |extra: u64| {
            rules(move |b| {
                b.observer.set_polling_period_ms(50);
                conformant_start(b);
                let start = b.now;
                b.send(&[0x40, 0x42]);
                b.now = start + 50 * MS + extra;
                b.send(&[0x40, 0x42]);
                b.now += 20 * MS;
                b.send(&[0x40, 0x42]);
            })
        };
        assert_eq!(gap(0), vec![]);
        assert_eq!(gap(1), vec![Rule::NoCyclicRequest]);
    }

    /// A fragment that is no request is judged once the line has been quiet for four
    /// timeouts (it may still be joined by the rest of a request with a gap).
    #[test]
    fn a_lone_fragment_is_judged_after_four_timeouts() {
        let mut bus = Bus::new(profiles::srs50());
        conformant_start(&mut bus);
        bus.send_raw(&[0x40, 0x42], &[]);
        let last = bus.now;
        bus.at(last + 4 * TIMEOUT - 1);
        assert!(bus.seen.is_empty(), "{:?}", bus.seen);
        bus.at(last + 4 * TIMEOUT);
        assert_eq!(bus.seen.iter().map(|o| o.rule).collect::<Vec<_>>(), vec![Rule::Malformed]);
    }

    /// Two requests with no pause: the pause measured is 0 and located where the
    /// second began.
    #[test]
    fn a_missing_pause_is_measured() {
        let pause = figures(|b| {
            conformant_start(b);
            b.send_raw(&[0x40, 0x42, 0x02, 0x40, 0x50, 0x10], &[]);
        });
        assert_eq!(pause, vec![(Rule::NoPause, Some(0))]);
        let later = figures(|b| {
            conformant_start(b);
            b.send_raw(&[0x40, 0x42, 0x02, 0x40, 0x50, 0x10], &[(3, 1000)]);
        });
        assert_eq!(later, vec![(Rule::NoPause, Some(1000))]);
    }

    /// The power-up timeline starts again when the Encoder Reset's frame is over (its
    /// last character and the timeout): a request 950 ms later is in the settings
    /// change, measured from there (000:T9, 000:T34).
    #[test]
    fn the_timeline_after_a_reset_starts_at_the_reset() {
        let seen = figures(|b| {
            conformant_start(b);
            b.send(&[0x40, 0x53]);
            let reset_end = b.now + TIMEOUT;
            b.now = reset_end + 950 * MS;
            b.send(&[0x40, 0x50]);
        });
        assert_eq!(seen, vec![(Rule::DuringSettingsChange, Some(950 * MS))]);
    }

    /// The same failing request may be sent RETRY_BOUND times; once more is unbounded.
    #[test]
    fn retries_are_bounded_at_retry_bound() {
        let run = |sendings: u8| {
            rules(move |b| {
                conformant_start(b);
                for _ in 0..sendings {
                    b.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::Checksum));
                }
            })
        };
        assert_eq!(run(RETRY_BOUND), vec![]);
        assert_eq!(run(RETRY_BOUND + 1), vec![Rule::UnboundedRetry]);
    }

    /// A request with the error bit is only that when it is a request otherwise; with
    /// a wrong checksum it is malformed (000:2.3.2, 000:2.3.3).
    #[test]
    fn the_error_bit_counts_only_in_a_frame_with_a_right_checksum() {
        let with = |checksum_ok: bool| {
            rules(move |b| {
                conformant_start(b);
                let c = hiperface_model::checksum::xor(&[0x40, 0xC2]) ^ u8::from(!checksum_ok);
                b.send_raw(&[0x40, 0xC2, c], &[]);
            })
        };
        assert_eq!(with(true), vec![Rule::ErrorBit]);
        assert_eq!(with(false), vec![Rule::Malformed]);
    }

    /// Requests back to back are found up to the longest frame: a Read Position and a
    /// Store Data of 125 bytes fill 135 bytes; six bytes that are not two requests
    /// are one malformed frame, not a missing pause.
    #[test]
    fn requests_back_to_back_fill_the_longest_frame() {
        let mut store = vec![0x40, 0x4B, 0x00, 0x00, 125, 0x55];
        store.extend([0xA5; 125]);
        store.push(hiperface_model::checksum::xor(&store));
        let mut both = vec![0x40, 0x42, 0x02];
        both.extend(&store);
        assert_eq!(both.len(), hiperface_model::frame::MAX_FRAME);
        let r = rules(|b| {
            conformant_start(b);
            b.send_raw(&both, &[]);
        });
        assert_eq!(r, vec![Rule::NoPause]);
        let r = rules(|b| {
            conformant_start(b);
            b.send_raw(&[0x40, 0x42, 0x03, 0x40, 0x42, 0x03], &[]);
        });
        assert_eq!(r, vec![Rule::Malformed]);
        // A frame ending in a whole request is no stack when what comes before it is
        // no request: the frame is malformed, not two requests without a pause.
        let r = rules(|b| {
            conformant_start(b);
            b.send_raw(&[0x40, 0x42, 0x03, 0x11, 0x40, 0x42, 0x02], &[]);
        });
        assert_eq!(r, vec![Rule::Malformed]);
    }

    /// A critical fault read from the stack wants an Encoder Reset within three other
    /// requests (REACTION_REQUESTS, 000:T74): the third without one is the breach.
    #[test]
    fn the_reset_after_a_critical_fault_is_due_within_three_requests() {
        let run = |requests: usize| {
            rules(move |b| {
                b.at(120 * MS).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::AnalogLimits));
                for _ in 0..requests {
                    b.ask(&[0x40, 0x42], POSITION);
                }
            })
        };
        assert_eq!(REACTION_REQUESTS, 3);
        assert_eq!(run(2), vec![]);
        assert_eq!(run(3), vec![Rule::NoResetAfterCriticalFault]);
        assert_eq!(run(6), vec![Rule::NoResetAfterCriticalFault], "reported once");
    }

    /// A fault whose reaction is "Retry command" that is not a protocol error (a
    /// position fault, 000:T74) asks for the same request again.
    #[test]
    fn a_retry_is_due_after_a_position_fault_too() {
        let r = rules(|b| {
            conformant_start(b);
            b.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::decode(0x1C)));
            b.ask(&[0x40, 0x46], Response::Counter(0));
        });
        assert_eq!(r, vec![Rule::NoRetry]);
    }
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

/// Moving the observer's clock (`Observer::rebase`) and forgetting what only the
/// recommendations read (`Observer::forget_recommendations`), as the model checker of
/// the reference master does where the master decides (proofs/src/master_fixpoint.rs),
/// change no must judged afterwards: each session breaks the same musts, or none, with
/// and without, and at the same times relative to the move.
#[test]
fn a_moved_observer_judges_the_musts_alike() {
    type Part = fn(&mut Bus);
    let cases: [(&str, Part, Part, Option<Rule>); 6] = [
        (
            "talks during initialization",
            |b| {
                b.at(40 * MS);
            },
            |b| {
                b.ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault));
            },
            Some(Rule::DuringInitialization),
        ),
        (
            "first request in the settings change",
            |b| {
                b.at(850 * MS);
            },
            |b| {
                b.wait_ms(100).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::NoFault));
            },
            Some(Rule::DuringSettingsChange),
        ),
        (
            "too soon after Encoder Reset",
            |b| {
                conformant_start(b);
                b.send(&[0x40, 0x53]).wait_ms(30);
            },
            |b| {
                b.send(&[0x40, 0x50]);
            },
            Some(Rule::TooSoonAfterReset),
        ),
        (
            "no pause",
            |b| {
                conformant_start(b);
            },
            |b| {
                b.send_raw(&[0x40, 0x42, 0x02, 0x40, 0x42, 0x02], &[]);
            },
            Some(Rule::NoPause),
        ),
        (
            "talks over the reply",
            |b| {
                conformant_start(b);
                b.send(&[0x40, 0x42]);
                let start = b.now + TIMEOUT + 300;
                let rf = ResponseFrame { address: 0x40, warning: false, response: POSITION };
                b.at(start).observer.encoder_reply(start, start + 7 * CT, Some(&rf));
            },
            |b| {
                b.now += CT;
                b.send(&[0x40, 0x42]);
            },
            Some(Rule::TalksOverReply),
        ),
        (
            "conformant polling",
            |b| {
                conformant_start(b);
                b.wait_ms(500);
            },
            |b| {
                for _ in 0..5 {
                    b.ask(&[0x40, 0x42], POSITION).wait_ms(2);
                }
            },
            None,
        ),
    ];
    let profile = profiles::srs50();
    let musts = |b: &mut Bus, from: u64| -> Vec<(Rule, u64)> {
        let edition = profile.edition;
        b.rules();
        b.seen.iter().filter(|o| o.rule.clause().binding(edition).is_some()).map(|o| (o.rule, o.at_us - from)).collect()
    };
    for (name, before, after, broken) in cases {
        let (mut kept, mut moved) = (Bus::new(profile), Bus::new(profile));
        before(&mut kept);
        before(&mut moved);
        let (now, to) = (kept.now, 10_000_000);
        assert!(to >= moved.observer.look_back_us());
        moved.observer.forget_recommendations();
        moved.observer.rebase(now, to);
        moved.now = to;
        kept.seen.clear();
        moved.seen.clear();
        after(&mut kept);
        after(&mut moved);
        let (k, m) = (musts(&mut kept, now), musts(&mut moved, to));
        assert_eq!(k, m, "{name}");
        assert_eq!(k.first().map(|(r, _)| *r), broken, "{name}: {k:?}");
    }
}
