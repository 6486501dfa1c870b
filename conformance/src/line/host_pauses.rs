//! When this machine's processors stopped: a sentinel thread on each processor, at a
//! real-time priority above everything the harness and a device under test run at,
//! wakes every millisecond and notes each time it saw none pass for longer. What stops
//! it is what stops any thread on that processor: the hypervisor pausing the virtual
//! processor (steal), an interrupt storm, the kernel's own stop work.
//!
//! The kernel counts the hypervisor's steal only in 10 ms steps (`/proc/stat`), and a
//! pause of 5 ms splits a request at 9600 Bd: measured on this machine with the host
//! taking 7 to 9 % of the processors, the encoder images under QEMU answered a valid
//! Encoder Reset with 0Ch in an exchange whose steal count had not moved. The
//! sentinels see each pause to within their period, and time-stamp it, so a span is
//! asked about after the fact (`line::device_held`; a master's scenario run sums them).
//!
//! They run only where a real-time priority is permitted: at an ordinary one they
//! would see every busy thread's turn as a pause.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How often a sentinel wakes.
const PERIOD: Duration = Duration::from_millis(1);

/// A wake more than this after the one before is a pause (its period and a margin
/// for the timer's own lateness).
const PAUSE_OVER: Duration = Duration::from_micros(1_500);

/// The sentinels' priority: above the harness's threads and an emulator (50) and the
/// kernel's pseudo-terminal workers while raised (51, `sched::KernelDelivery`), so
/// that none of them is taken for a pause.
const PRIORITY: u8 = 70;

/// How long pauses are kept: longer than any exchange.
const KEEP: Duration = Duration::from_secs(10);

/// One pause a sentinel saw: from its last wake before to its wake after.
#[derive(Debug, Clone, Copy)]
struct Pause {
    from: Instant,
    to: Instant,
}

/// The sentinels, stopped on drop.
#[derive(Debug)]
pub struct HostPauses {
    pauses: Arc<Mutex<VecDeque<Pause>>>,
    stop: Arc<AtomicBool>,
    /// How many processors are watched.
    pub processors: usize,
}

impl HostPauses {
    /// A sentinel on each processor this process may run on; `None` where a real-time
    /// priority or the pinning to a processor is not permitted (nothing is watched).
    pub fn start() -> Option<HostPauses> {
        let cpus: Vec<usize> = {
            let allowed = nix::sched::sched_getaffinity(nix::unistd::Pid::from_raw(0)).ok()?;
            (0..nix::sched::CpuSet::count()).filter(|c| allowed.is_set(*c).unwrap_or(false)).collect()
        };
        let pauses = Arc::new(Mutex::new(VecDeque::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let (started, granted) = std::sync::mpsc::channel();
        for cpu in &cpus {
            let (cpu, pauses, stopped, started) = (*cpu, pauses.clone(), stop.clone(), started.clone());
            let spawned = std::thread::Builder::new().name(format!("host-pauses-{cpu}")).spawn(move || {
                let ok = pin_to(cpu) && crate::sched::real_time_priority_at(PRIORITY);
                let _ = started.send(ok);
                if ok {
                    watch(&pauses, &stopped);
                }
            });
            if spawned.is_err() {
                stop.store(true, Ordering::Relaxed);
                return None;
            }
        }
        let all = (0..cpus.len()).all(|_| granted.recv_timeout(Duration::from_secs(1)).unwrap_or(false));
        if !all {
            stop.store(true, Ordering::Relaxed);
            return None;
        }
        Some(HostPauses { pauses, stop, processors: cpus.len() })
    }

    /// The longest any processor stopped within `from`..`to` (the part of a pause inside
    /// the span).
    pub fn longest_within(&self, from: Instant, to: Instant) -> Duration {
        let Ok(pauses) = self.pauses.lock() else { return Duration::ZERO };
        pauses
            .iter()
            .filter(|p| p.to > from && p.from < to)
            .map(|p| p.to.min(to).saturating_duration_since(p.from.max(from)))
            .max()
            .unwrap_or(Duration::ZERO)
    }

    /// The longest pause that ended within `from`..=`to`, whole (from its start, also
    /// before `from`). Summed over consecutive spans it counts each pause once, in the
    /// span it ended in: a pause still going on at a span's end is not seen yet (its
    /// sentinel notes it as it wakes), and clipped to the span it would lose its part
    /// before the next one.
    pub fn longest_ending_within(&self, from: Instant, to: Instant) -> Duration {
        let Ok(pauses) = self.pauses.lock() else { return Duration::ZERO };
        pauses
            .iter()
            .filter(|p| p.to > from && p.to <= to)
            .map(|p| p.to.saturating_duration_since(p.from))
            .max()
            .unwrap_or(Duration::ZERO)
    }
}

impl Drop for HostPauses {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn watch(pauses: &Mutex<VecDeque<Pause>>, stop: &AtomicBool) {
    let mut last = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(PERIOD);
        let now = Instant::now();
        if now.duration_since(last) > PAUSE_OVER {
            if let Ok(mut p) = pauses.lock() {
                while p.front().is_some_and(|old| now.duration_since(old.to) > KEEP) {
                    p.pop_front();
                }
                p.push_back(Pause { from: last, to: now });
            }
        }
        last = now;
    }
}

/// Pin the calling thread to processor `cpu`.
fn pin_to(cpu: usize) -> bool {
    let mut set = nix::sched::CpuSet::new();
    set.set(cpu).is_ok() && nix::sched::sched_setaffinity(nix::unistd::Pid::from_raw(0), &set).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pause_counts_its_part_inside_a_span_or_whole_in_the_span_it_ended_in() {
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        let h = HostPauses {
            pauses: Arc::new(Mutex::new(VecDeque::from([
                Pause { from: at(10), to: at(16) },
                Pause { from: at(30), to: at(33) },
            ]))),
            stop: Arc::new(AtomicBool::new(true)),
            processors: 1,
        };
        assert_eq!(h.longest_within(at(0), at(40)), Duration::from_millis(6));
        assert_eq!(h.longest_within(at(13), at(40)), Duration::from_millis(3));
        assert_eq!(h.longest_within(at(12), at(14)), Duration::from_millis(2));
        assert_eq!(h.longest_within(at(16), at(30)), Duration::ZERO);
        // Whole, in the span it ended in: spans 0..12, 12..31, 31..40 count 0, 6 and 3
        // ms, where clipped they would count 2, 6 and 2 (a pause sampled in progress).
        let ending = |a, b| h.longest_ending_within(at(a), at(b));
        assert_eq!([ending(0, 12), ending(12, 31), ending(31, 40)], [0, 6, 3].map(Duration::from_millis));
        assert_eq!(ending(16, 33), Duration::from_millis(3), "the one that ended at the span's start is not its");
    }

    /// Where a real-time priority is permitted (root, as in CI), the sentinels start,
    /// one a processor, and a span they watched has a finite longest pause.
    #[test]
    #[cfg(target_os = "linux")]
    fn the_sentinels_watch_each_processor_where_permitted() {
        let Some(h) = HostPauses::start() else { return };
        assert!(h.processors >= 1);
        let from = Instant::now();
        std::thread::sleep(Duration::from_millis(50));
        assert!(h.longest_within(from, Instant::now()) < Duration::from_secs(1));
    }
}
