//! Where each timing rule's limit lies: at the limit is allowed, a microsecond past it
//! is not, and the figure reported is the measured one.

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

/// A reset owed for a critical start-up fault stays owed when a later request draws an
/// error whose reaction is a retry (02h to a locked Read Position): the retries do not
/// postpone it (blind trial HX-M3, d15: a master that reset only once its retries ran
/// out was let through). // 000:T74
#[test]
fn a_reset_owed_is_not_postponed_by_a_later_retry() {
    let run = |reset_after: usize| {
        rules(move |b| {
            b.at(120 * MS).ask(&[0x40, 0x50], Response::EncoderStatus(FaultCode::AnalogLimits));
            b.ask(
                &[0x40, 0x52],
                Response::TypeLabel { settings: 0xE4, type_code: 0x22, memory_blocks: 0x80, option: 0x00 },
            );
            for _ in 0..reset_after {
                b.send(&[0x40, 0x42]).reply(false, Response::Error(FaultCode::AngularOffset));
            }
            b.send(&[0x40, 0x53]);
        })
    };
    assert_eq!(run(1), vec![], "the reset as the third request");
    assert_eq!(run(2), vec![Rule::NoResetAfterCriticalFault], "the reset as the fourth");
}

/// A frame begun while the master's settings changed: it went out at one of the two
/// rates, so only where both are other than the encoder's is the rule broken.
#[test]
fn a_data_rate_changed_as_the_master_sent_is_graded_where_both_are_wrong() {
    let mut o = Observer::new(profiles::srs50());
    let mut seen = Vec::new();
    o.master_data_rate_changing(150 * MS, 9600, 38400, &mut |x| seen.push(x));
    assert!(seen.is_empty(), "9600 Bd may have been the one: {seen:?}");
    o.master_data_rate_changing(160 * MS, 38400, 9600, &mut |x| seen.push(x));
    assert!(seen.is_empty(), "{seen:?}");
    o.master_data_rate_changing(170 * MS, 38400, 19200, &mut |x| seen.push(x));
    let rates = seen.iter().map(|x| (x.rule, x.data_rates)).collect::<Vec<_>>();
    let both = hiperface_model::master::obligations::DataRates {
        master_bps: 19200,
        encoder_bps: 9600,
        changed_from_bps: Some(38400),
    };
    assert_eq!(rates, vec![(Rule::DataRate, Some(both))]);
    o.master_data_rate_changing(180 * MS, 19200, 19200, &mut |x| seen.push(x));
    assert_eq!(seen.last().and_then(|x| x.data_rates.map(|r| r.changed_from_bps)), Some(None), "held still");
}
