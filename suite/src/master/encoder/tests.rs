//! The tests of the encoder: the timeline's judgments of what the harness's or the
//! machine's timing could explain, and the hooks on a late read and a UART fault.

use super::*;
use hiperface_model::datalink::UartFault;
use hiperface_model::master::obligations::{Observation, Rule};
use hiperface_model::{RequestFrame, Slave};

fn observation(rule: Rule, at_us: u64, measured_us: u64) -> Observation {
    Observation { rule, at_us, measured_us: Some(measured_us), command: None, data_rates: None }
}

#[test]
fn a_late_request_from_a_master_process_that_waited_as_long_for_a_processor_is_not_proven() {
    let p = hiperface_model::profiles::srs50();
    let timeout = UartSettings::DEFAULT.timeout_us(p.edition);
    // The first request 32.8 ms into the settings-change window (seen under load).
    let late = observation(Rule::DuringSettingsChange, 932_810, 932_810);
    let mut t = Timeline::default();
    assert_eq!(t.master_slowed(&late, timeout, &p, 1_000_000), None, "not measured: it stands");
    // The master's process waited 5 ms for a processor since it started: it stands.
    t.master_waited = vec![(100_000, 2_000), (935_000, 5_000)];
    assert_eq!(t.master_slowed(&late, timeout, &p, 1_000_000), None);
    // It waited 600 ms (a busy machine): a master on time may have been pushed there.
    t.master_waited = vec![(100_000, 90_000), (935_000, 600_000)];
    assert_eq!(t.master_slowed(&late, timeout, &p, 1_000_000), Some(600_000));
    // A gap in the polling: only the wait within the gap counts.
    let gap = observation(Rule::NoCyclicRequest, 2_000_000, 1_200_000);
    t.master_waited = vec![(1_990_000, 500_000), (3_300_000, 520_000)];
    assert_eq!(t.master_slowed(&gap, timeout, &p, 1_000_000), None, "20 ms waited, 200 ms over");
    t.master_waited = vec![(1_990_000, 500_000), (3_300_000, 750_000)];
    assert_eq!(t.master_slowed(&gap, timeout, &p, 1_000_000), Some(250_000));
    // Rules a slow master cannot break (too early) always stand.
    assert_eq!(t.master_slowed(&observation(Rule::NoPause, 2_000_000, 0), timeout, &p, 1_000_000), None);
}

/// A master process on a processor the hypervisor stopped stops with it without
/// waiting for a processor: its run delay does not show the pause, the sentinels do.
/// Seen as a gap inside a request from the master image under QEMU.
#[test]
fn a_request_in_two_parts_while_a_processor_stopped_as_long_is_not_proven() {
    let p = hiperface_model::profiles::srs50();
    let timeout = UartSettings::DEFAULT.timeout_us(p.edition);
    // Two parts 7.3 ms apart: 1.57 ms over the timeout.
    let gap = observation(Rule::GapInRequest, 2_000_000, 7_300);
    let mut t = Timeline { master_waited: vec![(1_995_000, 40_000), (2_010_000, 40_200)], ..Default::default() };
    assert_eq!(t.master_slowed(&gap, timeout, &p, 1_000_000), None, "0.2 ms waited: it stands");
    // A processor stopped 1.2 ms within the gap: with the 0.2 ms waited, short of 1.57.
    t.host_paused = vec![(1_995_000, 9_000), (2_010_000, 10_200)];
    assert_eq!(t.master_slowed(&gap, timeout, &p, 1_000_000), None, "1.4 ms in all: it stands");
    // Stopped 7.1 ms within it: the gap may be the machine's.
    t.host_paused = vec![(1_995_000, 9_000), (2_010_000, 16_100)];
    assert_eq!(t.master_slowed(&gap, timeout, &p, 1_000_000), Some(7_300));
    // A pause outside the gap's samples explains nothing.
    t.host_paused = vec![(1_000_000, 0), (1_995_000, 9_000), (2_010_000, 9_000), (2_500_000, 16_100)];
    assert_eq!(t.master_slowed(&gap, timeout, &p, 1_000_000), None);
    // Nor a rule a slow master cannot break.
    t.host_paused = vec![(1_995_000, 0), (2_010_000, 100_000)];
    assert_eq!(t.master_slowed(&observation(Rule::NoPause, 2_000_000, 0), timeout, &p, 1_000_000), None);
}

#[test]
fn a_rule_broken_by_less_than_the_harness_was_late_is_not_proven() {
    let p = hiperface_model::profiles::srs50();
    let timeout = UartSettings::DEFAULT.timeout_us(p.edition);
    let ct = UartSettings::DEFAULT.char_time_us();
    let no_pause = observation(Rule::NoPause, 100_000, 0);
    // Read attentively: the two requests came together; the FAIL stands.
    let mut t = Timeline::default();
    t.late_chars.push((100_000 - ct, 800));
    assert_eq!(t.unproven(&no_pause, timeout, &p), None);
    // The first read after 12 ms unwatched: it may have come that much earlier, and
    // the pause after it been longer than the timeout.
    t.late_chars.push((100_000 - ct, 12_000));
    assert_eq!(t.unproven(&no_pause, timeout, &p), Some(12_000));
    // A pause of 3 ms measured, the first request read after 2 ms unwatched: at
    // most 5 ms, under the timeout; it stands.
    let short = observation(Rule::NoPause, 100_000, 3_000);
    let mut t = Timeline::default();
    t.late_chars.push((100_000 - 3_000 - ct, 2_000));
    assert_eq!(t.unproven(&short, timeout, &p), None);
    // A gap of 8 ms inside a request, the second fragment read after 1 ms
    // unwatched: it was at least 7 ms, over the timeout; it stands.
    let gap = observation(Rule::GapInRequest, 200_000, 8_000);
    let mut t = Timeline::default();
    t.late_chars.push((200_000 + 8_000 + 2 * ct, 1_000));
    assert_eq!(t.unproven(&gap, timeout, &p), None);
    // Read after 4 ms unwatched: it may have been 4 ms, under the timeout.
    t.late_chars.push((200_000 + 8_000 + 2 * ct, 4_000));
    assert_eq!(t.unproven(&gap, timeout, &p), Some(4_000));
    // Rules about order, not time, always stand.
    assert_eq!(t.unproven(&observation(Rule::StatusNotRead, 200_000, 0), timeout, &p), None);
    // A talk-over by 1 ms, a character of the request read 30 default character
    // times after it began, after 5 ms unwatched: past the longest request at the
    // default rate, so it stands; where the encoder listened at 600 Bd (000:T28) a
    // request stretches 16 times as far, and the late read may be its own.
    let talk = observation(Rule::TalksOverReply, 300_000, 1_000);
    let mut t = Timeline::default();
    t.late_chars.push((300_000 + 30 * ct, 5_000));
    assert_eq!(t.unproven(&talk, timeout, &p), None);
    let baud = hiperface_model::settings::Baud::B600;
    t.slowest_char_us = UartSettings { baud, ..UartSettings::DEFAULT }.char_time_us();
    assert_eq!(t.unproven(&talk, timeout, &p), Some(5_000));
}

/// Seen under load (CI, 2026-11-26): a master that talked 1.4 ms before a reply's end
/// was PASSed once, its request read late. A request read after the reply's end
/// but after the line had gone unwatched for longer than the pause between them may
/// have talked over the reply: not proven either way.
#[test]
fn a_request_read_late_after_a_reply_may_hide_a_talk_over() {
    let ct = UartSettings::DEFAULT.char_time_us();
    let position = RequestFrame::decode(&[0x40, 0x42, 0x02]).unwrap();
    let logged = |begin_us: u64, char_us: u64| LoggedRequest {
        begin_us,
        end_us: begin_us + 3 * char_us,
        char_us,
        request: position,
    };
    let mut t = Timeline::default();
    t.replies.push((100_000, 108_000));
    // Read 3 ms after the reply's end (its first character then began 3 ms after).
    let read = logged(108_000 + 3_000, ct);
    let end = read.end_us;
    t.requests_log.push(read);
    assert_eq!(t.hidden_talk_over(), None, "read attentively: it came after the reply");
    // Its characters read after 2 ms unwatched: at most 2 ms earlier, still after.
    t.late_chars.push((end - ct, 2_000));
    assert_eq!(t.hidden_talk_over(), None);
    // After 5 ms unwatched: it may have begun 2 ms before the reply's end.
    t.late_chars.push((end, 5_000));
    assert_eq!(t.hidden_talk_over(), Some((108_000 + 3_000, 5_000)));
    // Unwatched before an earlier character of another request: not this one's.
    let mut t = Timeline::default();
    t.replies.push((100_000, 108_000));
    t.requests_log.push(read);
    t.late_chars.push((90_000, 50_000));
    assert_eq!(t.hidden_talk_over(), None);
    // A request seen beginning inside the reply is the observer's (TalksOverReply).
    let mut t = Timeline::default();
    t.replies.push((100_000, 108_000));
    t.requests_log.push(logged(107_000, ct));
    t.late_chars.push((107_000 + 3 * ct, 50_000));
    assert_eq!(t.hidden_talk_over(), None);
    // Before any reply: nothing to talk over.
    let mut t = Timeline::default();
    t.requests_log.push(read);
    t.late_chars.push((end, 50_000));
    assert_eq!(t.hidden_talk_over(), None);
    // At a user data rate (38400 Bd, 000:T28) its characters are a quarter of the
    // default's: a request begun 2 ms after the reply's end, read after 5 ms
    // unwatched, is taken from where it began at that rate, not three default
    // characters before its end (which would put it inside the reply, 1.4 ms too
    // early, and skip it).
    let baud = hiperface_model::settings::Baud::B38400;
    let fast = UartSettings { baud, ..UartSettings::DEFAULT }.char_time_us();
    assert!(fast * 4 <= ct + 4, "{fast} µs a character at 38400 Bd");
    let quick = logged(108_000 + 2_000, fast);
    let mut t = Timeline::default();
    t.replies.push((100_000, 108_000));
    t.requests_log.push(quick);
    t.late_chars.push((quick.end_us, 5_000));
    assert_eq!(t.hidden_talk_over(), Some((110_000, 5_000)));
}

/// Seen under load: a Read Position read 36 ms late was answered 36 ms late; the
/// master (rightly) gave up, asked again and met the reply. That reply is disturbed.
#[test]
fn a_reply_to_a_request_read_late_is_disturbed() {
    use crate::serve::Hooks;
    let p = hiperface_model::profiles::srs50();
    let scenario = crate::master::scenarios::catalogue().into_iter().next().unwrap();
    let reply_disturbance = |read_late_us| {
        let mut encoder = DriveEncoder::new(p, &scenario, false, None);
        let mut slave = Slave::operational(p);
        let ct = UartSettings::DEFAULT.char_time_us();
        encoder.read(read_late_us);
        let mut steps = Vec::new();
        for (i, b) in [0x40, 0x42, 0x02].into_iter().enumerate() {
            let ch = RxChar::ok(b, 100_000 + i as u64 * ct);
            encoder.received(ch, Some(UartSettings::DEFAULT));
            steps.extend(slave.receive(ch));
        }
        steps.extend(slave.poll(200_000));
        let step = steps.into_iter().find(|s| s.transmission.is_some()).unwrap();
        encoder.frame(&mut slave, &step);
        let tx = step.transmission.unwrap();
        let planned = crate::serve::planned_reply(&tx);
        encoder.reply(&mut slave, &step, planned).map(|p| p.answered_late_us)
    };
    assert_eq!(reply_disturbance(0), Some(0));
    assert_eq!(reply_disturbance(36_000), Some(36_000));
    // Read 5 ms late: answered 5.3 ms after the timeout, within Read Position's
    // 10 ms: nothing any master could tell.
    assert_eq!(reply_disturbance(5_000), Some(0));
}

/// A master's character read with a parity error (a port that marks them) is
/// counted and put on the timeline; the encoder's model answers the frame with
/// 09h, as an encoder does (000:T47).
#[test]
fn a_masters_uart_fault_is_counted_and_answered_09h() {
    use crate::line::echo::{Echo, EchoMode};
    use crate::serve::Hooks;
    let p = hiperface_model::profiles::srs50();
    let scenario = crate::master::scenarios::catalogue().into_iter().next().unwrap();
    let echo = ReplyEcho::new(EchoMode::Auto, Echo::Quiet, 0);
    let mut encoder = DriveEncoder::new(p, &scenario, false, None).on_port(OnPort { echo });
    assert!(encoder.serving().marks_errors);
    let mut slave = Slave::operational(p);
    let ct = UartSettings::DEFAULT.char_time_us();
    let mut steps = Vec::new();
    for (i, b) in [0x40, 0x42, 0x02].into_iter().enumerate() {
        let fault = (i == 1).then_some(UartFault::Parity);
        let ch = RxChar { byte: b, at_us: 100_000 + i as u64 * ct, fault };
        encoder.received(ch, Some(UartSettings::DEFAULT));
        steps.extend(slave.receive(ch));
    }
    steps.extend(slave.poll(200_000));
    assert_eq!(encoder.timeline.uart_faults, 1);
    assert!(encoder.timeline.entries.iter().any(|e| e.bytes.contains("42 read with a Parity error")));
    let reply = steps.into_iter().find_map(|s| s.transmission).expect("a reply");
    assert_eq!(reply.frame.as_bytes()[1..3], [0x50, 0x09], "09h, 000:T47");
}

/// Traced on this machine (2026-11-29, three busy loops, the master image under
/// QEMU): a 40-character reply's last characters reached the master 7.3 ms late, held
/// by a kernel worker queued on a processor the hypervisor had paused; the master took
/// the reply for ended, went on, and two of its requests then followed each other
/// without the pause of the timeout: a FAIL of 000:2.2.2 charged to a master that
/// did nothing wrong. The workers' wait while a reply is written makes it a
/// disturbance of the harness's own line; a wait under a character time does not.
#[test]
fn a_reply_the_kernels_workers_may_have_held_back_is_a_disturbance() {
    let ct = UartSettings::DEFAULT.char_time_us();
    let mut t = Timeline {
        replies: vec![(100_000, 146_000), (200_000, 208_000), (300_000, 308_000)],
        // Sampled every 5 ms: 0.3 ms during the first reply, 7.3 ms during the second.
        kernel_waited: vec![(95_000, 1_000), (150_000, 1_300), (195_000, 1_300), (210_000, 8_600), (310_000, 8_600)],
        ..Default::default()
    };
    t.disturbed.push(Disturbance {
        at_us: 300_000,
        pause_us: 2_000,
        split: false,
        answered_late_us: 0,
        delivered_late_us: 0,
    });
    t.disturbed_by_kernel();
    let at: Vec<(u64, u64, u64)> = t.disturbed.iter().map(|d| (d.at_us, d.pause_us, d.delivered_late_us)).collect();
    assert_eq!(at, vec![(200_000, 0, 7_300), (300_000, 2_000, 0)], "in order, the harness's own pause kept");
    assert!(300 < ct, "0.3 ms is under a character time: no disturbance");
    assert!(t.disturbed.iter().all(|d| !d.decides()), "it decides a run only where the master broke a rule after it");
    // Not measured (a master on a port, a kernel without delay accounting): nothing.
    let mut t = Timeline { replies: vec![(200_000, 208_000)], ..Default::default() };
    t.disturbed_by_kernel();
    assert!(t.disturbed.is_empty());
}

/// What the master wrote reaches the harness through the same workers: a gap inside a
/// request by less than they waited meanwhile is not proven the master's.
#[test]
fn a_gap_the_kernels_workers_may_have_made_is_not_proven() {
    let p = hiperface_model::profiles::srs50();
    let timeout = UartSettings::DEFAULT.timeout_us(p.edition);
    // Seen under load: "40" read, then "42 02" 7.3 ms later, the harness watching the
    // line every 0.5 ms.
    let gap = observation(Rule::GapInRequest, 1_326_345, 7_337);
    let mut t = Timeline::default();
    assert_eq!(t.unproven(&gap, timeout, &p), None, "nothing measured: it stands");
    t.kernel_waited = vec![(1_330_000, 400), (1_335_000, 700), (1_340_000, 700)];
    assert_eq!(t.unproven(&gap, timeout, &p), None, "0.3 ms waited, 1.6 ms over the timeout: it stands");
    t.kernel_waited = vec![(1_330_000, 400), (1_335_000, 6_400), (1_340_000, 6_400)];
    assert_eq!(t.unproven(&gap, timeout, &p), Some(6_000));
}

/// A sampled wait is kept by its changes: any window's growth reads the same from
/// what is kept as from every sample.
#[test]
fn a_sampled_wait_keeps_its_changes_only() {
    let samples: Vec<(u64, u64)> =
        vec![(0, 0), (5, 0), (10, 0), (15, 300), (20, 300), (25, 300), (30, 7_600), (35, 7_600), (40, 7_600)];
    let kept = changes_only(&samples);
    assert_eq!(kept, vec![(0, 0), (10, 0), (15, 300), (25, 300), (30, 7_600), (40, 7_600)]);
    let timeline = |kernel_waited| Timeline { kernel_waited, ..Default::default() };
    let (all, short) = (timeline(samples), timeline(kept));
    for from in 0..45 {
        for to in from..45 {
            assert_eq!(all.kernel_waited_in(from, to), short.kernel_waited_in(from, to), "{from}..{to}");
        }
    }
    assert_eq!(changes_only(&[]), Vec::<(u64, u64)>::new());
    assert_eq!(changes_only(&[(7, 1)]), vec![(7, 1)]);
}

/// A frame the master sends at another data rate than the encoder listens at reaches
/// a real encoder as noise: the served encoder does not hear it (no request, no
/// reply), says so on the timeline, and grades the rate where both readings are
/// wrong; a frame at the encoder's rate is heard. HX-M3's d11 retried an unanswered
/// request at 38400 Bd, set just before it wrote, and was answered on a
/// pseudo-terminal, which passes any rate (000:3.3.1).
#[test]
fn a_frame_at_another_data_rate_is_noise_to_the_encoder() {
    use crate::serve::Hooks;
    use std::sync::atomic::{AtomicU32, Ordering};
    let p = hiperface_model::profiles::srs50();
    let scenario = crate::master::scenarios::catalogue().into_iter().next().unwrap();
    let rate = std::sync::Arc::new(AtomicU32::new(9600));
    let peer = Box::new(crate::master::in_process::Rate(rate.clone()));
    let mut encoder = DriveEncoder::new(p, &scenario, false, Some(peer));
    let listening = Some(UartSettings::DEFAULT);
    let ct = UartSettings::DEFAULT.char_time_us();
    // Each frame: the line quiet (the master's rate read then), the master's port set
    // to `sent_bps`, then Read Position's 3 bytes; whether the encoder heard each.
    let frame = |at_us: u64, sent_bps: u32, encoder: &mut DriveEncoder| -> Vec<bool> {
        // The serving loop's watch of the quiet line: the first ends the frame before,
        // the next reads the master's rate.
        encoder.idle(at_us - 1000);
        encoder.idle(at_us);
        rate.store(sent_bps, Ordering::Relaxed);
        [0x40u8, 0x42, 0x02]
            .into_iter()
            .enumerate()
            .map(|(i, b)| encoder.received(RxChar::ok(b, at_us + (i as u64 + 1) * ct), listening))
            .collect()
    };
    let noise = |e: &DriveEncoder| e.timeline.entries.iter().filter(|e| e.bytes.starts_with("heard as noise")).count();
    let rated = |e: &DriveEncoder| e.timeline.observations.iter().filter(|o| o.rule == Rule::DataRate).count();
    assert_eq!(frame(100_000, 9600, &mut encoder), [true; 3], "at the encoder's rate: heard");
    // Changed as it sent (9600 Bd when the line was quiet, 38400 at the frame): which
    // one it went out at is not known, so not graded; taken at 38400 for hearing, as
    // set last.
    assert_eq!(frame(200_000, 38_400, &mut encoder), [false; 3], "set to 38400 Bd as it sent: noise");
    assert_eq!((noise(&encoder), rated(&encoder)), (1, 0));
    // Both readings wrong (38400 quiet, 19200 as it sent): noise, and graded.
    assert_eq!(frame(300_000, 19_200, &mut encoder), [false; 3]);
    assert_eq!((noise(&encoder), rated(&encoder)), (2, 1));
    // Set back to 9600 Bd as it sent: heard (the other reading is 19200, not graded).
    assert_eq!(frame(400_000, 9600, &mut encoder), [true; 3]);
    assert_eq!((noise(&encoder), rated(&encoder)), (2, 1));
}
