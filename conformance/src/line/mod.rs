//! The master's view of a serial line: send bytes, receive timestamped characters,
//! always within a bounded time. Implementations: [`virtual_line::VirtualLine`]
//! (in-process, virtual time) and [`serial::SerialLine`] (a real port or a
//! pseudo-terminal, real time).

pub mod serial;
pub mod tcp;
pub mod virtual_line;

use hiperface_model::datalink::RxChar;
use hiperface_model::UartSettings;

/// Receive time of a character on a pseudo-terminal, where bytes arrive without a
/// baud rate: a UART delivers them at least one character time apart, so
/// `max(arrival, previous + char time)`. A backlog of more than one frame is more
/// than any UART could have received: such a character is an overrun at its arrival.
pub fn clock_pty_char(arrival_us: u64, previous_us: u64, char_time_us: u64) -> (u64, bool) {
    let clocked = arrival_us.max(previous_us + char_time_us);
    let backlog_limit = hiperface_model::frame::MAX_FRAME as u64 * char_time_us;
    if clocked - arrival_us > backlog_limit {
        (arrival_us, true)
    } else {
        (clocked, false)
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
