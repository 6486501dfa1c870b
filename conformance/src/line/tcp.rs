//! TCP to a serial device server: raw (`tcp://host:port`, e.g. ser2net), where the
//! server owns the UART and its settings, or RFC 2217 (`rfc2217://host:port`), where
//! the harness sets the server's data rate and parity (see [`super::rfc2217`]). TCP has
//! no baud rate: the harness writes a request at once and knows its end as a window,
//! and stamps received bytes like on a pseudo-terminal (see [`super::clock`]).

use super::clock;
use super::rfc2217::{self, Event, Telnet};
use hiperface_model::datalink::RxChar;
use hiperface_model::UartSettings;
use hiperface_suite::line::{Line, LineError, LineKind, Sent, Window};
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
    /// RFC 2217's Telnet state, where the server speaks it.
    telnet: Option<Telnet>,
}

/// How long a device server may take to confirm new UART settings.
const SETTINGS_CONFIRMED_WITHIN: Duration = Duration::from_secs(2);

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
        let time = clock::RealTime::new(DEFAULT_TOLERANCE_US);
        Ok(TcpLine { stream, address: address.to_string(), time, settings, telnet: None })
    }

    /// Connect to a device server that speaks RFC 2217, and set its UART to `settings`
    /// (refused if it does not confirm them).
    pub fn connect_rfc2217(address: &str, settings: UartSettings) -> Result<TcpLine, LineError> {
        let mut line = TcpLine::connect(address, settings)?;
        line.telnet = Some(Telnet::default());
        line.stream.write_all(&rfc2217::greeting()).map_err(|e| LineError::Gone(e.to_string()))?;
        line.configure(settings).map_err(|e| LineError::Open {
            port: format!("rfc2217://{address}"),
            reason: format!("the server did not take the UART settings through RFC 2217: {e}"),
        })?;
        Ok(line)
    }

    /// Allow this much timing jitter (µs) before a reply's start is graded.
    pub fn with_tolerance(mut self, tolerance_us: u64) -> TcpLine {
        self.time.tolerance_us = tolerance_us;
        self
    }
}

/// Read whatever the server sends within `wait`, answering its negotiation; the
/// first serial data byte, if one came.
fn read_data(
    stream: &mut TcpStream,
    address: &str,
    telnet: &mut Option<Telnet>,
    wait: Duration,
) -> Result<Option<u8>, LineError> {
    let deadline = std::time::Instant::now() + wait;
    loop {
        let mut b = [0u8; 1];
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        let read = if left.is_zero() {
            // A zero timeout is refused by a socket: look without waiting instead.
            stream.set_nonblocking(true)?;
            let read = stream.read(&mut b);
            stream.set_nonblocking(false)?;
            read
        } else {
            stream.set_read_timeout(Some(left))?;
            stream.read(&mut b)
        };
        let byte = match read {
            Ok(1) => b[0],
            Ok(_) => return Err(LineError::Gone(format!("{address} closed the connection"))),
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => {
                return Ok(None)
            }
            Err(e) => return Err(LineError::Gone(e.to_string())),
        };
        let Some(t) = telnet.as_mut() else { return Ok(Some(byte)) };
        match t.take(byte) {
            Event::Data(d) => return Ok(Some(d)),
            Event::Answer(a) => stream.write_all(&a).map_err(|e| LineError::Gone(e.to_string()))?,
            Event::Nothing | Event::Applied { .. } => {}
        }
        if left.is_zero() {
            return Ok(None);
        }
    }
}

impl Line for TcpLine {
    fn now_us(&mut self) -> u64 {
        self.time.now_us()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        let ct = self.settings.char_time_us();
        let stream = &mut self.stream;
        let telnet = self.telnet.is_some();
        let sent = clock::write_whole(&self.time, ct, bytes, |b| {
            let wire = if telnet { rfc2217::escape(b) } else { b.to_vec() };
            stream.write_all(&wire).map_err(|e| LineError::Gone(e.to_string()))
        })?;
        // Behind the server a UART adds one character time (a pseudo-terminal none).
        Ok(Sent { end: Window { earliest_us: sent.end.earliest_us, latest_us: sent.end.latest_us + ct }, ..sent })
    }

    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        let (stream, address, telnet) = (&mut self.stream, &self.address, &mut self.telnet);
        let got = clock::read_until(&self.time, until_us, |wait| read_data(stream, address, telnet, wait))?;
        // TCP has no baud rate: the server's UART delivered the bytes a character apart.
        let clocked = Some(self.settings.char_time_us());
        Ok(got.map(|(byte, arrival)| self.time.rx.stamp(byte, arrival, clocked)))
    }

    fn start_of(&self, ch: &RxChar) -> Window {
        // Behind the server a UART (the character began a character time before the
        // server had it) or a pseudo-terminal (a write may mark the start).
        Window { earliest_us: ch.at_us.saturating_sub(self.settings.char_time_us()), latest_us: ch.at_us }
    }

    clock::real_time_methods!(time);

    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        if self.telnet.is_some() {
            // RFC 2217: ask, and wait until the server says it applied them. No serial
            // data is expected meanwhile (the harness changes settings between
            // exchanges); any that comes is the line's fault, not lost silently.
            self.stream.write_all(&rfc2217::set_settings(settings)).map_err(|e| LineError::Gone(e.to_string()))?;
            let started = std::time::Instant::now();
            while !self.telnet.as_ref().is_some_and(|t| t.has_applied(settings)) {
                let left = SETTINGS_CONFIRMED_WITHIN.saturating_sub(started.elapsed());
                if left.is_zero() {
                    return Err(LineError::Settings { settings, reason: "the server did not confirm them".into() });
                }
                let wait = left.min(Duration::from_millis(50));
                if let Some(d) = read_data(&mut self.stream, &self.address, &mut self.telnet, wait)? {
                    return Err(LineError::Echo(format!(
                        "serial data {d:02X} came while the server was switching its UART settings"
                    )));
                }
            }
            self.settings = settings;
            return Ok(());
        }
        // The server's port settings are its configuration's.
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
        self.telnet.is_some()
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
        match self.telnet {
            Some(_) => format!("rfc2217://{} (serial device server, RFC 2217)", self.address),
            None => format!("tcp://{} ({})", self.address, self.kind().label()),
        }
    }
}
