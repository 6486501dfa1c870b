//! Certifying a master given in-process, in virtual time: the whole scenario catalogue
//! against a master that is a value (a C callback, a Python object), with the same
//! encoder, observer, grades, record and report as `certify master --exec`, but no
//! pseudo-terminal, no process and no clock: what the master sends is on the line
//! exactly when it says, each reply character reaches it exactly when it ends.
//!
//! The line here drives the same session as the harness's real-time loop and the
//! replay of a record ([`crate::serve::Session`]: a read's characters, then the time,
//! then each reply), so that the record it writes is taken in again by
//! [`super::record::replay`] as a real run's is.

use super::encoder::{DriveEncoder, MasterSettings};
use super::record::Start;
use super::run::{run_catalogue, Catalogue, ScenarioLine, ScenarioRun};
use super::scenario::Scenario;
use super::{scenarios, DriveReport};
use crate::serve::{Next, Sending, Session, READ_US};
use crate::verdict::{CaseResult, Finding};
use hiperface_model::datalink::RxChar;
use hiperface_model::master::obligations::POLLING_PERIOD_MS;
use hiperface_model::{CommandId, Profile, Slave};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// What a master under test does at one moment.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MasterAction {
    /// Bytes to send: their first character starts at `start_us` (no earlier than
    /// now, nor than the end of what the master sent before), one character after the
    /// other at `bps`.
    pub send: Option<Transmit>,
    /// When to be called again if nothing is heard before; `None`: only when
    /// something is heard.
    pub wake_us: Option<u64>,
}

/// Bytes a master sends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Transmit {
    pub bytes: Vec<u8>,
    pub start_us: u64,
    /// The master's data rate, bit/s (9600 at power-on, 000:T7): graded against the
    /// rate the encoder listens at (000:T26), as on a pseudo-terminal. A character is
    /// taken as 11 bits (8E1); its parity and size are not graded, as on a
    /// pseudo-terminal.
    pub bps: u32,
}

/// A master under test, given in-process.
pub trait MasterUnderTest {
    /// Power-on, the encoder's and the master's, at time 0: start afresh (called
    /// before each scenario).
    fn power_on(&mut self);
    /// Called at `now_us` (µs since power-on): at power-on, when characters of the
    /// encoder's reply have ended (`heard`, each stamped at the end of its stop bit),
    /// and when the time it asked for has come.
    fn step(&mut self, now_us: u64, heard: &[RxChar]) -> MasterAction;
}

/// How an in-process master is certified.
#[derive(Debug, Clone)]
pub struct Options {
    /// Only scenarios whose id matches (globs, comma-separated).
    pub scenarios: Option<String>,
    /// The application's polling period (000:3.2.2 "a sufficient cyclic request").
    pub polling_period_ms: u32,
    /// The commands the master declares it never sends: the scenarios about them are
    /// NOT-APPLICABLE (`super::declared_out`).
    pub not_used: Vec<CommandId>,
}

impl Default for Options {
    fn default() -> Options {
        Options { scenarios: None, polling_period_ms: POLLING_PERIOD_MS, not_used: Vec::new() }
    }
}

/// More characters than any master sends in a scenario: the rest of a flood is not
/// put on the line (the encoder stops counting at its own cap).
const MAX_MASTER_CHARACTERS: usize = 2 * super::encoder::MAX_CHARACTERS;

/// The master's data rate as it sent last, read by the encoder as it reads a
/// pseudo-terminal's.
#[derive(Clone)]
pub(crate) struct Rate(pub(crate) Arc<AtomicU32>);

impl MasterSettings for Rate {
    fn data_rate(&self) -> Option<u32> {
        Some(self.0.load(Ordering::Relaxed))
    }
}

/// A character time at `bps` for an 11-bit character (8E1), µs, rounded up; a rate
/// of 0 is taken as 1 bit/s.
fn char_time_us(bps: u32) -> u64 {
    11_000_000u64.div_ceil(u64::from(bps.max(1)))
}

/// Run the catalogue (or `options.scenarios`) against `master`, for an encoder of
/// `profile`; `name` names the master in the report. Each scenario is a fresh encoder
/// and a fresh power-on of the master.
pub fn run(master: &mut dyn MasterUnderTest, name: &str, profile: Profile, options: &Options) -> DriveReport {
    let chosen = scenarios::chosen(options.scenarios.as_deref());
    let mut report = DriveReport::new(&profile, name.to_string(), options.polling_period_ms, &options.not_used);
    report.notes = vec![
        "The master was certified in-process, in virtual time: what it sent was on the line exactly when it said, \
         each reply character reached it exactly when it ended; nothing of a machine's load is in the verdicts."
            .into(),
        "The master's data rate was the one it gave with what it sent; parity and character size were not graded \
         (a character is taken as 11 bits, 8E1)."
            .into(),
        format!(
            "A sufficient cyclic request (000:3.2.2) was taken as one at least every {} ms.",
            options.polling_period_ms
        ),
    ];
    report.notes.extend(super::declaration_note(&options.not_used));
    let catalogue = Catalogue { chosen: &chosen, profile, not_used: &options.not_used };
    let mut line = VirtualLine { master, options };
    run_catalogue(&mut report, &catalogue, &mut line, &mut |_| {});
    report
}

/// The master under test on a line in virtual time.
struct VirtualLine<'a> {
    master: &'a mut dyn MasterUnderTest,
    options: &'a Options,
}

impl ScenarioLine for VirtualLine<'_> {
    fn run(&mut self, profile: Profile, scenario: &Scenario) -> ScenarioRun {
        run_scenario(self.master, profile, scenario, self.options)
    }
}

/// One scenario, in virtual time: never disturbed, so never run again.
fn run_scenario(
    master: &mut dyn MasterUnderTest,
    profile: Profile,
    scenario: &Scenario,
    options: &Options,
) -> ScenarioRun {
    let polling_period_ms = options.polling_period_ms;
    let mut result = CaseResult::named(scenario.id, scenario.title, scenario.clauses);
    let mut slave = Slave::new(profile);
    (scenario.world)(&profile).apply_at_power_on(&mut slave);
    let rate = Rate(Arc::new(AtomicU32::new(9600)));
    let mut hooks =
        DriveEncoder::new(profile, scenario, true, Some(Box::new(rate.clone()))).declared_not_used(&options.not_used);
    hooks.set_polling_period_ms(polling_period_ms);
    let mut session = Session::new(slave, hooks);
    master.power_on();
    let mut line = Line::default();
    let mut now = 0u64;
    let mut action = master.step(0, &[]);
    let mut flooded = false;
    loop {
        // What the master asked for.
        if let Some(t) = action.send.take() {
            flooded |= line.master_sends(t, now, &rate);
        }
        if let Some(w) = action.wake_us.take() {
            // A wake in the past is now: the loop still moves on.
            line.wake_us = Some(w.max(now + 1));
        }
        let situation_ms = session.hooks().timeline.situation_us.map(|t| t / 1000);
        let end_us = scenario.end_ms(situation_ms, polling_period_ms) * 1000;
        // The next moment anything happens: a character ends either way, the model's
        // deadline, the master's wake, or the serving loop's read (every 500 µs, as the
        // harness watches a master's line).
        let next = [
            line.to_encoder.front().map(|c| c.at_us),
            line.to_master.front().map(|c| c.at_us),
            line.wake_us,
            session.poll_timeout(now),
            Some((now / READ_US + 1) * READ_US),
        ]
        .into_iter()
        .flatten()
        .filter(|t| *t > now)
        .min()
        .unwrap_or(end_us);
        if next >= end_us {
            now = end_us;
            break;
        }
        now = next;
        // The master's characters that have ended: one read.
        session.handle_read(0);
        let mut ended = Vec::new();
        while let Some(ch) = line.to_encoder.front().copied().filter(|c| c.at_us <= now) {
            line.to_encoder.pop_front();
            ended.push(ch);
        }
        session.receive_all(ended, None);
        session.handle_timeout(now);
        while let Some(mut p) = session.poll_transmit() {
            // The encoder's line is free once its last reply is out.
            p.start_us = p.start_us.max(now).max(line.encoder_free_us);
            let (ct, timeout) = (p.settings.char_time_us(), p.settings.timeout_us(profile.edition));
            // Each character reaches the master as its stop bit ends, every run on time.
            let mut sending = Sending::new(p, timeout);
            let end = loop {
                match sending.poll() {
                    Next::Write { due_us, run } => {
                        let mut end = due_us.saturating_sub(ct);
                        for &byte in sending.frame().get(run).unwrap_or_default() {
                            end += ct;
                            line.to_master.push_back(RxChar { byte, at_us: end, fault: None });
                        }
                        sending.written(due_us, due_us);
                    }
                    Next::Wait { .. } => {}
                    Next::Done { end_us } => break end_us,
                }
            };
            line.encoder_free_us = end;
            session.on_sent(sending.sent(), end);
        }
        // What reached the master, or its wake: it acts.
        let mut heard = Vec::new();
        while let Some(ch) = line.to_master.front().copied().filter(|c| c.at_us <= now) {
            line.to_master.pop_front();
            heard.push(ch);
        }
        let woken = line.wake_us.is_some_and(|w| w <= now);
        if woken {
            line.wake_us = None;
        }
        if woken || !heard.is_empty() {
            action = master.step(now, &heard);
        }
        if session.wants_stop() {
            break; // a flood: the encoder has taken in all it will
        }
    }
    let mut hooks = session.into_hooks();
    hooks.finish(now);
    if flooded {
        result.push(Finding::unknown(format!(
            "the master sent more than {MAX_MASTER_CHARACTERS} characters: the rest were not put on the line"
        )));
    }
    ScenarioRun::graded(result, hooks, scenario, 0.0, Start::PowerOnAtStart, false)
}

/// The line between the master and the encoder, in virtual time.
#[derive(Default)]
struct Line {
    /// The master's characters, each stamped at the end of its stop bit.
    to_encoder: VecDeque<RxChar>,
    /// The encoder's reply characters on their way to the master.
    to_master: VecDeque<RxChar>,
    /// When the master's last character ends.
    master_free_us: u64,
    /// When the encoder's last reply ends.
    encoder_free_us: u64,
    /// When the master asked to be called again.
    wake_us: Option<u64>,
    /// The master's characters put on the line in this scenario.
    sent: usize,
}

impl Line {
    /// Put what the master sends on the line; `true` where a flood was cut.
    fn master_sends(&mut self, t: Transmit, now: u64, rate: &Rate) -> bool {
        rate.0.store(t.bps, Ordering::Relaxed);
        let ct = char_time_us(t.bps);
        let mut start = t.start_us.max(now).max(self.master_free_us);
        for &byte in &t.bytes {
            if self.sent >= MAX_MASTER_CHARACTERS {
                return true;
            }
            start += ct;
            self.to_encoder.push_back(RxChar { byte, at_us: start, fault: None });
            self.sent += 1;
        }
        self.master_free_us = start;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_eleven_bit_character_takes_its_time_at_each_rate() {
        assert_eq!(char_time_us(9600), 1146);
        assert_eq!(char_time_us(38400), 287);
        assert_eq!(char_time_us(0), 11_000_000);
    }

    #[test]
    fn a_master_that_sends_nothing_is_graded_as_the_command_grades_it() {
        struct Mute;
        impl MasterUnderTest for Mute {
            fn power_on(&mut self) {}
            fn step(&mut self, _now_us: u64, _heard: &[RxChar]) -> MasterAction {
                MasterAction::default()
            }
        }
        let options = Options { scenarios: Some("startup.default".into()), ..Options::default() };
        let report = run(&mut Mute, "mute", hiperface_model::profiles::srs50(), &options);
        assert_eq!(report.scenarios.len(), 1);
        let verdict = report.scenarios[0].verdict;
        assert_eq!(verdict, crate::verdict::CaseVerdict::Error, "{:?}", report.scenarios[0].findings);
        assert!(report.scenarios[0].findings.iter().any(|f| f.message().contains("the master sent nothing")));
    }

    /// The contract `step` is called under (the C and Python masters' too): once at
    /// power-on with nothing heard; once for each character of a reply as its stop bit
    /// ends (`now_us` that end); at the wake asked for when nothing came first, a wake
    /// not after now 1 µs later; a wake stays asked until it comes or another replaces
    /// it (an action without one leaves it); what is sent starts at `start_us`, or now,
    /// or when the master's line is free, whichever is latest.
    #[test]
    fn step_is_called_at_power_on_per_character_and_at_its_wake() {
        #[derive(Default)]
        struct Recorder {
            calls: Vec<(u64, Vec<RxChar>)>,
            wakes: Vec<u64>,
        }
        impl MasterUnderTest for Recorder {
            fn power_on(&mut self) {}
            fn step(&mut self, now_us: u64, heard: &[RxChar]) -> MasterAction {
                self.calls.push((now_us, heard.to_vec()));
                let read_position = || vec![0x40, 0x42, 0x02];
                let mut action = MasterAction::default();
                match (self.calls.len(), heard.is_empty()) {
                    // Power-on: a wake 2 s on, past the encoder's start-up (000:T9).
                    (1, _) => action.wake_us = Some(2_000_000),
                    // A request to start 5 ms from now, and a wake already past.
                    (2, true) => {
                        action.send = Some(Transmit { bytes: read_position(), start_us: now_us + 5_000, bps: 9600 });
                        action.wake_us = Some(now_us - 10);
                    }
                    // Past the wake in the past: a wake 0.5 s on, which the reply's
                    // characters (no wake asked) leave standing.
                    (3, true) => action.wake_us = Some(2_500_000),
                    _ => {}
                }
                self.wakes.extend(action.wake_us);
                action
            }
        }
        let options = Options { scenarios: Some("polling.long".into()), ..Options::default() };
        let mut master = Recorder::default();
        let _ = run(&mut master, "recorder", hiperface_model::profiles::srs50(), &options);
        let calls = &master.calls;
        assert_eq!(calls.first(), Some(&(0, Vec::new())), "first at power-on, nothing heard");
        assert_eq!((calls[1].0, calls[1].1.is_empty()), (2_000_000, true), "then at its wake");
        assert_eq!((calls[2].0, calls[2].1.is_empty()), (2_000_001, true), "a wake in the past: 1 µs on");
        let replies: Vec<_> = calls.iter().filter(|(_, h)| !h.is_empty()).collect();
        assert_eq!(replies.len(), 7, "one call per character of the 7-byte reply: {calls:?}");
        for (now, heard) in &replies {
            assert_eq!((heard.len(), heard[0].at_us), (1, *now), "one character, called as it ends");
        }
        // The request started 5 ms after the call that sent it (not at once), so its
        // reply's first character ends later than 2 000 000 + 5 000 + its 3 characters.
        assert!(replies[0].0 > 2_000_000 + 5_000 + 3 * 1_146, "{calls:?}");
        let last = calls.last().map(|(t, h)| (*t, h.is_empty()));
        assert_eq!(last, Some((2_500_000, true)), "the wake asked before the reply still came: {calls:?}");
    }

    /// A master that floods the line is cut off where the encoder has taken in all it
    /// will: an ERROR (as the guide says), not a FAIL of the rules the flood breaks,
    /// and a record no longer than the cut (issue 55: gigabytes per scenario).
    #[test]
    fn a_flooding_master_is_cut_off_and_is_an_error() {
        struct Flood;
        impl MasterUnderTest for Flood {
            fn power_on(&mut self) {}
            fn step(&mut self, now_us: u64, _heard: &[RxChar]) -> MasterAction {
                // As a process writes a pseudo-terminal: far faster than any UART.
                MasterAction {
                    send: Some(Transmit { bytes: vec![0x40; 64], start_us: now_us, bps: 1_000_000 }),
                    wake_us: Some(now_us + 64 * 11),
                }
            }
        }
        let options = Options { scenarios: Some("polling.long".into()), ..Options::default() };
        let report = run(&mut Flood, "flood", hiperface_model::profiles::srs50(), &options);
        let s = &report.scenarios[0];
        assert_eq!(s.verdict, crate::verdict::CaseVerdict::Error, "{:?}", s.findings);
        assert!(s.findings.iter().any(|f| f.message().contains("flooded")), "{:?}", s.findings);
        let record = report.record.as_ref().unwrap();
        let received =
            record.runs[0].inputs.iter().filter(|i| matches!(i, super::super::inputs::Input::Received { .. })).count();
        assert_eq!(received, super::super::encoder::MAX_CHARACTERS);
    }

    /// The encoder the harness serves knows its fields: a master that reads the
    /// Extended Type Label (64 bytes, field FFh) past its end breaks 000:T21's "offset
    /// plus byte count must not be larger than data field size", a FAIL in the scenario
    /// it does it in (HX-M4's d16 read a chunk at offset 40h); the same reads within
    /// the label are not.
    #[test]
    fn a_read_past_the_extended_type_labels_end_fails_on_read_datas_clause() {
        struct Reader {
            offsets: Vec<u8>,
            sent: usize,
        }
        impl MasterUnderTest for Reader {
            fn power_on(&mut self) {
                self.sent = 0;
            }
            fn step(&mut self, now_us: u64, heard: &[RxChar]) -> MasterAction {
                let mut action = MasterAction::default();
                if !heard.is_empty() {
                    return action;
                }
                // Past the encoder's initialization, then one Read Data every 100 ms.
                match self.offsets.get(self.sent) {
                    _ if now_us < 300_000 => action.wake_us = Some(300_000),
                    Some(offset) => {
                        let mut bytes = vec![0x40, 0x4A, 0xFF, *offset, 0x10, 0x00];
                        bytes.push(bytes.iter().fold(0, |x, b| x ^ b));
                        action.send = Some(Transmit { bytes, start_us: now_us, bps: 9600 });
                        action.wake_us = Some(now_us + 100_000);
                        self.sent += 1;
                    }
                    None => {}
                }
                action
            }
        }
        use hiperface_model::master::obligations::Rule;
        let options = Options { scenarios: Some("startup.extended-type-label".into()), ..Options::default() };
        let outside = |offsets: Vec<u8>| {
            let mut master = Reader { offsets, sent: 0 };
            let report = run(&mut master, "reader", hiperface_model::profiles::srs50(), &options);
            let s = report.scenarios.into_iter().next().unwrap();
            let told: Vec<_> =
                s.findings.iter().filter(|f| f.clause_id() == Rule::ReadOutsideField.clause().id()).cloned().collect();
            (s.verdict, told)
        };
        let (_, within) = outside(vec![0x00, 0x10, 0x20, 0x30]);
        assert!(within.is_empty(), "{within:?}");
        let (verdict, past) = outside(vec![0x00, 0x10, 0x20, 0x30, 0x40]);
        assert_eq!(verdict, crate::verdict::CaseVerdict::Fail, "{past:?}");
        assert_eq!(past.len(), 1, "{past:?}");
        assert_eq!(past[0].verdict(), crate::verdict::CaseVerdict::Fail);
        assert!(past[0].message().contains("outside its data field"), "{past:?}");
    }
}
