//! The joint state where the master decides, and its step: the reference master's
//! action done on the line in virtual time, the slave model answering, the encoder
//! doing the act chosen to its reply, the observer of the master's obligations told of
//! every character (the module documentation says which line this is); and the state
//! made canonical.

use super::{MasterStep, World, BASE_US, POLLING_PERIOD_MS};
use hiperface_model::master::obligations::{Observation, Observer};
use hiperface_model::master::reference::{Action, Done, Event, Options, ReferenceMaster};
use hiperface_model::response::ResponseFrame;
use hiperface_model::slave::act::{Act, Acted, ActedReply};
use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::{checksum, CommandId, RequestFrame, RxChar, Slave, Step, UartFault, UartSettings};
use std::collections::VecDeque;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The master's data rate: it never changes the settings (000:T7).
const MASTER: UartSettings = UartSettings::DEFAULT;

/// After a reply's last character, when the serving encoder plans it (suite/src/serve.rs
/// `REPLY_DELAY_US`).
const REPLY_DELAY_US: u64 = 300;

/// The line between the two, in virtual time, and what the master's `BusMaster` keeps.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Line {
    pub now_us: u64,
    /// The end of the last activity the master saw: its next request waits a timeout
    /// after it (000:2.2.2).
    pub idle_since_us: u64,
    /// The encoder's characters on their way to the master, or arrived and not yet
    /// read: (byte, end of its stop bit).
    pub inbound: VecDeque<(u8, u64)>,
    /// When the encoder's last reply ends.
    pub encoder_free_us: u64,
    /// The settings the encoder listened at when the master's last character came.
    pub listening: Option<UartSettings>,
}

/// The joint state where the master decides: its next action not yet done.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Joint {
    pub master: ReferenceMaster,
    pub action: Action,
    pub slave: Slave,
    pub observer: Observer,
    pub line: Line,
}

/// What one step showed, besides the state it leads to.
#[derive(Debug, Default)]
pub(super) struct Seen {
    pub(super) observations: Vec<Observation>,
    pub(super) events: Vec<Event>,
    /// The act changed what the encoder did.
    pub(super) applied: bool,
    /// Something the search does not model happened.
    pub(super) unmodelled: Option<String>,
}

impl Joint {
    /// Power-on of the encoder in `world` and of the master (both at 0).
    pub fn power_on(world: &World) -> Joint {
        let encoder = world.encoder;
        let mut slave = Slave::new(encoder);
        if world.hot {
            let inputs = PhysicalInputs { temperature_c: encoder.temperature_max_c + 5, ..PhysicalInputs::default() };
            slave.set_inputs(inputs);
        }
        slave.power_up_with(world.init_faults.iter().copied(), false);
        let mut observer = Observer::new(encoder);
        observer.power_on(0);
        let options = Options { polling_period_ms: POLLING_PERIOD_MS, duration_ms: None };
        let mut master = ReferenceMaster::new(encoder, options);
        let action = master.power_on();
        let line = Line { now_us: 0, idle_since_us: 0, inbound: VecDeque::new(), encoder_free_us: 0, listening: None };
        Joint { master, action, slave, observer, line }
    }

    fn edition(&self) -> hiperface_model::Edition {
        self.slave.profile().edition
    }

    fn timeout_us(&self) -> u64 {
        MASTER.timeout_us(self.edition())
    }

    /// Let the encoder act on everything due up to `t_us` (its frames' timeouts and the
    /// power-up windows), and the observer see the time.
    fn advance(&mut self, t_us: u64, act: Option<Act>, seen: &mut Seen) {
        while let Some(d) = self.slave.next_deadline(self.line.now_us).filter(|d| *d <= t_us) {
            if let Some(step) = self.slave.poll(d) {
                self.encoder_step(step, d, act, seen);
            }
            self.observer.poll(d, &mut |o| seen.observations.push(o));
            if self.slave.next_deadline(d) == Some(d) {
                break;
            }
            self.line.now_us = self.line.now_us.max(d);
        }
        self.observer.poll(t_us, &mut |o| seen.observations.push(o));
        self.line.now_us = self.line.now_us.max(t_us);
    }

    /// The next of the encoder's characters to reach the master by `until_us`, the time
    /// moved on to it (or to `until_us` when none comes). A character that came while
    /// the master was not reading (a wait) is read at once, stamped when it is read, as
    /// a real line gives it (conformance/src/line/clock.rs, `read_until`).
    fn recv(&mut self, until_us: u64, act: Option<Act>, seen: &mut Seen) -> Option<(u8, u64)> {
        loop {
            let now = self.line.now_us;
            if let Some((byte, at)) = self.line.inbound.front().copied().filter(|c| c.1 <= until_us.max(now)) {
                self.advance(at, act, seen);
                self.line.inbound.pop_front();
                return Some((byte, at.max(now)));
            }
            match self.slave.next_deadline(now).filter(|d| *d <= until_us && *d > now) {
                Some(d) => self.advance(d, act, seen),
                None => {
                    if self.line.inbound.front().is_some_and(|c| c.1 <= until_us) {
                        continue;
                    }
                    self.advance(until_us, act, seen);
                    return None;
                }
            }
        }
    }

    /// The encoder processed a frame at `now_us`: the act on its reply, the reply on
    /// the line, the observer told (suite/src/master/encoder/hooks.rs, `frame`,
    /// `reply`, `sent`).
    fn encoder_step(&mut self, step: Step, now_us: u64, act: Option<Act>, seen: &mut Seen) {
        let bytes = step.received.bytes.as_bytes();
        let answered = RequestFrame::decode(bytes).ok().map(|r| r.request.command());
        if let (Some(f), Some(_)) = (act.and_then(Act::position_fault), answered) {
            if !seen.applied {
                self.slave.inject_position_fault(f, true);
                seen.applied = true;
            }
        }
        let Some(tx) = step.transmission else { return };
        let mut reply = ActedReply { frame: tx.frame, start_us: tx.earliest_start_us + REPLY_DELAY_US, gap: None };
        if let Some(act) = act.filter(|a| !seen.applied && a.position_fault().is_none()) {
            seen.applied = true;
            let address = bytes.first().copied().unwrap_or(0x40);
            match act.apply(address, &mut reply) {
                Acted::Sent => {}
                Acted::Silent => return,
                Acted::Restart => {
                    // The master cannot know: the observer is not told of this power-on.
                    self.slave.power_cycle(step.received.complete_us);
                    return;
                }
            }
        }
        let (frame, start, gap) = (reply.frame.as_bytes().to_vec(), reply.start_us, reply.gap);
        if tx.settings != MASTER {
            seen.unmodelled = Some(format!("a reply at {:?}, the master listens at {MASTER:?}", tx.settings));
        }
        let start = start.max(now_us).max(self.line.encoder_free_us);
        let ct = tx.settings.char_time_us();
        let mut end = start;
        for (i, &byte) in frame.iter().enumerate() {
            if let Some((_, us)) = gap.filter(|(before, _)| *before == i) {
                end += us;
            }
            end += ct;
            self.line.inbound.push_back((byte, end));
        }
        self.line.encoder_free_us = end;
        // A pause of the timeout or more: two transmissions; the first is no reply the
        // master can read (000:2.2.2).
        let timeout = tx.settings.timeout_us(self.edition());
        if let Some((before, _)) = gap.filter(|(_, us)| *us >= timeout) {
            self.observer.encoder_reply(start, start + before as u64 * ct, None);
            return;
        }
        let reply = ResponseFrame::decode(&frame, answered.unwrap_or(CommandId::Unknown(0))).ok();
        self.observer.encoder_reply(start, end, reply.as_ref());
    }

    /// The master sends `bytes` from `start_us`: each character to the observer and to
    /// the encoder, at the end of its stop bit. The end of the last one.
    fn send(&mut self, bytes: &[u8], start_us: u64, act: Option<Act>, seen: &mut Seen) -> u64 {
        let ct = MASTER.char_time_us();
        let mut last = start_us;
        for (i, &byte) in bytes.iter().enumerate() {
            last = start_us + (i as u64 + 1) * ct;
            self.advance(last.saturating_sub(1), act, seen);
            let listening = self.slave.listening_settings(last);
            if listening != self.line.listening {
                if let Some(s) = listening {
                    self.observer.encoder_listens(s);
                }
                self.line.listening = listening;
            }
            if let (0, Some(s)) = (i, listening) {
                let frame_start = last.saturating_sub(s.char_time_us());
                self.observer
                    .master_data_rate(frame_start, MASTER.baud.bits_per_second(), &mut |o| seen.observations.push(o));
            }
            self.observer.master_char(RxChar::ok(byte, last), &mut |o| seen.observations.push(o));
            // A character in other settings than the encoder's reaches it with a fault.
            let fault = listening.filter(|s| *s != MASTER).map(|_| UartFault::Framing);
            if let Some(step) = self.slave.receive(RxChar { byte, at_us: last, fault }) {
                self.encoder_step(step, last, act, seen);
            }
        }
        self.line.now_us = self.line.now_us.max(last);
        last
    }

    /// One exchange as `BusMaster::exchange` does it (suite/src/exchange.rs), the
    /// encoder doing `act` to its reply: the reply's bytes and the request's end.
    fn exchange(&mut self, request: &[u8], listen_ms: u16, act: Option<Act>, seen: &mut Seen) -> (Vec<u8>, u64) {
        const MAX_FRAME: u64 = hiperface_model::frame::MAX_FRAME as u64;
        let timeout = self.timeout_us();
        let ct = MASTER.char_time_us();
        let now = self.line.now_us;
        let mut ready = (self.line.idle_since_us + timeout).min(now + MAX_FRAME * ct + timeout);
        let mut stray = 0;
        while let Some(c) = self.recv(ready, act, seen) {
            if stray < 2 * MAX_FRAME {
                ready = ready.max(c.1 + timeout);
            }
            stray += 1;
        }
        self.advance(ready, act, seen);
        let sent_start = self.line.now_us;
        let request_end = self.send(request, sent_start, act, seen);
        let complete = request_end + timeout;
        let deadline = complete + listen_ms as u64 * 1000 + ct;
        let mut reply: Vec<(u8, u64)> = Vec::new();
        if let Some(first) = self.recv(deadline, act, seen) {
            reply.push(first);
            // Further characters until a pause of the timeout (the data link's rule).
            let mut link = hiperface_model::DataLink::new(timeout);
            link.receive(RxChar::ok(first.0, first.1));
            while let Some(until) = link.deadline().filter(|_| (reply.len() as u64) < 2 * MAX_FRAME) {
                match self.recv(until.saturating_sub(1), act, seen) {
                    Some(c) => {
                        link.receive(RxChar::ok(c.0, c.1));
                        reply.push(c);
                    }
                    None => break,
                }
            }
        }
        let mut end = reply.last().map_or(complete.max(self.line.now_us), |c| c.1);
        let bytes: Vec<u8> = reply.iter().map(|c| c.0).collect();
        let cut = !bytes.is_empty() && (bytes.len() < 3 || !checksum::is_valid(&bytes));
        let pause = if cut { timeout.max(listen_ms as u64 * 1000) } else { timeout };
        let mut trailing = 0;
        while trailing < 2 * MAX_FRAME {
            match self.recv(end + pause, act, seen) {
                Some(c) => {
                    end = c.1;
                    trailing += 1;
                }
                None => break,
            }
        }
        self.line.idle_since_us = end;
        (bytes, request_end)
    }

    /// Do the master's action, the encoder doing `act` to the reply; the master's next
    /// action. `Err`: the master panicked.
    pub(super) fn step(&mut self, master_step: MasterStep, act: Option<Act>, seen: &mut Seen) -> Result<(), String> {
        let done_action = self.action;
        let (reply, request_end) = match done_action {
            Action::Stop => return Ok(()),
            Action::WaitUntil(t) => {
                let t = t.max(self.line.now_us);
                self.advance(t, act, seen);
                (None, 0)
            }
            Action::Exchange { request, listen_ms } => {
                let (bytes, end) = self.exchange(request.encode().as_bytes(), listen_ms, act, seen);
                (Some(bytes), end)
            }
        };
        let now_us = self.line.now_us;
        let done = match &reply {
            None => Done::Waited { now_us },
            Some(bytes) => {
                Done::Exchanged { now_us, request_end_us: request_end, timeout_us: self.timeout_us(), reply: bytes }
            }
        };
        let master = &mut self.master;
        let events = &mut seen.events;
        let next = catch_unwind(AssertUnwindSafe(|| master_step(master, done, &mut |e| events.push(e))));
        self.action = next.map_err(|_| format!("the master panicked after {done_action:?}"))?;
        Ok(())
    }

    /// The canonical state of this one's class: the clock at [`BASE_US`], every time
    /// relative to it, times that nothing reads any more brought forward, the model's
    /// bookkeeping cleared (`Slave::rebase`, `Observer::rebase`).
    pub fn canonical(&self) -> Joint {
        let now = self.line.now_us;
        let moved = |t: u64| t.saturating_add(BASE_US).saturating_sub(now);
        let mut c = self.clone();
        c.slave.reset_eeprom_writes();
        c.slave.rebase(now, BASE_US);
        c.observer.forget_recommendations();
        c.observer.rebase(now, BASE_US);
        c.master.flow_mut().now_us = BASE_US;
        c.action = match self.action {
            Action::WaitUntil(t) => Action::WaitUntil(moved(t.max(now))),
            other => other,
        };
        let timeout = self.timeout_us();
        // The line free long ago reads as free a timeout ago, unless characters still to
        // come are measured against it.
        let idle = if self.line.inbound.is_empty() {
            self.line.idle_since_us.max(now.saturating_sub(timeout))
        } else {
            self.line.idle_since_us
        };
        c.line = Line {
            now_us: BASE_US,
            idle_since_us: moved(idle),
            inbound: self.line.inbound.iter().map(|(b, t)| (*b, moved(*t))).collect(),
            encoder_free_us: moved(self.line.encoder_free_us.max(now)),
            listening: self.line.listening,
        };
        c
    }
}
