//! The master's view of a serial line: send bytes, receive stamped characters,
//! always within a bounded time. The core has the in-process line in virtual time
//! ([`virtual_line::VirtualLine`]) and the echo's handling ([`echo::EchoLine`]); the
//! harness (`hiperface-conformance`) implements [`Line`] on real ports,
//! pseudo-terminals and serial device servers, in real time.
//!
//! Each line says how well it knows when characters were on the wire: a request's
//! end and a reply's start are [`Window`]s, exact in virtual time and on a real UART,
//! wider where the far end has no UART clock.

pub mod delivery;
pub mod echo;
pub mod frame_encoder;
pub mod reply_echo;
pub mod rx_clock;
pub mod virtual_line;

use hiperface_model::datalink::RxChar;
use hiperface_model::UartSettings;

/// A time known to lie between two bounds, µs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Window {
    pub earliest_us: u64,
    pub latest_us: u64,
}

impl Window {
    pub const fn exact(t_us: u64) -> Window {
        Window { earliest_us: t_us, latest_us: t_us }
    }

    pub const fn shifted(self, by_us: u64) -> Window {
        Window { earliest_us: self.earliest_us + by_us, latest_us: self.latest_us + by_us }
    }
}

/// A request on the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sent {
    /// When the slave received the request's last character (the end of its stop bit).
    pub end: Window,
    /// How long the harness's own write of the request took, where the window holds
    /// it (a line without a UART clock: the request reached the line somewhere in the
    /// write): that much of the window is the harness's doing, not the line's
    /// latitude. A device is never passed on a reading only that width allows
    /// (`verdict::timing`); 0 where the end is known otherwise.
    pub write_us: u64,
}

impl Sent {
    /// A request whose end the line knows within `end`, without the harness's write
    /// in it.
    pub const fn within(end: Window) -> Sent {
        Sent { end, write_us: 0 }
    }
}

/// What kind of line it is, for reports and for what timing verdicts are worth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LineKind {
    /// In-process, virtual time: exact.
    Virtual,
    /// A real serial port (a UART, or a USB adapter with one).
    SerialPort,
    /// A pseudo-terminal: no baud rate; request ends and reply starts are windows.
    PseudoTerminal,
    /// Raw TCP to a serial device server.
    Tcp,
}

impl LineKind {
    pub fn label(self) -> &'static str {
        match self {
            LineKind::Virtual => "virtual line",
            LineKind::SerialPort => "serial port",
            LineKind::PseudoTerminal => "pseudo-terminal",
            LineKind::Tcp => "serial device server (TCP)",
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
    /// The line returned something else than the request it sent (or, with `--echo
    /// off`, the request itself): the line's fault.
    #[error("line fault: {0}")]
    Echo(String),
    #[error("cannot apply UART settings {settings}: {reason}")]
    Settings { settings: UartSettings, reason: String },
    /// A record played back (`decode` of a report) does not hold what the run asked.
    #[error("{0}")]
    Record(String),
}

/// A half-duplex serial line as the master sees it. Times are µs since the line
/// was opened.
pub trait Line {
    /// Now, in µs.
    fn now_us(&mut self) -> u64;
    /// Transmit `bytes` in the current settings, as one frame.
    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError>;
    /// The next received character, or `None` once `until_us` has passed.
    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError>;
    /// When the start bit of a received character may have begun.
    fn start_of(&self, ch: &RxChar) -> Window;
    /// Idle until `t_us`, discarding nothing: characters arriving meanwhile stay queued
    /// (in virtual time, nothing to wait for: time moves as the line is read).
    fn wait_until(&mut self, _t_us: u64) -> Result<(), LineError> {
        Ok(())
    }
    /// Switch the line's UART settings.
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError>;
    /// Whether [`Line::configure`] can change the data rate and parity (not on a raw
    /// TCP serial server, whose port settings are its own configuration).
    fn can_change_settings(&self) -> bool {
        true
    }
    fn settings(&self) -> UartSettings;
    /// Whether a character sent with the wrong parity reaches the device as a parity
    /// error (a UART and its wire do; a pseudo-terminal has no parity bit and a raw
    /// TCP serial server sends in its own settings): `Err` says why not.
    fn carries_parity(&self) -> Result<(), &'static str> {
        Err("the line carries no parity bit")
    }
    /// Transmit `bytes` with the wrong parity on every character (odd for even, even
    /// for odd), then return to the current settings to hear the reply: a request the
    /// device must take for a UART fault (000:T47).
    fn send_with_wrong_parity(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        let right = self.settings();
        let refused = |reason: &str| LineError::Settings { settings: right, reason: reason.to_string() };
        self.carries_parity().map_err(refused)?;
        let wrong = right.with_wrong_parity().ok_or_else(|| refused("no parity: a parity error cannot be made"))?;
        self.configure(wrong)?;
        let sent = self.send(bytes);
        self.configure(right)?;
        sent
    }
    /// Timing jitter the line adds, in µs (0 in virtual time).
    fn tolerance_us(&self) -> u64 {
        0
    }
    /// How late the harness woke from its timed waits since the last call, µs: its own
    /// scheduling delay on a busy machine (0 in virtual time).
    fn take_lateness_us(&mut self) -> u64 {
        0
    }
    /// How much the line itself may have delayed an exchange that ran from `from_us` to
    /// `to_us`, both ways (the request to the device, its reply to the harness), as
    /// measured beside it (a pseudo-terminal's delivery, see [`delivery`]); 0 where
    /// nothing is measured.
    fn delivery_late(&mut self, _from_us: u64, _to_us: u64) -> delivery::LineLate {
        delivery::LineLate::default()
    }
    /// What the delivery probe beside the line saw over the run, where there is one.
    fn delivery_stats(&self) -> Option<delivery::DeliveryStats> {
        None
    }
    /// How long the device's own processor was held since the last [`Line::send`],
    /// where the device runs on this machine (see [`delivery::DeviceHeld`]); zero
    /// where it has a processor of its own or nothing is measured.
    fn device_held(&mut self) -> delivery::DeviceHeld {
        delivery::DeviceHeld::default()
    }
    fn kind(&self) -> LineKind;
    /// A short description for reports ("virtual", "/dev/pts/3", ...).
    fn describe(&self) -> String;
    /// Facts about the line that bear on timing verdicts (an adapter's latency timer).
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }
    /// What the harness found of the line's echo, and how it was told to treat it;
    /// `None` where no [`echo::EchoLine`] watches it.
    fn echo(&self) -> Option<(echo::Echo, echo::EchoMode)> {
        None
    }
}

impl<L: Line + ?Sized> Line for Box<L> {
    fn now_us(&mut self) -> u64 {
        (**self).now_us()
    }
    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        (**self).send(bytes)
    }
    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        (**self).recv(until_us)
    }
    fn start_of(&self, ch: &RxChar) -> Window {
        (**self).start_of(ch)
    }
    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        (**self).wait_until(t_us)
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        (**self).configure(settings)
    }
    fn can_change_settings(&self) -> bool {
        (**self).can_change_settings()
    }
    fn settings(&self) -> UartSettings {
        (**self).settings()
    }
    fn carries_parity(&self) -> Result<(), &'static str> {
        (**self).carries_parity()
    }
    fn send_with_wrong_parity(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        (**self).send_with_wrong_parity(bytes)
    }
    fn tolerance_us(&self) -> u64 {
        (**self).tolerance_us()
    }
    fn take_lateness_us(&mut self) -> u64 {
        (**self).take_lateness_us()
    }
    fn delivery_late(&mut self, from_us: u64, to_us: u64) -> delivery::LineLate {
        (**self).delivery_late(from_us, to_us)
    }
    fn delivery_stats(&self) -> Option<delivery::DeliveryStats> {
        (**self).delivery_stats()
    }
    fn device_held(&mut self) -> delivery::DeviceHeld {
        (**self).device_held()
    }
    fn kind(&self) -> LineKind {
        (**self).kind()
    }
    fn describe(&self) -> String {
        (**self).describe()
    }
    fn notes(&self) -> Vec<String> {
        (**self).notes()
    }
    fn echo(&self) -> Option<(echo::Echo, echo::EchoMode)> {
        (**self).echo()
    }
}
