//! A real serial port or a pseudo-terminal, in real time. Frames are written whole;
//! a real port's UART clocks them out. A pseudo-terminal has no baud rate, so this
//! line plays the UART on it: a frame is written when its first character would be
//! complete, and received characters are clocked at least one character time apart
//! (`receive time = max(arrival, previous + character time)`), as a UART delivers
//! them. The simulator does the same on its end, so both ends agree on the wire time.

use super::{Line, LineError};
use hiperface_model::datalink::RxChar;
use hiperface_model::settings::Parity as HfParity;
use hiperface_model::UartSettings;
use serialport::{DataBits, FlowControl, Parity, SerialPort, StopBits};
use std::io::{ErrorKind, Read, Write};
use std::time::Duration;

/// Scheduler and pseudo-terminal jitter on a loaded 2-core machine.
pub const DEFAULT_TOLERANCE_US: u64 = 2_000;

pub struct SerialLine {
    port: Box<dyn SerialPort>,
    name: String,
    time: super::RealTime,
    settings: UartSettings,
    /// Pseudo-terminals ignore UART settings; real ports apply them.
    pseudo_terminal: bool,
}

fn parity(s: UartSettings) -> Parity {
    match s.parity {
        HfParity::None => Parity::None,
        HfParity::Even => Parity::Even,
        HfParity::Odd => Parity::Odd,
    }
}

impl SerialLine {
    /// Open a port by path with the given settings.
    pub fn open(path: &str, settings: UartSettings) -> Result<SerialLine, LineError> {
        let port = serialport::new(path, settings.baud.bits_per_second())
            .data_bits(DataBits::Eight)
            .stop_bits(StopBits::One)
            .parity(parity(settings))
            .flow_control(FlowControl::None)
            .timeout(Duration::from_millis(1))
            .open()
            .map_err(|e| LineError::Open { port: path.to_string(), reason: e.to_string() })?;
        let pseudo_terminal = path.starts_with("/dev/pts/") || path.contains("pty");
        Ok(SerialLine::from_port(port, path.to_string(), settings, pseudo_terminal))
    }

    /// Wrap an open port (e.g. one end of a pseudo-terminal pair).
    pub fn from_port(
        port: Box<dyn SerialPort>,
        name: String,
        settings: UartSettings,
        pseudo_terminal: bool,
    ) -> SerialLine {
        SerialLine { port, name, time: super::RealTime::new(DEFAULT_TOLERANCE_US), settings, pseudo_terminal }
    }

    /// Allow this much timing jitter (µs) before a reply's start is graded.
    pub fn with_tolerance(mut self, tolerance_us: u64) -> SerialLine {
        self.time.tolerance_us = tolerance_us;
        self
    }

    fn gone(e: std::io::Error) -> LineError {
        match e.kind() {
            ErrorKind::BrokenPipe | ErrorKind::NotConnected | ErrorKind::UnexpectedEof => {
                LineError::Gone(e.to_string())
            }
            _ if e.raw_os_error() == Some(5) => LineError::Gone(e.to_string()), // EIO: the other end closed
            _ => LineError::Io(e),
        }
    }
}

impl Line for SerialLine {
    fn now_us(&mut self) -> u64 {
        self.time.now_us()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<u64, LineError> {
        let ct = self.settings.char_time_us();
        let n = bytes.len() as u64;
        let start = self.now_us();
        self.port.write_all(bytes).map_err(Self::gone)?;
        self.port.flush().map_err(Self::gone)?;
        // On a pseudo-terminal the write is the first character's receive time.
        let end = if self.pseudo_terminal { start + n.saturating_sub(1) * ct } else { start + n * ct };
        // Half duplex: the line is busy until the last character is out.
        self.time.sleep_until(end);
        Ok(end)
    }

    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        let time = self.time;
        let port = &mut self.port;
        let got = super::read_until(
            || time.now_us(),
            until_us,
            |wait| {
                port.set_timeout(wait).map_err(|e| LineError::Io(e.into()))?;
                let mut b = [0u8; 1];
                match port.read(&mut b) {
                    Ok(1) => Ok(Some(b[0])),
                    Ok(_) => Err(LineError::Gone("end of file".into())),
                    Err(e)
                        if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) =>
                    {
                        Ok(None)
                    }
                    Err(e) => Err(Self::gone(e)),
                }
            },
        )?;
        let clocked = self.pseudo_terminal.then(|| self.settings.char_time_us());
        Ok(got.map(|(byte, arrival)| self.time.rx.stamp(byte, arrival, clocked)))
    }

    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        self.time.sleep_until(t_us);
        Ok(())
    }

    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        if !self.pseudo_terminal {
            let err = |e: serialport::Error| LineError::Settings { settings, reason: e.to_string() };
            self.port.set_baud_rate(settings.baud.bits_per_second()).map_err(err)?;
            self.port.set_parity(parity(settings)).map_err(err)?;
        }
        self.settings = settings;
        Ok(())
    }

    fn settings(&self) -> UartSettings {
        self.settings
    }

    fn tolerance_us(&self) -> u64 {
        self.time.tolerance_us
    }

    fn describe(&self) -> String {
        format!("{} ({})", self.name, if self.pseudo_terminal { "pseudo-terminal" } else { "serial port" })
    }
}
