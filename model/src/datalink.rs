//! The data link layer, sans-IO: characters in with their receive time, frames out
//! when the timeout elapses. // 000:2.2.2
//!
//! A character's receive time is the end of its stop bit, when a UART raises its
//! receive interrupt. Two characters belong to one frame when the second is received
//! less than the timeout after the first; a frame is complete `timeout` after its last
//! character. (000:2.2.2 explains that the 22/55 bit-time figures were chosen because
//! "UART interrupts are generated at the end of the first received character".)

use crate::frame::{Frame, Hex, MAX_FRAME};
use core::fmt;

/// A UART fault on one character. All are reported as 09h. // 000:T47
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UartFault {
    Parity,
    Framing,
    Noise,
    Overrun,
}

impl UartFault {
    pub const ALL: [UartFault; 4] = [UartFault::Parity, UartFault::Framing, UartFault::Noise, UartFault::Overrun];

    /// The fault's name, as captures, Python and (in capitals) C spell it.
    pub const fn name(self) -> &'static str {
        match self {
            UartFault::Parity => "parity",
            UartFault::Framing => "framing",
            UartFault::Noise => "noise",
            UartFault::Overrun => "overrun",
        }
    }

    pub fn from_name(name: &str) -> Option<UartFault> {
        UartFault::ALL.iter().copied().find(|f| f.name() == name)
    }
}

/// One received character.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RxChar {
    pub byte: u8,
    /// Receive time in µs (end of the stop bit).
    pub at_us: u64,
    pub fault: Option<UartFault>,
}

impl RxChar {
    pub const fn ok(byte: u8, at_us: u64) -> RxChar {
        RxChar { byte, at_us, fault: None }
    }
}

/// A frame as the timeout delimited it.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct ReceivedFrame {
    /// The first [`MAX_FRAME`] bytes.
    pub bytes: Frame,
    /// Characters received, which may exceed [`MAX_FRAME`].
    pub char_count: usize,
    /// The first UART fault seen in the frame.
    pub uart_fault: Option<UartFault>,
    pub first_us: u64,
    pub last_us: u64,
    /// When the timeout after the last character elapsed.
    pub complete_us: u64,
}

impl ReceivedFrame {
    /// More characters than any valid frame has.
    pub fn overflowed(&self) -> bool {
        self.char_count > MAX_FRAME
    }
}

impl fmt::Debug for ReceivedFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] at {}..{} µs", Hex(self.bytes.as_bytes()), self.first_us, self.last_us)?;
        if let Some(fault) = self.uart_fault {
            write!(f, " {fault:?}")?;
        }
        Ok(())
    }
}

/// When a frame whose last character ended at `last_us` is complete: once the
/// timeout after it has passed without another character. // 000:2.2.2
pub const fn complete_at(last_us: u64, timeout_us: u64) -> u64 {
    last_us.saturating_add(timeout_us)
}

/// The frame assembler.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct DataLink {
    timeout_us: u64,
    current: Option<ReceivedFrame>,
}

impl DataLink {
    pub const fn new(timeout_us: u64) -> DataLink {
        DataLink { timeout_us, current: None }
    }

    pub const fn timeout_us(&self) -> u64 {
        self.timeout_us
    }

    /// Change the timeout (new UART settings); a frame in progress keeps assembling.
    pub fn set_timeout(&mut self, timeout_us: u64) {
        self.timeout_us = timeout_us;
    }

    /// Move the clock of the frame in progress from `now_us` to `to_us` (its times
    /// move by the same amount; those before `now_us - to_us` would move to 0).
    pub fn rebase(&mut self, now_us: u64, to_us: u64) {
        let moved = |t: u64| t.saturating_add(to_us).saturating_sub(now_us);
        if let Some(f) = self.current.as_mut() {
            f.first_us = moved(f.first_us);
            f.last_us = moved(f.last_us);
            f.complete_us = moved(f.complete_us);
        }
    }

    /// Drop any frame in progress.
    pub fn clear(&mut self) {
        self.current = None;
    }

    /// Take a character. When it arrives at least the timeout after the previous one,
    /// the previous frame is complete and is returned.
    pub fn receive(&mut self, ch: RxChar) -> Option<ReceivedFrame> {
        // By reference: the frame in progress is not copied for each character.
        let done = match &self.current {
            Some(cur) if ch.at_us.saturating_sub(cur.last_us) >= self.timeout_us => self.close(),
            _ => None,
        };
        match &mut self.current {
            Some(cur) => {
                cur.char_count += 1;
                let _ = cur.bytes.push(ch.byte);
                cur.uart_fault = cur.uart_fault.or(ch.fault);
                cur.last_us = cur.last_us.max(ch.at_us);
                cur.complete_us = complete_at(cur.last_us, self.timeout_us);
            }
            None => {
                let mut bytes = Frame::new();
                let _ = bytes.push(ch.byte);
                self.current = Some(ReceivedFrame {
                    bytes,
                    char_count: 1,
                    uart_fault: ch.fault,
                    first_us: ch.at_us,
                    last_us: ch.at_us,
                    complete_us: complete_at(ch.at_us, self.timeout_us),
                });
            }
        }
        done
    }

    /// The frame in progress, once the timeout after its last character has elapsed.
    pub fn poll(&mut self, now_us: u64) -> Option<ReceivedFrame> {
        match &self.current {
            Some(cur) if now_us >= complete_at(cur.last_us, self.timeout_us) => self.close(),
            _ => None,
        }
    }

    /// When the frame in progress will be complete, if one is.
    pub fn deadline(&self) -> Option<u64> {
        self.current.as_ref().map(|c| complete_at(c.last_us, self.timeout_us))
    }

    fn close(&mut self) -> Option<ReceivedFrame> {
        let mut done = self.current.take()?;
        done.complete_us = complete_at(done.last_us, self.timeout_us);
        Some(done)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_uart_fault_is_read_back_by_its_name() {
        let names = UartFault::ALL.map(UartFault::name);
        assert_eq!(names, ["parity", "framing", "noise", "overrun"]);
        for f in UartFault::ALL {
            assert_eq!(UartFault::from_name(f.name()), Some(f));
        }
        assert_eq!(UartFault::from_name("Parity"), None);
        assert_eq!(UartFault::from_name(""), None);
    }

    #[test]
    fn frames_are_split_exactly_at_the_timeout() {
        let mut link = DataLink::new(5730);
        assert!(link.receive(RxChar::ok(0x40, 1000)).is_none());
        assert!(link.receive(RxChar::ok(0x42, 1000 + 5729)).is_none(), "just inside the timeout");
        assert!(link.poll(1000 + 5729 + 5729).is_none());
        let f = link.poll(1000 + 5729 + 5730).expect("timeout elapsed");
        assert_eq!(f.bytes.as_bytes(), &[0x40, 0x42]);
        assert_eq!(f.complete_us, 1000 + 5729 + 5730);
        assert!(link.poll(u64::MAX).is_none());

        link.receive(RxChar::ok(1, 0));
        let f = link.receive(RxChar { byte: 2, at_us: 5730, fault: Some(UartFault::Parity) }).expect("split");
        assert_eq!(f.bytes.as_bytes(), &[1]);
        let g = link.poll(20_000).unwrap();
        assert_eq!((g.bytes.as_bytes(), g.uart_fault), (&[2u8][..], Some(UartFault::Parity)));
    }

    #[test]
    fn overlong_frames_are_counted_not_stored() {
        let mut link = DataLink::new(100);
        for i in 0..(MAX_FRAME + 10) {
            assert!(link.receive(RxChar::ok(i as u8, i as u64)).is_none());
        }
        let f = link.poll(u64::MAX).unwrap();
        assert!(f.overflowed());
        assert_eq!((f.char_count, f.bytes.len()), (MAX_FRAME + 10, MAX_FRAME));
        // Exactly as many characters as the longest frame is no overflow.
        let mut full = DataLink::new(100);
        for i in 0..MAX_FRAME {
            full.receive(RxChar::ok(i as u8, i as u64));
        }
        assert!(!full.poll(u64::MAX).unwrap().overflowed());
        // Time running backwards never panics and never splits.
        link.receive(RxChar::ok(1, u64::MAX));
        assert!(link.receive(RxChar::ok(2, 0)).is_none());
    }

    /// The timeout is the one last set; a frame in progress keeps assembling across a
    /// change, and `clear` drops it (a reset, 000:T29).
    #[test]
    fn the_timeout_can_change_and_a_frame_can_be_dropped() {
        let mut link = DataLink::new(5730);
        assert_eq!(link.timeout_us(), 5730);
        link.receive(RxChar::ok(0x40, 1000));
        link.set_timeout(2292);
        assert_eq!((link.timeout_us(), link.deadline()), (2292, Some(1000 + 2292)));
        link.clear();
        assert_eq!((link.deadline(), link.poll(u64::MAX)), (None, None));
    }
}
