//! The harness's own scheduling on a shared machine: asking to be punctual (a
//! real-time priority, the kernel's delivering workers raised, the processors kept
//! awake). How punctual it was is measured in [`crate::run_delay`].

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
pub(crate) fn unbound_workers() -> Vec<crate::procfs::Stat> {
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
    _held: std::fs::File,
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

#[cfg(test)]
mod tests {
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
