//! `hiperface simulate`: the reference model as a virtual encoder on a serial port or
//! pseudo-terminal, in real time: replies start inside their window. On a
//! pseudo-terminal the simulator plays the UART (see `line::serial`): received bytes
//! are clocked one character time apart, and a reply is written whole when its first
//! character would be complete.

use hiperface_model::{Hex, Profile, Slave, Step};
use hiperface_suite::serve::{Hooks, Next, Planned, Receiving, Sending, Serving, Session, READ_US};
use hiperface_suite::world::World;
use serialport::SerialPort;
use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

mod builtin;
pub use builtin::PtySimulator;

/// A read that returns this much later than its own timeout allowed is reported to
/// the hooks with the characters that end it, as time the line was not watched.
const UNWATCHED_US: u64 = 500;

/// Serve `profile` on `port` until `stop` is set or the port goes away. Frames are
/// logged to `log` when given.
pub fn serve(
    port: Box<dyn SerialPort>,
    profile: Profile,
    world: &World,
    stop: Arc<AtomicBool>,
    log: Option<&mut dyn Write>,
) -> std::io::Result<()> {
    let mut slave = Slave::operational(profile);
    world.apply(&mut slave);
    let mut session = Session::new(slave, Logger { log });
    serve_with(port, &mut session, Serving::MODEL, Instant::now(), &stop, None)
}

/// Logs frames for `hiperface simulate --log`.
struct Logger<'a> {
    log: Option<&'a mut (dyn Write + 'a)>,
}

impl Hooks for Logger<'_> {
    fn frame(&mut self, _slave: &mut Slave, step: &Step) {
        if let Some(l) = self.log.as_deref_mut() {
            let t = step.received.last_us as f64 / 1000.0;
            let _ = writeln!(l, "{t:>12.3} ms  M> {}", Hex(step.received.bytes.as_bytes()));
        }
    }
    fn sent(&mut self, planned: &Planned, _end_us: u64) {
        if let Some(l) = self.log.as_deref_mut() {
            let _ = writeln!(l, "{:>12.3} ms  S< {}", planned.start_us as f64 / 1000.0, Hex(&planned.frame));
        }
    }
}

/// Serve `session` (the model and its hooks) on `port` in real time from `epoch` (its
/// power-on) until `stop` is set or the port goes away, the port used as `serving`
/// says: the port's reads, writes and pacing here, the rest the session's. `delivery`: a probe of the pseudo-terminal's
/// own delivery beside the line, where there is one: what it measures counts as the
/// line unwatched (see `line::delivery`).
pub fn serve_with<H: Hooks>(
    mut port: Box<dyn SerialPort>,
    session: &mut Session<H>,
    serving: Serving,
    epoch: Instant,
    stop: &AtomicBool,
    delivery: Option<std::sync::Arc<crate::line::delivery::DeliveryProbe>>,
) -> std::io::Result<()> {
    // A device's UART keeps time whatever the host does: be as punctual as permitted.
    session.real_time(crate::sched::real_time_priority());
    let now = |e: Instant| e.elapsed().as_micros() as u64;
    let mut buf = [0u8; 64];
    let mut port_settings = None;
    let mut watched =
        Watched { read_us: now(epoch), run_delay: crate::run_delay::RunDelay::of_this_thread(), delivery };
    // What the master sent while a reply went out, as it was read.
    let mut heard: Vec<Chunk> = Vec::new();
    // The master's characters as the encoder's UART received them.
    let mut receiving = Receiving::new(serving);
    while !stop.load(Ordering::Relaxed) && !session.wants_stop() {
        // Follow the slave's listening settings (67h, reset, power-up windows) on the
        // port; a pseudo-terminal accepts and ignores them.
        let listening = session.listening_settings(now(epoch));
        if serving.sets_port && listening.is_some() && listening != port_settings {
            if let Some(s) = listening {
                crate::line::serial::apply_settings(port.as_mut(), s).map_err(std::io::Error::from)?;
            }
            port_settings = listening;
        }
        // Characters that came while a reply went out were read then; otherwise read
        // the line.
        let chunks = if heard.is_empty() {
            // Sleep in the read until the next thing due (or a character).
            let at = now(epoch);
            let idle = serving.idle_read_us.max(READ_US);
            let wait_us = session.poll_timeout(at).map_or(idle, |d| d.saturating_sub(at).clamp(READ_US, idle));
            match watch(port.as_mut(), epoch, &mut watched, &mut buf, wait_us)? {
                Some(chunk) => vec![chunk],
                None => return Ok(()),
            }
        } else {
            std::mem::take(&mut heard)
        };
        let line_bps = line_rate(port.as_ref(), serving);
        for Chunk { bytes, at_us, unwatched_us } in chunks {
            receiving.read(session, &bytes, at_us, unwatched_us, line_bps);
        }
        receiving.turn(session);
        session.handle_timeout(now(epoch));
        while let Some(p) = session.poll_transmit() {
            if line_rate(port.as_ref(), serving).is_some_and(|bps| bps != p.settings.baud.bits_per_second()) {
                continue; // sent at a rate the line is not at: nobody hears it
            }
            let timeout = p.settings.timeout_us(session.slave().profile().edition);
            // Each run of characters written whole when its first character would be
            // complete; the line is busy until the last is out. A harness that writes
            // late (a busy machine) shifts the rest of the reply: what `sent` is told
            // is when the reply really went out.
            let mut sending = Sending::new(p, timeout);
            let end_us = loop {
                match sending.poll() {
                    Next::Write { due_us, run } => {
                        watch_until(port.as_mut(), epoch, due_us, &mut watched, &mut buf, &mut heard)?;
                        let began = now(epoch);
                        session.hooks_mut().writing(began.saturating_sub(due_us));
                        port.write_all(sending.frame().get(run).unwrap_or_default())?;
                        port.flush()?;
                        sending.written(began, now(epoch));
                    }
                    Next::Wait { until_us } => {
                        watch_until(port.as_mut(), epoch, until_us, &mut watched, &mut buf, &mut heard)?
                    }
                    Next::Done { end_us } => break end_us,
                }
            };
            let p = sending.into_sent();
            session.on_sent(&p, end_us);
            receiving.sent(session, &p.frame, end_us);
        }
    }
    // Stopped: what was read while the last reply went out holds part of its echo.
    for Chunk { bytes, at_us, .. } in heard {
        receiving.stopped(session, &bytes, at_us);
    }
    Ok(())
}

/// The line's data rate, where the other end sets it (RFC 2217 through ser2net, see
/// [`Serving::follows_line_settings`]); `None` where the port's own settings are not
/// the line's. Read when it is needed: the other end may change it at any time.
fn line_rate(port: &dyn SerialPort, serving: Serving) -> Option<u32> {
    serving.follows_line_settings.then(|| port.baud_rate().ok()).flatten()
}

/// The characters one read returned.
struct Chunk {
    bytes: Vec<u8>,
    /// When the read returned, µs.
    at_us: u64,
    /// How long the line had not been read before it, µs (0 when it was watched).
    unwatched_us: u64,
}

/// How punctually the line was read.
struct Watched {
    /// When the last read returned: a read returns at least every timeout it is given.
    read_us: u64,
    /// The reading thread's wait for a processor (a read woken late on a busy machine).
    run_delay: crate::run_delay::RunDelay,
    /// The pseudo-terminal's own delivery, measured beside the line.
    delivery: Option<std::sync::Arc<crate::line::delivery::DeliveryProbe>>,
}

/// One read of the line, waiting at most `timeout_us`; `None` when the other end has
/// gone.
fn watch(
    port: &mut dyn SerialPort,
    epoch: Instant,
    watched: &mut Watched,
    buf: &mut [u8],
    timeout_us: u64,
) -> std::io::Result<Option<Chunk>> {
    port.set_timeout(Duration::from_micros(timeout_us)).map_err(std::io::Error::from)?;
    let result = port.read(buf);
    let at_us = epoch.elapsed().as_micros() as u64;
    let since = at_us.saturating_sub(watched.read_us);
    // Unwatched: a read that returned well after its timeout, or one whose thread
    // waited for a processor (what came may have waited as long).
    let waited = watched.run_delay.take_us().unwrap_or(0);
    let overdue = if since >= timeout_us + UNWATCHED_US { since } else { 0 };
    // What the kernel held back before this read (a pseudo-terminal's work queue on a
    // busy machine) came that much earlier too.
    let delivered_late = watched.delivery.as_ref().map_or(0, |p| p.recent_delay_us(Instant::now()));
    let unwatched_us =
        [overdue, waited, delivered_late].into_iter().filter(|us| *us >= UNWATCHED_US).max().unwrap_or(0);
    watched.read_us = at_us;
    let n = match result {
        Ok(0) => return Ok(None),
        Ok(n) => n,
        Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => 0,
        Err(e) if e.raw_os_error() == Some(5) => return Ok(None), // EIO: the other end closed
        Err(e) => return Err(e),
    };
    Ok(Some(Chunk { bytes: buf.iter().take(n).copied().collect(), at_us, unwatched_us }))
}

/// Keep reading the line until `due_us` (while a reply goes out): what the master sends
/// meanwhile is kept in `heard`, so that it is timed as it came.
fn watch_until(
    port: &mut dyn SerialPort,
    epoch: Instant,
    due_us: u64,
    watched: &mut Watched,
    buf: &mut [u8],
    heard: &mut Vec<Chunk>,
) -> std::io::Result<()> {
    let due = epoch + Duration::from_micros(due_us);
    loop {
        let Some(left) = due.checked_duration_since(Instant::now()) else { return Ok(()) };
        if left < Duration::from_micros(600) {
            // Less than a read's timeout: sleep it out, to write on time.
            std::thread::sleep(left);
            return Ok(());
        }
        if let Some(chunk) = watch(port, epoch, watched, buf, READ_US)?.filter(|c| !c.bytes.is_empty()) {
            heard.push(chunk);
        }
    }
}
