//! The harness as HIPERFACE master: one exchange is a request, the pause the
//! protocol mandates, and the reply framed by the inter-character timeout exactly as
//! the model's data link frames it. Every read is bounded in time.
//!
//! Long because: the request, the mandated pause and the reply framed by the data
//! link's timeout are one bounded loop, read together; under 390 lines without its
//! tests.

use crate::line::{Line, LineError, Window};
use hiperface_model::datalink::{DataLink, RxChar};
use hiperface_model::frame::MAX_FRAME;
use hiperface_model::{checksum, Edition, UartFault, UartSettings};
use serde::{Deserialize, Serialize};

pub use crate::frame::sealed;

/// One request and what came back.
#[derive(Debug, Clone)]
pub struct Exchange {
    pub request: Vec<u8>,
    /// Characters that arrived before the request was sent (outside any reply).
    pub stray: Vec<RxChar>,
    /// When the master began writing the request.
    pub sent_start_us: u64,
    /// When the slave received the request's last character.
    pub request_end: Window,
    /// The reply's characters; empty for silence.
    pub reply: Vec<RxChar>,
    /// When the reply's first start bit began.
    pub reply_start: Option<Window>,
    /// Characters that came after the reply had ended (a pause of at least the
    /// timeout, 000:2.2.2) and before the next request could start: the rest of a
    /// reply with a gap, a late reply, or noise. Empty on a conformant line.
    pub trailing: Vec<RxChar>,
    pub settings: UartSettings,
    /// The slave's frame timeout, counted between character ends (the data link's).
    pub timeout_us: u64,
    /// The shortest pause after the request's last stop bit that the edition lets a
    /// reply follow (`UartSettings::pause_us`): the timeout in 000, 002's shorter
    /// figure for a legacy device (DESIGN:legacy-timeout).
    pub pause_us: u64,
    /// The longest the harness woke late from a timed wait during the exchange, or
    /// waited for a processor in it: its own scheduling delay, which bounds how late
    /// it may have noticed a character or written its request. What it could explain
    /// is never charged to the device.
    pub harness_late_us: u64,
    /// How long the harness's write of the request took, of the width of
    /// `request_end` (`line::Sent::write_us`): a reading of the request's end only
    /// that width allows is the harness's doing, and a reply is never passed on it.
    pub request_write_us: u64,
    /// How much the line itself may have delayed the exchange, both ways, as measured
    /// beside it (a pseudo-terminal's delivery: `line::delivery`); 0 where nothing is
    /// measured. Like the harness's own lateness, never charged to the device.
    pub line_late: crate::line::delivery::LineLate,
    /// How long the device's own processor was held during the exchange, where it runs
    /// on this machine (`line::delivery::DeviceHeld`): what could have split the
    /// request as the device heard it is never charged to the device.
    pub device_held: crate::line::delivery::DeviceHeld,
    /// How late a listener may have heard the request's end and the reply's start,
    /// measured for each (zero where the harness took the stamps itself).
    pub heard_late: HeardLate,
}

/// How late a listener may have heard the two instants a response time is measured
/// between: a live tap's read that returned them after its reader had waited for a
/// processor (see `crate::sched`). A request heard late ended earlier than stamped
/// (the reply came later after it than measured); a reply heard late began earlier.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct HeardLate {
    pub request_end_us: u64,
    pub reply_start_us: u64,
}

impl Exchange {
    /// How much of the reply's timing the harness could not see: its own lateness and
    /// the line's delay of the reply (the request's delivery moves the whole reply,
    /// not one part of it against another), µs.
    pub fn reply_unseen_late_us(&self) -> u64 {
        self.harness_late_us + self.line_late.reply_us
    }

    pub fn reply_bytes(&self) -> Option<Vec<u8>> {
        (!self.reply.is_empty()).then(|| self.reply.iter().map(|c| c.byte).collect())
    }

    /// When the slave's frame timeout after the request elapsed (000:2.2.2).
    pub fn complete(&self) -> Window {
        self.request_end.shifted(self.timeout_us)
    }

    /// The harness's point estimate of when the request was complete: the earliest
    /// reading (exact where the line knows).
    pub fn complete_us(&self) -> u64 {
        self.complete().earliest_us
    }

    /// Reply start relative to the end of the request's timeout, µs (negative:
    /// early): the least and the most the line's uncertainty and the edition allow.
    /// The most is counted from the earliest a reply may start (the request's end
    /// and the edition's pause), the least from the latest the timeout can elapse.
    pub fn response_time_us(&self) -> Option<(i64, i64)> {
        let (s, c) = (self.reply_start?, self.complete());
        let allowed_from = self.request_end.earliest_us + self.pause_us.min(self.timeout_us);
        Some((s.earliest_us as i64 - c.latest_us as i64, s.latest_us as i64 - allowed_from as i64))
    }
}

/// The bus as the slave certification sees it: the harness in the master's seat
/// ([`BusMaster`] on a live line), or a record of such a run played back
/// (`slave::record::Replay`). Everything a verdict rests on comes through here.
pub trait Bus {
    fn now_us(&mut self) -> u64;
    /// Send `request` and collect what came back (see [`BusMaster::exchange_listening`]).
    fn exchange_listening(&mut self, request: &[u8], listen: Listen) -> Result<Exchange, LineError>;
    /// Wait on an idle line until `t_us`, collecting anything that arrives.
    fn listen_until(&mut self, t_us: u64) -> Result<Vec<RxChar>, LineError>;
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError>;
    fn settings(&self) -> UartSettings;
    /// The slave's frame timeout in the current settings.
    fn timeout_us(&self) -> u64;
    /// What is known of the line for the whole run.
    fn facts(&self) -> LineFacts;
    /// What the run found out about the line by its end.
    fn findings(&self) -> LineFindings;
}

/// What a run knows of its line from the start.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct LineFacts {
    pub describe: String,
    pub kind: crate::line::LineKind,
    pub tolerance_us: u64,
    pub can_change_settings: bool,
    /// `Err`: why a parity error cannot be sent on the line.
    pub carries_parity: Result<(), NoParity>,
}

/// Why a parity error cannot be sent on a line (a pseudo-terminal has no parity bit, a
/// raw TCP server sends in its own settings): the case that needs one does not apply.
/// Kept in a record as the text it says.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize, thiserror::Error)]
#[serde(transparent)]
#[error("{0}")]
pub struct NoParity(pub String);

/// What a run found out about its line by its end.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LineFindings {
    pub notes: Vec<String>,
    pub echo: Option<(crate::line::echo::Echo, crate::line::echo::EchoMode)>,
    pub delivery: Option<crate::line::delivery::DeliveryStats>,
}

impl<L: Line> Bus for BusMaster<L> {
    fn now_us(&mut self) -> u64 {
        self.line.now_us()
    }
    fn exchange_listening(&mut self, request: &[u8], listen: Listen) -> Result<Exchange, LineError> {
        self.exchange_sent(request, listen)
    }
    fn listen_until(&mut self, t_us: u64) -> Result<Vec<RxChar>, LineError> {
        BusMaster::listen_until(self, t_us)
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        self.line.configure(settings)
    }
    fn settings(&self) -> UartSettings {
        self.line.settings()
    }
    fn timeout_us(&self) -> u64 {
        BusMaster::timeout_us(self)
    }
    fn facts(&self) -> LineFacts {
        LineFacts {
            describe: self.line.describe(),
            kind: self.line.kind(),
            tolerance_us: self.line.tolerance_us(),
            can_change_settings: self.line.can_change_settings(),
            carries_parity: self.line.carries_parity().map_err(|why| NoParity(why.to_string())),
        }
    }
    fn findings(&self) -> LineFindings {
        LineFindings { notes: self.line.notes(), echo: self.line.echo(), delivery: self.line.delivery_stats() }
    }
}

/// What an exchange listens for after its request.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Listen {
    /// How long after the request's timeout the reply's first character may start, ms.
    pub reply_ms: u16,
    /// Send the request with the wrong parity (see [`Line::send_with_wrong_parity`]).
    pub wrong_parity: bool,
    /// The slave goes into initialization after this request (Encoder Reset): with
    /// no reply, the exchange ends with its reply window.
    pub slave_initializes: bool,
    /// Where a reply is expected and none began in the window: how much longer to
    /// listen for a late one before the next request, ms (it costs only a device that
    /// answers late or not at all).
    pub late_grace_ms: u16,
}

/// How long past the reply window a harness that expects a reply still listens for a
/// late one, ms: a reply later than that is heard by the next exchange.
pub const LATE_REPLY_GRACE_MS: u16 = 1000;

/// The harness in the bus master's seat on a line: it sends requests and frames the
/// replies. (Not the drive-side model, `hiperface_model::master`, nor the reference
/// master command, `master::reference`.)
pub struct BusMaster<L: Line> {
    pub line: L,
    edition: Edition,
    /// End of the last activity on the line; the next request waits a timeout after it.
    idle_since_us: u64,
}

impl<L: Line> BusMaster<L> {
    pub fn new(line: L, edition: Edition) -> BusMaster<L> {
        BusMaster { line, edition, idle_since_us: 0 }
    }

    pub fn timeout_us(&self) -> u64 {
        self.line.settings().timeout_us(self.edition)
    }

    /// Send `request` and collect the reply. `listen_ms` bounds the wait for the
    /// first character (after the request's timeout), with the line's tolerance.
    pub fn exchange(&mut self, request: &[u8], listen_ms: u16) -> Result<Exchange, LineError> {
        self.exchange_sent(request, Listen { reply_ms: listen_ms, ..Listen::default() })
    }

    /// [`BusMaster::exchange`] with what to listen for said in full.
    pub fn exchange_listening(&mut self, request: &[u8], listen: Listen) -> Result<Exchange, LineError> {
        self.exchange_sent(request, listen)
    }

    fn exchange_sent(&mut self, request: &[u8], listen: Listen) -> Result<Exchange, LineError> {
        let Listen { reply_ms: listen_ms, wrong_parity, slave_initializes, late_grace_ms } = listen;
        let settings = self.line.settings();
        let timeout = self.timeout_us();
        let ct = settings.char_time_us();
        // 000:2.2.2: the end of a transmission is a pause of at least the timeout.
        // Never more than a frame's time ahead of now, whatever a babbling line reported.
        let now = self.line.now_us();
        let mut ready = (self.idle_since_us + timeout).min(now + MAX_FRAME as u64 * ct + timeout);
        let mut stray = Vec::new();
        // Up to now at least: what arrived while the master was not reading (a reply
        // that came after its exchange had ended, during a wait between requests) is
        // stray, not the start of the reply to the request about to go.
        while let Some(c) = self.line.recv(ready.max(now))? {
            // Someone is talking: the line is free a timeout after its last character
            // (000:2.2.2). A line that never stops is waited out for two frames' worth.
            if stray.len() < 2 * MAX_FRAME {
                ready = ready.max(c.at_us + timeout);
            }
            stray.push(c);
        }
        self.line.wait_until(ready)?;
        let sent_start_us = self.line.now_us();
        self.line.take_lateness_us();
        let sent = if wrong_parity { self.line.send_with_wrong_parity(request)? } else { self.line.send(request)? };
        let complete = sent.end.shifted(timeout);
        // A reply that starts within the window has its first character complete one
        // character time later; the line's tolerance covers the rest.
        let deadline = complete.latest_us + listen_ms as u64 * 1000 + ct + self.line.tolerance_us();
        let mut reply = Vec::new();
        let mut trailing = Vec::new();
        let mut link = DataLink::new(timeout);
        // Nothing in the window: a reply later still is this request's, late, and not
        // the next request's (its clause and its request would be wrong).
        let first = match self.line.recv(deadline)? {
            None if late_grace_ms > 0 => self.line.recv(deadline + late_grace_ms as u64 * 1000)?,
            first => first,
        };
        if let Some(first) = first {
            link.receive(first);
            reply.push(first);
            // Further characters belong to the reply until the data link's timeout
            // elapses; a device that never stops talking is cut off after two frames' worth.
            while let Some(until) = link.deadline().filter(|_| reply.len() < 2 * MAX_FRAME) {
                match self.line.recv(until.saturating_sub(1))? {
                    // Read late, after the pause that ends the reply: what follows it.
                    Some(c) if c.at_us >= until => {
                        trailing.push(c);
                        break;
                    }
                    Some(c) => {
                        link.receive(c);
                        reply.push(c);
                    }
                    None => break,
                }
            }
        }
        let mut end = trailing.last().or(reply.last()).map_or(complete.latest_us.max(self.line.now_us()), |c| c.at_us);
        // The pause before the next request belongs to this exchange: whatever arrives
        // in it is this exchange's (000:2.2.2: a transmission ends with a pause of at
        // least the timeout), not unsolicited traffic before the next one.
        // A reply that does not check (cut short, or with a bad checksum) may go on
        // after a gap: listen as long as for a reply, so that its rest is this
        // exchange's finding and not a collision with the next request.
        let bytes: Vec<u8> = reply.iter().map(|c| c.byte).collect();
        let cut = !bytes.is_empty() && (bytes.len() < 3 || !checksum::is_valid(&bytes));
        // After a request that puts the slave into initialization (Encoder Reset) and
        // no reply, nothing the slave sends can be a reply any more (000:T9: no UART
        // communication): the next exchange hears whatever comes.
        let pause = if cut {
            timeout.max(listen_ms as u64 * 1000)
        } else if slave_initializes && reply.is_empty() {
            0
        } else {
            timeout
        };
        while pause > 0 && trailing.len() < 2 * MAX_FRAME {
            match self.line.recv(end + pause)? {
                Some(c) => {
                    end = c.at_us;
                    trailing.push(c);
                }
                None => break,
            }
        }
        self.idle_since_us = end;
        let reply_start = reply.first().map(|c| self.line.start_of(c));
        Ok(Exchange {
            request: request.to_vec(),
            stray,
            sent_start_us,
            request_end: sent.end,
            reply,
            reply_start,
            trailing,
            settings,
            timeout_us: timeout,
            pause_us: settings.pause_us(self.edition),
            harness_late_us: self.line.take_lateness_us(),
            request_write_us: sent.write_us,
            line_late: self.line.delivery_late(sent_start_us, end.max(complete.latest_us)),
            device_held: self.line.device_held(),
            heard_late: HeardLate::default(),
        })
    }

    /// Wait on an idle line until `t_us`, collecting anything that arrives.
    pub fn listen_until(&mut self, t_us: u64) -> Result<Vec<RxChar>, LineError> {
        let mut got = Vec::new();
        while let Some(c) = self.line.recv(t_us)? {
            got.push(c);
            self.idle_since_us = c.at_us;
        }
        Ok(got)
    }

    pub fn now_us(&mut self) -> u64 {
        self.line.now_us()
    }
}

/// A received character as a record of the wire keeps it (`slave::record`,
/// `master::record`): byte, stamp (µs, the end of its stop bit on the harness's
/// clock) and UART fault, if any.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Char(pub u8, pub u64, #[serde(default, skip_serializing_if = "Option::is_none")] pub Option<Fault>);

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Fault {
    Parity,
    Framing,
    Noise,
    Overrun,
}

impl From<RxChar> for Char {
    fn from(c: RxChar) -> Char {
        let fault = c.fault.map(|f| match f {
            UartFault::Parity => Fault::Parity,
            UartFault::Framing => Fault::Framing,
            UartFault::Noise => Fault::Noise,
            UartFault::Overrun => Fault::Overrun,
        });
        Char(c.byte, c.at_us, fault)
    }
}

impl From<Char> for RxChar {
    fn from(Char(byte, at_us, fault): Char) -> RxChar {
        let fault = fault.map(|f| match f {
            Fault::Parity => UartFault::Parity,
            Fault::Framing => UartFault::Framing,
            Fault::Noise => UartFault::Noise,
            Fault::Overrun => UartFault::Overrun,
        });
        RxChar { byte, at_us, fault }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_character_keeps_its_byte_stamp_and_fault() {
        for fault in
            [None, Some(UartFault::Parity), Some(UartFault::Framing), Some(UartFault::Noise), Some(UartFault::Overrun)]
        {
            let c = RxChar { byte: 0xA5, at_us: 123_456, fault };
            assert_eq!(RxChar::from(Char::from(c)), c);
        }
    }
    use crate::line::{LineKind, Sent};
    use std::collections::VecDeque;

    const CT: u64 = 1_146;

    /// A line in virtual time that plays given characters and notes when the master
    /// began each request.
    struct Scripted {
        now: u64,
        inbound: VecDeque<RxChar>,
        sent_at: Vec<u64>,
    }

    impl Line for Scripted {
        fn now_us(&mut self) -> u64 {
            self.now
        }
        fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
            self.sent_at.push(self.now);
            self.now += bytes.len() as u64 * CT;
            Ok(Sent::within(Window::exact(self.now)))
        }
        fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
            match self.inbound.front() {
                Some(c) if c.at_us <= until_us => {
                    self.now = self.now.max(c.at_us);
                    Ok(self.inbound.pop_front())
                }
                _ => {
                    self.now = self.now.max(until_us);
                    Ok(None)
                }
            }
        }
        fn start_of(&self, ch: &RxChar) -> Window {
            Window::exact(ch.at_us - CT)
        }
        fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
            self.now = self.now.max(t_us);
            Ok(())
        }
        fn configure(&mut self, _: UartSettings) -> Result<(), LineError> {
            Ok(())
        }
        fn settings(&self) -> UartSettings {
            UartSettings::DEFAULT
        }
        fn kind(&self) -> LineKind {
            LineKind::Virtual
        }
        fn describe(&self) -> String {
            "scripted".into()
        }
    }

    fn line(chars: impl IntoIterator<Item = u64>) -> BusMaster<Scripted> {
        let inbound = chars.into_iter().map(|at| RxChar::ok(0x40, at)).collect();
        BusMaster::new(Scripted { now: 0, inbound, sent_at: Vec::new() }, Edition::Current)
    }

    #[test]
    fn a_request_waits_until_the_line_has_been_quiet_for_the_timeout() {
        // Someone talks from 3 ms on: the request goes a timeout after the last
        // character (000:2.2.2), not a timeout after the line was last known idle.
        let mut m = line([3_000, 3_000 + CT, 3_000 + 2 * CT]);
        let timeout = m.timeout_us();
        let x = m.exchange(&sealed(&[0x40, 0x42]), 10).unwrap();
        assert_eq!(x.stray.len(), 3);
        assert_eq!(m.line.sent_at, vec![3_000 + 2 * CT + timeout]);
    }

    #[test]
    fn a_reply_that_came_between_exchanges_is_stray_not_the_next_reply() {
        // The first request has no reply in its window; one comes 60 ms on, while the
        // master waits before its next request, which the slave does not answer.
        let late = [60_000, 60_000 + CT, 60_000 + 2 * CT];
        let mut m = line(late);
        let first = m.exchange(&sealed(&[0x40, 0x42]), 10).unwrap();
        assert!(first.reply.is_empty() && first.trailing.is_empty(), "{first:?}");
        m.line.wait_until(100_000).unwrap();
        let next = m.exchange(&sealed(&[0x40, 0x42]), 10).unwrap();
        assert_eq!(next.stray.iter().map(|c| c.at_us).collect::<Vec<_>>(), late);
        assert!(next.reply.is_empty(), "{next:?}");
        assert_eq!(m.line.sent_at[1], 100_000, "the line was quiet for the timeout already");
    }

    #[test]
    fn a_line_that_never_stops_is_waited_out_for_two_frames_only() {
        let mut m = line((0..1_000).map(|i| 1_000 + i * CT));
        m.exchange(&sealed(&[0x40, 0x42]), 10).unwrap();
        let waited = m.line.sent_at.first().copied().unwrap_or(u64::MAX);
        assert!(waited <= 1_000 + (2 * MAX_FRAME as u64 + 1) * CT + m.timeout_us(), "{waited}");
    }
}
