//! `hiperface simulate`: the reference model as a virtual encoder on a serial port or
//! pseudo-terminal, in real time: replies start inside their window. On a
//! pseudo-terminal the simulator plays the UART (see `line::serial`): received bytes
//! are clocked one character time apart, and a reply is written whole when its first
//! character would be complete.

use crate::certify::World;
use hiperface_model::{Hex, Profile, Slave};
use serialport::SerialPort;
use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long after the earliest allowed start the simulator begins a reply.
pub const REPLY_DELAY_US: u64 = 300;

/// Serve `profile` on `port` until `stop` is set or the port goes away. Frames are
/// logged to `log` when given.
pub fn serve(
    mut port: Box<dyn SerialPort>,
    profile: Profile,
    world: &World,
    stop: Arc<AtomicBool>,
    mut log: Option<&mut dyn Write>,
) -> std::io::Result<()> {
    let epoch = Instant::now();
    let now = |e: Instant| e.elapsed().as_micros() as u64;
    let mut slave = Slave::operational(profile);
    world.apply(&mut slave);
    let mut buf = [0u8; 64];
    let mut rx_clock = crate::line::RxClock::default();
    port.set_timeout(Duration::from_micros(500)).map_err(std::io::Error::from)?;
    let mut port_settings = None;
    while !stop.load(Ordering::Relaxed) {
        // Follow the slave's listening settings (67h, reset, power-up windows) on the
        // port; a pseudo-terminal accepts and ignores them.
        let listening = slave.listening_settings(now(epoch));
        if listening.is_some() && listening != port_settings {
            if let Some(s) = listening {
                apply_settings(port.as_mut(), s)?;
            }
            port_settings = listening;
        }
        let mut steps = Vec::new();
        match port.read(&mut buf) {
            Ok(0) => return Ok(()),
            Ok(n) => {
                let t = now(epoch);
                for b in &buf[..n] {
                    let ct = slave.listening_settings(t).unwrap_or_default().char_time_us();
                    steps.extend(slave.receive(rx_clock.stamp(*b, t, Some(ct))));
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => {}
            Err(e) if e.raw_os_error() == Some(5) => return Ok(()), // EIO: the other end closed
            Err(e) => return Err(e),
        }
        steps.extend(slave.poll(now(epoch)));
        for step in steps {
            if let Some(l) = log.as_deref_mut() {
                let _ = writeln!(
                    l,
                    "{:>12.3} ms  M> {}",
                    step.received.last_us as f64 / 1000.0,
                    Hex(step.received.bytes.as_bytes())
                );
            }
            let Some(tx) = step.transmission else { continue };
            let start = tx.earliest_start_us + REPLY_DELAY_US;
            let ct = tx.settings.char_time_us();
            let due = epoch + Duration::from_micros(start + ct);
            if let Some(d) = due.checked_duration_since(Instant::now()) {
                std::thread::sleep(d);
            }
            port.write_all(tx.frame.as_bytes())?;
            port.flush()?;
            // The line is busy until the reply's last character is out.
            let done = epoch + Duration::from_micros(start + tx.frame.len() as u64 * ct);
            if let Some(d) = done.checked_duration_since(Instant::now()) {
                std::thread::sleep(d);
            }
            if let Some(l) = log.as_deref_mut() {
                let _ = writeln!(l, "{:>12.3} ms  S< {}", start as f64 / 1000.0, Hex(tx.frame.as_bytes()));
            }
        }
    }
    Ok(())
}

fn apply_settings(port: &mut dyn SerialPort, s: hiperface_model::UartSettings) -> std::io::Result<()> {
    use hiperface_model::settings::Parity as P;
    let parity = match s.parity {
        P::None => serialport::Parity::None,
        P::Even => serialport::Parity::Even,
        P::Odd => serialport::Parity::Odd,
    };
    port.set_baud_rate(s.baud.bits_per_second()).map_err(std::io::Error::from)?;
    port.set_parity(parity).map_err(std::io::Error::from)
}

/// A pseudo-terminal pair with the simulator on one end, served by a thread until
/// dropped.
pub struct PtySimulator {
    pub path: String,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<std::io::Result<()>>>,
}

impl PtySimulator {
    /// Start; returns the simulator and the other end of the pair, for the harness.
    pub fn start(profile: Profile) -> Result<(PtySimulator, Box<dyn SerialPort>), String> {
        PtySimulator::start_in(profile, World::default())
    }

    /// Start in a given world (inputs, start-up faults).
    pub fn start_in(profile: Profile, world: World) -> Result<(PtySimulator, Box<dyn SerialPort>), String> {
        let (sim_end, harness_end) =
            serialport::TTYPort::pair().map_err(|e| format!("cannot create a pseudo-terminal pair: {e}"))?;
        let path = harness_end.name().unwrap_or_else(|| "pty".into());
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || serve(Box::new(sim_end), profile, &world, flag, None));
        Ok((PtySimulator { path, stop, thread: Some(thread) }, Box::new(harness_end)))
    }
}

impl Drop for PtySimulator {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
