//! Raw TCP to a serial device server (`tcp://host:port`, e.g. ser2net). The server
//! owns the UART and its settings. TCP has no baud rate: the harness writes a request
//! at once and knows its end as a window, and stamps received bytes like on a
//! pseudo-terminal (see [`super::clock`]).

use super::{clock, Line, LineError, LineKind, RealTime, Sent, Window};
use hiperface_model::datalink::RxChar;
use hiperface_model::UartSettings;
use std::io::{ErrorKind, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

/// Loopback TCP and the server's polling add jitter.
pub const DEFAULT_TOLERANCE_US: u64 = 4_000;

pub struct TcpLine {
    stream: TcpStream,
    address: String,
    time: clock::RealTime,
    settings: UartSettings,
}

impl TcpLine {
    /// Connect to `host:port` within 5 s.
    pub fn connect(address: &str, settings: UartSettings) -> Result<TcpLine, LineError> {
        let open_err = |reason: String| LineError::Open { port: format!("tcp://{address}"), reason };
        let addr = address
            .to_socket_addrs()
            .map_err(|e| open_err(e.to_string()))?
            .next()
            .ok_or_else(|| open_err("no address".into()))?;
        let stream = TcpStream::connect_timeout(&addr, Duration::from_secs(5)).map_err(|e| open_err(e.to_string()))?;
        stream.set_nodelay(true).map_err(|e| open_err(e.to_string()))?;
        Ok(TcpLine { stream, address: address.to_string(), time: clock::RealTime::new(DEFAULT_TOLERANCE_US), settings })
    }

    /// Allow this much timing jitter (µs) before a reply's start is graded.
    pub fn with_tolerance(mut self, tolerance_us: u64) -> TcpLine {
        self.time.tolerance_us = tolerance_us;
        self
    }
}

impl Line for TcpLine {
    fn now_us(&mut self) -> u64 {
        self.time.now_us()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        let ct = self.settings.char_time_us();
        let stream = &mut self.stream;
        let end = clock::write_whole(&self.time, ct, bytes, |b| {
            stream.write_all(b).map_err(|e| LineError::Gone(e.to_string()))
        })?;
        // Behind the server a UART adds one character time (a pseudo-terminal none).
        Ok(Sent { end: Window { earliest_us: end.earliest_us, latest_us: end.latest_us + ct } })
    }

    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        let time = &self.time;
        let (stream, address) = (&mut self.stream, &self.address);
        let got = clock::read_until(time, until_us, |wait| {
            let mut b = [0u8; 1];
            let read = if wait.is_zero() {
                // A zero timeout is refused by a socket: look without waiting instead,
                // and block again for the reads that wait.
                stream.set_nonblocking(true)?;
                let read = stream.read(&mut b);
                stream.set_nonblocking(false)?;
                read
            } else {
                stream.set_read_timeout(Some(wait))?;
                stream.read(&mut b)
            };
            match read {
                Ok(1) => Ok(Some(b[0])),
                Ok(_) => Err(LineError::Gone(format!("tcp://{address} closed the connection"))),
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => {
                    Ok(None)
                }
                Err(e) => Err(LineError::Gone(e.to_string())),
            }
        })?;
        // TCP has no baud rate: the server's UART delivered the bytes a character apart.
        let clocked = Some(self.settings.char_time_us());
        Ok(got.map(|(byte, arrival)| self.time.rx.stamp(byte, arrival, clocked)))
    }

    fn start_of(&self, ch: &RxChar) -> Window {
        // Behind the server a UART (the character began a character time before the
        // server had it) or a pseudo-terminal (a write may mark the start).
        Window { earliest_us: ch.at_us.saturating_sub(self.settings.char_time_us()), latest_us: ch.at_us }
    }

    fn clock(&self) -> Option<&RealTime> {
        Some(&self.time)
    }

    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        // The server's port settings are its configuration's; RFC 2217 is not spoken here.
        if settings.baud != self.settings.baud || settings.parity != self.settings.parity {
            return Err(LineError::Settings {
                settings,
                reason: "a raw TCP serial server keeps its own UART settings".into(),
            });
        }
        self.settings = settings;
        Ok(())
    }

    fn can_change_settings(&self) -> bool {
        false
    }

    fn settings(&self) -> UartSettings {
        self.settings
    }

    fn carries_parity(&self) -> Result<(), &'static str> {
        Err("a raw TCP serial server sends in its own UART settings: a parity error cannot be sent through it")
    }

    fn kind(&self) -> LineKind {
        LineKind::Tcp
    }

    fn describe(&self) -> String {
        format!("tcp://{} ({})", self.address, self.kind().label())
    }
}
