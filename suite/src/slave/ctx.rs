//! What a case sees: the master on the line, the model in lockstep, the oracle, and
//! the case's findings. Every exchange goes through [`Ctx::send_frame`], which grades
//! the answer, its timing and anything unsolicited.
//!
//! Long because: the line, the model in lockstep and the findings are the one context
//! every case uses; its transmit path is split into its jobs already (under 580 lines
//! without its tests).

use super::{CaseError, Identity, Options};
use crate::exchange::{sealed, Bus, Exchange, Listen, LATE_REPLY_GRACE_MS};
use crate::verdict::timing;
use crate::verdict::{CaseResult, CaseVerdict, Finding, WireEntry};
use hiperface_model::address::AddressByte;
use hiperface_model::clause::{self, Normative};
use hiperface_model::command::ResponseLimit;
use hiperface_model::request::{Request, RequestFrame};
use hiperface_model::response::ResponseFrame;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{CommandId, Edition, Grading, Hex, Oracle, Outcome, Profile, Reply, Slave};
use std::collections::BTreeMap;
use std::sync::atomic::Ordering;

/// What the harness checks on every exchange of every case, besides the oracle's grade
/// of the reply: no characters outside a reply, and the reply's end (see `exchange`).
pub const EVERY_EXCHANGE: [Normative; 2] = [clause::NO_UNSOLICITED, clause::REPLY_END];

/// What the run accumulates across cases.
#[derive(Debug, Default)]
pub(crate) struct Tally {
    /// Response times per command byte of the command's own replies (not error
    /// responses): the least and the most the line's uncertainty allows, µs; and the
    /// command's limit, ms (000:T10).
    pub response_times: BTreeMap<u8, (Vec<(i64, i64)>, u32)>,
    /// What the run's exchanges take on a real line, with a perfect master and the
    /// device's own response times (a pseudo-terminal can be faster), µs.
    pub line_time_us: u64,
    /// The device has answered at least once in this run.
    pub answered_any: bool,
    /// What the device said of itself.
    pub identity: Identity,
    /// What the harness could not vouch for (its own bookkeeping), for the report.
    pub notes: Vec<String>,
    /// The longest the harness woke late in any exchange, µs.
    pub harness_late_us: u64,
    /// The most the line itself may have delayed any exchange, both ways, as measured
    /// beside it, µs.
    pub line_late_us: u64,
}

/// What a request costs on a real line at best (an ideal master, the device's own
/// response time): the request, the slave's timeout, the reply (or, for silence,
/// the whole response time and one character) and the pause after it. The sum over a run is the line time a report
/// compares its wall time with: a real line's, which a pseudo-terminal may beat.
pub(crate) fn physical_time_us(x: &Exchange, max_ms: u16) -> u64 {
    let ct = x.settings.char_time_us();
    // On a real line the request takes its characters' time, whatever the harness's
    // line does (a pseudo-terminal delivers a write at once).
    let request_and_timeout = x.request.len() as u64 * ct + x.timeout_us;
    match x.response_time_us() {
        Some((lo, _)) => request_and_timeout + lo.max(0) as u64 + x.reply.len() as u64 * ct + x.timeout_us,
        None => request_and_timeout + max_ms as u64 * 1000 + ct,
    }
}

/// The pause before an exchange's trailing characters, as the data link framed the
/// reply (at least the timeout between two character ends).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TrailingPause {
    /// At least the timeout from a stop bit to the next start bit, whatever the
    /// harness's lateness: the reply had ended (000:2.2.2).
    Ended,
    /// Less than the timeout without the time the harness may have noticed the
    /// characters late: its lateness could explain it.
    LatenessCouldExplain,
    /// At least the timeout between character ends but less from stop bit to start
    /// bit: a receiver counting from character ends (000:2.2.2 note) ends the reply
    /// there, one watching the line does not.
    WithinOneCharacter,
}

fn trailing_pause(x: &Exchange) -> Option<TrailingPause> {
    let (last, next) = (x.reply.last()?, x.trailing.first()?);
    let gap = next.at_us.saturating_sub(last.at_us);
    let pause = gap.saturating_sub(x.settings.char_time_us());
    // A device this machine held may have paused for that long inside its reply.
    let late = x.reply_unseen_late_us() + x.device_held.exchange.at_most_us();
    Some(if late > 0 && gap.saturating_sub(late) < x.timeout_us {
        TrailingPause::LatenessCouldExplain
    } else if pause.saturating_sub(late) >= x.timeout_us {
        TrailingPause::Ended
    } else if late > 0 && pause + late >= x.timeout_us {
        // The part before the pause may have been read late: the pause may have been
        // of the timeout (a FAIL idle), or not (NON-STRICT). Neither is told on the
        // lateness: run again (issue 54: HX-1's pause of twice the timeout read as
        // NON-STRICT on a busy machine, a FAIL on an idle one).
        TrailingPause::LatenessCouldExplain
    } else {
        TrailingPause::WithinOneCharacter
    })
}

/// Why a device that runs on this machine may have heard `x`'s request, which the
/// harness sent whole, in two parts: it answered as a device answers the first part of
/// a frame (0Ah for its checksum, 0Ch for its length, or nothing where a reply was
/// due), and its processor was held while the request was on its way for at least the
/// pause that ends a request between two of its characters (000:2.2.2). `None` where
/// either is not so: a device with a processor of its own is never held by this
/// machine. A frame sent with the wrong parity is left to its own grade.
fn heard_split(x: &Exchange, wrong_parity: bool, expected: &Outcome, observed: Option<&[u8]>) -> Option<String> {
    use hiperface_model::FaultCode::{Checksum, WrongLength};
    let held = x.device_held.request;
    // The pause between two characters' ends that ends a request, less the character.
    let splits_us = x.timeout_us.saturating_sub(x.settings.char_time_us());
    if wrong_parity || x.request.len() < 2 || held.at_most_us() < splits_us.max(1) {
        return None;
    }
    let answer = match observed {
        None if matches!(expected.reply, Reply::Frame(_)) => "no reply".to_string(),
        Some(&[_, command, code, _]) if command & 0x7F == 0x50 => {
            let fault = hiperface_model::FaultCode::decode(code);
            if !matches!(fault, Checksum | WrongLength) {
                return None;
            }
            format!("error {code:02X}h ({})", fault.name())
        }
        _ => return None,
    };
    let ms = |us: u64| us as f64 / 1000.0;
    Some(format!(
        "not graded: {answer} to [{}], sent whole, is how a device answers the first part of a frame heard in two; \
         the device runs on this machine, which held it for up to {:.1} ms while the request was on its way (its \
         process waited {:.1} ms for a processor, a processor stopped for {:.1} ms, the hypervisor's steal counted \
         {:.0} ms), and a pause of {:.1} ms between two characters ends a request (000:2.2.2): not charged to the \
         device, the case is run again",
        Hex(&x.request),
        ms(held.at_most_us()),
        ms(held.waited_us),
        ms(held.paused_us),
        ms(held.steal_us),
        ms(splits_us),
    ))
}

/// A first part of `frame` that draws the error `observed` says the device answered:
/// the frame with a wrong checksum (0Ah) or its first two bytes (0Ch); `None` for
/// silence, which needs no part.
fn part_heard(frame: &[u8], observed: Option<&[u8]>) -> Option<Vec<u8>> {
    match observed? {
        [_, _, 0x0A, _] => {
            let mut part = frame.to_vec();
            if let Some(last) = part.last_mut() {
                *last ^= 0xFF;
            }
            Some(part)
        }
        _ => frame.get(..2).map(<[u8]>::to_vec),
    }
}

/// The frame of `request` to the address byte `address`.
fn frame(address: u8, request: Request) -> Vec<u8> {
    RequestFrame::new(AddressByte::decode(address), request).encode().as_bytes().to_vec()
}

/// An exchange as planned before its request goes.
struct Plan {
    command: Option<CommandId>,
    limits: ResponseLimit,
    /// The model before the request, for the oracle.
    before: Slave,
    listen: Listen,
}

/// An exchange as made: what the line carried, and the model's step on the request.
struct Taken {
    x: Exchange,
    expected: Outcome,
    /// When the slave took the request.
    taken_at: u64,
    /// The request reached the slave across a change of its power-up state.
    across_change: bool,
}

/// The model's step on `frame`, sent with the wrong parity or not, taken at `at_us`.
fn handle(model: &mut Slave, frame: &[u8], wrong_parity: bool, at_us: u64) -> Outcome {
    if wrong_parity {
        model.handle_faulty_frame(frame, at_us)
    } else {
        model.handle_frame(frame, at_us)
    }
}

/// The finding on characters that came after a reply (or in place of one), and
/// whether the harness's own lateness leaves it untold.
fn trailing_finding(x: &Exchange, edition: Edition) -> (Finding, bool) {
    let bytes: Vec<u8> = x.trailing.iter().map(|c| c.byte).collect();
    if x.reply.is_empty() {
        let msg = format!("{} characters [{}] arrived after the reply window", bytes.len(), Hex(&bytes));
        return (Finding::fail(msg, clause::NO_UNSOLICITED, edition), false);
    }
    match trailing_pause(x) {
        Some(TrailingPause::LatenessCouldExplain) => (
            Finding::unknown(format!(
                "cannot tell whether the reply had a pause of the timeout inside: {} more characters [{}] came \
                 after one as read, but the harness and the line may have been up to {:.3} ms late, and this \
                 machine may have held the device's processor up to {:.3} ms",
                bytes.len(),
                Hex(&bytes),
                x.reply_unseen_late_us() as f64 / 1000.0,
                x.device_held.exchange.at_most_us() as f64 / 1000.0
            )),
            true,
        ),
        Some(TrailingPause::WithinOneCharacter) => (
            Finding::non_strict(
                format!(
                    "the reply paused inside for less than the timeout from stop bit to start bit, but for at least \
                     the timeout between character ends: {} more characters [{}] came after it, which a receiver \
                     timing from character ends takes for another transmission",
                    bytes.len(),
                    Hex(&bytes)
                ),
                clause::REPLY_END,
            ),
            false,
        ),
        _ => {
            let msg = format!(
                "the reply went on after a pause of at least the timeout: {} more characters [{}]",
                bytes.len(),
                Hex(&bytes)
            );
            (Finding::fail(msg, clause::REPLY_END, edition), false)
        }
    }
}

/// A pending restore, released by the case once it has restored by itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use = "release the guard once the case has restored"]
pub struct Guard(u64);

/// A graded exchange.
pub struct Graded {
    pub exchange: Exchange,
    pub verdict: CaseVerdict,
    pub reply: Option<Vec<u8>>,
}

pub struct Ctx<'a> {
    master: &'a mut dyn Bus,
    pub model: &'a mut Slave,
    oracle: Oracle,
    result: &'a mut CaseResult,
    tally: &'a mut Tally,
    options: &'a Options,
    /// Requests that undo this case's changes, last first, run by the runner if the
    /// case does not release them itself.
    guards: Vec<(u64, Vec<u8>)>, // (id, whole frame)
    next_guard: u64,
    restoring: bool,
    /// A verdict of this case could not be told for the harness's own lateness: the
    /// runner runs it again.
    disturbed: bool,
}

impl<'a> Ctx<'a> {
    pub(crate) fn new(
        master: &'a mut dyn Bus,
        model: &'a mut Slave,
        result: &'a mut CaseResult,
        tally: &'a mut Tally,
        options: &'a Options,
    ) -> Ctx<'a> {
        Ctx {
            master,
            model,
            oracle: Oracle::new(options.grading),
            result,
            tally,
            options,
            guards: Vec::new(),
            next_guard: 0,
            restoring: false,
            disturbed: false,
        }
    }
}

impl Ctx<'_> {
    pub fn profile(&self) -> Profile {
        *self.model.profile()
    }

    pub fn address(&self) -> u8 {
        self.model.nonvolatile().address.byte()
    }

    /// Record a finding; the case verdict is the worst of its findings. A finding
    /// not placed on the wire already is about the last exchange (a check across
    /// exchanges is made after its last reply).
    pub fn push(&mut self, finding: Finding) {
        let last = self.result.wire.iter().rev().find(|w| w.direction == WireEntry::REQUEST).map(|w| w.t_us);
        self.result.push(match last {
            Some(t_us) => finding.at(t_us),
            None => finding,
        });
    }

    /// The device broke `rule` (FAIL where the rule binds the profile's edition).
    pub fn fail(&mut self, message: impl Into<String>, rule: Normative) {
        let edition = self.model.profile().edition;
        self.push(Finding::fail(message, rule, edition));
    }

    /// A check across exchanges (e.g. data read back equals data stored).
    pub fn check(&mut self, ok: bool, message: impl Into<String>, rule: Normative) {
        if !ok {
            self.fail(message, rule);
        }
    }

    /// Something the harness cannot vouch for (its bookkeeping of the device's state):
    /// a line of the report's safety section, never a verdict.
    pub fn note(&mut self, message: impl Into<String>) {
        self.tally.notes.push(format!("{}: {}", self.result.id, message.into()));
    }

    /// Register a request to `address` that undoes a change just made.
    pub fn guard(&mut self, address: u8, undo: Request) -> Guard {
        self.next_guard += 1;
        self.guards.push((self.next_guard, frame(address, undo)));
        Guard(self.next_guard)
    }

    /// The case restored by itself: drop the guard.
    pub fn release(&mut self, guard: Guard) {
        self.guards.retain(|(id, _)| *id != guard.0);
    }

    /// Whether the harness's own lateness left a verdict of this case untold.
    pub(crate) fn disturbed(&self) -> bool {
        self.disturbed
    }

    pub(crate) fn has_guards(&self) -> bool {
        !self.guards.is_empty()
    }

    /// Run the pending guards, last first.
    pub(crate) fn restore(&mut self) -> Result<usize, CaseError> {
        self.restoring = true;
        let mut n = 0;
        while let Some((_, undo)) = self.guards.pop() {
            self.send_frame(&undo)?;
            n += 1;
        }
        Ok(n)
    }

    /// Send a request meant to reach the slave in the power-up state `planned`
    /// (000:T9), and grade it. Where the harness's own timing put it elsewhere (it
    /// woke late), the case did not see what it is about: UNKNOWN, and the case is run
    /// again. Never a verdict on the device.
    pub fn request_in_state(&mut self, request: Request, planned: CommState) -> Result<Graded, CaseError> {
        let state_before = self.model.clone();
        let graded = self.request(request)?;
        let x = &graded.exchange;
        let first = x.request_end.earliest_us.saturating_sub((x.request.len() as u64 - 1) * x.settings.char_time_us());
        let reached = [first, x.request_end.latest_us].map(|t| state_before.state(t));
        if reached.iter().any(|s| *s != planned) {
            self.disturbed = true;
            self.push(Finding::unknown(format!(
                "not observed: request [{}] was meant for the state {} but reached the slave in {} (the harness's \
                 own timing)",
                Hex(&x.request),
                planned.name(),
                reached[1].name()
            )));
        }
        Ok(graded)
    }

    /// Send a request to the device's address; grade the answer.
    pub fn request(&mut self, request: Request) -> Result<Graded, CaseError> {
        let address = self.address();
        self.request_at(address, request)
    }

    /// Send a request with any address byte (another slave's, FFh); grade the answer.
    pub fn request_at(&mut self, address: u8, request: Request) -> Result<Graded, CaseError> {
        self.send_frame(&frame(address, request))
    }

    /// Send a body that no [`Request`] expresses (an unknown command, a wrong length)
    /// with its checksum appended; grade the answer.
    pub fn ask(&mut self, body: &[u8]) -> Result<Graded, CaseError> {
        self.send_frame(&sealed(body))
    }

    /// Send a frame as it is (for malformed frames); grade the answer.
    pub fn send_frame(&mut self, frame: &[u8]) -> Result<Graded, CaseError> {
        self.transmit(frame, false)
    }

    /// Send a frame with the wrong parity on every character; grade the answer, which
    /// must be the one to a UART fault (000:T47). The line must carry parity
    /// ([`Ctx::line_carries_parity`]).
    pub fn send_with_wrong_parity(&mut self, frame: &[u8]) -> Result<Graded, CaseError> {
        self.transmit(frame, true)
    }

    /// One exchange, in four jobs: plan it, make it (the model in lockstep), keep what
    /// the run accumulates, grade it.
    fn transmit(&mut self, frame: &[u8], wrong_parity: bool) -> Result<Graded, CaseError> {
        if self.interrupted() {
            return Err(CaseError::Interrupted);
        }
        let plan = self.plan(frame, wrong_parity)?;
        let taken = self.exchange(frame, wrong_parity, &plan)?;
        let observed = taken.x.reply_bytes();
        self.keep(frame, &plan, &taken, observed.as_deref())?;
        let (graded, found, heard_in_two) = self.grade(frame, &plan, &taken, observed.as_deref());
        if let (Some(bytes), Some(cmd)) = (&observed, plan.command) {
            self.learn(cmd, bytes, graded);
        }
        // The exchange's verdict is the worst of its findings, as the case's is.
        let verdict = found.iter().fold(graded, |v, f| v.worst(f.verdict()));
        for f in found {
            self.push(f.at(taken.x.request_end.earliest_us));
        }
        // A request the device may have heard in two did not change its settings.
        if let (Some(s), false) = (taken.expected.then_settings, heard_in_two) {
            self.master.configure(s)?;
        }
        Ok(Graded { exchange: taken.x, verdict, reply: observed })
    }

    /// Before the request goes: the line set to how the slave listens, and how long to
    /// listen for its answer.
    fn plan(&mut self, frame: &[u8], wrong_parity: bool) -> Result<Plan, CaseError> {
        // Talk in the settings the slave listens with now (67h, reset, power-up windows),
        // or will listen with next: a request into a silent window (initialization)
        // must not run past its end in the settings before it (seen: 600 Bd stored,
        // a request sent at 600 Bd after a reset reached the slave at 9600 Bd, 09h).
        let now = self.master.now_us();
        let heard = self.model.settings_heard_next(now);
        if heard != self.master.settings() {
            self.master.configure(heard)?;
        }
        let command = (frame.len() > 1).then(|| CommandId::of_frame(frame));
        let limits = self.model.profile().response_limit(command.unwrap_or(CommandId::Unknown(0)));
        let before = self.model.clone();
        // Where the model expects a reply, listen well past the limit so that a late
        // reply is measured and graded; where it expects silence, only to the limit.
        let estimate = self.master.now_us()
            + frame.len() as u64 * self.master.settings().char_time_us()
            + self.master.timeout_us();
        let mut after = before.clone();
        let expects_reply = matches!(handle(&mut after, frame, wrong_parity, estimate).reply, Reply::Frame(_));
        let listen = Listen {
            reply_ms: if expects_reply { timing::reply_awaited_ms(limits) } else { limits.max_ms },
            wrong_parity,
            slave_initializes: after.listening_settings(estimate).is_none(),
            late_grace_ms: if expects_reply { LATE_REPLY_GRACE_MS } else { 0 },
        };
        Ok(Plan { command, limits, before, listen })
    }

    /// The request on the line and the model's step on it, when the slave took it.
    fn exchange(&mut self, frame: &[u8], wrong_parity: bool, plan: &Plan) -> Result<Taken, CaseError> {
        let x = self.master.exchange_listening(frame, plan.listen)?;
        // The slave takes a frame when its timeout elapsed, if it listened when the
        // characters arrived; characters that arrive while it does not listen are lost
        // (000:T9). A frame across a change of the power-up state is heard in part: the
        // harness cannot say what a conformant slave made of it.
        let last_char = x.request_end.earliest_us;
        let first_char = last_char.saturating_sub((frame.len() as u64).saturating_sub(1) * x.settings.char_time_us());
        let across_change = self.model.state_changes_within(first_char, x.request_end.latest_us);
        let taken_at = match self.model.listening_settings(last_char) {
            None => last_char,
            Some(_) => x.complete_us(),
        };
        let expected = handle(self.model, frame, wrong_parity, taken_at);
        Ok(Taken { x, expected, taken_at, across_change })
    }

    /// What the run keeps of the exchange (the wire log, the tally), or why the run
    /// cannot go on (the write budget spent, a device that never answered).
    fn keep(&mut self, frame: &[u8], plan: &Plan, taken: &Taken, observed: Option<&[u8]>) -> Result<(), CaseError> {
        if self.model.eeprom_writes() > self.options.write_budget {
            return Err(CaseError::Budget(self.options.write_budget));
        }
        self.tally.answered_any |= observed.is_some();
        if !self.tally.answered_any && matches!(taken.expected.reply, Reply::Frame(_)) {
            // Never a word from the device: it is not there, not powered, or at another
            // address or data rate. The harness cannot run the case.
            return Err(CaseError::Silent);
        }
        let x = &taken.x;
        self.log(frame, x, observed);
        self.tally.harness_late_us = self.tally.harness_late_us.max(x.harness_late_us);
        self.tally.line_late_us = self.tally.line_late_us.max(x.line_late.both_ways_us());
        self.tally.line_time_us += physical_time_us(x, plan.limits.max_ms);
        // The command's own reply (its command byte echoed), not an error response
        // (50h's format): a newcomer read "53h Encoder Reset | 1 reply" beside "53h:
        // no frame". // 000:2.3.4
        let own = observed.and_then(|r| r.get(1)).zip(plan.command).is_some_and(|(b, c)| b & 0x7F == c.byte());
        if let (true, Some(cmd), Some(t)) = (own, plan.command, x.response_time_us()) {
            let (times, limit) = self.tally.response_times.entry(cmd.byte()).or_default();
            times.push(t);
            *limit = plan.limits.max_ms as u32;
        }
        Ok(())
    }

    /// The oracle's verdict on the answer, and the findings of the exchange: the
    /// oracle's, characters outside the reply, the reply's end, its timing. Where the
    /// harness's own timing leaves one untold, the case is marked to run again; and
    /// whether the device may have heard the request in two parts (see
    /// [`heard_split`]), in which case the model is put where such a device is.
    fn grade(
        &mut self,
        frame: &[u8],
        plan: &Plan,
        taken: &Taken,
        observed: Option<&[u8]>,
    ) -> (CaseVerdict, Vec<Finding>, bool) {
        let Taken { x, expected, taken_at, across_change } = taken;
        let grade = self.oracle.grade(&plan.before, frame, *taken_at, expected, observed);
        let mut graded = CaseVerdict::from(grade.verdict());
        let split = (graded == CaseVerdict::Fail)
            .then(|| heard_split(x, plan.listen.wrong_parity, expected, observed))
            .flatten();
        let heard_in_two = split.is_some();
        let mut found: Vec<Finding> = if let Some(why) = split {
            // The device's processor is this machine's, which held it: what it heard
            // may not be what was sent. Not the device's; run the case again. The
            // model goes on from where such a device is: the request not carried
            // out, the part it heard answered (seen: a Delete Data Field heard in two
            // left the field there, and the case's run again FAILed on it).
            self.disturbed = true;
            graded = CaseVerdict::Unknown;
            *self.model = plan.before.clone();
            if let Some(part) = part_heard(frame, observed) {
                let _ = handle(self.model, &part, false, *taken_at);
            }
            vec![Finding::unknown(why)]
        } else if *across_change {
            // The harness's own timing put the request there (a case never plans it):
            // not the device's; run the case again.
            self.disturbed = true;
            vec![Finding::unknown(format!(
                "not graded: request [{}] reached the slave across a change of its power-up state (000:T9), \
                 partly in one and partly in another",
                Hex(frame)
            ))]
        } else {
            Finding::graded(&grade, frame).into_iter().collect()
        };
        let edition = self.model.profile().edition;
        if !x.stray.is_empty() {
            let bytes: Vec<u8> = x.stray.iter().map(|c| c.byte).collect();
            let msg = format!("{} characters [{}] arrived outside any reply", bytes.len(), Hex(&bytes));
            found.push(Finding::fail(msg, clause::NO_UNSOLICITED, edition));
        }
        if !x.trailing.is_empty() {
            let (finding, disturbed) = trailing_finding(x, edition);
            self.disturbed |= disturbed;
            found.push(finding);
        }
        if matches!(expected.reply, Reply::Frame(_)) && !across_change {
            let tol = self.master.facts().tolerance_us;
            let timing = timing::grade(x, plan.limits, tol, self.options.timing, edition);
            // Timing is UNKNOWN only where the harness's lateness could explain it.
            self.disturbed |= timing.iter().any(|f| f.verdict() == CaseVerdict::Unknown);
            found.extend(timing);
        }
        (graded, found, heard_in_two)
    }

    fn log(&mut self, frame: &[u8], x: &Exchange, observed: Option<&[u8]>) {
        self.result.exchanges += 1;
        let t_us = x.request_end.earliest_us;
        self.result.wire.push(WireEntry { t_us, direction: WireEntry::REQUEST, bytes: Hex(frame).to_string() });
        if let (Some(bytes), Some(start)) = (observed, x.reply_start) {
            let t_us = start.earliest_us;
            self.result.wire.push(WireEntry { t_us, direction: WireEntry::REPLY, bytes: Hex(bytes).to_string() });
        }
    }

    /// Learn from a well-formed reply: the identity for the certificate, and on a real
    /// device what the documents let it choose and the model cannot know (the shaft's
    /// position, the preset 6Ah rounded to, bytes of fields it did not write).
    fn learn(&mut self, command: CommandId, bytes: &[u8], verdict: CaseVerdict) {
        let Ok(frame) = ResponseFrame::decode(bytes, command) else { return };
        self.tally.identity.record(&frame.response);
        if verdict == CaseVerdict::Fail || self.options.grading != Grading::Range {
            return;
        }
        self.model.adopt_reply(&frame.response);
    }

    /// An interrupt (Ctrl-C, SIGTERM) asks the case to stop; not while restoring.
    fn interrupted(&self) -> bool {
        !self.restoring && self.options.interrupt.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// Wait, with nothing on the line; anything that arrives is a FAIL. In steps of at
    /// most 50 ms, so that an interrupt takes effect within one (a power-up window's
    /// wait is most of a second).
    pub fn wait_ms(&mut self, ms: u64) -> Result<(), CaseError> {
        const STEP_US: u64 = 50_000;
        let until = self.master.now_us() + ms * 1000;
        let mut got = Vec::new();
        loop {
            let now = self.master.now_us();
            if now >= until {
                break;
            }
            if self.interrupted() {
                return Err(CaseError::Interrupted);
            }
            got.extend(self.master.listen_until(until.min(now + STEP_US))?);
        }
        self.tally.line_time_us += ms * 1000;
        if !got.is_empty() {
            let bytes: Vec<u8> = got.iter().map(|c| c.byte).collect();
            self.fail(format!("unsolicited characters [{}]", Hex(&bytes)), clause::NO_UNSOLICITED);
        }
        Ok(())
    }

    /// Now on the line's clock, µs.
    pub fn now_us(&mut self) -> u64 {
        self.master.now_us()
    }

    /// Whether the line can follow the device to another data rate (67h).
    pub fn line_can_change_settings(&self) -> bool {
        self.master.facts().can_change_settings
    }

    /// Whether the line carries a data rate, so that a device at another one than the
    /// harness is heard garbled; `Err` says why not (a pseudo-terminal passes bytes
    /// whatever the rate either end set).
    pub fn line_carries_data_rate(&self) -> Result<(), &'static str> {
        match self.master.facts().kind {
            crate::line::LineKind::PseudoTerminal => Err("a pseudo-terminal carries no data rate"),
            _ => Ok(()),
        }
    }

    /// Whether a parity error can be sent on the line; `Err` says why not.
    pub fn line_carries_parity(&self) -> Result<(), crate::exchange::NoParity> {
        self.master.facts().carries_parity
    }

    pub fn allow_counter_change(&self) -> bool {
        self.options.allow_counter_change
    }

    /// Whether the run may write the device's EEPROM (`--allow-writes`).
    pub fn allow_writes(&self) -> bool {
        self.options.allow_writes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exchange::HeardLate;
    use crate::line::Window;
    use hiperface_model::datalink::RxChar;
    use hiperface_model::UartSettings;

    #[test]
    fn the_part_a_device_heard_of_a_split_request_draws_the_error_it_answered() {
        let frame = [0x40, 0x4D, 0x00, 0x40, 0x55, 0x18];
        let part = |observed: Option<&[u8]>| part_heard(&frame, observed);
        assert_eq!(part(Some(&[0x40, 0x50, 0x0A, 0x1A])), Some(vec![0x40, 0x4D, 0x00, 0x40, 0x55, 0xE7]));
        assert_eq!(part(Some(&[0x40, 0x50, 0x0C, 0x1C])), Some(vec![0x40, 0x4D]));
        assert_eq!(part(None), None);
        // The model's answer to each part is the error the device gave.
        let mut model = Slave::operational(hiperface_model::profiles::srs50());
        for (observed, code) in [([0x40, 0x50, 0x0A, 0x1A], 0x0A), ([0x40, 0x50, 0x0C, 0x1C], 0x0C)] {
            let Some(p) = part(Some(&observed)) else { panic!("a part") };
            let Reply::Frame(reply) = handle(&mut model, &p, false, 0).reply else { panic!("an answer") };
            assert_eq!(reply.encode().as_bytes().get(2), Some(&code), "{observed:02X?}");
        }
    }

    #[test]
    fn a_pause_in_a_reply_is_charged_only_where_it_ended_the_reply_whatever_the_lateness() {
        let ct = UartSettings::DEFAULT.char_time_us();
        let timeout = UartSettings::DEFAULT.timeout_us(hiperface_model::Edition::Current);
        // The reply's last character ended at 10 ms; the next began a timeout + 0.5 ms later.
        let x = |harness_late_us| Exchange {
            request: vec![0x40, 0x42, 0x02],
            stray: Vec::new(),
            sent_start_us: 0,
            request_end: Window::exact(2_000),
            reply: vec![RxChar::ok(0x40, 10_000)],
            reply_start: Some(Window::exact(10_000 - ct)),
            trailing: vec![RxChar::ok(0x42, 10_000 + timeout + 500 + ct)],
            settings: UartSettings::DEFAULT,
            timeout_us: timeout,
            pause_us: timeout,
            harness_late_us,
            request_write_us: 0,
            line_late: Default::default(),
            device_held: Default::default(),
            heard_late: HeardLate::default(),
        };
        assert_eq!(trailing_pause(&x(0)), Some(TrailingPause::Ended));
        assert_eq!(trailing_pause(&x(400)), Some(TrailingPause::Ended));
        // Late by 0.6 ms: the pause between stop and start bit was a timeout - 0.1 ms to
        // a timeout + 1.1 ms: a FAIL or not, which the lateness decides: untold.
        assert_eq!(trailing_pause(&x(600)), Some(TrailingPause::LatenessCouldExplain));
        // Late by more than the character and the half millisecond: lateness explains it.
        assert_eq!(trailing_pause(&x(ct + 600)), Some(TrailingPause::LatenessCouldExplain));
        // Not late at all, a pause of the timeout between character ends but less
        // between stop and start bit: never charged to the harness's lateness.
        let y = Exchange { trailing: vec![RxChar::ok(0x42, 10_000 + timeout + 100)], ..x(0) };
        assert_eq!(trailing_pause(&y), Some(TrailingPause::WithinOneCharacter));
    }
}
