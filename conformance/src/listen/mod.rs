//! The passive listener: grade both sides of a conversation it only overhears (a live
//! bus tapped by a third transceiver, or a logic-analyzer capture). Sans-IO: it is
//! fed [`Event`]s in time order and reports each exchange as it closes.
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

use crate::capture::{Event, Mark, Role};
use crate::exchange::{Exchange, HeardLate};
use crate::line::Window;
use crate::verdict::timing::{self, TimingMode};
use crate::verdict::{CaseVerdict, Finding};
use heard::Heard;
use hiperface_model::command::CommandId;
use hiperface_model::datalink::{RxChar, UartFault};
use hiperface_model::frame::Hex;
use hiperface_model::master::obligations::{Observation, Observer};
use hiperface_model::oracle::{Deviation, Oracle};
use hiperface_model::request::RequestFrame;
use hiperface_model::response::ResponseFrame;
use hiperface_model::slave::{Reply, Slave};
use hiperface_model::{Grading, Profile, UartSettings};
use serde::Serialize;

pub mod cli;
mod heard;
pub mod monitor;
pub mod report;
mod summary;
pub mod tap;
pub use summary::Summary;

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

/// The frame being assembled on one channel.
#[derive(Debug)]
struct Assembly {
    channel: u8,
    /// Who sends on it, where the capture says.
    role: Option<Role>,
    heard: Heard,
}

/// A reply as heard: its characters, their bytes, and the frame they decode to.
struct ReplyHeard {
    heard: Heard,
    bytes: Vec<u8>,
    decoded: Option<ResponseFrame>,
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

/// One exchange as heard: what the live view prints and the report counts.
#[derive(Debug, Clone, Serialize)]
pub struct HeardExchange {
    /// End of the request, ms from the capture's start.
    pub t_ms: f64,
    #[serde(serialize_with = "summary::command_name")]
    pub command: CommandId,
    #[serde(serialize_with = "summary::hex")]
    pub request: Vec<u8>,
    #[serde(serialize_with = "summary::hex_or_silence")]
    pub reply: Option<Vec<u8>>,
    /// From the end of the request's timeout to the reply's first start bit, ms.
    pub response_ms: Option<f64>,
    pub verdict: CaseVerdict,
    pub findings: Vec<Finding>,
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
            summary: Summary::default(),
            options,
        }
    }

    /// Take in one event; `out` gets every exchange it closes.
    pub fn feed(&mut self, e: Event, out: &mut impl FnMut(&HeardExchange)) {
        self.advance(e.at_us, out);
        let role = e.role.or(match self.options.master_channel {
            Some(m) if m == e.channel => Some(Role::Master),
            Some(_) => Some(Role::Slave),
            None => None,
        });
        let (byte, fault) = match e.mark {
            Mark::Byte(b) => (b, None),
            Mark::ParityError(b) => (b, Some(UartFault::Parity)),
            Mark::FramingError(b) => (b, Some(UartFault::Framing)),
            Mark::Break => {
                // A break ends the frame it interrupts. // 000:T47 (a UART fault)
                self.summary.breaks += 1;
                self.close_channel(e.channel, out);
                return;
            }
        };
        self.summary.characters += 1;
        self.summary.flagged += u64::from(fault.is_some());
        const MAX: usize = 4 * hiperface_model::frame::MAX_FRAME;
        let at = match self.frames.binary_search_by_key(&e.channel, |a| a.channel) {
            Ok(at) => at,
            Err(at) => {
                self.frames.insert(at, Assembly { channel: e.channel, role, heard: Heard::default() });
                at
            }
        };
        let Some(a) = self.frames.get_mut(at) else { return };
        a.role = role;
        // A frame longer than any valid one is cut: memory stays bounded.
        if a.heard.len() < MAX {
            a.heard.push(RxChar { byte, at_us: e.at_us, fault }, e.late_us);
        }
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
                .filter_map(|a| Some((a.heard.chars.first()?.at_us, a.heard.chars.last()?.at_us, a.channel)))
                .filter(|(_, last, _)| last.saturating_add(self.timeout_us) <= now)
                .min();
            let Some((_, _, ch)) = due else { break };
            self.close_channel(ch, out);
        }
        if let Some(open) = &self.open {
            // A frame still being assembled that began in the window may be the reply.
            let end = open.window_end_us;
            let reply_under_way = self
                .frames
                .iter()
                .any(|a| a.heard.chars.first().is_some_and(|c| c.at_us.saturating_sub(self.char_us) <= end));
            // A reply that starts at the window's end is heard a character later.
            if now > end.saturating_add(self.char_us) && !reply_under_way {
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
    }

    /// The last instant a reply to a request of `command` that ended at `end_us` may
    /// start and still be heard as its reply: well past the command's limit, so that
    /// a late reply is measured, not lost.
    fn window_end(&self, command: CommandId, end_us: u64) -> u64 {
        let limit_us = self.options.profile.response_limit(command).max_ms as u64 * 1000;
        end_us.saturating_add(self.timeout_us + 3 * limit_us + self.options.tolerance_us)
    }

    fn close_channel(&mut self, ch: u8, out: &mut impl FnMut(&HeardExchange)) {
        let Some(a) = self.frames.iter_mut().find(|a| a.channel == ch) else { return };
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
        let bytes = heard.bytes();
        let command = CommandId::of_frame(&bytes);
        self.open = Some(Open {
            bytes,
            start_us: first.at_us.saturating_sub(self.char_us),
            end_us: last.at_us,
            end_late_us: heard.last_late_us(),
            window_end_us: self.window_end(command, last.at_us),
        });
    }

    fn reply(&mut self, heard: Heard, out: &mut impl FnMut(&HeardExchange)) {
        let Some(open) = self.open.take() else { return };
        let (Some(first), Some(last)) = (heard.chars.first(), heard.chars.last()) else { return };
        let bytes = heard.bytes();
        let decoded = ResponseFrame::decode(&bytes, open.command()).ok();
        self.observer.encoder_reply(first.at_us.saturating_sub(self.char_us), last.at_us, decoded.as_ref());
        self.exchange(open, Some(ReplyHeard { heard, bytes, decoded }), out);
    }

    /// Grade one exchange (its reply's characters and bytes, if one was heard): the
    /// reply's form and timing, and its content where the listener can know it.
    fn exchange(&mut self, open: Open, reply: Option<ReplyHeard>, out: &mut impl FnMut(&HeardExchange)) {
        let edition = self.options.profile.edition;
        let command = open.command();
        // The timeout the encoder framed the request with (its settings may have changed
        // since the capture began: 57h and a reset). // 000:T28/settings
        let timeout_us = self.shadow.timeout_us(open.end_us);
        let complete_us = open.end_us.saturating_add(timeout_us);
        let (reply, observed, decoded) = match reply {
            Some(r) => (Some(r.heard), Some(r.bytes), r.decoded),
            None => (None, None, None),
        };
        let mut before = self.shadow.clone();
        let mut expected = self.shadow.handle_frame(&open.bytes, complete_us);
        if let Some(code0) = accepted_code0(&open.bytes, &expected, decoded.as_ref()) {
            // The encoder took a Code0 the model refused: the listener does not know
            // the codes, so that one is the encoder's. // 000:T26
            before.adopt_access_code(0, code0);
            self.shadow = before.clone();
            expected = self.shadow.handle_frame(&open.bytes, complete_us);
        }
        let grade = self.oracle.grade(&before, &open.bytes, complete_us, &expected, observed.as_deref());
        let mut findings = Vec::new();
        if let Some(f) = Finding::graded(&grade, &open.bytes) {
            let knowable = grade.deviation().is_some_and(|d| knowable(&d, &open.bytes));
            findings.push(if knowable {
                f
            } else {
                Finding::unknown(format!(
                    "not graded: {f}; the listener does not know the encoder's stored state or its address"
                ))
            });
        }
        if let Some(r) = reply.as_ref().filter(|r| r.chars.iter().any(|c| c.fault.is_some())) {
            let n = r.chars.iter().filter(|c| c.fault.is_some()).count();
            findings.push(Finding::unknown(format!(
                "{n} characters of the reply had a parity or framing error as captured: the line, the tap or the encoder"
            )));
        }
        let mut response_ms = None;
        let mut request = open.bytes;
        if let (Some(r), Reply::Frame(_)) = (reply, expected.reply) {
            let heard_late = HeardLate { request_end_us: open.end_late_us, reply_start_us: r.first_late_us() };
            let x = Exchange {
                request,
                stray: Vec::new(),
                sent_start_us: open.start_us,
                request_end: Window::exact(open.end_us),
                reply_start: r.chars.first().map(|c| Window::exact(c.at_us.saturating_sub(self.char_us))),
                reply: r.chars,
                trailing: Vec::new(),
                settings: self.shadow.listening_settings(open.end_us).unwrap_or(self.options.settings),
                timeout_us,
                harness_late_us: 0,
                heard_late,
            };
            let limits = self.options.profile.response_limit(command);
            findings.extend(timing::grade(&x, limits, self.options.tolerance_us, TimingMode::Strict, edition));
            if let Some(t) = timing::at_most_us(&x) {
                response_ms = Some(t as f64 / 1000.0);
                self.summary.response_time(command, t);
            }
            request = x.request;
        }
        // What a well-formed reply tells of the encoder's world (as `certify` does on a
        // real device).
        if let (Some(frame), true) = (decoded, findings.is_empty()) {
            self.shadow.adopt_reply(&frame.response);
        }
        self.follow(complete_us);
        let heard = HeardExchange {
            t_ms: open.end_us as f64 / 1000.0,
            command,
            request,
            reply: observed,
            response_ms,
            verdict: findings.iter().fold(CaseVerdict::Pass, |v, f| v.worst(f.verdict())),
            findings,
        };
        self.summary.exchange(&heard);
        out(&heard);
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

/// Read a whole capture and listen to it, without printing, the reader on a thread
/// of its own as `decode` does: what the throughput benchmark and the tests run.
/// `format`: `None` detects it.
pub fn listen_to(
    input: &[u8],
    format: Option<crate::capture::Format>,
    read: crate::capture::ReadOptions,
    options: Options,
) -> Result<Summary, crate::capture::ParseError> {
    let (_, capture) = crate::capture::open(Box::new(input), format, read)?;
    std::thread::scope(|s| listen_all(crate::capture::prefetch(s, capture), options))
}

fn listen_all(
    capture: impl Iterator<Item = Result<crate::capture::Event, crate::capture::ParseError>>,
    options: Options,
) -> Result<Summary, crate::capture::ParseError> {
    let mut listener = Listener::new(options);
    let mut last_us = 0;
    for e in capture {
        let e = e?;
        last_us = e.at_us;
        listener.feed(e, &mut |_| {});
    }
    listener.finish(last_us, &mut |_| {});
    Ok(listener.summary)
}

/// The fuzz targets' entry (fuzz/fuzz_targets/capture_*.rs) and their corpus replay:
/// any bytes as a capture of `format` (9600 Bd, sigrok at 1 MHz) through its reader
/// and the listener, on one thread. An error for bad input is fine; a panic or a
/// hang is not.
pub fn fuzz_capture(format: crate::capture::Format, input: &[u8]) {
    let profile = hiperface_model::profiles::srs50();
    let options = Options {
        profile,
        settings: UartSettings::DEFAULT,
        tolerance_us: 1_000,
        master_channel: None,
        polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
    };
    let read = crate::capture::ReadOptions { baud: 9600, samplerate_hz: Some(1_000_000) };
    if let Ok((_, capture)) = crate::capture::open(Box::new(input), Some(format), read) {
        let _ = listen_all(capture, options);
    }
}

/// The Code0 of a request the model refused for its access code and the encoder
/// accepted (a reply of the command's own form, not an error).
fn accepted_code0(
    request: &[u8],
    expected: &hiperface_model::slave::Outcome,
    heard: Option<&ResponseFrame>,
) -> Option<u8> {
    use hiperface_model::response::Response;
    use hiperface_model::FaultCode::WrongAccessCode;
    let refused = match expected.reply {
        Reply::Frame(f) => f.response == Response::Error(WrongAccessCode) || expected.also.contains(WrongAccessCode),
        Reply::Silent(_) => false,
    };
    let accepted = heard.is_some_and(|h| !matches!(h.response, Response::Error(_)));
    let code0 = RequestFrame::decode(request).ok().and_then(|r| r.request.code0());
    code0.filter(|_| refused && accepted)
}

/// A deviation the listener can see whatever the encoder's stored state: the reply's
/// form, its address echo to a request that named one, a warning bit with "no fault".
fn knowable(d: &Deviation, request: &[u8]) -> bool {
    match d {
        Deviation::Malformed(_) | Deviation::WarningWithoutCode => true,
        Deviation::WrongAddress { .. } => request.first() != Some(&0xFF),
        _ => false,
    }
}
