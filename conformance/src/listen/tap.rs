//! The monitor's ear: a port opened so that it cannot talk. A serial port or a
//! pseudo-terminal is opened read-only (`O_RDONLY`: the kernel refuses any write on
//! it), with echo off (a terminal that echoes would send what it hears back to the
//! bus); a serial device server over TCP is read through a type that has no write.
//!
//! On a serial port the kernel marks what the UART saw (`PARMRK`): a character
//! with a parity or framing error arrives as `FF 00 c`, a break as `FF 00 00`, a
//! data byte FFh as `FF FF`. the core's `capture::parmrk::Marks` turns that back into marks. A
//! pseudo-terminal has no UART (no errors, FFh still doubled); a TCP server sends
//! the bytes as they are.
//!
//! Times: bytes arrive in chunks (the UART's FIFO, a USB adapter's latency timer, a
//! server's polling). The last byte of a chunk is taken to have ended when the chunk
//! arrived, the ones before it one character time apart before it (no earlier than a
//! character time after the previous chunk): what a receiver delivering whole
//! characters means. See [`Stamps`].

use crate::port::PortSpec;
use hiperface_model::settings::{Baud, Parity};
use hiperface_model::UartSettings;
use std::io::{ErrorKind, Read};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

/// How long one read waits before the monitor looks at the clock (and at Ctrl-C).
const READ_SLICE: Duration = Duration::from_millis(100);

/// What one read gave.
#[derive(Debug, PartialEq, Eq)]
pub enum Got {
    /// Bytes as the port delivered them (before unmarking).
    Bytes(usize),
    /// Nothing within the read slice.
    Quiet,
    /// The other end is gone (a pseudo-terminal closed, the server hung up).
    Closed,
}

/// A port the monitor listens on. It has no way to write.
pub struct Tap {
    source: Source,
    pub name: String,
    /// What the port does to timing, for the report.
    pub notes: Vec<String>,
    /// Timing jitter the port adds, µs (the default tolerance).
    pub jitter_us: u64,
}

enum Source {
    /// The port, and its settings as the monitor found them (put back when it is done:
    /// the port may be someone else's).
    Tty(std::fs::File, nix::sys::termios::Termios),
    Tcp(TcpStream),
}

impl Drop for Tap {
    fn drop(&mut self) {
        if let Source::Tty(file, found) = &self.source {
            let _ = nix::sys::termios::tcsetattr(file, nix::sys::termios::SetArg::TCSANOW, found);
        }
    }
}

impl Tap {
    /// Open `spec` to listen at `settings`.
    pub fn open(spec: &PortSpec, settings: UartSettings) -> Result<Tap, String> {
        match spec {
            PortSpec::Path(path) => open_tty(path, settings),
            PortSpec::Tcp(address) => open_tcp(address),
            other => Err(format!(
                "`{other}`: the monitor listens on a serial port or pseudo-terminal path, or tcp://HOST:PORT"
            )),
        }
    }

    /// Whether the kernel marks parity errors and breaks in what it delivers.
    pub fn marks_errors(&self) -> bool {
        matches!(self.source, Source::Tty(..))
    }

    /// Read what came, waiting at most a read slice.
    pub fn read(&mut self, buf: &mut [u8]) -> std::io::Result<Got> {
        let got = match &mut self.source {
            // VMIN 0, VTIME 1: returns as soon as a byte is there, else after 0.1 s.
            Source::Tty(f, _) => f.read(buf),
            Source::Tcp(s) => s.read(buf),
        };
        match got {
            Ok(0) if matches!(self.source, Source::Tcp(_)) => Ok(Got::Closed),
            Ok(0) => Ok(Got::Quiet),
            Ok(n) => Ok(Got::Bytes(n)),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted) => {
                Ok(Got::Quiet)
            }
            // A pseudo-terminal whose other end closed answers EIO.
            Err(e) if e.raw_os_error() == Some(nix::libc::EIO) => Ok(Got::Closed),
            Err(e) => Err(e),
        }
    }

    /// Whether the open file can be written at all (false for a serial port or
    /// pseudo-terminal: it is opened `O_RDONLY`). A TCP tap has no write in its type.
    pub fn file_is_writable(&self) -> bool {
        match &self.source {
            Source::Tty(f, _) => nix::fcntl::fcntl(f, nix::fcntl::FcntlArg::F_GETFL)
                .map(|fl| nix::fcntl::OFlag::from_bits_truncate(fl) & nix::fcntl::OFlag::O_ACCMODE)
                .is_ok_and(|mode| mode != nix::fcntl::OFlag::O_RDONLY),
            Source::Tcp(_) => false,
        }
    }
}

fn baud_rate(b: Baud) -> nix::sys::termios::BaudRate {
    use nix::sys::termios::BaudRate as R;
    match b {
        Baud::B600 => R::B600,
        Baud::B1200 => R::B1200,
        Baud::B2400 => R::B2400,
        Baud::B4800 => R::B4800,
        Baud::B9600 => R::B9600,
        Baud::B19200 => R::B19200,
        Baud::B38400 => R::B38400,
    }
}

fn open_tty(path: &str, settings: UartSettings) -> Result<Tap, String> {
    use nix::sys::termios::{self, ControlFlags as C, InputFlags as I, SetArg, SpecialCharacterIndices as V};
    use std::os::unix::fs::OpenOptionsExt;
    let fail = |what: &str, e: &dyn std::fmt::Display| format!("{path}: {what}: {e}");
    if let Some(why) = crate::line::serial::not_a_port(path) {
        return Err(format!("{path}: {why}"));
    }
    // Read-only, and not as the controlling terminal.
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(nix::libc::O_NOCTTY)
        .open(path)
        .map_err(|e| fail("cannot open it read-only", &e))?;
    let found = termios::tcgetattr(&file).map_err(|e| fail("not a terminal", &e))?;
    let mut t = found.clone();
    // Raw: no echo (a terminal that echoes talks), no line editing, no flow control.
    termios::cfmakeraw(&mut t);
    t.input_flags.remove(I::IGNPAR | I::IGNBRK | I::BRKINT | I::ISTRIP | I::IXON | I::IXOFF);
    // Mark parity and framing errors and breaks in the data. // 000:T47
    t.input_flags.insert(I::INPCK | I::PARMRK);
    t.control_flags.remove(C::CSIZE | C::PARENB | C::PARODD | C::CSTOPB | C::CRTSCTS | C::HUPCL);
    t.control_flags.insert(C::CS8 | C::CLOCAL | C::CREAD);
    match settings.parity {
        Parity::Even => t.control_flags.insert(C::PARENB),
        Parity::Odd => t.control_flags.insert(C::PARENB | C::PARODD),
        Parity::None => {}
    }
    t.control_chars[V::VMIN as usize] = 0;
    t.control_chars[V::VTIME as usize] = (READ_SLICE.as_millis() / 100) as u8;
    termios::cfsetspeed(&mut t, baud_rate(settings.baud)).map_err(|e| fail("cannot set the data rate", &e))?;
    termios::tcsetattr(&file, SetArg::TCSANOW, &t).map_err(|e| fail("cannot set the line settings", &e))?;
    let pseudo = crate::line::serial::is_pseudo_terminal(path);
    let mut notes = Vec::new();
    let mut jitter_us = crate::line::serial::DEFAULT_TOLERANCE_US;
    if pseudo {
        notes.push("a pseudo-terminal: no UART, so no parity or framing errors can be seen".to_string());
    } else if let Some(a) = crate::line::adapter::Adapter::detect(path, std::path::Path::new("/sys")) {
        // The monitor does not change the adapter's settings: it may be someone else's.
        jitter_us = jitter_us.max(a.input_latency_us());
        notes.push(format!(
            "{}: timing differences below {:.1} ms are not graded (the adapter's latency)",
            a.describe(),
            a.input_latency_us() as f64 / 1000.0
        ));
    }
    Ok(Tap { source: Source::Tty(file, found), name: path.to_string(), notes, jitter_us })
}

fn open_tcp(address: &str) -> Result<Tap, String> {
    let fail = |e: &dyn std::fmt::Display| format!("tcp://{address}: {e}");
    let addr = address.to_socket_addrs().map_err(|e| fail(&e))?.next().ok_or_else(|| fail(&"no address"))?;
    let stream = TcpStream::connect_timeout(&addr, Duration::from_secs(5)).map_err(|e| fail(&e))?;
    stream.set_read_timeout(Some(READ_SLICE)).map_err(|e| fail(&e))?;
    Ok(Tap {
        source: Source::Tcp(stream),
        name: format!("tcp://{address}"),
        notes: vec!["a serial device server: bytes arrive in its chunks; parity errors are not seen".to_string()],
        jitter_us: crate::line::tcp::DEFAULT_TOLERANCE_US,
    })
}

/// Receive times for characters that arrive in chunks: the last of a chunk ended at
/// its arrival, the ones before it a character time apart, none earlier than a
/// character time after the one before.
#[derive(Debug, Clone, Copy)]
pub struct Stamps {
    char_us: u64,
    last_us: Option<u64>,
}

impl Stamps {
    pub fn new(char_us: u64) -> Stamps {
        Stamps { char_us, last_us: None }
    }

    /// The end times of `n` characters that arrived together at `arrival_us`.
    pub fn chunk(&mut self, n: usize, arrival_us: u64) -> impl Iterator<Item = u64> + Clone {
        let span = (n.saturating_sub(1) as u64).saturating_mul(self.char_us);
        let mut first = arrival_us.saturating_sub(span);
        if let Some(last) = self.last_us {
            first = first.max(last.saturating_add(self.char_us));
        }
        if n > 0 {
            self.last_us = Some(first + span);
        }
        let ct = self.char_us;
        (0..n as u64).map(move |i| first + i * ct)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chunk_ends_at_its_arrival_and_never_overlaps_the_one_before() {
        let mut s = Stamps::new(1_000);
        assert_eq!(s.chunk(3, 10_000).collect::<Vec<_>>(), vec![8_000, 9_000, 10_000]);
        // Arrived too soon after: pushed to a character time after the last.
        assert_eq!(s.chunk(2, 11_500).collect::<Vec<_>>(), vec![11_000, 12_000]);
        assert_eq!(s.chunk(0, 20_000).count(), 0);
        assert_eq!(s.chunk(1, 20_000).collect::<Vec<_>>(), vec![20_000]);
    }
}
