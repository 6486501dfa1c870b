//! Raw TCP to a serial device server (`tcp://host:port`, e.g. ser2net). The server
//! owns the UART; TCP has no baud rate, so received bytes are clocked like on a
//! pseudo-terminal (see `RxClock`), and the settings are the server's.

use super::{Line, LineError};
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
    time: super::RealTime,
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
        Ok(TcpLine { stream, address: address.to_string(), time: super::RealTime::new(DEFAULT_TOLERANCE_US), settings })
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

    fn send(&mut self, bytes: &[u8]) -> Result<u64, LineError> {
        let ct = self.settings.char_time_us();
        let start = self.now_us();
        self.stream.write_all(bytes).map_err(|e| LineError::Gone(e.to_string()))?;
        // The server's UART clocks the frame out from now on.
        let end = start + bytes.len() as u64 * ct;
        self.time.sleep_until(end);
        Ok(end)
    }

    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        let time = self.time;
        let (stream, address) = (&mut self.stream, &self.address);
        let got = super::read_until(
            || time.now_us(),
            until_us,
            |wait| {
                stream.set_read_timeout(Some(wait))?;
                let mut b = [0u8; 1];
                match stream.read(&mut b) {
                    Ok(1) => Ok(Some(b[0])),
                    Ok(_) => Err(LineError::Gone(format!("tcp://{address} closed the connection"))),
                    Err(e)
                        if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) =>
                    {
                        Ok(None)
                    }
                    Err(e) => Err(LineError::Gone(e.to_string())),
                }
            },
        )?;
        // TCP has no baud rate: the server's UART delivered the bytes a character apart.
        let clocked = Some(self.settings.char_time_us());
        Ok(got.map(|(byte, arrival)| self.time.rx.stamp(byte, arrival, clocked)))
    }

    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        self.time.sleep_until(t_us);
        Ok(())
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

    fn settings(&self) -> UartSettings {
        self.settings
    }

    fn tolerance_us(&self) -> u64 {
        self.time.tolerance_us
    }

    fn describe(&self) -> String {
        format!("tcp://{} (serial device server)", self.address)
    }
}
