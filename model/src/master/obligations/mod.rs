//! What a master must and should do on the line, graded from what it sends: the oracle
//! for certifying a drive. // 000:2.2, 000:2.2.2, 000:2.3, 000:T9, 000:T30, 000:3.3.1,
//! 000:3.3.4
//!
//! Long because: the observer's state and the timing rules checked where a frame begins
//! are one piece; framing, the rules and the reactions are files of their own already
//! (under 440 lines without its tests).
//!
//! The [`Observer`] is told what the encoder does (power-on, each reply it sends) and
//! sees every character the master sends, stamped at the end of its stop bit. It
//! frames the master's characters by the pause the master leaves on the line
//! (`framing`), and reports an [`Observation`] for every rule the master breaks
//! (`rule`): timing where a frame begins (here), form where it ends (`framing`), and
//! the reactions a request shows (`reaction`). Sans-IO and allocation-free: the
//! caller passes a sink for the observations.
//!
//! A frame that is no request is held until the next frame or the line has been quiet
//! for a while: two fragments that make one request are a gap inside it (000:2.2.2),
//! one frame that splits into two requests is a missing pause, anything else is a
//! malformed frame.

use crate::address::SlaveAddress;
use crate::command::CommandId;
use crate::datalink::RxChar;
use crate::fault::{self, FaultCode};
use crate::master::fault_reaction;
use crate::profile::Profile;
use crate::request::RequestFrame;
use crate::response::{Response, ResponseFrame};
use crate::settings::{Edition, UartSettings};

mod framing;
mod reaction;
mod rule;

use framing::{Framer, Held};
use reaction::{Pending, StackRead};
pub use rule::{DataRates, Observation, Rule, POLLING_PERIOD_MS, REACTION_REQUESTS, RETRY_BOUND};

/// The observer of one master. See the module documentation.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
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
    polling_period_us: u64,
    /// What only the recommendations' rules read.
    memo: Recommendations,
}

/// What the observer remembers for the rules of recommendations only (reactions to
/// replies, the status and the Extended Type Label read, retries, the polling gap):
/// one value, so that [`Observer::forget_recommendations`] forgets all of it and a
/// field added here is forgotten with the rest.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct Recommendations {
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
    /// When the master's last frame began, and whether the gap after it was reported.
    last_frame_us: Option<u64>,
    gap_reported: bool,
}

impl Recommendations {
    const NONE: Recommendations = Recommendations {
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
        last_frame_us: None,
        gap_reported: false,
    };
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
            polling_period_us: POLLING_PERIOD_MS as u64 * 1000,
            memo: Recommendations::NONE,
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
        let Some(last) = self.memo.last_frame_us else { return };
        let gap = now_us.saturating_sub(last);
        if gap > self.polling_period_us && !self.memo.gap_reported {
            self.memo.gap_reported = true;
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

    /// How far back from now the observer's judgments of what comes later can read a
    /// time it keeps, µs: the power-up windows (000:T9), the polling period. A caller
    /// that moves the clock ([`Observer::rebase`]) moves it to at least this.
    pub fn look_back_us(&self) -> u64 {
        let p = &self.profile;
        let windows = p.init_ms.max(p.default_window_ms).max(p.user_settings_ms) as u64 * 1000;
        windows.max(self.polling_period_us + 1)
    }

    /// Forget what only the recommendations' rules read (the reactions the replies
    /// asked for, the status and the Extended Type Label read or not, the retries
    /// counted, the last frame for the polling gap): the rules on a normative clause
    /// (framing, pauses, the reply, power-up and reset timing, the data rate) judge
    /// what follows as before; the recommendations' judgments from here on mean
    /// nothing. For a model checker of the musts (proofs/src/master_fixpoint/), where
    /// that memory would make states differ that the musts cannot tell apart.
    pub fn forget_recommendations(&mut self) {
        self.memo = Recommendations::NONE;
    }

    /// Move the observer's clock from `now_us` to `to_us`: every time it keeps moves by
    /// the same amount, so that it judges what comes at or after `now_us` as it would
    /// have, at times moved alike (the rules compare times with one another, never with
    /// a fixed instant). A time further back than any rule reads it from now on is
    /// brought forward to the latest instant that reads the same: power-on once the
    /// windows of 000:T9 that still matter are over, a reply that has ended, a reply
    /// window that has closed, a last frame older than the polling period. So two
    /// observers that differ only in how long ago such things happened become equal
    /// (model checking the reference master to a fixpoint,
    /// proofs/src/master_fixpoint/joint.rs). A judgment's figure (`measured_us`) may read the
    /// moved time; its rule does not change. `to_us` must be at least
    /// [`Observer::look_back_us`]; the characters of a frame in progress older than
    /// `now_us - to_us` would be moved to 0.
    pub fn rebase(&mut self, now_us: u64, to_us: u64) {
        let moved = |t: u64| t.saturating_add(to_us).saturating_sub(now_us);
        let at_least = |t: u64, back: u64| moved(t.max(now_us.saturating_sub(back)));
        if let Some(t0) = self.started_us {
            // After the initialization only the default window and the change of
            // settings read power-on, and only until the encoder kept the default
            // settings (000:T9, DESIGN:power-up).
            let p = &self.profile;
            let windows = if self.kept_default { p.init_ms } else { p.init_ms.max(p.user_settings_ms) };
            self.started_us = Some(at_least(t0, windows as u64 * 1000));
        }
        // A reply that ended, a window that closed, before now: every later instant is
        // after it, and a reply's start after a closed window is late (`start > until`).
        self.reply_start_us = self.reply_start_us.map(|t| at_least(t, 0));
        self.reply_end_us = self.reply_end_us.map(|t| at_least(t, 0));
        self.window_until_us = self.window_until_us.map(|t| at_least(t, 1));
        self.memo.last_frame_us = self.memo.last_frame_us.map(|t| at_least(t, self.polling_period_us + 1));
        let n = self.framer.bytes.len();
        for t in self.framer.ends_us.iter_mut().take(n) {
            *t = moved(*t);
        }
        if let Some(h) = self.held.as_mut() {
            h.start_us = moved(h.start_us);
            let n = h.framer.bytes.len();
            for t in h.framer.ends_us.iter_mut().take(n) {
                *t = moved(*t);
            }
        }
    }

    fn char_time_us(&self) -> u64 {
        self.settings.char_time_us()
    }

    /// The encoder was powered on at `at_us`.
    pub fn power_on(&mut self, at_us: u64) {
        self.started_us = Some(at_us);
        self.memo.last_frame_us = None;
        self.after_reset = false;
        self.kept_default = false;
        self.memo.status_read = false;
        self.memo.status_reported = false;
        self.memo.label_pending = false;
        self.settings = UartSettings::DEFAULT;
        self.clear_reactions();
    }

    fn clear_reactions(&mut self) {
        self.memo.warning_left = None;
        self.memo.warning_reported = false;
        self.memo.pending = Pending::Nothing;
        self.memo.sync_fault = false;
        self.memo.unknown_code = false;
        self.window_until_us = None;
        self.memo.stack_read = StackRead::EMPTY;
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
        self.master_data_rate_changing(at_us, master_bps, master_bps, out);
    }

    /// A frame of the master began at `at_us` while its settings went from
    /// `before_bps` (the line last quiet) to `now_bps`: it went out at one of the two,
    /// which the harness cannot tell, so the rule is broken only where both differ from
    /// the encoder's (a master that retries at 38400 and then 19200 Bd changed its
    /// settings before each retry and was never graded; blind trial HX-M3, d11).
    /// // 000:3.3.1
    pub fn master_data_rate_changing(
        &mut self,
        at_us: u64,
        before_bps: u32,
        now_bps: u32,
        out: &mut impl FnMut(Observation),
    ) {
        let encoder_bps = self.settings.baud.bits_per_second();
        if before_bps != encoder_bps && now_bps != encoder_bps {
            let changed_from_bps = (before_bps != now_bps).then_some(before_bps);
            out(Observation {
                rule: Rule::DataRate,
                at_us,
                measured_us: None,
                command: None,
                data_rates: Some(DataRates { master_bps: now_bps, encoder_bps, changed_from_bps }),
            });
        }
    }

    /// What the encoder itself answered the request `command` that began at `at_us`,
    /// before anything a harness put in its place: it knows what a listener does not,
    /// its data fields' sizes. A Read Data or Store Data it refuses with 11h (Wrong data
    /// field offset) asked outside its field, which 000 forbids the master ("Offset plus
    /// byte count must not be larger than data field size"). Only a caller that serves
    /// the encoder as the model answers says so. // 000:T21, 000:T22
    pub fn served_reply(
        &mut self,
        command: CommandId,
        reply: &ResponseFrame,
        at_us: u64,
        out: &mut impl FnMut(Observation),
    ) {
        let rule = match (command, reply.response) {
            (CommandId::ReadData, Response::Error(FaultCode::WrongOffset)) => Rule::ReadOutsideField,
            (CommandId::StoreData, Response::Error(FaultCode::WrongOffset)) => Rule::StoreOutsideField,
            _ => return,
        };
        out(Observation { rule, at_us, measured_us: None, command: Some(command), data_rates: None });
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
            self.memo.label_pending = true;
        }
        let asked = self.memo.answered;
        if reply.warning && self.memo.warning_left.is_none() && !self.memo.warning_reported {
            self.memo.warning_left = Some(REACTION_REQUESTS);
        }
        let code = match reply.response {
            Response::Error(code) => Some(code),
            Response::EncoderStatus(code) if code != FaultCode::NoFault => Some(code),
            _ => None,
        };
        let Some(code) = code else {
            if !matches!(self.memo.pending, Pending::Reset { .. }) {
                self.memo.pending = Pending::Nothing;
            }
            return;
        };
        // Codes read from the stack are judged together: 06h read with a companion code
        // has the row of the pair (000:T74 "06h + 08h").
        if let Response::EncoderStatus(_) = reply.response {
            self.memo.stack_read.push(code);
            let reactions = || fault_reaction::stack_reactions(self.memo.stack_read.codes());
            if reactions().any(|(_, r)| !r.known) {
                self.memo.unknown_code = true;
            }
            if code.byte() == 0x22 {
                self.memo.sync_fault = true;
            }
            let reset = reactions().any(|(_, r)| r.is_reset());
            self.memo.pending = match (self.memo.pending, reset) {
                (Pending::Reset { left }, true) => Pending::Reset { left },
                (_, true) => Pending::Reset { left: REACTION_REQUESTS },
                (Pending::Reset { .. }, false) => Pending::Nothing,
                (other, false) => other,
            };
            return;
        }
        let reaction = fault_reaction::reaction(code, fault::runtime_group(code));
        let asks = match code.byte() {
            0x22 => {
                self.memo.sync_fault = true;
                Pending::Nothing
            }
            _ if !reaction.known => {
                self.memo.unknown_code = true;
                Pending::Nothing
            }
            // "Retry command." (protocol errors 09h-0Dh), "Retry command. If error
            // persists, SW reset of Slave." (many position and other faults). // 000:T74
            _ if reaction.is_retry() => asked.map_or(Pending::Nothing, Pending::Retry),
            _ => Pending::Nothing,
        };
        // A reset owed for a critical fault stays owed, on its first count: a later
        // error's retry neither discharges nor postpones it (a master that ignored a
        // critical start-up fault and reset only once its retries of a locked Read
        // Position ran out was let through; blind trial HX-M3, d15). // 000:T74
        self.memo.pending = match self.memo.pending {
            Pending::Reset { left } => Pending::Reset { left },
            _ => asks,
        };
    }

    /// Time has reached `now_us` with no character from the master: a frame in
    /// progress completes once its timeout has elapsed.
    pub fn poll(&mut self, now_us: u64, out: &mut impl FnMut(Observation)) {
        if self.frame_complete_us().is_some_and(|complete| now_us >= complete) {
            self.complete(out);
        }
        // A held fragment with nothing after it for long: it was malformed on its own.
        if self.held_alone_us().is_some_and(|alone| now_us >= alone) {
            self.release_held(out);
        }
    }

    /// When the frame in progress completes: the timeout after its last character.
    #[inline]
    fn frame_complete_us(&self) -> Option<u64> {
        self.framer.last_us().map(|last| last.saturating_add(self.timeout_us()))
    }

    /// When a held fragment stands alone, with no frame in progress after it: the line
    /// quiet four timeouts after it.
    #[inline]
    fn held_alone_us(&self) -> Option<u64> {
        let h = self.held.as_ref().filter(|_| self.framer.bytes.is_empty())?;
        Some(h.framer.last_us().unwrap_or(0).saturating_add(self.timeout_us().saturating_mul(4)))
    }

    /// The first instant at which [`Observer::poll`] may observe anything, where
    /// nothing else happens before: a frame in progress completes at its timeout, a
    /// held fragment stands alone once the line has been quiet. A caller that polls
    /// only from then on (a listener fed millions of characters) misses nothing.
    pub fn next_due_us(&self) -> Option<u64> {
        match (self.frame_complete_us(), self.held_alone_us()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// A character from the master.
    pub fn master_char(&mut self, ch: RxChar, out: &mut impl FnMut(Observation)) {
        let start = ch.at_us.saturating_sub(self.char_time_us());
        if let Some(last) = self.framer.last_us() {
            if start >= last.saturating_add(self.timeout_us()) {
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
        self.memo.last_frame_us = Some(start);
        self.memo.gap_reported = false;
        let mut report =
            |rule, measured_us| out(Observation { rule, at_us: start, measured_us, command: None, data_rates: None });
        if let Some(t0) = self.started_us {
            let init = self.profile.init_ms as u64 * 1000;
            let since = start.saturating_sub(t0);
            // Saturating: the observer takes any time a capture gives, up to u64::MAX.
            if start < t0.saturating_add(init) {
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

    fn address(&self) -> SlaveAddress {
        self.address
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Forgetting the recommendations' memory leaves an observer that told a reply with
    /// the warning bit and a type label of FFh equal to one told the same reply without
    /// them: what the musts read is the same, the rest is forgotten.
    #[test]
    fn forgetting_the_recommendations_leaves_what_the_musts_read() {
        let profile = crate::profiles::sek37();
        let reply = |warning, type_code| ResponseFrame {
            address: 0x40,
            warning,
            response: Response::TypeLabel { settings: 0xE4, type_code, memory_blocks: 0x70, option: 0 },
        };
        let told = |r: ResponseFrame| {
            let mut o = Observer::new(profile);
            o.power_on(0);
            o.encoder_reply(200_000, 207_000, Some(&r));
            o
        };
        let (mut remembers, mut plain) = (told(reply(true, 0xFF)), told(reply(false, 0x42)));
        assert_ne!(remembers, plain, "the warning and the label are remembered");
        remembers.forget_recommendations();
        plain.forget_recommendations();
        assert_eq!(remembers, plain);
        assert_eq!(remembers.memo, Recommendations::NONE);
    }

    /// What a master sends in the property below: requests, fragments of one, two run
    /// together.
    const SENT: &[&[u8]] = &[
        &[0x40, 0x42, 0x02],
        &[0x40, 0x50, 0x10],
        &[0x40, 0x42],
        &[0x02],
        &[0x40, 0x42, 0x02, 0x40, 0x50, 0x10],
        &[0xFF, 0x53, 0x11, 0xBF],
    ];

    proptest::proptest! {
        /// Before `next_due_us` a poll observes nothing and changes nothing, whatever
        /// the master sent (requests, fragments, several run together) with whatever
        /// gaps: a listener that polls only from then on misses nothing. And where
        /// something is due, polling then does change the observer.
        #[test]
        fn nothing_is_due_before_next_due(
            frames in proptest::collection::vec(
                (proptest::sample::select(SENT),
                 0u64..30_000, 0u64..3_000, proptest::bool::ANY),
                1..8),
            probe in proptest::prop_oneof![0u64..6_000, 0u64..200_000],
        ) {
            let mut o = Observer::new(crate::profiles::srs50());
            let mut now = 0;
            let mut sink = |_: Observation| {};
            for (bytes, gap, inside, completed) in frames {
                now += gap + 1;
                for b in bytes.iter() {
                    now += 1_146 + inside % 2_000;
                    if o.next_due_us().is_some_and(|due| due <= now) {
                        o.poll(now, &mut sink);
                    }
                    o.master_char(RxChar::ok(*b, now), &mut sink);
                }
                // The frame completed (a fragment is then held, the framer empty), or
                // still in the framer.
                if let Some(due) = o.next_due_us().filter(|_| completed) {
                    now = now.max(due);
                    o.poll(now, &mut sink);
                }
                let due = o.next_due_us();
                let t = now + probe;
                let mut polled = o.clone();
                let mut seen = 0;
                polled.poll(t, &mut |_| seen += 1);
                match due {
                    Some(due) if t >= due => proptest::prop_assert_ne!(&polled, &o, "due at {} µs, polled at {}", due, t),
                    _ => proptest::prop_assert_eq!((&polled, seen), (&o, 0), "nothing due before {:?}, polled at {}", due, t),
                }
            }
        }
    }
}
