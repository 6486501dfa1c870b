//! How punctual the harness and what runs beside it were on a shared machine.
//!
//! A thread that waits for a processor notices whatever happened meanwhile late: a
//! character that arrived while it waited is stamped when it finally runs. Linux
//! counts that wait for every thread (its *run delay*, delay accounting in
//! `/proc/thread-self/schedstat`), which makes the harness's lateness a measurement
//! instead of a guess: a read that returned a character after the reader waited 11 ms
//! for a processor may have got it 11 ms after it came. On a pseudo-terminal with
//! three busy loops on two cores, what a reader's stamps lost (up to 6 ms) was its own
//! run delay to within 0.2 ms (docs/src/design.md, "The harness's own lateness").

use std::fs::File;
use std::os::unix::fs::FileExt;

/// The run delay of one thread: how long it has been runnable but not running.
/// Open it on the thread it measures (each thread has its own).
#[derive(Debug)]
pub struct RunDelay {
    file: Option<File>,
    /// The thread it measures (a `RunDelay` moved to another thread reopens).
    thread: i32,
    last_us: Option<u64>,
}

/// A copy measures the thread it is used on, from zero.
impl Clone for RunDelay {
    fn clone(&self) -> RunDelay {
        RunDelay::of_this_thread()
    }
}

impl RunDelay {
    /// The calling thread's run delay; `available()` says whether the kernel counts it.
    pub fn of_this_thread() -> RunDelay {
        let mut r = RunDelay { file: None, thread: 0, last_us: None };
        r.reopen();
        r
    }

    fn reopen(&mut self) {
        self.thread = nix::unistd::gettid().as_raw();
        self.file = File::open("/proc/thread-self/schedstat").ok();
        self.last_us = None;
        // A kernel booted without delay accounting shows zeros: not a measurement.
        if self.total_us().is_none() {
            self.file = None;
        }
    }

    /// Whether this kernel counts run delays (Linux with delay accounting).
    pub fn available(&self) -> bool {
        self.file.is_some()
    }

    /// The thread's run delay since it started, µs; `None` where it is not counted.
    fn total_us(&mut self) -> Option<u64> {
        if self.thread != nix::unistd::gettid().as_raw() {
            self.reopen();
        }
        let mut buf = [0u8; 96];
        let n = self.file.as_ref()?.read_at(&mut buf, 0).ok()?;
        parse_schedstat(buf.get(..n)?)
    }

    /// The run delay since the last call (since opening, the first time), µs; `None`
    /// where it is not counted.
    pub fn take_us(&mut self) -> Option<u64> {
        let total = self.total_us()?;
        let since = self.last_us.map_or(0, |last| total.saturating_sub(last));
        self.last_us = Some(total);
        Some(since)
    }
}

/// How long the kernel's unbound workers (`kworker/u*`) have waited for a processor
/// during a run, µs: what the harness writes to a pseudo-terminal reaches the program
/// at the other end only when one of them runs, and one that waits holds the
/// characters back. The harness's own delivery probe (`line::delivery`) sees such a
/// wait only where its writes went to the same worker: traced on this machine (three
/// busy loops, a master image under QEMU), a reply's last characters reached the
/// master 7.3 ms late, held by a worker queued on a processor the hypervisor had
/// paused, while the probe's worker on the other processor ran at once.
///
/// Counted per reading: the longest wait any one worker added since the reading
/// before. Over a span, the sum of those bounds what any one worker held back in it
/// (one worker's wait over the span is the sum of its waits between readings), and
/// unlike the sum over all workers it does not add up the waits of workers that
/// delivered nothing of the line's.
#[derive(Debug, Default)]
pub struct KernelWorkersWait {
    /// Each worker seen and its run delay when last read, µs (`None`: a worker of the
    /// first reading, its baseline not read yet).
    workers: Vec<(u32, Option<u64>)>,
    /// The waits counted since the first reading (per reading, the longest), µs.
    total_us: u64,
    /// When the workers were last listed (the kernel starts and ends them as it needs);
    /// `None` before the first reading, which is the baseline: waits before the run
    /// are not the run's.
    listed: Option<std::time::Instant>,
}

/// How often the workers are listed again (reading each one's wait is cheap, listing
/// every process is not).
const WORKERS_LISTED_EVERY: std::time::Duration = std::time::Duration::from_millis(50);

impl KernelWorkersWait {
    /// The workers' waits since the first call, µs; `None` where the kernel does not
    /// count them (no delay accounting, no worker readable).
    pub fn total_us(&mut self) -> Option<u64> {
        let now = std::time::Instant::now();
        let first = self.listed.is_none();
        if self.listed.is_none_or(|t| now.duration_since(t) >= WORKERS_LISTED_EVERY) {
            self.listed = Some(now);
            for pid in crate::sched::unbound_workers().into_iter().map(|w| w.pid) {
                if !self.workers.iter().any(|(p, _)| *p == pid) {
                    // A worker started during the run: all its wait is the run's.
                    self.workers.push((pid, if first { None } else { Some(0) }));
                }
            }
        }
        let (mut read_any, mut longest) = (false, 0);
        self.workers.retain_mut(|(pid, last)| {
            let Some(us) = std::fs::read(format!("/proc/{pid}/schedstat")).ok().and_then(|t| parse_schedstat(&t))
            else {
                return false; // ended
            };
            read_any = true;
            if let Some(last) = last {
                longest = longest.max(us.saturating_sub(*last));
            }
            *last = Some(us);
            true
        });
        self.total_us += longest;
        read_any.then_some(self.total_us)
    }
}

/// How long the threads of process `pid` have waited for a processor since each
/// started, µs (the sum of `/proc/<pid>/task/*/schedstat`): a master under test
/// started as a process (`certify master --exec`) runs on the harness's machine, and
/// on a busy one its timing is partly the machine's. `None` where it is not counted
/// (no such process, no delay accounting). Threads that ended are not counted.
pub fn process_run_delay_us(pid: u32) -> Option<u64> {
    let tasks = std::fs::read_dir(format!("/proc/{pid}/task")).ok()?;
    let mut total = None;
    for task in tasks.flatten() {
        let Ok(text) = std::fs::read(task.path().join("schedstat")) else { continue };
        if let Some(us) = parse_schedstat(&text) {
            total = Some(total.unwrap_or(0) + us);
        }
    }
    total
}

/// `/proc/<pid>/schedstat`: time on a processor, time waiting for one (ns), and the
/// number of time slices. The wait in µs, or `None` for all zeros (no accounting) or
/// text that is not three numbers.
fn parse_schedstat(text: &[u8]) -> Option<u64> {
    let text = std::str::from_utf8(text).ok()?;
    let mut fields = text.split_ascii_whitespace().map(|f| f.parse::<u64>().ok());
    let (ran, waited, slices) = (fields.next()??, fields.next()??, fields.next()??);
    (ran != 0 || waited != 0 || slices != 0).then_some(waited / 1000)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wait_is_the_second_field() {
        assert_eq!(parse_schedstat(b"289285 7000500 12\n"), Some(7000));
        assert_eq!(parse_schedstat(b"0 0 0\n"), None);
        assert_eq!(parse_schedstat(b"12 x 3\n"), None);
        assert_eq!(parse_schedstat(b"12 3"), None);
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn a_process_run_delay_is_read_for_a_live_process_only() {
        if !RunDelay::of_this_thread().available() {
            return;
        }
        assert!(process_run_delay_us(std::process::id()).is_some_and(|us| us < 60_000_000));
        assert_eq!(process_run_delay_us(u32::MAX), None);
    }

    /// On this Linux machine the kernel counts run delays, and a thread that never
    /// gives up its processor still reads a plausible, non-decreasing figure.
    #[test]
    #[cfg(target_os = "linux")]
    fn a_threads_run_delay_is_read_and_grows() {
        let mut r = RunDelay::of_this_thread();
        if !r.available() {
            eprintln!("this kernel does not count run delays (no delay accounting)");
            return;
        }
        assert_eq!(r.take_us(), Some(0));
        let later = r.take_us();
        assert!(later.is_some_and(|us| us < 60_000_000), "{later:?}");
        // Moved to another thread, it measures that thread.
        let here = r.thread;
        let there = std::thread::spawn(move || {
            let first = r.take_us();
            (r.thread, first)
        });
        let (there, first) = there.join().unwrap();
        assert_ne!(there, here);
        assert_eq!(first, Some(0), "a reopened measure starts from zero");
    }

    /// The kernel's workers' wait is read from the first call on, and only grows.
    #[test]
    #[cfg(target_os = "linux")]
    fn the_kernels_workers_wait_is_counted_from_the_first_reading() {
        let mut k = KernelWorkersWait::default();
        let Some(first) = k.total_us() else {
            eprintln!("no worker's wait readable here (no delay accounting, or no unbound worker)");
            return;
        };
        assert_eq!(first, 0, "waits before the run are not the run's");
        let mut last = first;
        for _ in 0..20 {
            std::thread::sleep(std::time::Duration::from_millis(5));
            let now = k.total_us().unwrap_or(last);
            assert!(now >= last && now < 60_000_000, "{last} then {now}");
            last = now;
        }
    }
}
