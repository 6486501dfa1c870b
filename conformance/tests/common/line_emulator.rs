//! A line emulator between two pseudo-terminals (test support, not product): what a
//! lab bench puts between the harness and a device. It passes characters on at 9600 Bd,
//! and can echo the harness's characters
//! back to it (a two-wire RS-485 adapter whose receiver stays on), hold the device's
//! characters like a USB adapter's latency timer, and add a gap before each character
//! it passes on.

use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
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
    /// The kernel's delivery between pseudo-terminals while the emulator runs: the
    /// emulator writes each character on its own, and a delivery held back by a
    /// timeout splits a request the harness sent whole (the emulated line is not
    /// hardware; a run where that may have happened is no test of the harness).
    delivery: hiperface_conformance::line::delivery::DeliveryProbe,
    /// Every character passed on after another of the same burst, both ways: when it
    /// was written, and how long after the one before it (µs).
    written: Arc<Mutex<Vec<(Instant, u64)>>>,
    stop: Arc<AtomicBool>,
    threads: Vec<Option<JoinHandle<()>>>,
    _harness_end: std::os::fd::OwnedFd,
    /// The kernel's workers that deliver what is written to a pseudo-terminal, raised
    /// while the emulator runs, as `certify` raises them for its own line: with three
    /// busy loops they held back the last character of a request the emulator passed on
    /// 0.3 ms after the one before, a timeout late, which neither the emulator's clock nor
    /// the simulator's could see (real_lines' gap test: 0Ah to a valid request).
    _kernel: Option<hiperface_conformance::sched::KernelDelivery>,
}

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
        let written = Arc::new(Mutex::new(Vec::new()));
        let flags = (stop.clone(), stop.clone());
        let late = written.clone();
        let threads = [
            std::thread::spawn(move || outbound(harness, device_out, behaviour, &flags.0)),
            std::thread::spawn(move || inbound(device, to_harness, behaviour, &flags.1, &late)),
        ];
        let delivery = hiperface_conformance::line::delivery::DeliveryProbe::start_with(Instant::now(), true)
            .unwrap_or_else(|e| panic!("{e}"));
        let threads = threads.into_iter().map(Some).collect();
        let _kernel = hiperface_conformance::sched::KernelDelivery::raise();
        LineEmulator { path, delivery, written, stop, threads, _harness_end: pty.slave, _kernel }
    }

    /// Whether the emulated line was a line: no two characters of one burst it passed
    /// on may have arrived a timeout apart (see `late_moments`).
    pub fn was_faithful(&self) -> bool {
        self.late_moments().is_empty()
    }

    /// When the emulated line was no line: the characters passed on that may have
    /// arrived a timeout (5.73 ms at 9600 Bd) after the one before them of the same
    /// burst, for the emulator's own lateness between them and the kernel's delivery
    /// between pseudo-terminals at the time (the probe's writes around the second one).
    pub fn late_moments(&self) -> Vec<Instant> {
        let period = hiperface_conformance::line::delivery::PERIOD.as_micros() as u64;
        let epoch = self.delivery.epoch();
        let written = self.written.lock().unwrap_or_else(|e| e.into_inner());
        let mut worst = 0;
        let late: Vec<Instant> = written
            .iter()
            .filter_map(|&(at, after_us)| {
                let at_us = at.saturating_duration_since(epoch).as_micros() as u64;
                let held = self.delivery.max_delay_us(at_us.saturating_sub(2 * period), at_us + 2 * period);
                let apart = after_us + held.unwrap_or(0);
                worst = worst.max(apart);
                (apart >= 5_730).then_some(at)
            })
            .collect();
        if !late.is_empty() {
            eprintln!(
                "{} characters may have arrived a timeout after the one before them, at worst {worst} µs (a busy machine)",
                late.len()
            );
        }
        late
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

/// One character's time at 9600 Bd, 11 bits (8E1). // 000:T28
const CHAR_US: u64 = 1146;

/// The harness sends: each character on the wire for its time and its gap, echoed as it
/// goes. The device is handed what the harness wrote when its last character is
/// through, at once: the kernel would otherwise deliver the characters one by one, and
/// on a busy machine a timeout apart (seen with three busy loops and the gap: 0Ch and
/// 0Ah to valid requests), a request split by the test's line, not the harness. A
/// device framing by the timeout (000:2.2.2) sees the same request either way, ending
/// when a line with gaps would end it.
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
                let mut slot = Instant::now();
                for byte in &buf[..n] {
                    slot += Duration::from_micros(CHAR_US + b.gap_us);
                    pace_to(slot);
                    if b.echo {
                        let _ = echo.write_all(&[*byte]);
                    }
                }
                let _ = device.write_all(&buf[..n]);
            }
            // The harness has not opened its end, or closed it (EIO): nothing to relay.
            Err(_) => std::thread::sleep(Duration::from_millis(5)),
        }
    }
}

/// The device answers: passed on as it comes (after the gap), or held for the latency
/// timer and handed on in one burst.
fn inbound(
    mut device: Box<dyn serialport::SerialPort>,
    mut harness: File,
    b: Behaviour,
    stop: &AtomicBool,
    written: &Mutex<Vec<(Instant, u64)>>,
) {
    hiperface_conformance::sched::real_time_priority();
    let mut held: Vec<u8> = Vec::new();
    let mut held_since: Option<Instant> = None;
    let mut buf = [0u8; 256];
    while !stop.load(Ordering::Relaxed) {
        if let Ok(n) = device.read(&mut buf) {
            let mut slot = Instant::now();
            let mut last = None;
            for byte in &buf[..n] {
                if b.latency_ms == 0 {
                    slot += Duration::from_micros(b.gap_us);
                    pace_to(slot);
                    let _ = harness.write_all(&[*byte]);
                    last = noted(written, last);
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

/// Wait for `slot` (the pace of the line, kept across a late wake-up).
fn pace_to(slot: Instant) {
    let now = Instant::now();
    if slot > now {
        std::thread::sleep(slot - now);
    }
}

/// Note a character just written after `last` of the same burst; returns when.
fn noted(written: &Mutex<Vec<(Instant, u64)>>, last: Option<Instant>) -> Option<Instant> {
    let now = Instant::now();
    if let Some(before) = last {
        let after_us = now.saturating_duration_since(before).as_micros() as u64;
        written.lock().unwrap_or_else(|e| e.into_inner()).push((now, after_us));
    }
    Some(now)
}
