//! A real serial port or a pseudo-terminal, in real time.
//!
//! Long because: a real port and a pseudo-terminal share the opening, the settings and
//! the reading loop, and differ in a few branches best read side by side; under 400
//! lines without its tests.
//!
//! On a real port the UART clocks a request out, so it is written whole; a USB
//! adapter in between adds latency, which widens the timing windows (see
//! [`super::adapter`]). A pseudo-terminal has no baud rate: the harness writes the
//! request at once and knows its end as a window (see [`super::clock`]), and stamps
//! received characters at least a character time apart, as a UART delivers them.

use super::adapter::Adapter;
use super::clock;
use hiperface_model::datalink::RxChar;
use hiperface_model::settings::Parity as HfParity;
use hiperface_model::UartSettings;
use hiperface_suite::line::{Line, LineError, LineKind, Sent, Window};
use serialport::{DataBits, FlowControl, Parity, SerialPort, StopBits};
use std::io::{ErrorKind, Read, Write};
use std::time::Duration;

/// Scheduler and pseudo-terminal jitter on a loaded 2-core machine.
pub const DEFAULT_TOLERANCE_US: u64 = 2_000;

pub struct SerialLine {
    port: Box<dyn SerialPort>,
    name: String,
    time: clock::RealTime,
    settings: UartSettings,
    /// Pseudo-terminals ignore UART settings; real ports apply them.
    pseudo_terminal: bool,
    /// The USB adapter behind a real port, if any.
    adapter: Option<Adapter>,
    /// How late the line may deliver a received character, as the user declared it
    /// (`--latency-ms`: a latency timer the harness cannot read), µs.
    declared_latency_us: u64,
    notes: Vec<String>,
    /// On a pseudo-terminal: how late the kernel delivers, measured beside the line.
    delivery: Option<super::delivery::DeliveryProbe>,
    /// On a pseudo-terminal: the device's processes at its other end, which this
    /// machine's processors run.
    device: Option<super::device_held::DeviceProcesses>,
}

fn parity(s: UartSettings) -> Parity {
    match s.parity {
        HfParity::None => Parity::None,
        HfParity::Even => Parity::Even,
        HfParity::Odd => Parity::Odd,
    }
}

/// Open a serial port or pseudo-terminal by path at `settings` (eight data bits, one
/// stop bit, no flow control: 000:T7), each read waiting at most 1 ms. The one place a
/// port is opened for writing: the harness as master ([`SerialLine`]), as encoder
/// (`certify master --port`) and the simulator. (`monitor` opens its tap read-only,
/// which needs termios itself: `listen/tap.rs`.)
pub fn open_port(path: &str, settings: UartSettings) -> Result<Box<dyn SerialPort>, LineError> {
    Ok(Box::new(open_native(path, settings)?))
}

/// Why `path` cannot be a serial line, in words, where it exists and is no character
/// device (a regular file, a directory): said before the kernel's ENOTTY ("Not a
/// typewriter") would be.
pub fn not_a_port(path: &str) -> Option<String> {
    use std::os::unix::fs::FileTypeExt as _;
    let kind = std::fs::metadata(path).ok()?.file_type();
    let what = if kind.is_dir() {
        "a directory"
    } else if kind.is_file() {
        "a regular file"
    } else if kind.is_char_device() {
        return None;
    } else {
        "neither a serial port nor a pseudo-terminal"
    };
    Some(format!(
        "it is {what}; give a serial port (/dev/ttyUSB0), a pseudo-terminal (/dev/pts/N), tcp://host:port, \
         rfc2217://host:port or sim"
    ))
}

fn open_native(path: &str, settings: UartSettings) -> Result<serialport::TTYPort, LineError> {
    if let Some(reason) = not_a_port(path) {
        return Err(LineError::Open { port: path.to_string(), reason });
    }
    serialport::new(path, settings.baud.bits_per_second())
        .data_bits(DataBits::Eight)
        .stop_bits(StopBits::One)
        .parity(parity(settings))
        .flow_control(FlowControl::None)
        .timeout(Duration::from_millis(1))
        .open_native()
        .map_err(|e| LineError::Open { port: path.to_string(), reason: open_failure(path, &e) })
}

/// Why a port would not open, with what helps: the ports there are where it is not
/// there, the group that may open them where permission was refused.
fn open_failure(path: &str, e: &serialport::Error) -> String {
    let mut reason = e.to_string();
    let denied = matches!(e.kind(), serialport::ErrorKind::Io(std::io::ErrorKind::PermissionDenied))
        || reason.contains("Permission denied");
    if denied {
        reason.push_str(
            "; a user opens serial ports as a member of their group (usually `dialout`: `sudo usermod -aG dialout \
             $USER`, then log in again)",
        );
    } else if !std::path::Path::new(path).exists() {
        let ports: Vec<String> =
            serialport::available_ports().unwrap_or_default().into_iter().map(|p| p.port_name).collect();
        reason.push_str(&match ports.as_slice() {
            [] => "; no serial port is there now (is the adapter plugged in?)".to_string(),
            _ => format!("; the serial ports there now: {}", ports.join(", ")),
        });
    }
    reason
}

/// As [`open_port`], with the kernel marking what the UART saw in the data it
/// delivers (`PARMRK`, as `monitor` reads: `FF 00 c` a character with a parity or
/// framing error, `FF 00 00` a break, `FF FF` a data byte FFh; `listen::tap::Marks`
/// takes it back). The encoder's port (`certify master --port`): a master's UART
/// faults reach the model as such (09h, 000:T47). A pseudo-terminal marks too (it
/// doubles FFh; it has no UART to see faults). The marking stays when the data rate
/// or parity is changed ([`apply_settings`] changes `INPCK` and `IGNPAR` only).
pub fn open_marking_port(path: &str, settings: UartSettings) -> Result<Box<dyn SerialPort>, LineError> {
    use nix::sys::termios::{tcgetattr, tcsetattr, InputFlags as I, SetArg};
    let mut port = open_native(path, settings)?;
    let fail = |e: &dyn std::fmt::Display| LineError::Open {
        port: path.to_string(),
        reason: format!("cannot mark UART faults: {e}"),
    };
    // The settings are the terminal's, whichever descriptor sets them: set through a
    // second one, opened while the port lets it (no unsafe descriptor juggling).
    port.set_exclusive(false).map_err(|e| fail(&e))?;
    let marked = (|| -> Result<(), String> {
        use std::os::unix::fs::OpenOptionsExt;
        let file = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(nix::libc::O_NOCTTY | nix::libc::O_NONBLOCK)
            .open(path)
            .map_err(|e| e.to_string())?;
        let mut t = tcgetattr(&file).map_err(|e| e.to_string())?;
        t.input_flags.remove(I::IGNPAR | I::IGNBRK | I::BRKINT | I::ISTRIP);
        t.input_flags.insert(I::PARMRK);
        tcsetattr(&file, SetArg::TCSANOW, &t).map_err(|e| e.to_string())
    })();
    port.set_exclusive(true).map_err(|e| fail(&e))?;
    marked.map_err(|e| fail(&e))?;
    Ok(Box::new(port))
}

/// Change an open port's data rate and parity (57h, 67h).
pub fn apply_settings(port: &mut dyn SerialPort, settings: UartSettings) -> Result<(), serialport::Error> {
    port.set_baud_rate(settings.baud.bits_per_second())?;
    port.set_parity(parity(settings))
}

/// Whether a path names a pseudo-terminal, by what it is rather than what it is called:
/// the device behind a symbolic link (socat's `link=`, a `/dev/serial/by-id` name) is
/// the one judged. On Linux a pseudo-terminal's slave is a character device of the
/// Unix98 majors 136 to 143 (`/dev/pts/N`); elsewhere, or where the device cannot be
/// examined, the name as resolved (`/dev/pts/N`, BSD-style `ptyXY`/`ttypN`).
pub fn is_pseudo_terminal(path: &str) -> bool {
    let resolved = resolved(path);
    let named = |p: &str| p.starts_with("/dev/pts/") || p.contains("pty");
    named(path) || resolved.as_deref().is_some_and(named) || unix98_pty_major(resolved.as_deref().unwrap_or(path))
}

/// The path a port's path resolves to, where that differs (a symbolic link).
pub fn resolved(path: &str) -> Option<String> {
    let real = std::fs::canonicalize(path).ok()?;
    let real = real.to_string_lossy().into_owned();
    (real != path).then_some(real)
}

/// Whether `path` is a character device of a Unix98 pseudo-terminal slave's major.
fn unix98_pty_major(path: &str) -> bool {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let Ok(m) = std::fs::metadata(path) else { return false };
    if !m.file_type().is_char_device() {
        return false;
    }
    let rdev = m.rdev();
    // glibc's gnu_dev_major.
    let major = ((rdev >> 8) & 0xfff) | ((rdev >> 32) & !0xfff);
    (136..=143).contains(&major)
}

impl SerialLine {
    /// Open a port by path with the given settings. On a USB adapter with a latency
    /// timer, lower it to 1 ms for the run where permitted.
    pub fn open(path: &str, settings: UartSettings) -> Result<SerialLine, LineError> {
        let port = open_port(path, settings)?;
        let pseudo_terminal = is_pseudo_terminal(path);
        // The report names the path given and, behind a link, the device it opened.
        let name = match resolved(path) {
            Some(real) => format!("{path} (a link to {real})"),
            None => path.to_string(),
        };
        let mut line = SerialLine::from_port(port, name, settings, pseudo_terminal);
        if pseudo_terminal {
            line.device = super::device_held::DeviceProcesses::of_pseudo_terminal(path);
            if let Some(d) = &line.device {
                let pids: Vec<String> = d.pids().iter().map(u32::to_string).collect();
                let how = match d.processors_watched() {
                    Some(n) => format!(
                        "its process's wait for a processor, and the pauses of the machine's {n} processors, which a \
                         sentinel at a real-time priority on each timed"
                    ),
                    None => "its process's wait for a processor, and the hypervisor's steal in 10 ms steps".into(),
                };
                line.notes.push(format!(
                    "The device runs on this machine (process {} at the pseudo-terminal's other end): how long this \
                     machine held it is measured around each exchange ({how}), and an answer a request heard in two \
                     parts explains, or a reply late by less than the hold, is not charged.",
                    pids.join(", ")
                ));
            }
        }
        if !pseudo_terminal {
            line.adapter = Adapter::detect(path, std::path::Path::new("/sys"));
            if let Some(a) = line.adapter.as_mut() {
                if let Err(why) = a.lower_latency() {
                    line.notes.push(format!("The adapter's latency timer could not be lowered: {why}."));
                }
            }
        }
        Ok(line)
    }

    /// Wrap an open port (e.g. one end of a pseudo-terminal pair).
    pub fn from_port(
        port: Box<dyn SerialPort>,
        name: String,
        settings: UartSettings,
        pseudo_terminal: bool,
    ) -> SerialLine {
        let time = clock::RealTime::new(DEFAULT_TOLERANCE_US);
        let mut notes = Vec::new();
        let delivery = if pseudo_terminal {
            super::delivery::DeliveryProbe::start(time.epoch())
                .map_err(|e| notes.push(format!("The pseudo-terminal's delivery could not be measured: {e}.")))
                .ok()
        } else {
            None
        };
        SerialLine {
            port,
            name,
            time,
            settings,
            pseudo_terminal,
            adapter: None,
            declared_latency_us: 0,
            notes,
            delivery,
            device: None,
        }
    }

    /// Allow this much timing jitter (µs) before a reply's start is graded.
    pub fn with_tolerance(mut self, tolerance_us: u64) -> SerialLine {
        self.time.tolerance_us = tolerance_us;
        self
    }

    /// The far end is the harness's own simulator, which reports how late it was
    /// ([`crate::simulate::PtySimulator::lateness`]): its lateness is the harness's.
    /// Where it says when it received each character (`heard`), how long after the
    /// harness wrote it is the harness's lateness too.
    pub fn with_peer_lateness(
        mut self,
        lateness: std::sync::Arc<std::sync::atomic::AtomicU64>,
        heard: Option<super::clock::PeerHeard>,
    ) -> SerialLine {
        self.time.peer_lateness = Some(lateness);
        self.time.peer_heard = heard;
        self
    }

    /// The USB adapter behind the port, if one was found.
    pub fn adapter(&self) -> Option<&Adapter> {
        self.adapter.as_ref()
    }

    /// The line may deliver received characters up to `latency_us` late (an adapter's
    /// latency timer the harness cannot read or lower, a device server's buffering):
    /// reply windows are widened by it and the certificate says so.
    pub fn with_declared_latency(mut self, latency_us: u64) -> SerialLine {
        self.declared_latency_us = latency_us;
        if latency_us > 0 {
            self.notes.push(format!(
                "The line may deliver received characters up to {:.1} ms late (--latency-ms): reply windows are widened by it.",
                latency_us as f64 / 1000.0
            ));
        }
        self
    }

    /// How late a received character may reach the harness: the adapter's latency
    /// found in sysfs, or what the user declared, whichever is more, µs.
    pub fn input_latency_us(&self) -> u64 {
        self.adapter.as_ref().map_or(0, Adapter::input_latency_us).max(self.declared_latency_us)
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

    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        let ct = self.settings.char_time_us();
        if self.pseudo_terminal {
            let port = &mut self.port;
            let sent = clock::write_whole(&self.time, ct, bytes, |b| {
                port.write_all(b).map_err(Self::gone)?;
                port.flush().map_err(Self::gone)
            });
            if let Some(d) = self.device.as_mut() {
                // The device has heard the request when its characters and the longest
                // timeout of either edition after them have passed (000:2.2.2).
                use hiperface_model::Edition::{Current, Legacy};
                let timeout = self.settings.timeout_us(Current).max(self.settings.timeout_us(Legacy));
                d.mark(Duration::from_micros(bytes.len() as u64 * ct + timeout));
            }
            return sent;
        }
        let start = self.now_us();
        self.port.write_all(bytes).map_err(Self::gone)?;
        self.port.flush().map_err(Self::gone)?;
        // The UART clocks the frame out; an adapter may hold it up to a USB frame first.
        let end = start + bytes.len() as u64 * ct;
        let late = self.adapter.as_ref().map_or(0, Adapter::output_latency_us);
        // Half duplex: the line is busy until the last character is out.
        self.time.sleep_until(end);
        Ok(Sent::within(Window { earliest_us: end, latest_us: end + late }))
    }

    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        let time = &self.time;
        let port = &mut self.port;
        let got = clock::read_until(time, until_us, |wait| {
            port.set_timeout(wait).map_err(|e| LineError::Io(e.into()))?;
            let mut b = [0u8; 1];
            match port.read(&mut b) {
                Ok(1) => Ok(Some(b[0])),
                Ok(_) => Err(LineError::Gone("end of file".into())),
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => {
                    Ok(None)
                }
                Err(e) => Err(Self::gone(e)),
            }
        })?;
        let clocked = self.pseudo_terminal.then(|| self.settings.char_time_us());
        if let Some((_, arrival)) = got {
            self.time.read_at(arrival);
        }
        Ok(got.map(|(byte, arrival)| self.time.rx.stamp(byte, arrival, clocked)))
    }

    fn start_of(&self, ch: &RxChar) -> Window {
        let ct = self.settings.char_time_us();
        let latency = self.input_latency_us();
        if self.pseudo_terminal {
            // A peer's write is the start of the character (a program) or its end (a
            // program playing the UART); what is in between may hold it back.
            return Window { earliest_us: ch.at_us.saturating_sub(ct + latency), latest_us: ch.at_us };
        }
        // A UART stamps a character after its stop bit; an adapter may pass it on late.
        Window { earliest_us: ch.at_us.saturating_sub(ct + latency), latest_us: ch.at_us.saturating_sub(ct) }
    }

    clock::real_time_methods!(time);

    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        if !self.pseudo_terminal {
            apply_settings(self.port.as_mut(), settings)
                .map_err(|e| LineError::Settings { settings, reason: e.to_string() })?;
        }
        self.settings = settings;
        Ok(())
    }

    fn settings(&self) -> UartSettings {
        self.settings
    }

    fn carries_parity(&self) -> Result<(), &'static str> {
        if self.pseudo_terminal {
            Err("a pseudo-terminal carries no parity bit: a parity error cannot be sent on it; a serial port or the virtual line (--port virtual) runs it")
        } else {
            Ok(())
        }
    }

    fn delivery_late(&mut self, from_us: u64, to_us: u64) -> hiperface_suite::line::delivery::LineLate {
        let Some(probe) = &self.delivery else { return Default::default() };
        probe.late_both_ways(from_us, to_us, self.time.now_us())
    }

    fn delivery_stats(&self) -> Option<hiperface_suite::line::delivery::DeliveryStats> {
        self.delivery.as_ref().map(|p| p.stats())
    }

    fn device_held(&mut self) -> hiperface_suite::line::delivery::DeviceHeld {
        self.device.as_mut().map(|d| d.held()).unwrap_or_default()
    }

    fn kind(&self) -> LineKind {
        if self.pseudo_terminal {
            LineKind::PseudoTerminal
        } else {
            LineKind::SerialPort
        }
    }

    fn describe(&self) -> String {
        format!("{} {}", self.kind().label(), self.name)
    }

    fn notes(&self) -> Vec<String> {
        let mut notes: Vec<String> = self.adapter.iter().map(Adapter::describe).collect();
        notes.extend(self.notes.iter().cloned());
        notes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A port that is not there: the error lists the ports that are (issue 56: a user
    /// with `/dev/ttyUSB0` unplugged learned nothing of where the adapter went).
    #[test]
    fn a_missing_port_is_named_with_the_ports_there_are() {
        let Err(e) = open_native("/dev/ttyUSB-hiperface-missing", UartSettings::DEFAULT) else {
            panic!("a port that is not there opened")
        };
        let e = e.to_string();
        assert!(e.contains("cannot open /dev/ttyUSB-hiperface-missing"), "{e}");
        assert!(e.contains("the serial ports there now") || e.contains("no serial port is there now"), "{e}");
    }
    use hiperface_model::settings::{Baud, Parity as HfParity};
    use std::io::Write;

    /// A pseudo-terminal is one whatever its name: through a symbolic link (socat's
    /// `link=`, a by-id name) it is classified as one, and the line says which path was
    /// opened and what it resolved to; a regular file is none.
    #[test]
    fn a_pseudo_terminal_behind_a_link_is_one_and_says_so() {
        let (_far, near) = serialport::TTYPort::pair().expect("a pseudo-terminal pair");
        let path = near.name().expect("a path");
        let dir = std::env::temp_dir().join(format!("hf-link-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a directory");
        let link = dir.join("ttyENCODER");
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(&path, &link).expect("a link");
        let link = link.to_string_lossy().into_owned();
        assert!(is_pseudo_terminal(&path));
        assert!(is_pseudo_terminal(&link), "{link} -> {path}");
        assert_eq!(resolved(&link).as_deref(), Some(path.as_str()));
        let line = SerialLine::open(&link, UartSettings::DEFAULT).expect("opened");
        assert!(line.pseudo_terminal);
        assert_eq!(line.name, format!("{link} (a link to {path})"));
        let plain = dir.join("plain");
        std::fs::write(&plain, b"").expect("a file");
        assert!(!is_pseudo_terminal(&plain.to_string_lossy()));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Read what `port` delivers until `n` bytes or half a second.
    fn read_n(port: &mut dyn SerialPort, n: usize) -> Vec<u8> {
        let (mut got, mut buf) = (Vec::new(), [0u8; 16]);
        let until = std::time::Instant::now() + Duration::from_millis(500);
        while got.len() < n && std::time::Instant::now() < until {
            if let Ok(k) = port.read(&mut buf) {
                got.extend_from_slice(&buf[..k]);
            }
        }
        got
    }

    /// The encoder's port marks what the UART saw: on a pseudo-terminal (no UART, so
    /// no faults) a data byte FFh comes doubled, as on a serial port, and the marks
    /// are taken back to what was sent; the marking stays when the settings change.
    #[test]
    fn a_marking_port_doubles_ffh_and_keeps_marking_after_a_settings_change() {
        let (mut far, near) = serialport::TTYPort::pair().expect("a pseudo-terminal pair");
        let path = near.name().expect("a path");
        let mut port = open_marking_port(&path, UartSettings::DEFAULT).expect("opened");
        let unmark = |raw: &[u8]| {
            let (mut marks, mut out) = (hiperface_suite::capture::parmrk::Marks::default(), Vec::new());
            for b in raw {
                marks.push(*b, &mut |m| out.push(m.as_received()));
            }
            out
        };
        let sent = [0x40, 0xFF, 0x00, 0x41];
        for settings in
            [UartSettings::DEFAULT, UartSettings { baud: Baud::B19200, parity: HfParity::Odd, ..UartSettings::DEFAULT }]
        {
            apply_settings(port.as_mut(), settings).expect("settings");
            far.write_all(&sent).expect("written");
            let raw = read_n(port.as_mut(), 5);
            assert_eq!(raw, [0x40, 0xFF, 0xFF, 0x00, 0x41], "{settings:?}");
            assert_eq!(unmark(&raw), sent.iter().map(|b| (*b, None)).collect::<Vec<_>>());
        }
        // Without the marking, FFh comes as it is.
        drop(port);
        let mut plain = open_port(&path, UartSettings::DEFAULT).expect("opened");
        far.write_all(&sent).expect("written");
        assert_eq!(read_n(plain.as_mut(), 4), sent);
    }
}
