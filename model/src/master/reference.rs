//! The reference master as a sans-IO state machine: the start-up flow of 000:3.3.1
//! (Figure 17), cyclic Read Position, the warning's codes read out (000:2.3.4) and the
//! fault reaction of Table 74 (000:T74). It decides what to send and how long to wait;
//! a driver runs its [`Action`]s on a line (the harness's `hiperface master`, on a real
//! or virtual line) or in a model checker (proofs/src/master_fixpoint/), and tells it
//! what each one gave ([`Done`]). What it tells the operator comes out as [`Event`]s.
//!
//! Long because: the start-up flow, the cyclic reads and the fault reaction are one
//! state machine whose stages hand over to each other, read as Figure 17 is; under 550
//! lines without its tests.
//!
//! The flow, as the harness's reference master has always run it:
//!
//! - start-up: wait for the initialization (000:T9) and a margin, read the status
//!   until the stack is empty and react to the codes read (000:3.3.1), read the type
//!   label and, for type FFh, the Extended Type Label (000:T19), read the version;
//! - then cyclically: Read Position, retried up to [`RETRIES`] times after a protocol
//!   error or a reply it cannot read, then a SW reset (000:T74 "If error persists, SW
//!   reset of Slave"); a critical code whose reaction is a reset, and an unknown code
//!   (000:3.3.4, worst case), reset at once; after [`RESETS`] resets, or on 22h
//!   ("Only use sine/cosine based position until shut-down"), position reads stop and
//!   the status is read every [`STOPPED_STATUS_PERIOD_US`];
//! - every reply with the warning bit has the stack read out before anything else
//!   (000:2.3.4); after a reset the master waits the timeout plus the initialization
//!   time (000:T29) and reads the status again.
//!
//! Allocation-free and without panics: the codes read from the stack are a fixed
//! array, every state is a plain value ([`Flow`]), so that a model checker can keep
//! and compare it.

use crate::address::AddressByte;
use crate::checksum;
use crate::command::CommandId;
use crate::fault::{self, FaultCode};
use crate::master::fault_reaction::{self, Reaction};
use crate::profile::Profile;
use crate::request::{Request, RequestFrame};
use crate::response::{Response, ResponseFrame, Version};

/// Retries of one request before a SW reset (000:T74 "If error persists, SW reset").
pub const RETRIES: u8 = 3;
/// SW resets before the master gives up position reads (worst case: motor stop).
pub const RESETS: u8 = 3;
/// How long after the initialization time the master starts talking: a margin for
/// its own start, µs. Also after a reset's wait (000:T29).
pub const START_MARGIN_US: u64 = 20_000;
/// How often the status is read once position reads have stopped, µs.
pub const STOPPED_STATUS_PERIOD_US: u64 = 100_000;
/// Read Encoder Status at most this often in one read-out: the stack holds four codes
/// (000:2.3.4), and one more read finds it empty.
pub const STATUS_READS: u8 = 5;
/// How long past the command's maximum response time the master listens for a reply,
/// ms (000:T10's limit plus a margin for the line).
pub const LISTEN_MARGIN_MS: u16 = 10;

/// How the reference master runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Options {
    /// Period of Read Position, ms.
    pub polling_period_ms: u64,
    /// Stop after this long (line time), ms; `None`: for ever.
    pub duration_ms: Option<u64>,
}

/// What the master does next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Action {
    /// Send `request` once the line is free (a pause of the timeout after the last
    /// transmission, 000:2.2.2) and listen for its reply until `listen_ms` after the
    /// request's timeout; then [`Done::Exchanged`].
    Exchange { request: RequestFrame, listen_ms: u16 },
    /// Wait until this time (µs of the line's clock); then [`Done::Waited`].
    WaitUntil(u64),
    /// The run's duration is over: nothing more.
    Stop,
}

/// What the last [`Action`] gave.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Done<'a> {
    /// The wait is over; the line's clock reads `now_us`.
    Waited { now_us: u64 },
    /// The exchange is over.
    Exchanged {
        now_us: u64,
        /// When the request's last character was complete (the latest the line can
        /// say), µs.
        request_end_us: u64,
        /// The slave's frame timeout on the line, µs (000:2.2.2).
        timeout_us: u64,
        /// The reply's bytes as framed on the line; empty when nothing came.
        reply: &'a [u8],
    },
}

impl Done<'_> {
    pub fn now_us(&self) -> u64 {
        match *self {
            Done::Waited { now_us } | Done::Exchanged { now_us, .. } => now_us,
        }
    }
}

/// Why the master resets the encoder (53h).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ResetCause {
    /// Read Position failed after its retries. // 000:T74 "If error persists"
    Persisting,
    /// A code whose reaction is a SW reset. // 000:T74
    Critical(FaultCode),
    /// A code Table 74 does not know: the worst case. // 000:3.3.4
    Unknown(FaultCode),
}

/// What the master tells the operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Event {
    /// The type label's type code (000:T19).
    TypeLabel {
        type_code: u8,
    },
    /// The Extended Type Label read (field FFh): how many bytes, and whether their
    /// checksum is right.
    ExtendedTypeLabel {
        bytes: usize,
        checksum_ok: bool,
    },
    Version(Version),
    /// A code read from the stack.
    Status(FaultCode),
    Position(u32),
    /// Read Position answered with an error code.
    PositionError(FaultCode),
    /// Read Position got no reply, or one that does not decode.
    PositionNoValidReply,
    /// 22h: position reads stop (sin/cos only). // 000:T74
    SyncFault,
    /// A code Table 74 does not know: the worst-case reaction follows. // 000:3.3.4
    UnknownCode(FaultCode),
    /// The fault persisted after [`RESETS`] resets: position reads stop.
    ResetsExhausted,
    /// Encoder Reset (53h) sent.
    Reset(ResetCause),
}

/// Where the master is in its flow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Waiting out the initialization after power-on. // 000:3.3.1
    Initializing,
    /// The status read of the start-up; the type label next.
    StartUpStatus,
    /// Read Type Label asked. // 000:T19
    TypeLabel,
    /// The Extended Type Label (field FFh) asked. // 000:T19
    ExtendedTypeLabel,
    /// Read Version asked.
    Version,
    /// Read Position asked; `attempt` 0 is the first, up to [`RETRIES`].
    Position { attempt: u8 },
    /// The cycle ended with a reset; the polling period follows once it is done.
    CycleReset,
    /// Waiting for the next cycle.
    Period,
    /// Position reads stopped: waiting before the next status read.
    StoppedWait,
    /// Position reads stopped: reading the status.
    StoppedStatus,
    /// The run's duration is over.
    Ended,
}

/// What runs before the stage goes on: the stack read out, and the resets its codes
/// ask for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Aside {
    None,
    /// Read Encoder Status asked, the `reads`-th time in this read-out; the codes
    /// read so far.
    Status {
        reads: u8,
        codes: [FaultCode; STATUS_READS as usize],
        len: u8,
    },
    /// Encoder Reset sent.
    ResetSent,
    /// Waiting out the timeout and the initialization after the reset. // 000:T29
    ResetWait,
}

/// The master's state between two actions: everything its decisions depend on but the
/// profile and the options.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Flow {
    pub stage: Stage,
    pub aside: Aside,
    /// A reply with the warning bit, held while the stack is read out; the stage
    /// takes it afterwards. // 000:2.3.4
    pub held: Option<ResponseFrame>,
    /// SW resets so far.
    pub resets: u8,
    /// Position reads stopped (22h, or faults that persist): sin/cos only.
    pub position_stopped: bool,
    /// The line's clock when the last action was done, µs.
    pub now_us: u64,
}

/// The reference master. See the module documentation.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ReferenceMaster {
    profile: Profile,
    options: Options,
    flow: Flow,
}

/// How a code's reaction goes on.
enum Reacted {
    /// Nothing to do now (a retry, or no action).
    GoOn,
    /// The reaction ends what the master was doing.
    Done,
    /// A SW reset.
    Reset(ResetCause),
}

impl ReferenceMaster {
    /// The master of an encoder of `profile`, at the encoder's power-on.
    pub fn new(profile: Profile, options: Options) -> ReferenceMaster {
        let flow = Flow {
            stage: Stage::Initializing,
            aside: Aside::None,
            held: None,
            resets: 0,
            position_stopped: false,
            now_us: 0,
        };
        ReferenceMaster { profile, options, flow }
    }

    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    pub fn flow(&self) -> &Flow {
        &self.flow
    }

    /// The state between actions, for a model checker that moves the clock
    /// (proofs/src/master_fixpoint/joint.rs): [`Flow::now_us`] is the only time it keeps.
    pub fn flow_mut(&mut self) -> &mut Flow {
        &mut self.flow
    }

    /// The first action at the encoder's power-on: wait for the initialization and
    /// the master's own start. Default settings throughout: the encoder is kept in
    /// default communication. // 000:3.3.1, 000:T9
    pub fn power_on(&mut self) -> Action {
        self.flow.stage = Stage::Initializing;
        Action::WaitUntil(self.profile.init_ms as u64 * 1000 + START_MARGIN_US)
    }

    /// The last action is done: the next one. What the master tells the operator goes
    /// to `say`.
    pub fn next(&mut self, done: Done<'_>, say: &mut impl FnMut(Event)) -> Action {
        self.flow.now_us = done.now_us();
        match done {
            Done::Waited { .. } => self.waited(say),
            Done::Exchanged { request_end_us, timeout_us, reply, .. } => {
                self.exchanged(request_end_us, timeout_us, reply, say)
            }
        }
    }

    fn frame(&self, request: Request) -> RequestFrame {
        RequestFrame::new(AddressByte::Slave(self.profile.address), request)
    }

    /// Ask `request`, listening up to the command's maximum response time and a margin.
    fn ask(&self, request: Request) -> Action {
        let limit = self.profile.response_limit(request.command()).max_ms;
        Action::Exchange { request: self.frame(request), listen_ms: limit.saturating_add(LISTEN_MARGIN_MS) }
    }

    fn waited(&mut self, say: &mut impl FnMut(Event)) -> Action {
        if self.flow.aside == Aside::ResetWait {
            return self.read_status();
        }
        match self.flow.stage {
            Stage::Initializing => {
                self.flow.stage = Stage::StartUpStatus;
                self.read_status()
            }
            Stage::StoppedWait => {
                self.flow.stage = Stage::StoppedStatus;
                self.read_status()
            }
            Stage::Period => self.cycle_top(),
            Stage::Ended => Action::Stop,
            // A wait the master did not ask for: where it is, it goes on as after one.
            _ => self.resume(say),
        }
    }

    fn exchanged(&mut self, request_end_us: u64, timeout_us: u64, reply: &[u8], say: &mut impl FnMut(Event)) -> Action {
        match self.flow.aside {
            Aside::ResetSent => {
                // 000:T29: the timeout plus the initialization time, then the margin.
                self.flow.aside = Aside::ResetWait;
                let init_us = self.profile.init_ms as u64 * 1000;
                Action::WaitUntil(request_end_us + timeout_us + init_us + START_MARGIN_US)
            }
            Aside::Status { reads, codes, len } => {
                self.status_read(decode(reply, CommandId::ReadEncoderStatus), reads, codes, len, say)
            }
            Aside::ResetWait => self.read_status(),
            Aside::None => {
                let Some(command) = self.asked() else { return self.resume(say) };
                let outcome = decode(reply, command);
                // A reply with the warning bit: the stack first. // 000:2.3.4
                if let Some(r) = outcome.filter(|r| r.warning) {
                    self.flow.held = Some(r);
                    return self.read_status();
                }
                self.deliver(outcome, say)
            }
        }
    }

    /// The command the stage asked, if it asked one.
    fn asked(&self) -> Option<CommandId> {
        Some(match self.flow.stage {
            Stage::TypeLabel => CommandId::ReadTypeLabel,
            Stage::ExtendedTypeLabel => CommandId::ReadData,
            Stage::Version => CommandId::ReadVersion,
            Stage::Position { .. } => CommandId::ReadPosition,
            _ => return None,
        })
    }

    /// Read Encoder Status until the stack is empty (four codes at most, 000:2.3.4),
    /// then react to the codes read, together (000:T74 "06h + 08h").
    fn read_status(&mut self) -> Action {
        self.flow.aside = Aside::Status { reads: 1, codes: [FaultCode::NoFault; STATUS_READS as usize], len: 0 };
        self.ask(Request::ReadEncoderStatus)
    }

    fn status_read(
        &mut self,
        outcome: Option<ResponseFrame>,
        reads: u8,
        mut codes: [FaultCode; STATUS_READS as usize],
        mut len: u8,
        say: &mut impl FnMut(Event),
    ) -> Action {
        let more = match outcome.map(|r| (r.warning, r.response)) {
            // Empty, and no warning left: done. (A warning with 00h: a fault stacked
            // after the read; read again.)
            Some((false, Response::EncoderStatus(FaultCode::NoFault))) => false,
            Some((true, Response::EncoderStatus(FaultCode::NoFault))) => true,
            Some((_, Response::EncoderStatus(code))) => {
                say(Event::Status(code));
                if let Some(slot) = codes.get_mut(len as usize) {
                    *slot = code;
                    len += 1;
                }
                true
            }
            _ => false,
        };
        if more && reads < STATUS_READS {
            self.flow.aside = Aside::Status { reads: reads + 1, codes, len };
            return self.ask(Request::ReadEncoderStatus);
        }
        self.flow.aside = Aside::None;
        let read = codes.get(..len as usize).unwrap_or(&[]);
        for (code, reaction) in fault_reaction::stack_reactions(read) {
            match self.react(code, reaction, say) {
                Reacted::GoOn => {}
                Reacted::Done => break,
                Reacted::Reset(cause) => return self.reset(cause, say),
            }
        }
        self.resume(say)
    }

    /// React to `code` as `reaction` says (000:T74).
    fn react(&mut self, code: FaultCode, reaction: Reaction, say: &mut impl FnMut(Event)) -> Reacted {
        match code.byte() {
            // "Retry command." // 000:T74 protocol group
            0x09..=0x0D => Reacted::GoOn,
            // "Only use sine/cosine based position until shut-down. Replace Slave."
            0x22 => {
                say(Event::SyncFault);
                self.flow.position_stopped = true;
                Reacted::Done
            }
            _ if !reaction.known => {
                // The worst case (motor stop): reset, and stop if it persists. // 000:3.3.4
                say(Event::UnknownCode(code));
                Reacted::Reset(ResetCause::Unknown(code))
            }
            _ if reaction.is_reset() => Reacted::Reset(ResetCause::Critical(code)),
            _ => Reacted::GoOn,
        }
    }

    /// Encoder Reset, then the timeout plus the initialization time (000:T29), then the
    /// status again; position reads stop after too many.
    fn reset(&mut self, cause: ResetCause, say: &mut impl FnMut(Event)) -> Action {
        if self.flow.resets >= RESETS {
            say(Event::ResetsExhausted);
            self.flow.position_stopped = true;
            self.flow.aside = Aside::None;
            return self.resume(say);
        }
        self.flow.resets += 1;
        say(Event::Reset(cause));
        self.flow.aside = Aside::ResetSent;
        Action::Exchange { request: self.frame(Request::EncoderReset), listen_ms: 0 }
    }

    /// What was set aside is done: the stage goes on.
    fn resume(&mut self, say: &mut impl FnMut(Event)) -> Action {
        match self.flow.stage {
            Stage::Initializing | Stage::StartUpStatus => {
                self.flow.stage = Stage::TypeLabel;
                self.ask(Request::ReadTypeLabel)
            }
            Stage::StoppedWait | Stage::StoppedStatus => self.cycle_top(),
            Stage::CycleReset => self.period(),
            Stage::Period => self.period(),
            Stage::Ended => Action::Stop,
            // The reply that had the warning bit, now that the stack is read.
            Stage::TypeLabel | Stage::ExtendedTypeLabel | Stage::Version | Stage::Position { .. } => {
                let held = self.flow.held.take();
                self.deliver(held, say)
            }
        }
    }

    /// The stage's request got `outcome` (`None`: no reply, or one that does not
    /// decode).
    fn deliver(&mut self, outcome: Option<ResponseFrame>, say: &mut impl FnMut(Event)) -> Action {
        let response = outcome.map(|r| r.response);
        match self.flow.stage {
            Stage::TypeLabel => {
                if let Some(Response::TypeLabel { type_code, .. }) = response {
                    say(Event::TypeLabel { type_code });
                    // FFh: the encoder's parameters are in the Extended Type Label. // 000:T19
                    if type_code == 0xFF {
                        self.flow.stage = Stage::ExtendedTypeLabel;
                        return self.ask(Request::ReadData { field: 0xFF, offset: 0, count: 64, code: 0 });
                    }
                }
                self.version()
            }
            Stage::ExtendedTypeLabel => {
                if let Some(Response::Data { data, .. }) = response {
                    let checksum_ok = checksum::xor(data.as_bytes()) == 0;
                    say(Event::ExtendedTypeLabel { bytes: data.len(), checksum_ok });
                }
                self.version()
            }
            Stage::Version => {
                if let Some(Response::Version(v)) = response {
                    say(Event::Version(v));
                }
                self.cycle_top()
            }
            Stage::Position { attempt } => self.position(attempt, response, say),
            _ => self.resume(say),
        }
    }

    fn version(&mut self) -> Action {
        self.flow.stage = Stage::Version;
        self.ask(Request::ReadVersion)
    }

    /// One attempt of the cycle: Read Position, with retries and the reactions of
    /// Table 74.
    fn position(&mut self, attempt: u8, response: Option<Response>, say: &mut impl FnMut(Event)) -> Action {
        match response {
            Some(Response::Position(p)) => {
                say(Event::Position(p));
                return self.period();
            }
            Some(Response::Error(code)) => {
                say(Event::PositionError(code));
                let reaction = fault_reaction::reaction(code, fault::runtime_group(code));
                match self.react(code, reaction, say) {
                    Reacted::GoOn => {}
                    Reacted::Done => return self.period(),
                    Reacted::Reset(cause) => {
                        self.flow.stage = Stage::CycleReset;
                        return self.reset(cause, say);
                    }
                }
            }
            Some(_) => {}
            None => say(Event::PositionNoValidReply),
        }
        if attempt < RETRIES {
            self.flow.stage = Stage::Position { attempt: attempt + 1 };
            return self.ask(Request::ReadPosition);
        }
        // The error persists: SW reset. // 000:T74
        self.flow.stage = Stage::CycleReset;
        self.reset(ResetCause::Persisting, say)
    }

    /// The cycle is over: the next one after the polling period.
    fn period(&mut self) -> Action {
        self.flow.stage = Stage::Period;
        Action::WaitUntil(self.flow.now_us + self.options.polling_period_ms * 1000)
    }

    /// The top of the cyclic loop: the run's end, the status now and then once
    /// position reads have stopped, or a cycle.
    fn cycle_top(&mut self) -> Action {
        let now = self.flow.now_us;
        if self.options.duration_ms.is_some_and(|d| now >= d * 1000) {
            self.flow.stage = Stage::Ended;
            return Action::Stop;
        }
        if self.flow.position_stopped {
            // Nothing more to read cyclically: the status now and then.
            self.flow.stage = Stage::StoppedWait;
            return Action::WaitUntil(now + STOPPED_STATUS_PERIOD_US);
        }
        self.flow.stage = Stage::Position { attempt: 0 };
        self.ask(Request::ReadPosition)
    }
}

/// A reply as the master reads it: `None` when nothing came or it does not decode as
/// a reply to `command`.
fn decode(reply: &[u8], command: CommandId) -> Option<ResponseFrame> {
    if reply.is_empty() {
        return None;
    }
    ResponseFrame::decode(reply, command).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profiles;
    use crate::response::ResponseFrame;

    const OPTIONS: Options = Options { polling_period_ms: 50, duration_ms: None };

    fn reply(response: Response, warning: bool) -> crate::frame::Frame {
        ResponseFrame { address: 0x40, warning, response }.encode()
    }

    /// Feed `m` the reply `bytes` to its exchange at `now_us`; the next action and
    /// the events said.
    fn answer(m: &mut ReferenceMaster, now_us: u64, bytes: &[u8]) -> (Action, [Option<Event>; 4]) {
        let mut said = [None; 4];
        let mut n = 0;
        let done = Done::Exchanged { now_us, request_end_us: now_us, timeout_us: 5_730, reply: bytes };
        let action = m.next(done, &mut |e| {
            if let Some(slot) = said.get_mut(n) {
                *slot = Some(e);
                n += 1;
            }
        });
        (action, said)
    }

    fn asks(action: Action) -> Option<Request> {
        match action {
            Action::Exchange { request, .. } => Some(request.request),
            _ => None,
        }
    }

    /// Through the start-up (000:3.3.1) to the first Read Position.
    fn started(profile: Profile) -> ReferenceMaster {
        let mut m = ReferenceMaster::new(profile, OPTIONS);
        assert_eq!(m.power_on(), Action::WaitUntil(profile.init_ms as u64 * 1000 + START_MARGIN_US));
        let a = m.next(Done::Waited { now_us: 120_000 }, &mut |_| {});
        assert_eq!(asks(a), Some(Request::ReadEncoderStatus));
        let (a, _) = answer(&mut m, 130_000, reply(Response::EncoderStatus(FaultCode::NoFault), false).as_bytes());
        assert_eq!(asks(a), Some(Request::ReadTypeLabel));
        let label = Response::TypeLabel { settings: 0xE4, type_code: 0x42, memory_blocks: 2, option: 0 };
        let (a, said) = answer(&mut m, 140_000, reply(label, false).as_bytes());
        assert_eq!(said[0], Some(Event::TypeLabel { type_code: 0x42 }));
        assert_eq!(asks(a), Some(Request::ReadVersion));
        let (a, _) = answer(&mut m, 150_000, &[]);
        assert_eq!(asks(a), Some(Request::ReadPosition));
        m
    }

    #[test]
    fn a_reply_with_the_warning_bit_has_the_stack_read_first() {
        let mut m = started(profiles::srs50());
        let (a, said) = answer(&mut m, 160_000, reply(Response::Position(7), true).as_bytes());
        assert_eq!(asks(a), Some(Request::ReadEncoderStatus), "000:2.3.4");
        assert_eq!(said, [None; 4], "the position waits for the stack");
        let hot = FaultCode::decode(0x1E);
        let (a, said) = answer(&mut m, 170_000, reply(Response::EncoderStatus(hot), false).as_bytes());
        assert_eq!(said[0], Some(Event::Status(hot)));
        assert_eq!(asks(a), Some(Request::ReadEncoderStatus));
        let (a, said) = answer(&mut m, 180_000, reply(Response::EncoderStatus(FaultCode::NoFault), false).as_bytes());
        // 1Eh asks for no reset: the held reply is taken, and the period follows.
        assert_eq!(said[0], Some(Event::Position(7)));
        assert_eq!(a, Action::WaitUntil(180_000 + 50_000));
    }

    #[test]
    fn a_failing_read_position_is_retried_then_the_encoder_reset_then_given_up() {
        let profile = profiles::srs50();
        let mut m = started(profile);
        let mut now = 200_000;
        for round in 1..=RESETS + 1 {
            // The first attempt and RETRIES retries, then a reset. // 000:T74
            let (mut a, mut said) = (Action::Stop, [None; 4]);
            for _ in 0..=RETRIES {
                now += 10_000;
                (a, said) = answer(&mut m, now, &[]);
                assert_eq!(said[0], Some(Event::PositionNoValidReply));
            }
            if round > RESETS {
                assert_eq!(said[1], Some(Event::ResetsExhausted));
                assert_eq!(a, Action::WaitUntil(now + 50_000));
                assert!(m.flow().position_stopped);
                // The status now and then, never the position again.
                let a = m.next(Done::Waited { now_us: now + 50_000 }, &mut |_| {});
                assert_eq!(a, Action::WaitUntil(now + 50_000 + STOPPED_STATUS_PERIOD_US));
                return;
            }
            assert_eq!(asks(a), Some(Request::EncoderReset));
            assert_eq!(m.flow().resets, round);
            // 000:T29: the timeout plus the initialization time after the request.
            now += 5_000;
            let (a, _) = answer(&mut m, now, &[]);
            assert_eq!(a, Action::WaitUntil(now + 5_730 + profile.init_ms as u64 * 1000 + START_MARGIN_US));
            let a = m.next(Done::Waited { now_us: now + 200_000 }, &mut |_| {});
            assert_eq!(asks(a), Some(Request::ReadEncoderStatus));
            now += 210_000;
            let (a, _) = answer(&mut m, now, reply(Response::EncoderStatus(FaultCode::NoFault), false).as_bytes());
            assert_eq!(a, Action::WaitUntil(now + 50_000), "the cycle ends with the reset");
            let a = m.next(Done::Waited { now_us: now + 50_000 }, &mut |_| {});
            assert_eq!(asks(a), Some(Request::ReadPosition));
            now += 50_000;
        }
        panic!("position reads never stopped");
    }

    #[test]
    fn a_multiturn_sync_fault_stops_position_reads_and_an_unknown_code_resets() {
        let mut m = started(profiles::srs50());
        let sync = FaultCode::decode(0x22);
        let (a, said) = answer(&mut m, 160_000, reply(Response::Error(sync), false).as_bytes());
        assert_eq!(said[..2], [Some(Event::PositionError(sync)), Some(Event::SyncFault)]);
        assert_eq!(a, Action::WaitUntil(210_000));
        assert!(m.flow().position_stopped, "000:T74: sin/cos only");
        let mut m = started(profiles::srs50());
        let unknown = FaultCode::decode(0x3A);
        let (a, said) = answer(&mut m, 160_000, reply(Response::Error(unknown), false).as_bytes());
        assert_eq!(said[1], Some(Event::UnknownCode(unknown)));
        assert_eq!(said[2], Some(Event::Reset(ResetCause::Unknown(unknown))), "000:3.3.4 worst case");
        assert_eq!(asks(a), Some(Request::EncoderReset));
    }
}
