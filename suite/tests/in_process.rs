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
use hiperface_model::{checksum, profiles, Frame, Profile, Slave};
use hiperface_suite::line::frame_encoder::Answer;
use hiperface_suite::slave::{self, Options, Outcome, Report};

/// The reference model as an encoder given frame by frame: the frame's characters are
/// fed to it a character time apart, ending when the frame's last one was received.
struct ModelByFrames {
    slave: Slave,
    /// A defect applied to each reply: (its bytes, its start) rewritten.
    defect: fn(&mut Vec<u8>, &mut u64, &ReceivedFrame),
}

impl ModelByFrames {
    fn new(profile: Profile, defect: fn(&mut Vec<u8>, &mut u64, &ReceivedFrame)) -> ModelByFrames {
        ModelByFrames { slave: Slave::operational(profile), defect }
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
        let Some(t) = step.transmission else {
            // After an Encoder Reset the stored settings again (000:T29), as the frame
            // interface says: the settings an encoder listens with from now on.
            let reset = matches!(step.outcome.reply, Reply::Silent(Silence::Reset));
            let then_settings = step.outcome.then_settings.or(reset.then(|| self.slave.nonvolatile().settings));
            return Answer { then_settings, ..Answer::SILENT };
        };
        let mut reply = t.frame.as_bytes().to_vec();
        let mut start_us = t.earliest_start_us + 300;
        (self.defect)(&mut reply, &mut start_us, f);
        let Some(reply) = Frame::from_bytes(&reply).ok().filter(|r| !r.is_empty()) else { return Answer::SILENT };
        Answer { reply: Some(reply), start_us, then_settings: t.then_settings }
    }
}

fn certify(profile: Profile, defect: fn(&mut Vec<u8>, &mut u64, &ReceivedFrame)) -> Report {
    let mut encoder = ModelByFrames::new(profile, defect);
    let report = slave::in_process(move |f: &ReceivedFrame| encoder.answer(f), profile, &Options::all_allowed());
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

/// Found 2026-11-28, not yet mended: with stored settings other than the default ones
/// (here 19200 Bd), the reference model behind the frame interface FAILs the power-up
/// cases after an Encoder Reset (000:T9, 000:T29, ...) and timing.read-position
/// (000:T12). The harness talks in the default settings in the default window (the
/// model's power-up windows) while the line lets the encoder listen with one
/// `then_settings` per answer: an encoder has no way to say "the default settings in
/// the default window, the stored ones after". The reference is conformant by
/// definition, so these are the harness's false FAILs; the mend (an answer that says
/// the encoder restarts, the line then taking the power-up windows from the profile,
/// in C and Python alike) is issue 58's item 6 (`then_settings` after 53h).
#[test]
#[ignore = "a known false FAIL of the frame interface (issue 58, then_settings after 53h): run with --ignored"]
fn the_reference_passes_with_stored_settings_other_than_the_default() {
    let mut profile = profiles::srs50();
    profile.settings =
        hiperface_model::UartSettings { baud: hiperface_model::settings::Baud::B19200, ..profile.settings };
    let r = certify(profile, conformant);
    assert_eq!(r.outcome(), Outcome::Passed, "{:?}", failing(&r));
}
