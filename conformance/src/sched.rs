//! The harness's own scheduling on a shared machine: asking to be punctual, and
//! knowing how punctual it was.
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

/// Ask for a real-time scheduling priority for the calling thread (SCHED_FIFO), so
/// that replies are paced on time on a busy machine. Where it is not permitted (no
/// privilege, a container's limits) the thread stays as it was, and timing is still
/// checked: correctness never depends on it. Returns whether it was granted.
pub fn real_time_priority() -> bool {
    real_time_priority_at(50)
}

/// As [`real_time_priority`], at SCHED_FIFO `priority` (1 to 99).
pub fn real_time_priority_at(priority: u8) -> bool {
    use thread_priority::unix::{
        set_thread_priority_and_policy, thread_native_id, RealtimeThreadSchedulePolicy, ThreadSchedulePolicy,
    };
    use thread_priority::ThreadPriority;
    let Ok(value) = priority.try_into() else { return false };
    let policy = ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo);
    set_thread_priority_and_policy(thread_native_id(), ThreadPriority::Crossplatform(value), policy).is_ok()
}

/// What is written to a pseudo-terminal reaches the other end through the kernel's
/// unbound workers (`kworker/u*`), which run at nice 0 and wait for a processor behind
/// every busy process: a reader at a real-time priority still gets its characters late.
/// At nice -20 they still wait behind every real-time thread, the harness's own and an
/// emulator's under test among them, which then wait for what the worker delivers. For
/// a run, where permitted, they run at a real-time priority just above the harness's
/// ([`RAISED_PRIORITY`]), else at nice -20, and are put back as they were afterwards
/// (the guard's drop). Workers the kernel starts during the run are raised by
/// [`KernelDelivery::refresh`].
pub struct KernelDelivery {
    /// Each raised worker as it was, and how it was raised.
    raised: Vec<(crate::procfs::Stat, Raised)>,
}

/// How a worker was raised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Raised {
    /// SCHED_FIFO at [`RAISED_PRIORITY`].
    RealTime,
    /// Nice [`RAISED_NICE`] (a real-time priority was not permitted).
    Nice,
}

/// The nice the workers are raised to where a real-time priority is not permitted.
const RAISED_NICE: i32 = -20;

/// The real-time priority the workers are raised to: above the harness's own threads
/// (50, [`real_time_priority`]) and an emulator the firmware script runs at 50, so
/// that a worker delivering to one of them is never behind it. Measured with the
/// master image under QEMU and three busy loops (2026-11-29, ten runs raised):
/// probe writes more than 1 ms late 14 to 123 per run, the latest 8 to 28 ms, against
/// 214 to 531 and 25 to 40 ms at nice -20.
const RAISED_PRIORITY: u32 = 51;

/// SCHED_FIFO and SCHED_RR in `/proc/PID/stat`'s policy field.
const FIFO: u32 = 1;
const RR: u32 = 2;

impl KernelDelivery {
    /// Raise the workers there are now; `None` where not permitted (no worker raised).
    pub fn raise() -> Option<KernelDelivery> {
        let mut k = KernelDelivery { raised: Vec::new() };
        k.refresh();
        (!k.raised.is_empty()).then_some(k)
    }

    /// Raise the workers not raised yet (the kernel starts and ends them as it needs).
    pub fn refresh(&mut self) {
        for w in unbound_workers() {
            if self.raised.iter().any(|(r, _)| r.pid == w.pid) {
                continue;
            }
            if matches!(w.policy, FIFO | RR) && w.rt_priority >= RAISED_PRIORITY {
                continue; // as high already (by someone else): not ours to put back
            }
            let priority = RAISED_PRIORITY.to_string();
            if chrt(&["--fifo", "-p", &priority], w.pid) {
                self.raised.push((w, Raised::RealTime));
            } else if renice(RAISED_NICE, [w.pid].into_iter()) {
                self.raised.push((w, Raised::Nice));
            }
        }
    }

    /// What a report says of it (the run's notes).
    pub fn note(&self) -> String {
        let how = if self.raised.iter().all(|(_, how)| *how == Raised::RealTime) {
            format!("at a real-time priority (SCHED_FIFO {RAISED_PRIORITY}, above the harness's own)")
        } else {
            format!("at a real-time priority or, where not permitted, at nice {RAISED_NICE}")
        };
        format!(
            "The kernel's unbound workers, which deliver what is written to a pseudo-terminal, ran {how} for the run \
             ({} threads), so that a busy machine does not hold the line's characters back; put back as they were \
             afterwards.",
            self.raised.len()
        )
    }
}

impl Drop for KernelDelivery {
    fn drop(&mut self) {
        for (w, how) in &self.raised {
            match how {
                // The policy and priority back; the nice was never changed.
                Raised::RealTime => {
                    let priority = w.rt_priority.to_string();
                    let (policy, priority) = match w.policy {
                        FIFO => ("--fifo", priority.as_str()),
                        RR => ("--rr", priority.as_str()),
                        _ => ("--other", "0"),
                    };
                    chrt(&[policy, "-p", priority], w.pid);
                }
                Raised::Nice => {
                    renice(w.nice, [w.pid].into_iter());
                }
            }
        }
    }
}

/// The kernel's unbound workers as the process table gives them.
fn unbound_workers() -> Vec<crate::procfs::Stat> {
    crate::procfs::processes().into_iter().filter(|p| p.comm.starts_with("kworker/u")).collect()
}

/// Set the scheduling of `pid` with the `chrt` utility (no `unsafe` priority call
/// here); whether it was permitted.
fn chrt(args: &[&str], pid: u32) -> bool {
    std::process::Command::new("chrt")
        .args(args)
        .arg(pid.to_string())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Set the nice of `pids` with the `renice` utility (no `unsafe` priority call here);
/// whether it was permitted.
fn renice(nice: i32, pids: impl Iterator<Item = u32>) -> bool {
    let pids: Vec<String> = pids.map(|p| p.to_string()).collect();
    std::process::Command::new("renice")
        .args(["-n", &nice.to_string(), "-p"])
        .args(&pids)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The processors kept out of their idle sleep for a run: `/dev/cpu_dma_latency` held
/// at 0 µs (the kernel's PM QoS request, as `cyclictest` makes it), released when the
/// guard goes (the file closed, by the kernel too if the harness is killed). An idle
/// virtual processor otherwise halts, and whatever wakes it waits for the host to run
/// it again (steal). Measured 2026-11-29, the reference master idle, runs in turn:
/// held, steal 0.1-0.3 % and wall over the scenarios' 1.00-1.08; not, 0.3-10.7 % and
/// 1.04-1.70 (design notes, "Keeping the processors awake"). Idle processors spin.
pub struct KeepAwake {
    _held: File,
}

impl KeepAwake {
    /// Hold the processors awake; why not where it cannot (no such file, not permitted).
    pub fn hold() -> Result<KeepAwake, String> {
        use std::io::Write as _;
        let mut held = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/cpu_dma_latency")
            .map_err(|e| format!("/dev/cpu_dma_latency: {e}"))?;
        // The request is a 32-bit count of µs in the machine's byte order.
        held.write_all(&0i32.to_ne_bytes()).map_err(|e| format!("/dev/cpu_dma_latency: {e}"))?;
        Ok(KeepAwake { _held: held })
    }

    /// What a report says of it (the run's notes), held or not.
    pub fn note(held: &Result<KeepAwake, String>) -> String {
        match held {
            Ok(_) => "The processors were kept out of their idle sleep for the run (/dev/cpu_dma_latency held at 0 \
                      µs, released at its end): an idle virtual processor's wake-up goes through the hypervisor, \
                      which made the harness late."
                .to_string(),
            Err(e) => format!(
                "The processors could not be kept out of their idle sleep ({e}): on an idle virtual machine the \
                 harness may be late more often, and run more scenarios or cases again."
            ),
        }
    }
}

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
            for pid in unbound_workers().into_iter().map(|w| w.pid) {
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

    /// The kernel's workers are raised for a run and put back as they were (where the
    /// harness may: as root; elsewhere nothing changes and `raise` says so).
    #[test]
    #[cfg(target_os = "linux")]
    fn the_kernels_workers_are_raised_and_put_back() {
        // The command shows the work a worker does now: a worker is its pid.
        let schedule = |w: &crate::procfs::Stat| (w.pid, w.nice, w.policy, w.rt_priority);
        let before: Vec<_> = super::unbound_workers().iter().map(schedule).collect();
        let Some(k) = super::KernelDelivery::raise() else {
            let now: Vec<_> = super::unbound_workers().iter().map(schedule).collect();
            assert!(now.iter().all(|w| before.contains(w) || !before.iter().any(|b| b.0 == w.0)), "nothing changed");
            return;
        };
        let raised = k.raised.clone();
        let now = super::unbound_workers();
        for (was, how) in &raised {
            if let Some(w) = now.iter().find(|w| w.pid == was.pid) {
                match how {
                    super::Raised::RealTime => {
                        assert_eq!((w.policy, w.rt_priority), (super::FIFO, super::RAISED_PRIORITY), "{}", w.pid)
                    }
                    super::Raised::Nice => assert_eq!(w.nice, super::RAISED_NICE, "worker {}", w.pid),
                }
            }
        }
        drop(k);
        let after = super::unbound_workers();
        for (was, _) in &raised {
            if let Some(w) = after.iter().find(|w| w.pid == was.pid) {
                assert_eq!(schedule(w), schedule(was), "worker {} put back", w.pid);
            }
        }
    }
}
