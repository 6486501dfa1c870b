//! Certification in-process (`slave::in_process`): an encoder given frame by frame
//! runs the whole catalogue in virtual time. Here the adapter itself is checked: the
//! reference model behind the frame interface passes in every built-in profile, and
//! each defect put between it and the line FAILs on its own clause. Independent
//! encoders (written from the specification alone) are certified this way from C
//! (`examples/c/tiny_encoder.c`) and Python (`python/tests`).

mod common;
use common::failing;

use hiperface_model::datalink::{ReceivedFrame, RxChar};
use hiperface_model::slave::{Reply, Silence};
use hiperface_model::{checksum, profiles, Frame, Profile, Slave, UartSettings};
use hiperface_suite::line::frame_encoder::Answer;
use hiperface_suite::slave::{self, Options, Report};
use hiperface_suite::verdict::Outcome;

/// The reference model as an encoder given frame by frame: the frame's characters are
/// fed to it a character time apart, ending when the frame's last one was received.
struct ModelByFrames {
    slave: Slave,
    /// Since an Encoder Reset, until it has said whether it kept the default settings.
    powering: bool,
    /// A defect applied to each reply: (its bytes, its start) rewritten.
    defect: fn(&mut Vec<u8>, &mut u64, &ReceivedFrame),
}

impl ModelByFrames {
    fn new(profile: Profile, defect: fn(&mut Vec<u8>, &mut u64, &ReceivedFrame)) -> ModelByFrames {
        ModelByFrames { slave: Slave::operational(profile), powering: false, defect }
    }

    fn answer(&mut self, f: &ReceivedFrame) -> Answer {
        let ct = self.slave.listening_settings(f.last_us).unwrap_or(self.slave.profile().settings).char_time_us();
        let n = f.char_count as u64;
        let bytes = f.bytes.as_bytes();
        for i in 0..n {
            let byte = bytes.get(i as usize).or(bytes.last()).copied().unwrap_or(0);
            let fault = if i == 0 { f.uart_fault } else { None };
            let at_us = f.last_us - (n - 1 - i) * ct;
            let _ = self.slave.receive(RxChar { byte, at_us, fault });
        }
        let Some(step) = self.slave.poll(f.complete_us) else { return Answer::SILENT };
        // After an Encoder Reset the power-up windows, then the stored settings
        // (000:T9, 000:T29); a request in the default window keeps the default ones.
        if matches!(step.outcome.reply, Reply::Silent(Silence::Reset)) {
            self.powering = true;
            return Answer::restart(self.slave.nonvolatile().settings);
        }
        let kept = self.powering && self.slave.power_up().kept_default;
        self.powering &= !kept;
        let then_settings = step.outcome.then_settings.or(kept.then_some(UartSettings::DEFAULT));
        let Some(t) = step.transmission else { return Answer { then_settings, ..Answer::SILENT } };
        let mut reply = t.frame.as_bytes().to_vec();
        let mut start_us = t.earliest_start_us + 300;
        (self.defect)(&mut reply, &mut start_us, f);
        let Some(reply) = Frame::from_bytes(&reply).ok().filter(|r| !r.is_empty()) else { return Answer::SILENT };
        Answer { reply: Some(reply), start_us, then_settings, restarts: false }
    }
}

fn certify(profile: Profile, defect: fn(&mut Vec<u8>, &mut u64, &ReceivedFrame)) -> Report {
    certify_answers(profile, defect, |a| a)
}

/// As [`certify`], each answer then rewritten by `answers` (a defect of what the
/// encoder says of its UART).
fn certify_answers(
    profile: Profile,
    defect: fn(&mut Vec<u8>, &mut u64, &ReceivedFrame),
    answers: fn(Answer) -> Answer,
) -> Report {
    let mut encoder = ModelByFrames::new(profile, defect);
    let report =
        slave::in_process(move |f: &ReceivedFrame| answers(encoder.answer(f)), profile, &Options::all_allowed());
    // The record plays back to the same verdicts (what `decode` does with report.json).
    let record = report.record.as_ref().expect("the run keeps its record");
    let again = slave::replay(record, |_, _, _| {}).expect("the record plays back");
    let verdicts = |r: &Report| r.cases.iter().map(|c| (c.id, c.verdict)).collect::<Vec<_>>();
    assert_eq!(verdicts(&report), verdicts(&again));
    report
}

fn conformant(_: &mut Vec<u8>, _: &mut u64, _: &ReceivedFrame) {}

#[test]
fn the_reference_behind_the_frame_interface_passes_in_every_profile() {
    for (name, make) in profiles::BUILTIN {
        let r = certify(make(), conformant);
        assert_eq!(r.outcome(), Outcome::Passed, "{name}: {:?} {:?}", r.summary, failing(&r));
        assert!(r.line.contains("frame by frame"), "{}", r.line);
    }
}

#[test]
fn a_checksum_without_the_address_byte_fails_on_2_3_3() {
    let r = certify(profiles::srs50(), |reply, _, _| {
        let n = reply.len() - 1;
        reply[n] = checksum::xor(&reply[1..n]);
    });
    assert_eq!(r.outcome(), Outcome::Failed);
    let fails = failing(&r);
    assert!(fails.iter().any(|f| f == "position.read 000:2.3.3"), "{fails:?}");
    assert!(fails.iter().all(|f| f.ends_with("000:2.3.3")), "only the checksum rule: {fails:?}");
}

#[test]
fn a_reply_that_does_not_wait_for_the_timeout_fails_on_timing() {
    // Start one character time after the request's last character: before the timeout.
    let r = certify(profiles::srs50(), |_, start, f| *start = f.last_us + 1_146);
    assert_eq!(r.outcome(), Outcome::Failed);
    let fails = failing(&r);
    assert!(fails.iter().any(|f| f.starts_with("timing.read-position ")), "{fails:?}");
}

#[test]
fn silence_to_read_position_fails_its_case() {
    let r = certify(profiles::srs50(), |reply, _, f| {
        if f.bytes.as_bytes().get(1) == Some(&0x42) {
            reply.clear();
        }
    });
    assert_eq!(r.outcome(), Outcome::Failed);
    assert!(failing(&r).iter().any(|f| f.starts_with("position.read ")), "{:?}", failing(&r));
}

/// With stored settings other than the default ones (here 19200 Bd) the harness talks
/// in the default settings in the default window after an Encoder Reset (000:T9,
/// 000:T29): the encoder's answer says it restarts, and the line follows the power-up
/// windows of the profile until the answer to a request in the default window keeps
/// the default settings. Before the answer could say so, the reference FAILed here.
#[test]
fn the_reference_passes_with_stored_settings_other_than_the_default() {
    let mut profile = profiles::srs50();
    profile.settings =
        hiperface_model::UartSettings { baud: hiperface_model::settings::Baud::B19200, ..profile.settings };
    let r = certify(profile, conformant);
    assert_eq!(r.outcome(), Outcome::Passed, "{:?}", failing(&r));
}

/// The defect the restart answer lets the harness see: an encoder that comes back
/// from an Encoder Reset listening in its stored settings at once, without the
/// default window of 000:T9, FAILs the power-up cases (and only where 000:T9 or
/// 000:T29 says so).
#[test]
fn an_encoder_that_restarts_in_its_stored_settings_at_once_fails_on_the_power_up_windows() {
    let mut profile = profiles::srs50();
    profile.settings =
        hiperface_model::UartSettings { baud: hiperface_model::settings::Baud::B19200, ..profile.settings };
    let r = certify_answers(profile, conformant, |a| Answer { restarts: false, ..a });
    assert_eq!(r.outcome(), Outcome::Failed);
    let fails = failing(&r);
    assert!(fails.iter().any(|f| f.starts_with("powerup.")), "{fails:?}");
}
