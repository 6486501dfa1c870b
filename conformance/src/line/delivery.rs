//! What a pseudo-terminal delays, measured beside the line.
//!
//! A pseudo-terminal has no wire: the kernel hands a write to the reader from a work
//! queue (a kernel worker at an ordinary priority). On a busy machine that worker waits
//! for a processor like any other thread, and a byte written on time reaches the
//! reader late, by more than the reader's own run delay: seen with three busy loops and
//! a build on two cores, a device's reply written 10 ms after its timeout was read
//! 38.7 ms later, while the harness had waited at most 2.5 ms for a processor. That
//! delay is the line's, not the device's, and the harness cannot see it on the line
//! itself.
//!
//! The probe is a second pseudo-terminal beside the line: a writer at the priority a
//! device's processor would have (a real-time priority where permitted) writes the time
//! every 2 ms; a reader at the harness's own priority notes how late each write
//! arrived. Around an exchange, the longest of those delays bounds how late the line
//! may have delivered what the device wrote, and how late the device may have received
//! the request: both are folded into the harness's own lateness (`Exchange::line_late`),
//! so that a reply the line may have delayed past its limit is UNKNOWN and its case is
//! run again, never a FAIL. A device late by more than the line could explain still
//! FAILs.

use hiperface_suite::line::delivery::{DeliveryStats, LineLate};

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How often the probe writes.
pub const PERIOD: Duration = Duration::from_millis(2);

/// How long samples are kept: longer than any exchange's window.
const KEEP_US: u64 = 5_000_000;

/// One write of the probe: when it was written and how late it was read, µs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    pub written_us: u64,
    pub delay_us: u64,
}

#[derive(Debug, Default)]
struct Shared {
    samples: VecDeque<Sample>,
    stats: DeliveryStats,
}

/// The probe: a pseudo-terminal pair with a writer and a reader thread, stopped on drop.
pub struct DeliveryProbe {
    epoch: Instant,
    shared: Arc<Mutex<Shared>>,
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
    /// The writer runs at a real-time priority.
    pub writer_real_time: bool,
}

impl DeliveryProbe {
    /// Start the probe; times are µs since `epoch` (the line's clock). Its reader runs
    /// at the priority of the thread that starts it, as the harness's own reader does.
    pub fn start(epoch: Instant) -> Result<DeliveryProbe, String> {
        DeliveryProbe::start_with(epoch, false)
    }

    /// As [`DeliveryProbe::start`]; with `reader_real_time` the reader asks for a
    /// real-time priority too, as the encoder that certifies masters reads at one.
    pub fn start_with(epoch: Instant, reader_real_time: bool) -> Result<DeliveryProbe, String> {
        let (writer_end, reader_end) =
            crate::line::pty_pair().map_err(|e| format!("cannot create the probe's pseudo-terminal pair: {e}"))?;
        let shared = Arc::new(Mutex::new(Shared::default()));
        let stop = Arc::new(AtomicBool::new(false));
        let (granted_tx, granted_rx) = std::sync::mpsc::channel();
        let writer = {
            let stop = stop.clone();
            let mut port = writer_end;
            std::thread::spawn(move || {
                let _ = granted_tx.send(crate::sched::real_time_priority());
                let mut next = Instant::now();
                while !stop.load(Ordering::Relaxed) {
                    next += PERIOD;
                    if let Some(d) = next.checked_duration_since(Instant::now()) {
                        std::thread::sleep(d);
                    } else {
                        next = Instant::now();
                    }
                    let written_us = epoch.elapsed().as_micros() as u64;
                    if port.write_all(&written_us.to_le_bytes()).is_err() {
                        return;
                    }
                }
            })
        };
        let reader = {
            let (stop, shared) = (stop.clone(), shared.clone());
            let mut port = reader_end;
            let _ = serialport::SerialPort::set_timeout(&mut port, Duration::from_millis(50));
            std::thread::spawn(move || {
                if reader_real_time {
                    crate::sched::real_time_priority();
                }
                let mut pending: Vec<u8> = Vec::with_capacity(64);
                let mut buf = [0u8; 256];
                while !stop.load(Ordering::Relaxed) {
                    let n = match port.read(&mut buf) {
                        Ok(0) => return,
                        Ok(n) => n,
                        Err(e)
                            if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted) =>
                        {
                            continue
                        }
                        Err(_) => return,
                    };
                    let read_us = epoch.elapsed().as_micros() as u64;
                    pending.extend_from_slice(buf.get(..n).unwrap_or(&[]));
                    let whole = pending.len() - pending.len() % 8;
                    let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
                    for word in pending.get(..whole).unwrap_or(&[]).chunks_exact(8) {
                        let mut w = [0u8; 8];
                        w.copy_from_slice(word);
                        let written_us = u64::from_le_bytes(w);
                        s.record(Sample { written_us, delay_us: read_us.saturating_sub(written_us) });
                    }
                    pending.drain(..whole);
                }
            })
        };
        let writer_real_time = granted_rx.recv_timeout(Duration::from_secs(1)).unwrap_or(false);
        Ok(DeliveryProbe { epoch, shared, stop, threads: vec![writer, reader], writer_real_time })
    }

    /// The epoch the probe's times count from.
    pub fn epoch(&self) -> Instant {
        self.epoch
    }

    /// The longest delay of a write made in `[from_us, to_us]`, µs; `None` where no
    /// write of that span has arrived yet (the probe itself is held up).
    pub fn max_delay_us(&self, from_us: u64, to_us: u64) -> Option<u64> {
        let s = self.shared.lock().unwrap_or_else(|e| e.into_inner());
        s.max_delay_us(from_us, to_us)
    }

    /// Wait until the probe has heard every write made up to `t_us` (at most `limit`):
    /// a write still on its way is the longest delay of all.
    pub fn settle(&self, t_us: u64, limit: Duration) -> Option<u64> {
        let until = Instant::now() + limit;
        loop {
            let newest = self.shared.lock().unwrap_or_else(|e| e.into_inner()).newest_written_us();
            if newest.is_some_and(|w| w + PERIOD.as_micros() as u64 >= t_us) || Instant::now() >= until {
                return newest;
            }
            std::thread::sleep(Duration::from_micros(500));
        }
    }

    /// How late the line may have delivered both ways in an exchange from `from_us`
    /// to `to_us`, µs: the request to the device (the probe's writes around when it was
    /// written) and the reply to the harness (its writes over the exchange). Writes
    /// still on their way at `now_us` (given a moment to arrive) count as late as they
    /// are old.
    pub fn late_both_ways(&self, from_us: u64, to_us: u64, now_us: u64) -> LineLate {
        let period = PERIOD.as_micros() as u64;
        let newest = self.settle(now_us, Duration::from_millis(20));
        let overdue = newest.map_or(0, |w| now_us.saturating_sub(w + 2 * period));
        let request = self.max_delay_us(from_us.saturating_sub(2 * period), from_us + 2 * period).unwrap_or(0);
        let reply = self.max_delay_us(from_us, to_us).unwrap_or(0);
        LineLate { request_us: request.max(overdue), reply_us: reply.max(overdue) }
    }

    /// How late what is read at `at` may have been delivered: the longest delay of the
    /// probe's writes delivered in the few milliseconds before (the kernel delivers in
    /// order: what reached the reader with them waited about as long), or the age of
    /// writes still on their way.
    pub fn recent_delay_us(&self, at: Instant) -> u64 {
        let at_us = at.saturating_duration_since(self.epoch).as_micros() as u64;
        let s = self.shared.lock().unwrap_or_else(|e| e.into_inner());
        let delivered = s.max_delay_read_us(at_us.saturating_sub(3 * PERIOD.as_micros() as u64), at_us);
        let overdue = s.newest_written_us().map_or(0, |w| at_us.saturating_sub(w + 2 * PERIOD.as_micros() as u64));
        delivered.max(overdue)
    }

    pub fn stats(&self) -> DeliveryStats {
        self.shared.lock().unwrap_or_else(|e| e.into_inner()).stats
    }
}

impl Shared {
    fn record(&mut self, sample: Sample) {
        self.stats.samples += 1;
        self.stats.max_us = self.stats.max_us.max(sample.delay_us);
        self.stats.over_1ms += u64::from(sample.delay_us > 1_000);
        self.samples.push_back(sample);
        while self.samples.front().is_some_and(|s| s.written_us + KEEP_US < sample.written_us) {
            self.samples.pop_front();
        }
    }

    fn newest_written_us(&self) -> Option<u64> {
        self.samples.back().map(|s| s.written_us)
    }

    /// The longest delay of a write read in `[from_us, to_us]`; 0 where none was.
    fn max_delay_read_us(&self, from_us: u64, to_us: u64) -> u64 {
        let read_in = |s: &&Sample| (from_us..=to_us).contains(&(s.written_us + s.delay_us));
        self.samples
            .iter()
            .rev()
            .take_while(|s| s.written_us + KEEP_US >= from_us)
            .filter(read_in)
            .map(|s| s.delay_us)
            .max()
            .unwrap_or(0)
    }

    fn max_delay_us(&self, from_us: u64, to_us: u64) -> Option<u64> {
        let in_span = self.samples.iter().filter(|s| s.written_us >= from_us && s.written_us <= to_us);
        in_span.map(|s| s.delay_us).max()
    }
}

impl Drop for DeliveryProbe {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_delay_of_a_span_is_that_of_its_writes() {
        let mut s = Shared::default();
        for (w, d) in [(1_000, 100), (2_000, 9_000), (3_000, 200), (10_000, 50)] {
            s.record(Sample { written_us: w, delay_us: d });
        }
        assert_eq!(s.max_delay_us(0, 1_500), Some(100));
        assert_eq!(s.max_delay_us(1_500, 3_000), Some(9_000));
        assert_eq!(s.max_delay_us(4_000, 9_000), None);
        assert_eq!((s.stats.samples, s.stats.max_us, s.stats.over_1ms), (4, 9_000, 1));
        // By when they were read: the 9 ms write arrived at 11 ms.
        assert_eq!(s.max_delay_read_us(10_500, 11_000), 9_000);
        assert_eq!(s.max_delay_read_us(3_000, 10_000), 200);
        assert_eq!(s.max_delay_read_us(10_001, 10_100), 50);
        assert_eq!(s.max_delay_read_us(11_001, 20_000), 0);
        // Old samples go.
        s.record(Sample { written_us: 10_000 + KEEP_US + 1, delay_us: 1 });
        assert_eq!(s.max_delay_us(0, 3_000), None);
    }

    /// Real time, generous: the probe hears its writes, and a few milliseconds late at
    /// most on a machine that is not overloaded.
    #[test]
    fn the_probe_hears_its_writes() {
        let epoch = Instant::now();
        let probe = DeliveryProbe::start(epoch).expect("a pseudo-terminal pair");
        std::thread::sleep(Duration::from_millis(100));
        let now = epoch.elapsed().as_micros() as u64;
        probe.settle(now, Duration::from_secs(2));
        let stats = probe.stats();
        assert!(stats.samples >= 20, "{stats:?}");
        assert!(probe.max_delay_us(0, now).is_some());
    }
}
