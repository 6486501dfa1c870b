//! The reference master with the encoder model, to a fixpoint (docs/src/verification.md,
//! "The reference master to a fixpoint"): the model's reference master
//! (`hiperface_model::master::reference`) runs against the slave model in virtual time,
//! the observer of the master's obligations (`hiperface_model::master::obligations`)
//! watching every character it sends, and at every request the slave answers the
//! encoder may do any of the acts the master scenarios inject (suite/src/master/
//! scenarios.rs, [`acts`]): answer, an error code instead (not instead of Read Encoder
//! Status's reply, [`applies`]), silence, a wrong checksum, a late reply, a pause inside
//! the reply, a position fault from now on, a restart; in each of the scenarios' worlds
//! ([`worlds`]). The search is breadth-first over a canonical joint state and ends when
//! no new one appears. The master must never break a must of its obligations (an
//! observation on a normative clause that binds the edition: what `certify master`
//! FAILs), never panic and never hang (every step moves the clock on; no step stops
//! the master).
//!
//! The line is the one the harness gives the reference master: the exchanges of
//! `BusMaster` (suite/src/exchange.rs: the request once the line has been quiet for the
//! timeout, the reply framed by the timeout, the pause after it), and the encoder's
//! side as the in-process certification serves it (suite/src/master/in_process.rs and
//! encoder.rs: the reply 300 µs after its earliest start, the act applied to it, the
//! observer told of it). A character that came while the master was not reading is
//! read at once, as a real line gives it (conformance/src/line/clock.rs `read_until`);
//! the harness's virtual line gives it only by its stamp, and there a late reply that
//! arrives during a wait is taken for the next request's reply (docs/src/
//! verification.md says what this search found of it). A test of the harness
//! (conformance/tests/reference_master.rs) checks that, the encoder answering, the
//! master here decides at the instants and asks what it asks on the harness's
//! `BusMaster` over the virtual line.
//!
//! The joint state is taken where the master decides (each action done) and made
//! canonical ([`Joint::canonical`]): the clock moved to [`BASE_US`], every time kept
//! relative to it, a time further back than anything reads it from now on brought
//! forward (`Observer::rebase`, `Slave::rebase`: a power-up long past once the windows
//! of 000:T9 that can still matter are over), and the observer's memory that only the
//! recommendations read forgotten (`Observer::forget_recommendations`): only musts are
//! checked. Nothing else is abstracted: the master's flow (stage, retries, resets, the
//! held reply, the codes read), the slave (stack, faults, locks, power-up), the
//! observer's memory for the musts and the characters on the line stay as they are.

use crate::fixpoint::Fingerprint;
use hiperface_model::fault::{FaultGroup, FAULT_TABLE};
use hiperface_model::master::obligations::{Observation, Observer, Rule};
use hiperface_model::master::reference::{Action, Done, Event, Options, ReferenceMaster, ResetCause, Stage};
use hiperface_model::response::ResponseFrame;
use hiperface_model::slave::act::{Act, Acted, ActedReply};
use hiperface_model::slave::inputs::{InitFault, PhysicalInputs, PositionFault};
use hiperface_model::{
    checksum, profiles, CommandId, FaultCode, Profile, RequestFrame, RxChar, Slave, Step, UartFault, UartSettings,
};
use std::collections::{HashSet, VecDeque};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The error codes the scenarios answer with (0Ah, 0Ch, 09h, 0Bh, 0Dh, 12h, 3Ah).
pub const CATALOGUE_CODES: [u8; 7] = [0x0A, 0x0C, 0x09, 0x0B, 0x0D, 0x12, 0x3A];

/// The acts of the search: the scenarios' (their codes, 30 ms late, a 20 ms and a
/// 4.5 ms pause, the position faults 22h and 20h, a restart) and an error reply with
/// the first code of each fault group of Table 74 that none of them represents
/// (000:T37, 000:T74). `None` first: the model's reply as it is.
pub fn acts() -> Vec<Option<Act>> {
    let mut codes: Vec<FaultCode> = CATALOGUE_CODES.iter().map(|b| FaultCode::decode(*b)).collect();
    for group in
        [FaultGroup::Initialization, FaultGroup::Protocol, FaultGroup::Data, FaultGroup::Position, FaultGroup::Others]
    {
        let represented = |c: &FaultCode| hiperface_model::fault::rows(*c).any(|r| r.group == group);
        if !codes.iter().any(represented) {
            if let Some(row) = FAULT_TABLE.iter().find(|r| r.group == group) {
                codes.push(row.code);
            }
        }
    }
    let mut acts: Vec<Act> = codes.into_iter().map(Act::Error).collect();
    acts.extend([
        Act::Silence,
        Act::CorruptChecksum,
        Act::LateMs(30),
        Act::Gap { before: 3, us: 20_000 },
        Act::Gap { before: 2, us: 4_500 },
        Act::PositionFault(PositionFault::MultiturnSync),
        Act::PositionFault(PositionFault::Singleturn),
        Act::Restart,
    ]);
    core::iter::once(None).chain(acts.into_iter().map(Some)).collect()
}

/// Whether the encoder may do `act` to the reply to `action`'s request: any act to any
/// request, but an error code instead of Read Encoder Status's reply, which reads as
/// a code on the stack (000:T27): what the stack holds is the slave model's, from
/// the worlds' start-up faults and temperature and the position faults injected.
pub fn applies(act: Option<Act>, action: &Action) -> bool {
    match (act, action) {
        (Some(Act::Error(_)), Action::Exchange { request, .. }) => {
            request.request.command() != CommandId::ReadEncoderStatus
        }
        _ => true,
    }
}

/// An encoder at power-on: the scenarios' worlds and encoders.
#[derive(Debug, Clone)]
pub struct World {
    pub name: &'static str,
    pub encoder: Profile,
    pub init_faults: Vec<InitFault>,
    /// Above the profile's temperature limit: 1Eh stacked, the warning bit set.
    pub hot: bool,
}

/// The worlds of the scenarios for an encoder of `profile`: calm; hot (1Eh); four codes
/// stacked (07h, 06h + 08h, 1Eh); a critical start-up fault (04h); type FFh (SKS36
/// with `profile`'s start-up timing, 000:T19); 38400 Bd stored.
pub fn worlds(profile: Profile) -> Vec<World> {
    let world =
        |name, encoder, init_faults: &[InitFault], hot| World { name, encoder, init_faults: init_faults.to_vec(), hot };
    let mut type_ff = profiles::sks36();
    type_ff.init_ms = profile.init_ms;
    type_ff.default_window_ms = profile.default_window_ms;
    type_ff.user_settings_ms = profile.user_settings_ms;
    type_ff.edition = profile.edition;
    let mut stored_38400 = profile;
    stored_38400.settings.baud = hiperface_model::settings::Baud::B38400;
    vec![
        world("calm", profile, &[], false),
        world("hot", profile, &[], true),
        world("four codes stacked", profile, &[InitFault::Watchdog, InitFault::Counter], true),
        world("critical at start", profile, &[InitFault::AnalogLimits], false),
        world("type FFh", type_ff, &[], false),
        world("38400 Bd stored", stored_38400, &[], false),
    ]
}

/// How the master under check steps: the reference master's [`reference_step`], or a
/// mutant's.
pub type MasterStep = fn(&mut ReferenceMaster, Done<'_>, &mut dyn FnMut(Event)) -> Action;

/// The reference master itself.
pub fn reference_step(m: &mut ReferenceMaster, done: Done<'_>, say: &mut dyn FnMut(Event)) -> Action {
    m.next(done, &mut |e| say(e))
}

/// The application's polling period of the search: the reference master's default on
/// the command line (`hiperface master --polling-period-ms`).
pub const POLLING_PERIOD_MS: u64 = 20;

/// The instant the canonical state's clock reads, µs: later than anything the observer
/// looks back (checked when the search starts).
pub const BASE_US: u64 = 10_000_000;

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
struct Seen {
    observations: Vec<Observation>,
    events: Vec<Event>,
    /// The act changed what the encoder did.
    applied: bool,
    /// Something the search does not model happened.
    unmodelled: Option<String>,
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
    /// the line, the observer told (suite/src/master/encoder.rs, `frame`, `reply`,
    /// `sent`).
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
    fn step(&mut self, master_step: MasterStep, act: Option<Act>, seen: &mut Seen) -> Result<(), String> {
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

/// Whether `o` breaks a must: a rule on a normative clause that binds the edition (what
/// `certify master` FAILs; a recommendation or a decision is NON-STRICT).
pub fn is_must(o: &Observation, edition: hiperface_model::Edition) -> bool {
    o.rule.clause().binding(edition).is_some()
}

/// The master's events by kind, for counting which reactions were reached.
pub const EVENT_KINDS: [&str; 13] = [
    "type label",
    "extended type label",
    "version",
    "status code",
    "position",
    "position error",
    "no valid reply",
    "multiturn sync fault",
    "unknown code",
    "resets exhausted",
    "reset: persisting",
    "reset: critical code",
    "reset: unknown code",
];

fn event_kind(e: &Event) -> usize {
    match e {
        Event::TypeLabel { .. } => 0,
        Event::ExtendedTypeLabel { .. } => 1,
        Event::Version(_) => 2,
        Event::Status(_) => 3,
        Event::Position(_) => 4,
        Event::PositionError(_) => 5,
        Event::PositionNoValidReply => 6,
        Event::SyncFault => 7,
        Event::UnknownCode(_) => 8,
        Event::ResetsExhausted => 9,
        Event::Reset(ResetCause::Persisting) => 10,
        Event::Reset(ResetCause::Critical(_)) => 11,
        Event::Reset(ResetCause::Unknown(_)) => 12,
    }
}

/// What a search found.
#[derive(Debug, Clone)]
pub struct Report {
    pub profile: String,
    /// Distinct canonical joint states reached.
    pub states: usize,
    pub transitions: u64,
    /// The longest shortest path to a state, in steps (actions of the master).
    pub depth: usize,
    pub fixpoint: bool,
    /// Transitions in which each act of [`acts`] changed what the encoder did.
    pub acts_applied: Vec<(Option<Act>, u64)>,
    /// Each kind of the master's events ([`EVENT_KINDS`]), how often.
    pub events: [u64; EVENT_KINDS.len()],
    /// Stages the master was in where it decided.
    pub stages: Vec<Stage>,
    /// Transitions with a request before the previous one's reply window closed
    /// (`Rule::ReplyWindow`, a decision of this project: NON-STRICT). The one rule
    /// that is no must whose memory the canonical state keeps whole; the
    /// recommendations' memory is forgotten (`Observer::forget_recommendations`), so
    /// what they would say is not counted.
    pub reply_window: u64,
    pub seconds: f64,
}

impl core::fmt::Display for Report {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{}: {} states, {} transitions, depth {}, {}, {:.1} s",
            self.profile,
            self.states,
            self.transitions,
            self.depth,
            if self.fixpoint { "fixpoint reached" } else { "bounded" },
            self.seconds
        )
    }
}

/// A step of a counterexample: what the master did, what the encoder did to it, and
/// what was seen.
#[derive(Debug, Clone)]
pub struct TraceStep {
    pub at_us: u64,
    pub action: Action,
    pub act: Option<Act>,
    pub events: Vec<Event>,
    pub observations: Vec<Observation>,
}

impl core::fmt::Display for TraceStep {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let ms = self.at_us as f64 / 1000.0;
        match self.action {
            Action::Exchange { request, .. } => {
                let act = self.act.map_or("Answer".into(), |a| format!("{a:?}"));
                write!(f, "{ms:>9.3} ms  {:?} {act}", request.request.command())?
            }
            Action::WaitUntil(t) => write!(f, "{ms:>9.3} ms  wait until {:.3} ms", t as f64 / 1000.0)?,
            Action::Stop => write!(f, "{ms:>9.3} ms  stop")?,
        }
        for e in &self.events {
            write!(f, "; {e:?}")?;
        }
        for o in &self.observations {
            write!(f, "; broke {:?} ({})", o.rule, o.rule.clause().id())?;
        }
        Ok(())
    }
}

/// A must broken (or a panic, a hang), with the steps from power-on that lead to it.
#[derive(Debug, Clone)]
pub struct Counterexample {
    pub what: String,
    pub world: &'static str,
    pub trace: Vec<TraceStep>,
}

impl core::fmt::Display for Counterexample {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        writeln!(f, "{} (world: {}) after {} steps:", self.what, self.world, self.trace.len())?;
        for s in &self.trace {
            writeln!(f, "  {s}")?;
        }
        Ok(())
    }
}

/// How a state was first reached: its parent and the act (an index into the acts),
/// or for a power-on the world's index.
const ROOT: u32 = u32::MAX;

/// The breadth-first search from every world's power-on, the master stepping with
/// `master_step`, until no new canonical state appears (or `max_states`, an error).
pub fn search(profile: Profile, master_step: MasterStep, max_states: usize) -> Result<Report, Counterexample> {
    let started = std::time::Instant::now();
    let worlds = worlds(profile);
    let acts = acts();
    let edition = profile.edition;
    let mut seen_states: HashSet<u128> = HashSet::new();
    let mut parents: Vec<(u32, u16)> = Vec::new();
    let mut queue: VecDeque<(Joint, u32, usize)> = VecDeque::new();
    let mut report = Report {
        profile: profile.name.as_str().to_string(),
        states: 0,
        transitions: 0,
        depth: 0,
        fixpoint: false,
        acts_applied: acts.iter().map(|a| (*a, 0)).collect(),
        events: [0; EVENT_KINDS.len()],
        stages: Vec::new(),
        reply_window: 0,
        seconds: 0.0,
    };
    for (i, w) in worlds.iter().enumerate() {
        let first = Joint::power_on(w);
        let look_back = first.observer.look_back_us();
        let fail = |what: String| Counterexample { what, world: w.name, trace: Vec::new() };
        if look_back > BASE_US {
            return Err(fail(format!("the observer looks back {look_back} µs, past the base {BASE_US} µs")));
        }
        let first = first.canonical();
        if seen_states.insert(Fingerprint::of(&first)) {
            queue.push_back((first, parents.len() as u32, 0));
            parents.push((ROOT, i as u16));
        }
    }
    let counterexample = |parents: &[(u32, u16)], id: u32, last: Option<u16>, what: String| {
        let (world, trace) = replay(&worlds, &acts, master_step, parents, id, last);
        Counterexample { what, world, trace }
    };
    while let Some((state, id, d)) = queue.pop_front() {
        report.depth = report.depth.max(d);
        let stage = state.master.flow().stage;
        if !report.stages.contains(&stage) {
            report.stages.push(stage);
        }
        let choices: &[Option<Act>] = match state.action {
            Action::Exchange { .. } => &acts,
            Action::WaitUntil(_) => &acts[..1],
            // With no duration the master never stops: a stop is a hang.
            Action::Stop => return Err(counterexample(&parents, id, None, "the master stopped".into())),
        };
        for (a, &act) in choices.iter().enumerate() {
            if !applies(act, &state.action) {
                continue;
            }
            let mut next = state.clone();
            let mut seen = Seen::default();
            if let Err(what) = next.step(master_step, act, &mut seen) {
                return Err(counterexample(&parents, id, Some(a as u16), what));
            }
            // An act that changed nothing is the answer's transition again.
            if a > 0 && !seen.applied {
                continue;
            }
            report.transitions += 1;
            if let Some(what) = seen.unmodelled {
                return Err(counterexample(&parents, id, Some(a as u16), format!("not modelled: {what}")));
            }
            let exchange = matches!(state.action, Action::Exchange { .. });
            if let Some(slot) = report.acts_applied.get_mut(a).filter(|_| seen.applied || (a == 0 && exchange)) {
                slot.1 += 1;
            }
            for e in &seen.events {
                if let Some(n) = report.events.get_mut(event_kind(e)) {
                    *n += 1;
                }
            }
            for o in &seen.observations {
                if is_must(o, edition) {
                    let what = format!("must broken: {:?} ({}, {})", o.rule, o.rule.clause().id(), o.rule.text());
                    return Err(counterexample(&parents, id, Some(a as u16), what));
                }
                if o.rule == Rule::ReplyWindow {
                    report.reply_window += 1;
                }
            }
            // Never hangs: every step moves the clock on.
            if next.line.now_us <= state.line.now_us {
                let what = format!("the master's step took no time ({:?})", state.action);
                return Err(counterexample(&parents, id, Some(a as u16), what));
            }
            let canonical = next.canonical();
            if seen_states.insert(Fingerprint::of(&canonical)) {
                if parents.len() >= max_states {
                    let what = format!("no fixpoint within {max_states} states");
                    return Err(counterexample(&parents, id, None, what));
                }
                queue.push_back((canonical, parents.len() as u32, d + 1));
                parents.push((id, a as u16));
            }
        }
    }
    report.states = seen_states.len();
    report.fixpoint = true;
    report.seconds = started.elapsed().as_secs_f64();
    Ok(report)
}

/// The steps from power-on to state `id` (and the act `last` from it), replayed in
/// concrete time (nothing canonical): the world's name and the steps.
fn replay(
    worlds: &[World],
    acts: &[Option<Act>],
    master_step: MasterStep,
    parents: &[(u32, u16)],
    id: u32,
    last: Option<u16>,
) -> (&'static str, Vec<TraceStep>) {
    let mut path: Vec<u16> = last.into_iter().collect();
    let mut i = id;
    let mut world = 0;
    while let Some(&(p, e)) = parents.get(i as usize) {
        if p == ROOT {
            world = e;
            break;
        }
        path.push(e);
        i = p;
    }
    path.reverse();
    let Some(w) = worlds.get(world as usize) else { return ("?", Vec::new()) };
    let path = path.into_iter().map(|a| acts.get(a as usize).copied().flatten());
    (w.name, play(w, master_step, path))
}

/// The master's steps from power-on in `world`, the encoder doing the `acts` in turn
/// (one per step; a wait takes one too), in concrete time.
pub fn play(w: &World, master_step: MasterStep, acts: impl IntoIterator<Item = Option<Act>>) -> Vec<TraceStep> {
    let mut state = Joint::power_on(w);
    let mut trace = Vec::new();
    for act in acts {
        let mut seen = Seen::default();
        let (at_us, action) = (state.line.now_us, state.action);
        let _ = state.step(master_step, act, &mut seen);
        let exchange = matches!(action, Action::Exchange { .. });
        let observations = seen.observations.iter().filter(|o| is_must(o, w.encoder.edition)).copied().collect();
        trace.push(TraceStep { at_us, action, act: act.filter(|_| exchange), events: seen.events, observations });
    }
    trace
}

/// Deliberate defects, for showing what the search catches. Never the reference
/// master's behaviour: only a [`MasterStep`] passed to [`search`] runs them.
pub mod mutant {
    use super::*;
    use hiperface_model::master::reference::Aside;

    /// After Encoder Reset the master does not wait the timeout plus the
    /// initialization time (000:T29): it reads the status at once.
    pub fn no_reset_wait(m: &mut ReferenceMaster, done: Done<'_>, say: &mut dyn FnMut(Event)) -> Action {
        let action = m.next(done, &mut |e| say(e));
        match action {
            Action::WaitUntil(_) if m.flow().aside == Aside::ResetWait => {
                let now_us = m.flow().now_us;
                m.next(Done::Waited { now_us }, &mut |e| say(e))
            }
            other => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(profile: Profile, master_step: MasterStep) -> Result<Report, Counterexample> {
        let r = search(profile, master_step, 2_000_000);
        match &r {
            Ok(r) => eprintln!("{r}; {} with a request inside a reply window (DESIGN:reply-window)", r.reply_window),
            Err(c) => eprintln!("{c}"),
        }
        r
    }

    /// Every act changed what the encoder did somewhere, and every reaction of the
    /// master was reached: the search is not vacuous.
    fn covers_every_act_and_reaction(r: &Report) {
        for (act, n) in &r.acts_applied {
            assert!(*n > 0, "{act:?} never applied: {r}");
        }
        for (kind, n) in EVENT_KINDS.iter().zip(r.events) {
            assert!(n > 0, "the master never reached '{kind}': {r}");
        }
        for stage in [
            Stage::StartUpStatus,
            Stage::TypeLabel,
            Stage::ExtendedTypeLabel,
            Stage::Version,
            Stage::Position { attempt: hiperface_model::master::reference::RETRIES },
            Stage::CycleReset,
            Stage::Period,
            Stage::StoppedWait,
            Stage::StoppedStatus,
        ] {
            assert!(r.stages.contains(&stage), "{stage:?} never reached: {r}");
        }
    }

    /// The current edition (SEK37): the reference master never breaks a must, never
    /// panics or hangs, and the search ends because no new joint state appears.
    #[test]
    fn the_reference_master_to_a_fixpoint_current_edition() {
        let r = run(profiles::sek37(), reference_step).unwrap_or_else(|c| panic!("{c}"));
        assert!(r.fixpoint && r.to_string().contains("fixpoint reached"), "{r}");
        covers_every_act_and_reaction(&r);
        documented(&r, "current (SEK37)");
    }

    /// The legacy edition (002).
    #[test]
    fn the_reference_master_to_a_fixpoint_legacy_edition() {
        let r = run(profiles::legacy_srs(), reference_step).unwrap_or_else(|c| panic!("{c}"));
        assert!(r.fixpoint && r.to_string().contains("fixpoint reached"), "{r}");
        covers_every_act_and_reaction(&r);
        documented(&r, "legacy (Legacy-SRS)");
    }

    /// The book's table says what this search finds (docs/src/verification.md).
    fn documented(r: &Report, row: &str) {
        let documented = crate::documented::figures("The reference master to a fixpoint", row).unwrap();
        let found = [r.states as u64, r.transitions, r.depth as u64];
        assert_eq!(documented, found, "the book's figures for {row} (states, transitions, levels) against {r}");
    }

    /// A master that talks at once after Encoder Reset is caught, with a short trace
    /// that ends in its request inside the initialization (000:T29).
    #[test]
    fn a_master_that_does_not_wait_after_reset_is_caught() {
        let c = run(profiles::sek37(), mutant::no_reset_wait).expect_err("the mutant breaks a must");
        assert!(c.what.contains("TooSoonAfterReset") && c.what.contains("000:T29/master"), "{c}");
        let last = c.trace.last().expect("a trace");
        assert!(
            matches!(last.action, Action::Exchange { request, .. } if request.request.command() == CommandId::ReadEncoderStatus),
            "{c}"
        );
        assert!(c.trace.iter().any(|s| s.events.iter().any(|e| matches!(e, Event::Reset(_)))), "{c}");
        assert!(c.trace.len() <= 12, "a short trace: {c}");
    }
}
