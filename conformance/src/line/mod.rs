//! The master's view of a serial line: send bytes, receive timestamped characters,
//! always within a bounded time. Implementations: [`virtual_line::VirtualLine`]
//! (in-process, virtual time) and [`serial::SerialLine`] (a real port or a
//! pseudo-terminal, real time).

pub mod serial;
pub mod tcp;
pub mod virtual_line;

use hiperface_model::datalink::RxChar;
use hiperface_model::UartSettings;

/// Receive times on a line. A UART stamps a character when it arrives. A
/// pseudo-terminal or TCP has no baud rate: a UART would deliver the bytes at least
/// one character time apart, so `max(arrival, previous + char time)`; a backlog of
/// more than one frame is more than any UART could have received, and such a
/// character is an overrun at its arrival.
#[derive(Debug, Clone, Copy, Default)]
pub struct RxClock {
    last_us: u64,
}

impl RxClock {
    /// Stamp a byte. `clocked_char_time_us`: `Some` on lines without a baud rate.
    pub fn stamp(&mut self, byte: u8, arrival_us: u64, clocked_char_time_us: Option<u64>) -> RxChar {
        let (at_us, overrun) = match clocked_char_time_us {
            Some(ct) => {
                let clocked = arrival_us.max(self.last_us + ct);
                if clocked - arrival_us > hiperface_model::frame::MAX_FRAME as u64 * ct {
                    (arrival_us, true)
                } else {
                    (clocked, false)
                }
            }
            None => (arrival_us, false),
        };
        self.last_us = at_us;
        RxChar { byte, at_us, fault: overrun.then_some(hiperface_model::UartFault::Overrun) }
    }
}

/// The clock of a real-time line: µs since the line opened, sleeping until a time,
/// receive times, and the timing jitter graded with.
#[derive(Debug, Clone, Copy)]
pub struct RealTime {
    epoch: std::time::Instant,
    pub rx: RxClock,
    pub tolerance_us: u64,
}

impl RealTime {
    pub fn new(tolerance_us: u64) -> RealTime {
        RealTime { epoch: std::time::Instant::now(), rx: RxClock::default(), tolerance_us }
    }

    pub fn now_us(&self) -> u64 {
        self.epoch.elapsed().as_micros() as u64
    }

    pub fn sleep_until(&self, t_us: u64) {
        let target = self.epoch + std::time::Duration::from_micros(t_us);
        if let Some(d) = target.checked_duration_since(std::time::Instant::now()) {
            std::thread::sleep(d);
        }
    }
}

/// Wait for one byte until `until_us` (on the clock `now`), in slices of at most
/// 20 ms: `read_within` waits up to the given time and answers `None` on a timeout.
pub fn read_until(
    now: impl Fn() -> u64,
    until_us: u64,
    mut read_within: impl FnMut(std::time::Duration) -> Result<Option<u8>, LineError>,
) -> Result<Option<(u8, u64)>, LineError> {
    loop {
        let t = now();
        if t > until_us {
            return Ok(None);
        }
        let wait = std::time::Duration::from_micros((until_us - t).clamp(100, 20_000));
        if let Some(b) = read_within(wait)? {
            return Ok(Some((b, now())));
        }
    }
}

/// Why the line failed. Each is an ERROR for the case that hit it, never a FAIL.
#[derive(Debug, thiserror::Error)]
pub enum LineError {
    #[error("cannot open {port}: {reason}")]
    Open { port: String, reason: String },
    #[error("serial line I/O failed: {0}")]
    Io(#[from] std::io::Error),
    #[error("the port is gone: {0}")]
    Gone(String),
    #[error("cannot apply UART settings {settings}: {reason}")]
    Settings { settings: UartSettings, reason: String },
}

/// A half-duplex serial line as the master sees it. Times are µs since the line
/// was opened.
pub trait Line {
    /// Now, in µs.
    fn now_us(&mut self) -> u64;
    /// Transmit `bytes` back to back in the current settings; returns the receive
    /// time of the last character at the far end (the end of its stop bit).
    fn send(&mut self, bytes: &[u8]) -> Result<u64, LineError>;
    /// The next received character, or `None` once `until_us` has passed.
    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError>;
    /// Idle until `t_us`, discarding nothing: characters arriving meanwhile stay queued.
    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError>;
    /// Switch the line's UART settings.
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError>;
    fn settings(&self) -> UartSettings;
    /// Timing jitter the line adds, in µs (0 in virtual time).
    fn tolerance_us(&self) -> u64;
    /// A short description for reports ("virtual", "/dev/pts/3", ...).
    fn describe(&self) -> String;
}

impl<L: Line + ?Sized> Line for Box<L> {
    fn now_us(&mut self) -> u64 {
        (**self).now_us()
    }
    fn send(&mut self, bytes: &[u8]) -> Result<u64, LineError> {
        (**self).send(bytes)
    }
    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        (**self).recv(until_us)
    }
    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        (**self).wait_until(t_us)
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        (**self).configure(settings)
    }
    fn settings(&self) -> UartSettings {
        (**self).settings()
    }
    fn tolerance_us(&self) -> u64 {
        (**self).tolerance_us()
    }
    fn describe(&self) -> String {
        (**self).describe()
    }
}
