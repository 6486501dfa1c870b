//! The passive listener: grade both sides of a conversation it only overhears (a live
//! bus tapped by a third transceiver, or a logic-analyzer capture). Sans-IO: it is
//! fed [`Event`]s in time order and reports each exchange as it closes.
//!
//! Long because: framing per channel and telling requests from replies share the
//! listener's state and one order of events; heard.rs, grade.rs and summary.rs hold the
//! rest (under 480 lines without its tests).
//!
//! - Framing by the inter-character timeout at the bus's settings (000:2.2.2), per
//!   channel.
//! - Requests and replies are told apart by the capture's direction where it has one
//!   (a wire log, `--master-channel`), otherwise by timing and structure: a frame that
//!   starts within the reply window of an open request is its reply; a frame that
//!   decodes as a request is one; a request with an early reply run into it (less
//!   than the timeout between them) is split where the request ends.
//! - The master is graded by the master rules (`hiperface_model::master::obligations`),
//!   the slave by the oracle against a model that follows the requests it hears.
//!
//! What a listener cannot know is never charged to a device: it does not see the
//! encoder's stored state (data fields, access codes, address, counter, error stack)
//! or whether it was powered on before the capture began. A reply's form (length and
//! checksum for its command, its address echo, a warning bit without a code) and its
//! timing are graded; a difference in content from the model is reported as
//! UNKNOWN with the oracle's reason, not as FAIL.

use crate::capture::{Event, Mark, Role, Run};
use crate::verdict::timing;
use crate::verdict::{CaseVerdict, Finding, Outcome};
pub use heard::HeardExchange;
use heard::{Heard, Spare};
use hiperface_model::command::CommandId;
use hiperface_model::datalink::{self, RxChar};
use hiperface_model::frame::Hex;
use hiperface_model::master::obligations::{Observation, Observer};
use hiperface_model::oracle::Oracle;
use hiperface_model::request::RequestFrame;
use hiperface_model::response::{ResponseError, ResponseFrame};
use hiperface_model::slave::Slave;
use hiperface_model::{Grading, Profile, UartSettings};

pub mod decode;
mod grade;
mod heard;
pub mod report;
mod summary;
pub use decode::{fuzz_capture, listen_to};
pub use summary::{Summary, BUCKETS_MS};

/// What the listener is told.
#[derive(Debug, Clone)]
pub struct Options {
    pub profile: Profile,
    /// The bus's settings (the encoder's listening settings).
    pub settings: UartSettings,
    /// The capture's timing uncertainty, µs: its sample period, a logger's latency.
    pub tolerance_us: u64,
    /// The channel the master talks on, where the capture has several.
    pub master_channel: Option<u8>,
    /// The application's polling period, ms (000:3.2.2).
    pub polling_period_ms: u32,
}

/// A frame longer than any valid one is cut at this many characters: memory stays
/// bounded.
const MAX_HEARD: usize = 4 * hiperface_model::frame::MAX_FRAME;

/// The frame being assembled on one channel: it ends where the model's data link
/// ends one, the timeout after its last character (000:2.2.2); `heard` keeps its
/// characters with how late each was heard.
#[derive(Debug)]
struct Assembly {
    channel: u8,
    /// Who sends on it, where the capture says.
    role: Option<Role>,
    /// When its last character ended, if it has begun (its characters may be cut).
    last_us: Option<u64>,
    heard: Heard,
}

impl Assembly {
    /// When the frame is complete, if one is being assembled.
    fn deadline(&self, timeout_us: u64) -> Option<u64> {
        self.last_us.map(|last| datalink::complete_at(last, timeout_us))
    }

    /// Take `ch`, sent by `role` and heard `late_us` late, into the frame (a buffer
    /// from `spare` for its first); when the frame is complete now.
    fn file(
        &mut self,
        ch: RxChar,
        late_us: u64,
        role: Option<Role>,
        spare: &mut Spare,
        timeout_us: u64,
    ) -> Option<u64> {
        self.role = role;
        // `advance` to this instant closed the frame this character comes too late for:
        // it belongs to the frame being assembled.
        self.last_us = Some(self.last_us.map_or(ch.at_us, |last| last.max(ch.at_us)));
        if self.heard.chars.capacity() == 0 {
            self.heard = Heard::in_buffer(spare.chars());
        }
        // A frame longer than any valid one is cut: memory stays bounded.
        if self.heard.len() < MAX_HEARD {
            self.heard.push(ch, late_us);
        }
        self.deadline(timeout_us)
    }
}

/// A reply as heard: its characters, their bytes, and what they decode to for the
/// request's command (decoded once, for the master's rules and the oracle).
struct ReplyHeard {
    heard: Heard,
    bytes: Vec<u8>,
    decoded: Result<ResponseFrame, ResponseError>,
}

/// A request waiting for its reply.
#[derive(Debug, Clone)]
struct Open {
    bytes: Vec<u8>,
    start_us: u64,
    end_us: u64,
    /// How late its last character may have been heard, µs.
    end_late_us: u64,
    /// The last instant a reply may start and still be heard as this one's.
    window_end_us: u64,
}

impl Open {
    fn command(&self) -> CommandId {
        CommandId::of_frame(&self.bytes)
    }
}

/// The listener.
pub struct Listener {
    options: Options,
    oracle: Oracle,
    shadow: Slave,
    observer: Observer,
    timeout_us: u64,
    char_us: u64,
    /// Frames being assembled, one per channel heard, by channel.
    frames: Vec<Assembly>,
    open: Option<Open>,
    now_us: u64,
    /// The summary says once that the encoder moved to another data rate.
    rate_noted: bool,
    /// Buffers kept from frame to frame.
    spare: Spare,
    /// Before this instant time passing changes nothing ([`Listener::next_due`]): most
    /// characters of a capture arrive before it and pass straight to their frame.
    due_us: u64,
    /// Whether characters before `due_us` skip `advance` (the tests compare with not).
    skip_until_due: bool,
    pub summary: Summary,
}

impl Listener {
    pub fn new(options: Options) -> Listener {
        let mut observer = Observer::new(options.profile);
        observer.encoder_listens(options.settings);
        observer.set_polling_period_ms(options.polling_period_ms);
        let edition = options.profile.edition;
        Listener {
            oracle: Oracle::new(Grading::Range),
            shadow: Slave::operational(options.profile),
            observer,
            timeout_us: options.settings.timeout_us(edition),
            char_us: options.settings.char_time_us(),
            frames: Vec::new(),
            open: None,
            now_us: 0,
            rate_noted: false,
            spare: Spare::default(),
            due_us: 0,
            skip_until_due: true,
            summary: Summary::default(),
            options,
        }
    }

    /// Take in one event; `out` gets every exchange it closes.
    pub fn feed(&mut self, e: Event, out: &mut impl FnMut(&HeardExchange)) {
        if e.at_us >= self.due_us || !self.skip_until_due {
            self.advance(e.at_us, out);
        } else {
            self.now_us = self.now_us.max(e.at_us);
        }
        let role = self.role_of(&e);
        if e.mark == Mark::Break {
            // A break ends the frame it interrupts. // 000:T47 (a UART fault)
            self.summary.breaks += 1;
            self.close_channel(e.channel, out);
            self.due_us = self.next_due();
            return;
        }
        let (byte, fault) = e.mark.as_received();
        self.summary.characters += 1;
        self.summary.flagged += u64::from(fault.is_some());
        let at = match self.frames.binary_search_by_key(&e.channel, |a| a.channel) {
            Ok(at) => at,
            Err(at) => {
                self.frames.insert(at, Assembly { channel: e.channel, role, last_us: None, heard: Heard::default() });
                at
            }
        };
        let Some(a) = self.frames.get_mut(at) else { return };
        let ch = RxChar { byte, at_us: e.at_us, fault };
        if let Some(complete) = a.file(ch, e.late_us, role, &mut self.spare, self.timeout_us) {
            self.due_us = self.due_us.min(complete);
        }
    }

    /// Take in a run of characters, as [`Listener::feed`] takes in each of its events
    /// in turn. Characters that come before anything falls due go straight to their
    /// channel's frame, found once for them.
    pub fn feed_run(&mut self, run: &Run, out: &mut impl FnMut(&HeardExchange)) {
        self.feed(run.first, out);
        let role = self.role_of(&run.first);
        let mut at_us = run.first.at_us;
        let mut rest = run.rest().iter();
        loop {
            // What `feed` does with a byte before anything is due, on the frame that
            // took the character before (`feed` left one on the run's channel).
            let frame = self.frames.binary_search_by_key(&run.first.channel, |a| a.channel).ok();
            if let Some(a) = frame.and_then(|at| self.frames.get_mut(at)).filter(|_| self.skip_until_due) {
                while let Some(&byte) = rest.as_slice().first() {
                    let next_us = at_us + run.step_us;
                    if next_us >= self.due_us {
                        break;
                    }
                    rest.next();
                    at_us = next_us;
                    self.now_us = self.now_us.max(at_us);
                    self.summary.characters += 1;
                    let ch = RxChar { byte, at_us, fault: None };
                    if let Some(complete) = a.file(ch, run.first.late_us, role, &mut self.spare, self.timeout_us) {
                        self.due_us = self.due_us.min(complete);
                    }
                }
            }
            // One that falls due: the whole way.
            let Some(&byte) = rest.next() else { return };
            at_us += run.step_us;
            self.feed(Event { at_us, mark: Mark::Byte(byte), ..run.first }, out);
        }
    }

    /// Who sent `e`: as the capture says, else by the master's channel if known.
    fn role_of(&self, e: &Event) -> Option<Role> {
        e.role.or(match self.options.master_channel {
            Some(m) if m == e.channel => Some(Role::Master),
            Some(_) => Some(Role::Slave),
            None => None,
        })
    }

    /// Nothing was heard until `now_us` (a live bus, quiet): close what timed out.
    pub fn idle(&mut self, now_us: u64, out: &mut impl FnMut(&HeardExchange)) {
        if now_us > self.now_us {
            self.advance(now_us, out);
        }
    }

    /// The capture ended at `at_us`: close what is open.
    pub fn finish(&mut self, at_us: u64, out: &mut impl FnMut(&HeardExchange)) {
        let end = at_us.max(self.now_us).saturating_add(self.timeout_us);
        self.advance(end, out);
        let channels: Vec<u8> = self.frames.iter().map(|a| a.channel).collect();
        for ch in channels {
            self.close_channel(ch, out);
        }
        if let Some(open) = self.open.take() {
            self.exchange(open, None, out);
        }
        let mut obs = Vec::new();
        self.observer.end(end, &mut |o| obs.push(o));
        self.master_observations(obs);
    }

    /// Time passes to `now`: frames whose timeout elapsed complete, in the order they
    /// began; a request whose reply window closed was not answered.
    fn advance(&mut self, now: u64, out: &mut impl FnMut(&HeardExchange)) {
        loop {
            let due = self
                .frames
                .iter()
                .filter(|a| a.deadline(self.timeout_us).is_some_and(|complete| complete <= now))
                .filter_map(|a| Some((a.heard.chars.first()?.at_us, a.channel)))
                .min();
            let Some((_, ch)) = due else { break };
            self.close_channel(ch, out);
        }
        if let Some(open) = &self.open {
            // A frame still being assembled that began in the window may be the reply.
            let end = open.window_end_us;
            let reply_under_way = self
                .frames
                .iter()
                .any(|a| a.heard.chars.first().is_some_and(|c| c.at_us.saturating_sub(self.char_us) <= end));
            if now > self.window_heard_until(open) && !reply_under_way {
                let open = self.open.take();
                if let Some(open) = open {
                    self.exchange(open, None, out);
                }
            }
        }
        let mut obs = Vec::new();
        self.observer.poll(now, &mut |o| obs.push(o));
        self.master_observations(obs);
        self.now_us = self.now_us.max(now);
        self.due_us = self.next_due();
    }

    /// The last instant a reply in `open`'s window may still be heard beginning: one
    /// that starts at the window's end is heard a character later.
    fn window_heard_until(&self, open: &Open) -> u64 {
        open.window_end_us.saturating_add(self.char_us)
    }

    /// The first instant at which time passing may change anything: a frame times
    /// out, a request's reply window closes (just after `window_heard_until`, as
    /// `advance` closes it), the master's rules are due.
    fn next_due(&self) -> u64 {
        let frame = self.frames.iter().filter_map(|a| a.deadline(self.timeout_us)).min().unwrap_or(u64::MAX);
        let window = self.open.as_ref().map_or(u64::MAX, |o| self.window_heard_until(o).saturating_add(1));
        frame.min(window).min(self.observer.next_due_us().unwrap_or(u64::MAX))
    }

    /// The last instant a reply to a request of `command` that ended at `end_us` may
    /// start and still be heard as its reply (`timing::reply_awaited_ms`).
    fn window_end(&self, command: CommandId, end_us: u64) -> u64 {
        let awaited_us = timing::reply_awaited_ms(self.options.profile.response_limit(command)) as u64 * 1000;
        end_us.saturating_add(self.timeout_us + awaited_us + self.options.tolerance_us)
    }

    fn close_channel(&mut self, ch: u8, out: &mut impl FnMut(&HeardExchange)) {
        let Some(a) = self.frames.iter_mut().find(|a| a.channel == ch) else { return };
        a.last_us = None;
        let (role, heard) = (a.role, std::mem::take(&mut a.heard));
        if !heard.is_empty() {
            self.frame(role, heard, out);
        }
    }

    /// A complete frame: a request, a reply, or both run together.
    fn frame(&mut self, role: Option<Role>, heard: Heard, out: &mut impl FnMut(&HeardExchange)) {
        let start = heard.chars.first().map_or(0, |c| c.at_us.saturating_sub(self.char_us));
        let in_window = self.open.as_ref().is_some_and(|o| start <= o.window_end_us);
        match role {
            Some(Role::Master) => self.request(heard, out),
            Some(Role::Slave) if in_window => self.reply(heard, out),
            Some(Role::Slave) => self.stray(&heard.bytes(), start, "a reply frame with no request open"),
            None => self.unmarked(heard, start, in_window, out),
        }
    }

    /// A frame of a capture that does not say who sent it: told by its window and
    /// its structure.
    fn unmarked(&mut self, heard: Heard, start: u64, in_window: bool, out: &mut impl FnMut(&HeardExchange)) {
        let bytes = heard.bytes();
        let request = RequestFrame::decode(&bytes).is_ok();
        match () {
            () if in_window && !request => self.reply(heard, out),
            () if request => self.request(heard, out),
            () => match (2..bytes.len()).find(|n| RequestFrame::decode(&bytes[..*n]).is_ok()) {
                // A request and a reply with less than the timeout between them.
                Some(n) => {
                    let mut heard = heard;
                    let reply = heard.split_off(n);
                    self.request(heard, out);
                    self.reply(reply, out);
                }
                None => self.stray(&bytes, start, "a frame that is neither a request nor a reply in its window"),
            },
        }
    }

    fn stray(&mut self, bytes: &[u8], start_us: u64, what: &str) {
        self.summary.unattributed += 1;
        self.summary.unattributed_characters += bytes.len() as u64;
        self.summary.note(format!("{:.3} ms: {what} [{}]: not graded", start_us as f64 / 1000.0, Hex(bytes)));
    }

    fn request(&mut self, heard: Heard, out: &mut impl FnMut(&HeardExchange)) {
        if let Some(open) = self.open.take() {
            self.exchange(open, None, out);
        }
        if let Some(first) = heard.chars.first() {
            self.follow(first.at_us.saturating_sub(self.char_us));
        }
        let mut obs = Vec::new();
        for c in &heard.chars {
            self.observer.master_char(*c, &mut |o| obs.push(o));
        }
        self.master_observations(obs);
        let (Some(first), Some(last)) = (heard.chars.first(), heard.chars.last()) else { return };
        let bytes = heard.bytes_into(self.spare.bytes());
        let command = CommandId::of_frame(&bytes);
        self.open = Some(Open {
            bytes,
            start_us: first.at_us.saturating_sub(self.char_us),
            end_us: last.at_us,
            end_late_us: heard.last_late_us(),
            window_end_us: self.window_end(command, last.at_us),
        });
        self.spare.keep_chars(heard.chars);
    }

    fn reply(&mut self, heard: Heard, out: &mut impl FnMut(&HeardExchange)) {
        let Some(open) = self.open.take() else { return };
        let (Some(first), Some(last)) = (heard.chars.first(), heard.chars.last()) else { return };
        let bytes = heard.bytes_into(self.spare.bytes());
        let decoded = ResponseFrame::decode(&bytes, open.command());
        self.observer.encoder_reply(first.at_us.saturating_sub(self.char_us), last.at_us, decoded.as_ref().ok());
        self.exchange(open, Some(ReplyHeard { heard, bytes, decoded }), out);
    }

    /// What the encoder accepted moves where it answers (55h) and, after a reset, how
    /// it listens (57h): the master's rules follow it at `at_us`. // 000:T30, 000:T32
    fn follow(&mut self, at_us: u64) {
        self.observer.encoder_at(self.shadow.nonvolatile().address);
        let Some(settings) = self.shadow.listening_settings(at_us) else { return };
        self.observer.encoder_listens(settings);
        if settings.baud != self.options.settings.baud && !self.rate_noted {
            self.rate_noted = true;
            self.summary.note(format!(
                "{:.3} ms: the encoder now listens at {} Bd; a capture read at {} Bd cannot follow it",
                at_us as f64 / 1000.0,
                settings.baud.bits_per_second(),
                self.options.settings.baud.bits_per_second()
            ));
        }
    }

    fn master_observations(&mut self, obs: Vec<Observation>) {
        let edition = self.options.profile.edition;
        for o in obs {
            let figure = o.measured_us.map_or(String::new(), |m| format!(", {:.3} ms", m as f64 / 1000.0));
            let message = format!("{} at {:.3} ms{figure}", o.rule.text(), o.at_us as f64 / 1000.0);
            self.summary.master(o.rule, Finding::broken(o.rule.clause(), message, edition));
        }
    }
}

/// The report of a listening run.
#[derive(Debug, serde::Serialize)]
pub struct ListeningReport {
    pub tool: String,
    pub capture: String,
    pub format: String,
    pub profile: String,
    pub baud: u32,
    pub tolerance_us: u64,
    pub channels: Vec<String>,
    pub assumptions: Vec<String>,
    /// The worst verdict heard.
    pub verdict: CaseVerdict,
    /// What the run adds up to.
    pub outcome: Outcome,
    /// Why it is not PASSED, where that is not a FAIL.
    pub incomplete: Option<String>,
    pub summary: Summary,
    /// When, where and how the run was made, where the harness made it.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub run_info: Option<crate::report::RunInfo>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Frames a bus carries: requests, their replies, fragments, noise.
    const FRAMES: &[&[u8]] = &[
        &[0x40, 0x42, 0x02],
        &[0x40, 0x42, 0x00, 0x00, 0x00, 0x00, 0x02],
        &[0x40, 0x50, 0x10],
        &[0x40, 0x50, 0x00, 0x10],
        &[0x40, 0x52, 0x12],
        &[0x40, 0x52, 0xE4, 0x22, 0x80, 0x00, 0x54],
        &[0x40, 0x42],
        &[0x02, 0x40, 0x42, 0x00],
        &[0xFF, 0x53, 0x11, 0xBF],
        &[0x40, 0x42, 0x02, 0x40, 0x42, 0x00, 0x00, 0x00, 0x00, 0x02],
    ];

    fn events() -> impl Strategy<Value = Vec<Event>> {
        let frame = (
            proptest::sample::select(FRAMES),
            prop_oneof![Just(None), Just(Some(Role::Master)), Just(Some(Role::Slave))],
            prop_oneof![0u64..4_000, 0u64..400_000],
            0u64..3_000,
            0u8..20,
        );
        proptest::collection::vec(frame, 1..24).prop_map(|frames| {
            let mut at_us = 0;
            let mut events = Vec::new();
            for (bytes, role, gap, jitter, fault) in frames {
                at_us += gap;
                for (i, b) in bytes.iter().enumerate() {
                    at_us += 1_146 + jitter * (i as u64 % 2);
                    let mark = match fault {
                        0 if i == 1 => Mark::Break,
                        1 if i == 0 => Mark::ParityError(*b),
                        _ => Mark::Byte(*b),
                    };
                    let channel = role.map_or(0, |r| r as u8);
                    events.push(Event { at_us, channel, role, mark, late_us: u64::from(fault == 2) * 3_000 });
                }
            }
            events
        })
    }

    fn heard(events: &[Event], skip_until_due: bool) -> (Vec<String>, String) {
        let options = Options {
            profile: hiperface_model::profiles::srs50(),
            settings: UartSettings::DEFAULT,
            tolerance_us: 100,
            master_channel: None,
            polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
        };
        let mut l = Listener::new(options);
        l.skip_until_due = skip_until_due;
        let mut lines = Vec::new();
        for e in events {
            l.feed(*e, &mut |h| lines.push(h.to_string()));
        }
        l.finish(events.last().map_or(0, |e| e.at_us), &mut |h| lines.push(h.to_string()));
        (lines, serde_json::to_string(&l.summary).unwrap_or_default())
    }

    /// Frames as runs: bytes of [`FRAMES`] (a long one too), at paces from faster
    /// than the bus to slower than its timeout.
    fn runs() -> impl Strategy<Value = Vec<Run>> {
        let long: &'static [u8] = &[0x40; 40];
        let frame = (
            prop_oneof![proptest::sample::select(FRAMES), Just(long)],
            prop_oneof![Just(None), Just(Some(Role::Master)), Just(Some(Role::Slave))],
            prop_oneof![0u64..4_000, 0u64..400_000],
            prop_oneof![Just(1_146u64), 0u64..1_146, 1_146u64..30_000],
        );
        proptest::collection::vec(frame, 1..24).prop_map(|frames| {
            let mut at_us = 0;
            let mut runs = Vec::new();
            for (bytes, role, gap, step) in frames {
                at_us += gap + 1_146;
                let channel = role.map_or(0, |r| r as u8);
                for part in bytes.chunks(Run::REST + 1) {
                    runs.extend(Run::of_bytes(at_us, step, channel, role, part));
                    at_us += step * part.len() as u64;
                }
            }
            runs
        })
    }

    fn heard_runs(runs: &[Run], by_event: bool, master_channel: Option<u8>) -> (Vec<String>, String) {
        let options = Options {
            profile: hiperface_model::profiles::srs50(),
            settings: UartSettings::DEFAULT,
            tolerance_us: 100,
            master_channel,
            polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
        };
        let mut l = Listener::new(options);
        let mut lines = Vec::new();
        for r in runs {
            if by_event {
                r.events().for_each(|e| l.feed(e, &mut |h| lines.push(h.to_string())));
            } else {
                l.feed_run(r, &mut |h| lines.push(h.to_string()));
            }
        }
        l.finish(runs.last().map_or(0, Run::last_us), &mut |h| lines.push(h.to_string()));
        (lines, serde_json::to_string(&l.summary).unwrap_or_default())
    }

    proptest! {
        /// A run is heard as its characters one by one.
        #[test]
        fn a_run_is_heard_as_its_events(runs in runs(), master_channel in proptest::option::of(0u8..2)) {
            prop_assert_eq!(heard_runs(&runs, false, master_channel), heard_runs(&runs, true, master_channel));
        }
    }

    proptest! {
        /// Characters that arrive before anything is due skip `advance`: the listener
        /// hears exactly what it hears when every character advances time first.
        #[test]
        fn skipping_until_due_changes_nothing(events in events()) {
            let (skipping, summary) = heard(&events, true);
            let (advancing, every) = heard(&events, false);
            prop_assert_eq!(skipping, advancing);
            prop_assert_eq!(summary, every);
        }
    }
}
