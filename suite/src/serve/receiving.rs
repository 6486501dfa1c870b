//! What the reads of a line bring a served encoder, without the line: each read's
//! bytes stamped as the encoder's UART would have received them, the kernel's marks
//! of UART faults taken back, a character at another data rate than the encoder
//! listens at made a framing error, the echo of its own replies taken off, and the
//! master's characters handed to the session in the order they came. The real-time
//! serving loop reads the port and hands each read here.

use super::{Hooks, Serving, Session};
use crate::capture::parmrk::Marks;
use crate::line::rx_clock::RxClock;
use hiperface_model::datalink::RxChar;
use hiperface_model::UartFault;

/// The receiving side of an encoder served on a line.
#[derive(Debug)]
pub struct Receiving {
    serving: Serving,
    rx_clock: RxClock,
    /// The kernel's marks of UART faults, taken back across reads.
    marks: Marks,
    /// The master's characters, off the line and its echo, in the order they came.
    master_chars: Vec<RxChar>,
    /// How far the line has been watched by the reads since [`Receiving::turn`] (a
    /// read that came back at `t` after the line was unwatched for a while saw what
    /// had come by `t - unwatched`, no later: what came meanwhile may wait in the
    /// kernel for the next read).
    watched_through_us: Option<u64>,
}

impl Receiving {
    /// Nothing received yet, the port used as `serving` says.
    pub fn new(serving: Serving) -> Receiving {
        Receiving {
            serving,
            rx_clock: RxClock::default(),
            marks: Marks::default(),
            master_chars: Vec::new(),
            watched_through_us: None,
        }
    }

    /// One read: `bytes` returned at `at_us`, the line not watched for `unwatched_us`
    /// before it (0 when it was); `line_bps`: the line's data rate where the other end
    /// sets it ([`Serving::follows_line_settings`]).
    pub fn read<H: Hooks>(
        &mut self,
        session: &mut Session<H>,
        bytes: &[u8],
        at_us: u64,
        unwatched_us: u64,
        line_bps: Option<u32>,
    ) {
        self.watched_through_us = Some(at_us.saturating_sub(unwatched_us));
        session.handle_read(unwatched_us);
        let listening = session.listening_settings(at_us);
        let arrived = if self.serving.stamps_as_early_as_unwatched {
            let timeout = listening.unwrap_or_default().timeout_us(session.slave().profile().edition);
            let last_us = self.rx_clock.last_us();
            let in_progress = (last_us > session.framed_through_us()).then_some(last_us);
            continued_arrival_us(at_us, unwatched_us, in_progress, timeout)
        } else {
            at_us
        };
        let char_time_us = listening.unwrap_or_default().char_time_us();
        for (byte, fault) in unmarked(bytes, self.serving.marks_errors.then_some(&mut self.marks)) {
            let mut ch = self.rx_clock.stamp(byte, arrived, Some(char_time_us));
            ch.fault = ch.fault.or(fault);
            if let (Some(bps), Some(l)) = (line_bps, listening) {
                if bps != l.baud.bits_per_second() {
                    ch.fault = Some(UartFault::Framing);
                }
            }
            match session.hooks_mut().reply_echo() {
                Some(echo) => echo.take(ch, &mut self.master_chars),
                None => self.master_chars.push(ch),
            }
        }
        // The master's characters in the order they came, at the settings the model
        // listened at when they were read.
        session.receive_all(self.master_chars.drain(..), Some(at_us));
    }

    /// The reads of this turn are in: an echo awaited is given up only for time the
    /// line was watched (one the harness did not read for its own lateness may still
    /// be in the kernel, and is the echo, not the master's), and the characters the
    /// echo held that were the master's go to the model, at the settings it listened
    /// at when they came.
    pub fn turn<H: Hooks>(&mut self, session: &mut Session<H>) {
        if let (Some(echo), Some(through)) = (session.hooks_mut().reply_echo(), self.watched_through_us.take()) {
            echo.idle(through, &mut self.master_chars);
        }
        session.receive_all(self.master_chars.drain(..), None);
    }

    /// A reply `frame` went out, its last character ending at `end_us`: the echo
    /// awaits it; characters it held that were the master's after all come first at
    /// the next turn.
    pub fn sent<H: Hooks>(&mut self, session: &mut Session<H>, frame: &[u8], end_us: u64) {
        if let Some(echo) = session.hooks_mut().reply_echo() {
            echo.sent(frame, end_us, &mut self.master_chars);
        }
    }

    /// Serving stopped with `bytes` read at `at_us` while the last reply went out:
    /// they hold part of its echo, which the echo takes off, so that whoever serves
    /// the port next (the next scenario) does not await the part it already had.
    pub fn stopped<H: Hooks>(&mut self, session: &mut Session<H>, bytes: &[u8], at_us: u64) {
        if let Some(echo) = session.hooks_mut().reply_echo() {
            for (byte, fault) in unmarked(bytes, self.serving.marks_errors.then_some(&mut self.marks)) {
                echo.take(RxChar { byte, at_us, fault }, &mut Vec::new());
            }
        }
    }
}

/// When characters read at `read_us`, the line unwatched for `unwatched_us` before,
/// arrived for a simulator that plays the UART: those that may have continued the frame
/// in progress (its last character ended at `in_progress`; they may have arrived within
/// `timeout_us` of it) as early as the lateness allows, so that its own lateness never
/// splits a request; the first of a frame when read (a reply is then planned late,
/// never before the request ended).
fn continued_arrival_us(read_us: u64, unwatched_us: u64, in_progress: Option<u64>, timeout_us: u64) -> u64 {
    let earliest = read_us.saturating_sub(unwatched_us);
    match in_progress {
        Some(last_us) if earliest < last_us + timeout_us => earliest,
        _ => read_us,
    }
}

/// The characters of `bytes` as the UART received them: taken back from the kernel's
/// marks where the port marks faults (`marks`, kept across reads).
fn unmarked(bytes: &[u8], marks: Option<&mut Marks>) -> Vec<(u8, Option<UartFault>)> {
    let mut out = Vec::with_capacity(bytes.len());
    match marks {
        Some(marks) => {
            for b in bytes {
                marks.push(*b, &mut |m| out.push(m.as_received()));
            }
        }
        None => out.extend(bytes.iter().map(|b| (*b, None))),
    }
    out
}

#[cfg(test)]
mod tests {
    use super::continued_arrival_us;

    /// A simulator woken 8 ms late (the timeout at 9600 Bd is 5.73 ms): the rest of a
    /// request it had begun to receive came as early as 1 ms after the last character,
    /// and is stamped so (not split); the first character of a frame is stamped when
    /// read; what came only after the timeout whatever the lateness stays apart.
    #[test]
    fn a_simulator_s_own_lateness_does_not_split_a_request() {
        const TIMEOUT: u64 = 5_730;
        assert_eq!(continued_arrival_us(20_000, 8_000, Some(11_000), TIMEOUT), 12_000);
        assert_eq!(continued_arrival_us(20_000, 8_000, None, TIMEOUT), 20_000);
        assert_eq!(continued_arrival_us(20_000, 2_000, Some(11_000), TIMEOUT), 20_000);
        assert_eq!(continued_arrival_us(20_000, 0, Some(19_000), TIMEOUT), 20_000);
    }
}
