//! What a case sees: the master on the line, the model in lockstep, the oracle, and
//! the case's findings. Every exchange goes through [`Ctx::send_frame`], which grades
//! the answer, its timing and anything unsolicited.

use super::timing;
use super::{CaseError, CaseResult, CaseVerdict, Finding, Identity, Options, WireEntry};
use crate::exchange::{sealed, BusMaster, Exchange};
use crate::line::Line;
use hiperface_model::address::AddressByte;
use hiperface_model::clause::{self, Normative};
use hiperface_model::request::{Request, RequestFrame};
use hiperface_model::response::ResponseFrame;
use hiperface_model::{CommandId, Grading, Hex, Oracle, Profile, Reply, Slave};
use std::collections::BTreeMap;
use std::sync::atomic::Ordering;

/// What the harness checks on every exchange of every case, besides the oracle's grade
/// of the reply: no characters outside a reply, and the reply's end (see `exchange`).
pub const EVERY_EXCHANGE: [Normative; 2] = [clause::NO_UNSOLICITED, clause::REPLY_END];

/// What the run accumulates across cases.
#[derive(Debug, Default)]
pub(crate) struct Tally {
    /// Response times per command byte (the most the line's uncertainty allows), µs.
    pub response_times: BTreeMap<u8, Vec<i64>>,
    /// The physical minimum of the wire log: what a perfect master would need, µs.
    pub physical_min_us: u64,
    /// The device has answered at least once in this run.
    pub answered_any: bool,
    /// What the device said of itself.
    pub identity: Identity,
    /// What the harness could not vouch for (its own bookkeeping), for the report.
    pub notes: Vec<String>,
    /// The longest the harness woke late in any exchange, µs.
    pub harness_late_us: u64,
}

/// What a request costs on a real line at best (an ideal master, the device's own
/// response time): the request, the slave's timeout, the reply (or, for silence,
/// the whole response time and one character) and the pause after it. The sum over a run is the physical minimum a report compares its
/// wall time with.
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

/// Whether the pause before an exchange's trailing characters could be the harness's
/// own lateness: as read it is at least the timeout, but less without the time the
/// harness may have noticed them late.
fn pause_explained_by_lateness(x: &Exchange) -> bool {
    let (Some(last), Some(next)) = (x.reply.last(), x.trailing.first()) else { return false };
    let pause = next.at_us.saturating_sub(x.settings.char_time_us()).saturating_sub(last.at_us);
    pause.saturating_sub(x.harness_late_us) < x.timeout_us
}

/// The frame of `request` to the address byte `address`.
fn frame(address: u8, request: Request) -> Vec<u8> {
    RequestFrame::new(AddressByte::decode(address), request).encode().as_bytes().to_vec()
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
    master: &'a mut BusMaster<Box<dyn Line>>,
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
        master: &'a mut BusMaster<Box<dyn Line>>,
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

    /// Record a finding; the case verdict is the worst of its findings.
    pub fn push(&mut self, finding: Finding) {
        self.result.push(finding);
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

    fn transmit(&mut self, frame: &[u8], wrong_parity: bool) -> Result<Graded, CaseError> {
        if self.interrupted() {
            return Err(CaseError::Interrupted);
        }
        // Talk in the settings the slave listens with now (67h, reset, power-up windows).
        let now = self.master.now_us();
        if let Some(s) = self.model.listening_settings(now).filter(|s| *s != self.master.line.settings()) {
            self.master.line.configure(s)?;
        }
        let command = (frame.len() > 1).then(|| CommandId::of_frame(frame));
        let limits = self.model.profile().response_limit(command.unwrap_or(CommandId::Unknown(0)));
        let before = self.model.clone();
        // Where the model expects a reply, listen well past the limit so that a late
        // reply is measured and graded; where it expects silence, only to the limit.
        let estimate = self.master.now_us()
            + frame.len() as u64 * self.master.line.settings().char_time_us()
            + self.master.timeout_us();
        let handle = |s: &mut Slave, at_us| {
            if wrong_parity {
                s.handle_faulty_frame(frame, at_us)
            } else {
                s.handle_frame(frame, at_us)
            }
        };
        let expects_reply = matches!(handle(&mut before.clone(), estimate).reply, Reply::Frame(_));
        let listen_ms = if expects_reply { timing::reply_awaited_ms(limits) } else { limits.max_ms };
        let x = if wrong_parity {
            self.master.exchange_with_wrong_parity(frame, listen_ms)?
        } else {
            self.master.exchange(frame, listen_ms)?
        };
        let expected = handle(self.model, x.complete_us());
        if self.model.eeprom_writes() > self.options.write_budget {
            return Err(CaseError::Budget(self.options.write_budget));
        }
        let observed = x.reply_bytes();
        self.tally.answered_any |= observed.is_some();
        if !self.tally.answered_any && matches!(expected.reply, Reply::Frame(_)) {
            // Never a word from the device: it is not there, not powered, or at another
            // address or data rate. The harness cannot run the case.
            return Err(CaseError::Silent);
        }
        self.log(frame, &x, observed.as_deref());
        self.tally.harness_late_us = self.tally.harness_late_us.max(x.harness_late_us);
        self.tally.physical_min_us += physical_time_us(&x, limits.max_ms);
        if let (Some(cmd), Some(t)) = (command, timing::at_most_us(&x)) {
            self.tally.response_times.entry(cmd.byte()).or_default().push(t);
        }
        let grade = self.oracle.grade(&before, frame, x.complete_us(), &expected, observed.as_deref());
        let graded = CaseVerdict::from(grade.verdict());
        if let (Some(bytes), Some(cmd)) = (&observed, command) {
            self.learn(cmd, bytes, graded);
        }
        let mut found: Vec<Finding> = Finding::graded(&grade, frame).into_iter().collect();
        let edition = self.model.profile().edition;
        if !x.stray.is_empty() {
            let bytes: Vec<u8> = x.stray.iter().map(|c| c.byte).collect();
            let msg = format!("{} characters [{}] arrived outside any reply", bytes.len(), Hex(&bytes));
            found.push(Finding::fail(msg, clause::NO_UNSOLICITED, edition));
        }
        if !x.trailing.is_empty() {
            let bytes: Vec<u8> = x.trailing.iter().map(|c| c.byte).collect();
            found.push(if x.reply.is_empty() {
                let msg = format!("{} characters [{}] arrived after the reply window", bytes.len(), Hex(&bytes));
                Finding::fail(msg, clause::NO_UNSOLICITED, edition)
            } else if pause_explained_by_lateness(&x) {
                self.disturbed = true;
                Finding::unknown(format!(
                    "cannot tell whether the reply had a pause of the timeout inside: {} more characters [{}] \
                     came after one as read, but the harness itself was up to {:.3} ms late",
                    bytes.len(),
                    Hex(&bytes),
                    x.harness_late_us as f64 / 1000.0
                ))
            } else {
                let msg = format!(
                    "the reply went on after a pause of at least the timeout: {} more characters [{}]",
                    bytes.len(),
                    Hex(&bytes)
                );
                Finding::fail(msg, clause::REPLY_END, edition)
            });
        }
        if matches!(expected.reply, Reply::Frame(_)) {
            let tol = self.master.line.tolerance_us();
            let timing = timing::grade(&x, limits, tol, self.options.timing, edition);
            // Timing is UNKNOWN only where the harness's lateness could explain it.
            self.disturbed |= timing.iter().any(|f| f.verdict() == CaseVerdict::Unknown);
            found.extend(timing);
        }
        // The exchange's verdict is the worst of its findings, as the case's is.
        let verdict = found.iter().fold(graded, |v, f| v.worst(f.verdict()));
        for f in found {
            self.push(f);
        }
        if let Some(s) = expected.then_settings {
            self.master.line.configure(s)?;
        }
        Ok(Graded { exchange: x, verdict, reply: observed })
    }

    fn log(&mut self, frame: &[u8], x: &Exchange, observed: Option<&[u8]>) {
        self.result.exchanges += 1;
        let t_us = x.request_end.earliest_us;
        self.result.wire.push(WireEntry { t_us, direction: "M>", bytes: Hex(frame).to_string() });
        if let (Some(bytes), Some(start)) = (observed, x.reply_start) {
            let t_us = start.earliest_us;
            self.result.wire.push(WireEntry { t_us, direction: "S<", bytes: Hex(bytes).to_string() });
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
        self.tally.physical_min_us += ms * 1000;
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
        self.master.line.can_change_settings()
    }

    /// Whether a parity error can be sent on the line; `Err` says why not.
    pub fn line_carries_parity(&self) -> Result<(), &'static str> {
        self.master.line.carries_parity()
    }

    pub fn allow_counter_change(&self) -> bool {
        self.options.allow_counter_change
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
    fn a_pause_in_a_reply_is_charged_only_beyond_the_harness_lateness() {
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
            harness_late_us,
            heard_late: HeardLate::default(),
        };
        assert!(!pause_explained_by_lateness(&x(0)));
        assert!(!pause_explained_by_lateness(&x(400)));
        assert!(pause_explained_by_lateness(&x(600)));
    }
}
