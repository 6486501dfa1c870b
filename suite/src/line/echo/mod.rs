//! Local echo: a two-wire RS-485 adapter whose receiver stays on while it sends hears
//! its own request before the device's reply. [`EchoLine`] wraps any line, finds out
//! at the first request whether it echoes (`--echo auto`), and takes the echo off the
//! line, so that the exchange sees only what the device sent. An echo that differs
//! from the request is the line's fault (a collision, a broken transceiver): an ERROR
//! of the line, never charged to the device.

use super::{Line, LineError, LineKind, Sent, Window};
use hiperface_model::datalink::RxChar;
use hiperface_model::{Hex, UartSettings};
use std::collections::VecDeque;

/// Whether the line echoes what the harness sends (`--echo`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum EchoMode {
    /// Found out at the harness's first frame (its request, or as the encoder its
    /// reply, comes back byte for byte before the other end could answer) and taken
    /// off the line where it does.
    #[default]
    Auto,
    /// The line echoes: every frame the harness sends comes back and is taken off the
    /// line.
    On,
    /// The line does not echo; a frame of the harness's that comes back is reported
    /// as a line fault ("the line echoes: use --echo auto"), not graded as the other
    /// end's.
    Off,
}

/// What the harness knows about the line's echo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Echo {
    /// No request sent yet (`auto`).
    Unknown,
    /// Requests come back; the echo is taken off the line.
    Echoes,
    /// Requests do not come back.
    Quiet,
}

/// The certificate's "echo" row: what was found of the line's echo of what the
/// harness sent (`what`: "request" as master, "reply" as encoder), under `--echo`.
pub fn describe(state: Option<(Echo, EchoMode)>, what: &str) -> String {
    match state {
        Some((Echo::Echoes, EchoMode::On)) => format!("the line echoes (--echo on): each {what}'s echo was taken off the line"),
        Some((Echo::Echoes, EchoMode::Off)) => format!(
            "the line echoes, not expected (--echo off): reported as a fault of the line at each {what}, not graded; use --echo auto"
        ),
        Some((Echo::Echoes, EchoMode::Auto)) => {
            // As master, the echo's end also bounds when the request ended.
            let times = if what == "request" { " and times its end" } else { "" };
            format!("the line echoes (found at the first {what}): each {what}'s echo was taken off the line{times}")
        }
        Some((Echo::Quiet, EchoMode::Off)) => format!("not expected (--echo off); no {what} came back"),
        Some((Echo::Quiet, _)) => format!("none (found at the first {what})"),
        Some((Echo::Unknown, _)) => format!("unknown: no {what} was sent"),
        None => "not watched".into(),
    }
}

/// How long past its deadline an echo known to come is still waited for, µs: as long
/// as the exchanges wait for a late reply (`exchange::LATE_REPLY_GRACE_MS`). The echo
/// of a request here, of a reply in `reply_echo`.
pub(crate) const LATE_ECHO_GRACE_US: u64 = 1_000_000;

/// A line with its echo handled.
pub struct EchoLine<L: Line> {
    inner: L,
    mode: EchoMode,
    echo: Echo,
    /// Characters read while looking for an echo that were not one: the device's.
    held: VecDeque<RxChar>,
}

impl<L: Line> EchoLine<L> {
    pub fn new(inner: L, mode: EchoMode) -> EchoLine<L> {
        let echo = match mode {
            EchoMode::Auto | EchoMode::Off => Echo::Unknown,
            EchoMode::On => Echo::Echoes,
        };
        EchoLine { inner, mode, echo, held: VecDeque::new() }
    }

    pub fn echo(&self) -> Echo {
        self.echo
    }

    /// By when the echo of `sent` has come back: it is on the line while the request
    /// is, so by the time a reply could begin (the request's end and the device's
    /// timeout, 000:2.2.2), with the line's own latency.
    fn echo_deadline(&self, sent: &Sent) -> u64 {
        let timeout = self.inner.settings().timeout_us(hiperface_model::Edition::Current);
        sent.end.latest_us + timeout + self.inner.tolerance_us()
    }

    /// The next character, the held ones first.
    fn next(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        match self.held.pop_front() {
            Some(c) => Ok(Some(c)),
            None => self.inner.recv(until_us),
        }
    }

    /// Read what came back of `sent` by `until_us`: the characters that match it from
    /// its start, and the first that does not (or `None` when the line fell quiet).
    fn read_back(&mut self, sent: &[u8], until_us: u64) -> Result<(Vec<RxChar>, Option<RxChar>), LineError> {
        let mut matched = Vec::with_capacity(sent.len());
        while matched.len() < sent.len() {
            match self.next(until_us)? {
                Some(c) if Some(&c.byte) == sent.get(matched.len()) => matched.push(c),
                other => return Ok((matched, other)),
            }
        }
        Ok((matched, None))
    }
}

/// `--echo off` on a line that echoes.
fn off_but_echoes() -> LineError {
    LineError::Echo("the line echoes: the request came back byte for byte before any reply; use --echo auto".into())
}

/// The request's end, narrowed by its echo: the last character cannot have come back
/// before it was on the wire, so the request ended no later than the echo's last
/// character arrived.
fn narrowed(end: Window, echo_end_us: u64) -> Window {
    Window { earliest_us: end.earliest_us, latest_us: end.latest_us.min(echo_end_us.max(end.earliest_us)) }
}

impl<L: Line> Line for EchoLine<L> {
    fn now_us(&mut self) -> u64 {
        self.inner.now_us()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        let sent = self.inner.send(bytes)?;
        if self.echo == Echo::Quiet {
            return Ok(sent);
        }
        // An echo is on its way however late the machine delivers it (seen: none back
        // by the deadline with three busy loops on a pseudo-terminal), and it comes
        // before anything the device sends, which is on the wire after it; so it is
        // waited for as a late reply is. What is read meanwhile decides as it comes,
        // as it did by the deadline (a reply is told from the echo where the two
        // differ); only a line that lost its echo, or a device silent at the first
        // request, pays the whole wait.
        let until = self.echo_deadline(&sent) + LATE_ECHO_GRACE_US;
        if self.mode == EchoMode::Off && self.echo == Echo::Echoes {
            // Found echoing under --echo off: whatever comes back now (the echo, or a
            // reply to an earlier request still on its way on a slow machine) is not
            // graded, and the diagnosis is the same at every request.
            let (_, other) = self.read_back(bytes, until)?;
            self.held.extend(other);
            return Err(off_but_echoes());
        }
        let (matched, other) = self.read_back(bytes, until)?;
        // The request came back: found now (at the first request only: a later reply
        // may be its request byte for byte, Increment Counter's is; the harness's
        // first request is Read Type Label, whose reply has data), or as expected.
        let came_back = matched.len() == bytes.len() && (self.echo == Echo::Echoes || !bytes.is_empty());
        match (came_back, self.echo) {
            (true, _) => {
                self.echo = Echo::Echoes;
                self.held.extend(other);
                if self.mode == EchoMode::Off {
                    // Watched all the same, to say so rather than grade it; and from
                    // now on at every request, so that nothing is graded.
                    return Err(off_but_echoes());
                }
                let end = matched.last().map_or(sent.end, |c| narrowed(sent.end, c.at_us));
                Ok(Sent { end, ..sent })
            }
            (false, Echo::Echoes) => {
                let heard: Vec<u8> = matched.iter().chain(other.iter()).map(|c| c.byte).collect();
                Err(LineError::Echo(format!(
                    "the echo of [{}] came back as [{}]: a collision or a fault of the line, not the device's",
                    Hex(bytes),
                    Hex(&heard)
                )))
            }
            // The device's reply (or nothing): given back to the exchange.
            (false, _) => {
                self.echo = Echo::Quiet;
                self.held.extend(matched);
                self.held.extend(other);
                Ok(sent)
            }
        }
    }

    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        match self.held.front() {
            Some(c) if c.at_us <= until_us => Ok(self.held.pop_front()),
            Some(_) => Ok(None),
            None => self.inner.recv(until_us),
        }
    }

    fn start_of(&self, ch: &RxChar) -> Window {
        self.inner.start_of(ch)
    }
    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        self.inner.wait_until(t_us)
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        self.inner.configure(settings)
    }
    fn can_change_settings(&self) -> bool {
        self.inner.can_change_settings()
    }
    fn settings(&self) -> UartSettings {
        self.inner.settings()
    }
    fn carries_parity(&self) -> Result<(), &'static str> {
        self.inner.carries_parity()
    }
    fn send_with_wrong_parity(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        // The echo of a request sent with the wrong parity comes back with parity
        // errors, or not at all: whatever of it comes back is not the device's.
        let sent = self.inner.send_with_wrong_parity(bytes)?;
        if self.echo == Echo::Echoes {
            let until = self.echo_deadline(&sent);
            for _ in 0..bytes.len() {
                if self.next(until)?.is_none() {
                    break;
                }
            }
        }
        Ok(sent)
    }
    fn tolerance_us(&self) -> u64 {
        self.inner.tolerance_us()
    }
    fn take_lateness_us(&mut self) -> u64 {
        self.inner.take_lateness_us()
    }
    fn delivery_late(&mut self, from_us: u64, to_us: u64) -> super::delivery::LineLate {
        self.inner.delivery_late(from_us, to_us)
    }
    fn delivery_stats(&self) -> Option<super::delivery::DeliveryStats> {
        self.inner.delivery_stats()
    }
    fn device_held(&mut self) -> super::delivery::DeviceHeld {
        self.inner.device_held()
    }
    fn kind(&self) -> LineKind {
        self.inner.kind()
    }
    fn describe(&self) -> String {
        self.inner.describe()
    }
    fn notes(&self) -> Vec<String> {
        self.inner.notes()
    }
    fn echo(&self) -> Option<(Echo, EchoMode)> {
        Some((self.echo, self.mode))
    }
}

#[cfg(test)]
mod tests;
