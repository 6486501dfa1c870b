//! The observer moved (`Observer::rebase`, `Observer::forget_recommendations`) as the
//! model checker of the reference master moves it: the musts judged alike.

use super::*;

/// Moving the observer's clock (`Observer::rebase`) and forgetting what only the
/// recommendations read (`Observer::forget_recommendations`), as the model checker of
/// the reference master does where the master decides (proofs/src/master_fixpoint/),
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
