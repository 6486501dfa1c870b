//! What a master must and should do on the line, graded from what it sends: the oracle
//! for certifying a drive. // 000:2.2, 000:2.2.2, 000:2.3, 000:T9, 000:T30, 000:3.3.1,
//! 000:3.3.4
//!
//! The [`Observer`] is told what the encoder does (power-on, each reply it sends) and
//! sees every character the master sends, stamped at the end of its stop bit. It
//! frames the master's characters by the timeout as a slave would, and reports an
//! [`Observation`] for every rule the master breaks. Sans-IO and allocation-free: the
//! caller passes a sink for the observations.
//!
//! A frame that is no request is held until the next frame or the line has been quiet
//! for a while: two fragments that make one request are a gap inside it (000:2.2.2),
//! one frame that splits into two requests is a missing pause, anything else is a
//! malformed frame.

use crate::address::{AddressByte, SlaveAddress};
use crate::clause::{self, Clause};
use crate::command::{CommandByte, CommandId};
use crate::datalink::RxChar;
use crate::fault::{self, FaultCode};
use crate::frame::{Frame, MAX_FRAME};
use crate::master::fault_reaction;
use crate::profile::Profile;
use crate::request::{RequestChecks, RequestFrame};
use crate::response::{Response, ResponseFrame};
use crate::settings::{Edition, UartSettings};

/// A rule of the master's obligations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Rule {
    /// A frame that is no request: too short, bad checksum, unknown command or wrong
    /// length for its command. // 000:2.3
    Malformed,
    /// The command byte's error bit is set: faults go from slave to master only.
    ErrorBit,
    /// The address byte has fixed bits wrong (and is not FFh). // 000:T5
    AddressFormat,
    /// A gap of at least the timeout inside one request split it. // 000:2.2.2
    GapInRequest,
    /// Two requests without the timeout's pause between them. // 000:2.2.2
    NoPause,
    /// A request while the encoder was still sending a reply that came in time.
    /// // 000:2.2
    TalksOverReply,
    /// A request before the reply window of the previous request closed, with no reply
    /// seen: a late reply would collide with it. // DESIGN:reply-window
    ReplyWindow,
    /// A character during initialization after power-on. // 000:T9, 000:3.3.1
    DuringInitialization,
    /// A character before the timeout plus the initialization time after Encoder Reset.
    /// // 000:T29
    TooSoonAfterReset,
    /// A request while the encoder changes its settings (no UART communication).
    /// // 000:T9, 000:3.3.1
    DuringSettingsChange,
    /// Position read before the status after power-on. // 000:3.3.1 (recommended)
    StatusNotRead,
    /// Replies carried the warning bit, and the master went on without reading the
    /// codes (50h) or resetting (53h). // 000:2.3.4 (recommended)
    WarningIgnored,
    /// A protocol error (09h...0Dh) was answered and the master did not retry.
    /// // 000:T74 "Retry command."
    NoRetry,
    /// The same request failed again and again without a reset. // 000:T74 "If error
    /// persists, SW reset of Slave."
    UnboundedRetry,
    /// A critical fault whose reaction is a SW reset, and the master went on without
    /// one. // 000:T74
    NoResetAfterCriticalFault,
    /// Position read again after a multiturn sync fault (22h: "Only use sine/cosine
    /// based position until shut-down"). // 000:T74
    PositionAfterSyncFault,
    /// An unknown fault code, and the master kept reading position without a reset.
    /// // 000:3.3.4
    UnknownCodeIgnored,
    /// The type label said FFh and the master read the position without reading the
    /// Extended Type Label (field FFh), where the encoder's parameters are. // 000:T19
    ExtendedTypeLabelNotRead,
    /// No request for longer than the polling period once the master has begun: faults
    /// go unseen, for the slave only indicates them in replies. // 000:3.2.2 (should)
    NoCyclicRequest,
    /// A request at a data rate other than the one the encoder listens at: the default
    /// settings until the default window has passed, the stored ones after it.
    /// // 000:3.3.1, 000:T9
    DataRate,
}

impl Rule {
    /// Every rule.
    pub const ALL: [Rule; 20] = [
        Rule::Malformed,
        Rule::ErrorBit,
        Rule::AddressFormat,
        Rule::GapInRequest,
        Rule::NoPause,
        Rule::TalksOverReply,
        Rule::ReplyWindow,
        Rule::DuringInitialization,
        Rule::TooSoonAfterReset,
        Rule::DuringSettingsChange,
        Rule::StatusNotRead,
        Rule::WarningIgnored,
        Rule::NoRetry,
        Rule::UnboundedRetry,
        Rule::NoResetAfterCriticalFault,
        Rule::PositionAfterSyncFault,
        Rule::UnknownCodeIgnored,
        Rule::ExtendedTypeLabelNotRead,
        Rule::NoCyclicRequest,
        Rule::DataRate,
    ];

    /// The clause the rule rests on; a FAIL only where it is normative.
    pub const fn clause(self) -> Clause {
        match self {
            Rule::Malformed => clause::MASTER_FRAME.clause(),
            Rule::ErrorBit => clause::MASTER_NO_FAULTS.clause(),
            Rule::AddressFormat => clause::ADDRESS.clause(),
            Rule::GapInRequest => clause::MASTER_CHARACTER_GAP.clause(),
            Rule::NoPause => clause::MASTER_PAUSE.clause(),
            Rule::TalksOverReply => clause::MASTER_CYCLE.clause(),
            Rule::ReplyWindow => clause::MASTER_REPLY_WINDOW,
            Rule::DuringInitialization | Rule::DuringSettingsChange | Rule::DataRate => {
                clause::MASTER_START_UP.clause()
            }
            Rule::TooSoonAfterReset => clause::MASTER_RESET_WAIT.clause(),
            Rule::StatusNotRead => clause::MASTER_READ_STATUS,
            Rule::WarningIgnored => clause::MASTER_WARNING,
            Rule::NoRetry | Rule::UnboundedRetry | Rule::NoResetAfterCriticalFault | Rule::PositionAfterSyncFault => {
                clause::MASTER_FAULT_REACTION
            }
            Rule::UnknownCodeIgnored => clause::MASTER_UNKNOWN_CODE,
            Rule::NoCyclicRequest => clause::MASTER_CYCLIC,
            Rule::ExtendedTypeLabelNotRead => clause::MASTER_EXTENDED_TYPE_LABEL,
        }
    }

    /// What the rule says, for a report.
    pub const fn text(self) -> &'static str {
        match self {
            Rule::Malformed => "a frame that is no request",
            Rule::ErrorBit => "a request with the error bit set",
            Rule::AddressFormat => "an address byte that is no address",
            Rule::GapInRequest => "a gap of at least the timeout inside a request",
            Rule::NoPause => "no pause of the timeout between two requests",
            Rule::TalksOverReply => "a request while the encoder was replying",
            Rule::ReplyWindow => "a request before the reply window closed",
            Rule::DuringInitialization => "a request during the encoder's initialization",
            Rule::TooSoonAfterReset => "a request before the timeout plus 100 ms after Encoder Reset",
            Rule::DuringSettingsChange => "a request while the encoder changes its settings",
            Rule::StatusNotRead => "position read before the status after power-on",
            Rule::WarningIgnored => "the warning bit's codes not read out",
            Rule::NoRetry => "no retry after a protocol error",
            Rule::UnboundedRetry => "a failing request retried without bound",
            Rule::NoResetAfterCriticalFault => "no SW reset after a critical fault",
            Rule::PositionAfterSyncFault => "position read after a multiturn sync fault",
            Rule::UnknownCodeIgnored => "position read on after an unknown fault code",
            Rule::ExtendedTypeLabelNotRead => "type FFh, and position read without the Extended Type Label",
            Rule::DataRate => "a request at a data rate other than the encoder's",
            Rule::NoCyclicRequest => "no request within the polling period",
        }
    }
}

/// One broken rule: when, and the figure measured where there is one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Observation {
    pub rule: Rule,
    /// When the offending frame began (or the character, for timing rules), µs.
    pub at_us: u64,
    /// The gap, pause or lead measured, µs, where the rule is about time.
    pub measured_us: Option<u64>,
    /// The command of the offending request, where it has one.
    pub command: Option<CommandId>,
    /// The data rates, where the rule is about them.
    pub data_rates: Option<DataRates>,
}

/// The master's data rate against the encoder's, bits per second.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DataRates {
    pub master_bps: u32,
    pub encoder_bps: u32,
}

/// How many requests a master may make after a reply before it reacts (reads the
/// warning's codes, resets after a critical fault).
pub const REACTION_REQUESTS: u8 = 3;
/// The polling period unless the user sets the application's: a request at least this
/// often is "a sufficient cyclic request" (000:3.2.2); the figure is a decision of
/// this project (docs/design.md).
pub const POLLING_PERIOD_MS: u32 = 1000;
/// How many times in a row the same request may fail before the master resets.
pub const RETRY_BOUND: u8 = 8;

/// The master's characters of the frame in progress, with their receive times.
#[derive(Debug, Clone)]
struct Framer {
    bytes: Frame,
    ends_us: [u64; MAX_FRAME],
}

impl Framer {
    fn new() -> Framer {
        Framer { bytes: Frame::new(), ends_us: [0; MAX_FRAME] }
    }

    fn push(&mut self, byte: u8, end_us: u64) {
        let n = self.bytes.len();
        if self.bytes.push(byte).is_ok() {
            if let Some(t) = self.ends_us.get_mut(n) {
                *t = end_us;
            }
        }
    }

    fn last_us(&self) -> Option<u64> {
        self.bytes.len().checked_sub(1).and_then(|i| self.ends_us.get(i).copied())
    }
}

/// A completed frame that was no request, held to see what follows.
#[derive(Debug, Clone)]
struct Held {
    framer: Framer,
    start_us: u64,
}

/// Where the requests of a frame end, last first: at most one per three bytes.
struct Ends {
    at: [usize; MAX_FRAME / 3 + 1],
    len: usize,
}

impl Ends {
    /// In frame order.
    fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.at.iter().take(self.len).rev().copied()
    }
}

/// Where the requests end, if `bytes` is two or more requests back to back. The
/// caller has found that `bytes` is not one request.
fn requests_in(bytes: &[u8]) -> Option<Ends> {
    const NONE: usize = usize::MAX;
    let n = bytes.len();
    // from[j]: where a request ending at j begins, if the bytes up to j split.
    let mut from = [NONE; MAX_FRAME + 1];
    *from.get_mut(0)? = 0;
    for i in 0..n {
        if from.get(i) == Some(&NONE) {
            continue;
        }
        for j in (i + 3)..=n {
            let open = from.get(j) == Some(&NONE);
            if open && bytes.get(i..j).is_some_and(|r| RequestFrame::decode(r).is_ok()) {
                *from.get_mut(j)? = i;
            }
        }
    }
    let mut ends = Ends { at: [0; MAX_FRAME / 3 + 1], len: 0 };
    let mut j = n;
    while j > 0 {
        *ends.at.get_mut(ends.len)? = j;
        ends.len += 1;
        j = *from.get(j).filter(|&&f| f != NONE)?;
    }
    (ends.len >= 2).then_some(ends)
}

/// What the encoder's last reply asked of the master.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pending {
    Nothing,
    /// A protocol error to this request: the next request should be it again.
    Retry(CommandId),
    /// A critical fault whose reaction is a SW reset, within so many requests.
    Reset {
        left: u8,
    },
}

/// The codes the master read from the stack since its last other request.
#[derive(Debug, Clone, Copy)]
struct StackRead {
    codes: [FaultCode; 4],
    len: usize,
}

impl StackRead {
    const EMPTY: StackRead = StackRead { codes: [FaultCode::NoFault; 4], len: 0 };

    /// The stack holds four codes (000:2.3.4); a fifth read starts over.
    fn push(&mut self, code: FaultCode) {
        if self.len == self.codes.len() {
            *self = StackRead::EMPTY;
        }
        if let Some(slot) = self.codes.get_mut(self.len) {
            *slot = code;
            self.len += 1;
        }
    }

    fn codes(&self) -> &[FaultCode] {
        self.codes.get(..self.len).unwrap_or(&[])
    }
}

/// The observer of one master. See the module documentation.
#[derive(Debug, Clone)]
pub struct Observer {
    profile: Profile,
    settings: UartSettings,
    /// The encoder's address: the profile's until told otherwise (55h).
    address: SlaveAddress,
    framer: Framer,
    held: Option<Held>,
    /// Power-on, or the end of the last Encoder Reset's timeout.
    started_us: Option<u64>,
    after_reset: bool,
    /// A request arrived in the default window (the encoder keeps default settings).
    kept_default: bool,
    /// The end of the last reply, µs.
    reply_end_us: Option<u64>,
    reply_start_us: Option<u64>,
    /// The last reply started after its window closed: a master that talks over it
    /// had given up waiting, as it may.
    reply_late: bool,
    /// Until when the last request's reply window is open (no reply seen yet).
    window_until_us: Option<u64>,
    status_read: bool,
    status_reported: bool,
    warning_left: Option<u8>,
    pending: Pending,
    last_request: Option<(RequestFrame, u8)>,
    /// The command of the last frame, if it was a request: what a reply answers.
    answered: Option<CommandId>,
    warning_reported: bool,
    sync_fault: bool,
    unknown_code: bool,
    /// The type label said FFh and field FFh has not been read since.
    label_pending: bool,
    stack_read: StackRead,
    polling_period_us: u64,
    /// When the master's last frame began, and whether the gap after it was reported.
    last_frame_us: Option<u64>,
    gap_reported: bool,
}

impl Observer {
    /// An observer of a master talking to an encoder of `profile`, in its default
    /// settings at first.
    pub fn new(profile: Profile) -> Observer {
        Observer {
            profile,
            settings: UartSettings::DEFAULT,
            address: profile.address,
            framer: Framer::new(),
            held: None,
            started_us: None,
            after_reset: false,
            kept_default: false,
            reply_end_us: None,
            reply_start_us: None,
            reply_late: false,
            window_until_us: None,
            status_read: false,
            status_reported: false,
            warning_left: None,
            pending: Pending::Nothing,
            last_request: None,
            answered: None,
            warning_reported: false,
            sync_fault: false,
            unknown_code: false,
            label_pending: false,
            stack_read: StackRead::EMPTY,
            polling_period_us: POLLING_PERIOD_MS as u64 * 1000,
            last_frame_us: None,
            gap_reported: false,
        }
    }

    /// The application's polling period, instead of [`POLLING_PERIOD_MS`].
    pub fn set_polling_period_ms(&mut self, ms: u32) {
        self.polling_period_us = ms as u64 * 1000;
    }

    /// The observation ends at `now_us`: a gap in the polling that is still open counts.
    pub fn end(&mut self, now_us: u64, out: &mut impl FnMut(Observation)) {
        self.poll(now_us, out);
        self.polling_gap(now_us, out);
    }

    /// Report once a gap since the last frame longer than the polling period.
    fn polling_gap(&mut self, now_us: u64, out: &mut impl FnMut(Observation)) {
        let Some(last) = self.last_frame_us else { return };
        let gap = now_us.saturating_sub(last);
        if gap > self.polling_period_us && !self.gap_reported {
            self.gap_reported = true;
            out(Observation {
                rule: Rule::NoCyclicRequest,
                at_us: last,
                measured_us: Some(gap),
                command: None,
                data_rates: None,
            });
        }
    }

    fn timeout_us(&self) -> u64 {
        self.settings.timeout_us(self.profile.edition)
    }

    fn char_time_us(&self) -> u64 {
        self.settings.char_time_us()
    }

    /// The encoder was powered on at `at_us`.
    pub fn power_on(&mut self, at_us: u64) {
        self.started_us = Some(at_us);
        self.last_frame_us = None;
        self.after_reset = false;
        self.kept_default = false;
        self.status_read = false;
        self.status_reported = false;
        self.label_pending = false;
        self.settings = UartSettings::DEFAULT;
        self.clear_reactions();
    }

    fn clear_reactions(&mut self) {
        self.warning_left = None;
        self.warning_reported = false;
        self.pending = Pending::Nothing;
        self.sync_fault = false;
        self.unknown_code = false;
        self.window_until_us = None;
        self.stack_read = StackRead::EMPTY;
    }

    /// The encoder listens at `settings` from now on (its power-up windows, 57h and a
    /// reset, 67h): the timeout that frames the master's characters follows them.
    pub fn encoder_listens(&mut self, settings: UartSettings) {
        self.settings = settings;
    }

    /// The encoder answers at `address` from now on (it accepted a Set Encoder
    /// Address, 55h): the reply window is kept for requests to it. // 000:T30
    pub fn encoder_at(&mut self, address: SlaveAddress) {
        self.address = address;
    }

    /// A frame of the master began at `at_us`, sent at `master_bps` as far as the
    /// harness can see it (a pseudo-terminal's settings), while the encoder listened at
    /// the settings last given to [`Observer::encoder_listens`]. // 000:3.3.1
    pub fn master_data_rate(&mut self, at_us: u64, master_bps: u32, out: &mut impl FnMut(Observation)) {
        let encoder_bps = self.settings.baud.bits_per_second();
        if master_bps != encoder_bps {
            out(Observation {
                rule: Rule::DataRate,
                at_us,
                measured_us: None,
                command: None,
                data_rates: Some(DataRates { master_bps, encoder_bps }),
            });
        }
    }

    /// The encoder sent a reply from `start_us` to `end_us` (end of the last stop bit):
    /// `reply` as it decodes, `None` for a reply the master cannot read (a corrupted
    /// one injected on purpose).
    pub fn encoder_reply(&mut self, start_us: u64, end_us: u64, reply: Option<&ResponseFrame>) {
        self.reply_late = self.window_until_us.is_some_and(|until| start_us > until);
        self.reply_start_us = Some(start_us);
        self.reply_end_us = Some(end_us);
        self.window_until_us = None;
        let Some(reply) = reply else { return };
        if let Response::TypeLabel { type_code: 0xFF, .. } = reply.response {
            self.label_pending = true;
        }
        let asked = self.answered;
        if reply.warning && self.warning_left.is_none() && !self.warning_reported {
            self.warning_left = Some(REACTION_REQUESTS);
        }
        let code = match reply.response {
            Response::Error(code) => Some(code),
            Response::EncoderStatus(code) if code != FaultCode::NoFault => Some(code),
            _ => None,
        };
        let Some(code) = code else {
            if !matches!(self.pending, Pending::Reset { .. }) {
                self.pending = Pending::Nothing;
            }
            return;
        };
        // Codes read from the stack are judged together: 06h read with a companion code
        // has the row of the pair (000:T74 "06h + 08h").
        if let Response::EncoderStatus(_) = reply.response {
            self.stack_read.push(code);
            let reactions = || fault_reaction::stack_reactions(self.stack_read.codes());
            if reactions().any(|(_, r)| !r.known) {
                self.unknown_code = true;
            }
            if code.byte() == 0x22 {
                self.sync_fault = true;
            }
            let reset = reactions().any(|(_, r)| r.is_reset());
            self.pending = match (self.pending, reset) {
                (Pending::Reset { left }, true) => Pending::Reset { left },
                (_, true) => Pending::Reset { left: REACTION_REQUESTS },
                (Pending::Reset { .. }, false) => Pending::Nothing,
                (other, false) => other,
            };
            return;
        }
        let reaction = fault_reaction::reaction(code, fault::runtime_group(code));
        self.pending = match code.byte() {
            0x22 => {
                self.sync_fault = true;
                Pending::Nothing
            }
            _ if !reaction.known => {
                self.unknown_code = true;
                Pending::Nothing
            }
            // "Retry command." (protocol errors 09h-0Dh), "Retry command. If error
            // persists, SW reset of Slave." (many position and other faults). // 000:T74
            _ if reaction.is_retry() => asked.map_or(Pending::Nothing, Pending::Retry),
            _ => Pending::Nothing,
        };
    }

    /// Time has reached `now_us` with no character from the master: a frame in
    /// progress completes once its timeout has elapsed.
    pub fn poll(&mut self, now_us: u64, out: &mut impl FnMut(Observation)) {
        if let Some(last) = self.framer.last_us() {
            if now_us >= last + self.timeout_us() {
                self.complete(out);
            }
        }
        // A held fragment with nothing after it for long: it was malformed on its own.
        if let Some(h) = &self.held {
            let quiet = h.framer.last_us().unwrap_or(0) + 4 * self.timeout_us();
            if self.framer.bytes.is_empty() && now_us >= quiet {
                self.release_held(out);
            }
        }
    }

    /// A character from the master.
    pub fn master_char(&mut self, ch: RxChar, out: &mut impl FnMut(Observation)) {
        let start = ch.at_us.saturating_sub(self.char_time_us());
        if let Some(last) = self.framer.last_us() {
            if start >= last + self.timeout_us() {
                self.complete(out);
            }
        }
        if self.framer.bytes.is_empty() {
            self.frame_starts(start, out);
        }
        self.framer.push(ch.byte, ch.at_us);
    }

    /// Timing rules, checked where a frame begins.
    fn frame_starts(&mut self, start: u64, out: &mut impl FnMut(Observation)) {
        self.polling_gap(start, out);
        self.last_frame_us = Some(start);
        self.gap_reported = false;
        let mut report =
            |rule, measured_us| out(Observation { rule, at_us: start, measured_us, command: None, data_rates: None });
        if let Some(t0) = self.started_us {
            let init = self.profile.init_ms as u64 * 1000;
            let since = start.saturating_sub(t0);
            if start < t0 + init {
                let rule = if self.after_reset { Rule::TooSoonAfterReset } else { Rule::DuringInitialization };
                report(rule, Some(since));
            } else if self.profile.edition == Edition::Current
                && !self.kept_default
                && since >= self.profile.default_window_ms as u64 * 1000
                && since < self.profile.user_settings_ms as u64 * 1000
            {
                report(Rule::DuringSettingsChange, Some(since));
            }
        }
        match (self.reply_start_us, self.reply_end_us, self.window_until_us) {
            (Some(s), Some(e), _) if start >= s && start < e && !self.reply_late => {
                report(Rule::TalksOverReply, Some(start - s))
            }
            (_, _, Some(until)) if start < until => report(Rule::ReplyWindow, Some(until - start)),
            _ => {}
        }
    }

    /// The frame in progress is complete.
    fn complete(&mut self, out: &mut impl FnMut(Observation)) {
        let framer = core::mem::replace(&mut self.framer, Framer::new());
        let Some(first_end) = framer.ends_us.first().copied() else { return };
        let start = first_end.saturating_sub(self.char_time_us());
        let bytes = framer.bytes.as_bytes();
        let decoded = RequestFrame::decode(bytes).ok();
        self.answered = decoded.map(|r| r.request.command());
        if let Some(rf) = decoded {
            // A valid request right after a held fragment that completes it is not
            // possible (the fragment would be part of it); the fragment stands alone.
            self.release_held(out);
            self.request(rf, framer.last_us().unwrap_or(start), start, out);
            return;
        }
        // Two fragments of one request: a gap inside it.
        if let Some(h) = self.held.take() {
            let mut joined = h.framer.bytes;
            let joins = bytes.iter().all(|b| joined.push(*b).is_ok());
            if let Some(whole) = RequestFrame::decode(joined.as_bytes()).ok().filter(|_| joins) {
                let gap = start.saturating_sub(h.framer.last_us().unwrap_or(start));
                let command = Some(whole.request.command());
                out(Observation {
                    rule: Rule::GapInRequest,
                    at_us: h.start_us,
                    measured_us: Some(gap),
                    command,
                    data_rates: None,
                });
                return;
            }
            self.held = Some(h);
            self.release_held(out);
        }
        // One frame that is several requests (a reader that looked late sees them
        // together, too): no pause between them.
        if let Some(ends) = requests_in(bytes) {
            let ct = self.char_time_us();
            let mut from = 0;
            for end in ends.iter().take_while(|&e| e < bytes.len()) {
                let command =
                    bytes.get(from..end).and_then(|a| RequestFrame::decode(a).ok()).map(|r| r.request.command());
                let end_a = framer.ends_us.get(end - 1).copied().unwrap_or(0);
                let start_b = framer.ends_us.get(end).copied().unwrap_or(0).saturating_sub(ct);
                out(Observation {
                    rule: Rule::NoPause,
                    at_us: start_b,
                    measured_us: Some(start_b.saturating_sub(end_a)),
                    command,
                    data_rates: None,
                });
                from = end;
            }
            return;
        }
        self.held = Some(Held { framer, start_us: start });
    }

    /// A held fragment stands alone: say why it is no request.
    fn release_held(&mut self, out: &mut impl FnMut(Observation)) {
        let Some(h) = self.held.take() else { return };
        let bytes = h.framer.bytes.as_bytes();
        let rule = match bytes.get(1).and_then(|b| CommandByte::decode(*b)) {
            Some(CommandByte { error_bit: true, .. }) if RequestChecks::of(bytes).bad_checksum.is_none() => {
                Rule::ErrorBit
            }
            _ => Rule::Malformed,
        };
        out(Observation { rule, at_us: h.start_us, measured_us: None, command: None, data_rates: None });
    }

    /// A well-formed request: the address, and what it says of the master's reactions.
    /// `end`: when its last character was complete.
    fn request(&mut self, rf: RequestFrame, end: u64, start: u64, out: &mut impl FnMut(Observation)) {
        let command = rf.request.command();
        let mut report =
            |rule| out(Observation { rule, at_us: start, measured_us: None, command: Some(command), data_rates: None });
        if let AddressByte::Unknown(_) = rf.address {
            report(Rule::AddressFormat);
        }
        let timeout = self.timeout_us();
        let own = rf.address.addresses(self.address());
        if own {
            if let Some(t0) = self.started_us {
                let since = start.saturating_sub(t0);
                if since < self.profile.default_window_ms as u64 * 1000 {
                    self.kept_default = true;
                }
            }
            let max_ms = self.profile.response_limit(command).max_ms as u64;
            self.window_until_us = (command != CommandId::EncoderReset).then_some(end + timeout + max_ms * 1000);
        }
        // Reactions, from the most specific.
        match command {
            CommandId::EncoderReset => {
                self.started_us = Some(end + timeout);
                self.after_reset = true;
                self.kept_default = false;
                self.settings = UartSettings::DEFAULT;
                self.clear_reactions();
            }
            CommandId::ReadEncoderStatus => {
                self.status_read = true;
                self.warning_left = None;
                self.warning_reported = false;
            }
            CommandId::ReadPosition => {
                // Only where the power-on was seen: "after a power-on" (000:3.3.1).
                if !self.status_read && !self.status_reported && self.started_us.is_some() {
                    self.status_reported = true;
                    report(Rule::StatusNotRead);
                }
                if self.sync_fault {
                    report(Rule::PositionAfterSyncFault);
                }
                if self.unknown_code {
                    report(Rule::UnknownCodeIgnored);
                    self.unknown_code = false;
                }
                if self.label_pending {
                    report(Rule::ExtendedTypeLabelNotRead);
                    self.label_pending = false;
                }
            }
            CommandId::ReadData => {
                if let crate::request::Request::ReadData { field: 0xFF, .. } = rf.request {
                    self.label_pending = false;
                }
            }
            _ => {}
        }
        // Reading the stack (50h) and resetting (53h) are the reactions themselves.
        if !matches!(command, CommandId::EncoderReset | CommandId::ReadEncoderStatus) {
            self.stack_read = StackRead::EMPTY;
            match self.warning_left {
                Some(0 | 1) => {
                    report(Rule::WarningIgnored);
                    self.warning_left = None;
                    self.warning_reported = true;
                }
                Some(n) => self.warning_left = Some(n - 1),
                None => {}
            }
            match self.pending {
                Pending::Retry(c) if c != command => {
                    report(Rule::NoRetry);
                    self.pending = Pending::Nothing;
                }
                Pending::Reset { left } if left <= 1 => {
                    report(Rule::NoResetAfterCriticalFault);
                    self.pending = Pending::Nothing;
                }
                Pending::Reset { left } => self.pending = Pending::Reset { left: left - 1 },
                _ => {}
            }
        }
        // The same request failing again and again.
        let repeats = match self.last_request {
            Some((r, n)) if r == rf && matches!(self.pending, Pending::Retry(_)) => n.saturating_add(1),
            _ => 1,
        };
        if repeats == RETRY_BOUND + 1 {
            report(Rule::UnboundedRetry);
        }
        self.last_request = Some((rf, repeats));
    }

    fn address(&self) -> SlaveAddress {
        self.address
    }
}
