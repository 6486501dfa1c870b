//! A line emulator between two pseudo-terminals (test support, not product): what a
//! lab bench puts between the harness and a device. It passes characters on at the
//! line's data rate, and can echo the harness's characters back to it (a two-wire
//! RS-485 adapter whose receiver stays on), hold the device's characters like a USB
//! adapter's latency timer, and add a gap before each character it passes on.

use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What the emulated line does.
#[derive(Debug, Clone, Copy, Default)]
pub struct Behaviour {
    /// Every character the harness sends comes back to it as it goes out.
    pub echo: bool,
    /// The device's characters are held and handed on in bursts this far apart, as a
    /// USB adapter's latency timer does (16 ms by default on FTDI adapters).
    pub latency_ms: u64,
    /// Extra idle time before each character passed on, µs.
    pub gap_us: u64,
}

/// A running emulator; stopped on drop.
pub struct LineEmulator {
    /// The harness's end: a pseudo-terminal path to open as the port.
    pub path: String,
    stop: Arc<AtomicBool>,
    threads: Vec<Option<JoinHandle<()>>>,
    _harness_end: std::os::fd::OwnedFd,
}

/// One character's time at 9600 Bd, 11 bits (8E1). // 000:T28
const CHAR_US: u64 = 1146;

impl LineEmulator {
    /// Put the emulator in front of the device served on `device_path` (its
    /// pseudo-terminal, opened here as the harness would open it).
    pub fn open(device_path: &str, behaviour: Behaviour) -> LineEmulator {
        let device = serialport::new(device_path, 9600)
            .parity(serialport::Parity::Even)
            .timeout(Duration::from_millis(1))
            .open()
            .unwrap_or_else(|e| panic!("the line emulator cannot open {device_path}: {e}"));
        LineEmulator::start(device, behaviour)
    }

    /// Put the emulator in front of a device on the port `device` (the harness's end
    /// of its pseudo-terminal).
    pub fn start(mut device: Box<dyn serialport::SerialPort>, behaviour: Behaviour) -> LineEmulator {
        use nix::fcntl::{fcntl, FcntlArg, FdFlag};
        device.set_timeout(Duration::from_millis(1)).unwrap();
        let pty = nix::pty::openpty(None, None).unwrap();
        for fd in [&pty.master, &pty.slave] {
            fcntl(fd, FcntlArg::F_SETFD(FdFlag::FD_CLOEXEC)).unwrap();
        }
        let path = nix::unistd::ttyname(&pty.slave).unwrap().to_string_lossy().to_string();
        // Raw, so that the pseudo-terminal passes bytes as they are until the harness
        // opens it and sets its own mode.
        let mut t = nix::sys::termios::tcgetattr(&pty.slave).unwrap();
        nix::sys::termios::cfmakeraw(&mut t);
        nix::sys::termios::tcsetattr(&pty.slave, nix::sys::termios::SetArg::TCSANOW, &t).unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let harness = File::from(pty.master);
        let (to_harness, device_out) = (harness.try_clone().unwrap(), device.try_clone().unwrap());
        let flags = (stop.clone(), stop.clone());
        let threads = [
            std::thread::spawn(move || outbound(harness, device_out, behaviour, &flags.0)),
            std::thread::spawn(move || inbound(device, to_harness, behaviour, &flags.1)),
        ];
        LineEmulator { path, stop, threads: threads.into_iter().map(Some).collect(), _harness_end: pty.slave }
    }
}

impl Drop for LineEmulator {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.iter_mut().filter_map(Option::take) {
            let _ = t.join();
        }
    }
}

/// The harness sends: each character on the wire for its time, echoed as it goes.
fn outbound(mut harness: File, mut device: Box<dyn serialport::SerialPort>, b: Behaviour, stop: &AtomicBool) {
    // A line is hardware: where permitted, the emulator runs at a real-time priority,
    // so that a busy machine does not make the line itself late (as HX-1 and the
    // simulator do).
    hiperface_conformance::sched::real_time_priority();
    let mut echo = harness.try_clone().unwrap();
    let mut buf = [0u8; 256];
    while !stop.load(Ordering::Relaxed) {
        let mut fds = [PollFd::new(harness.as_fd(), PollFlags::POLLIN)];
        let readable = poll(&mut fds, PollTimeout::from(5u8)).is_ok_and(|n| n > 0);
        if !readable {
            continue;
        }
        match harness.read(&mut buf) {
            Ok(n) => {
                for byte in &buf[..n] {
                    pace(CHAR_US + b.gap_us);
                    let _ = device.write_all(&[*byte]);
                    if b.echo {
                        let _ = echo.write_all(&[*byte]);
                    }
                }
            }
            // The harness has not opened its end, or closed it (EIO): nothing to relay.
            Err(_) => std::thread::sleep(Duration::from_millis(5)),
        }
    }
}

/// The device answers: passed on as it comes (after the gap), or held for the latency
/// timer and handed on in one burst.
fn inbound(mut device: Box<dyn serialport::SerialPort>, mut harness: File, b: Behaviour, stop: &AtomicBool) {
    hiperface_conformance::sched::real_time_priority();
    let mut held: Vec<u8> = Vec::new();
    let mut held_since: Option<Instant> = None;
    let mut buf = [0u8; 256];
    while !stop.load(Ordering::Relaxed) {
        if let Ok(n) = device.read(&mut buf) {
            for byte in &buf[..n] {
                if b.latency_ms == 0 {
                    pace(b.gap_us);
                    let _ = harness.write_all(&[*byte]);
                } else {
                    held_since.get_or_insert_with(Instant::now);
                    held.push(*byte);
                }
            }
        }
        if held_since.is_some_and(|t| t.elapsed() >= Duration::from_millis(b.latency_ms)) {
            let _ = harness.write_all(&held);
            held.clear();
            held_since = None;
        }
    }
}

fn pace(us: u64) {
    if us > 0 {
        std::thread::sleep(Duration::from_micros(us));
    }
}
