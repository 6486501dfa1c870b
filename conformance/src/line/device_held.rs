//! How long a device that runs on the harness's own machine was held during an
//! exchange: a program or an emulator at a pseudo-terminal's other end.
//!
//! Such a device takes a request one character at a time as it runs (an emulated UART
//! hands the firmware one character, then the next when it is read). Held between two
//! of them for a timeout, by a wait for a processor or by the hypervisor pausing the
//! machine, it hears the request in two parts (000:2.2.2) and answers the first as a
//! damaged frame. Seen in CI: the Rust encoder image under QEMU answered a valid Set
//! Serial Interface with 0Ah (checksum error) with the hypervisor taking 4.1 % of the
//! processors over the run. A device with a processor of its own is never held so.
//!
//! Measured from each request's write to when the device had heard it (its characters
//! and the timeout after them: a thread of its own takes that reading), and to the
//! exchange's end: the run delay of the processes that hold the pseudo-terminal's
//! other end (found by the `tty-index` of their `/dev/ptmx` descriptors), and the
//! longest pause of any processor as the sentinels time it (`line::host_pauses`), or
//! where they may not run the machine's steal (`/proc/stat`, in 10 ms steps). Both
//! spans are upper bounds of what held the device; the grade uses the first only to
//! leave untold an answer a split request explains, the second a reply late by less
//! than it (`slave::ctx`, `verdict::timing`), and the case is run again. The first
//! span is kept short on purpose: over a silent exchange's whole wait (100 ms and
//! more) a 10 ms step of steal is nearly certain (seen: every silent exchange of a
//! crashed image taken for a split).

use hiperface_suite::line::delivery::{DeviceHeld, Hold, STEAL_STEP_US};
use std::sync::{mpsc, Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// The processes at a pseudo-terminal's other end, and the readings of the exchange
/// under way.
#[derive(Debug)]
pub struct DeviceProcesses {
    pids: Arc<Vec<u32>>,
    /// The request written last and not measured yet.
    marked: Option<Marked>,
    /// How many requests were written (each one's number for the thread's reading).
    written: u64,
    /// The thread that takes the reading once the device has heard the request.
    heard: mpsc::Sender<(u64, Instant)>,
    /// Its last reading, and the write it is of.
    slot: Arc<Slot>,
    /// The processors' pauses, where a sentinel watches them; else the steal counts.
    pauses: Option<super::host_pauses::HostPauses>,
}

/// A request as written: its number, the reading then, when it was written and when
/// the device had heard it.
#[derive(Debug, Clone, Copy)]
struct Marked {
    write: u64,
    reading: Reading,
    at: Instant,
    heard_at: Instant,
}

/// The thread's last reading and the number of the write it is of, and its signal.
type Slot = (Mutex<Option<(u64, Reading)>>, Condvar);

/// The processes' run delay (summed over their threads) and the machine's steal, µs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Reading {
    waited_us: u64,
    steal_us: u64,
}

impl Reading {
    /// Now; the steal only `with_steal` (where no sentinel times the pauses: then
    /// `/proc/stat`, which the kernel writes out whole, is not read for nothing).
    fn of(pids: &[u32], with_steal: bool) -> Reading {
        let steal = || crate::procfs::CpuTimes::now().map_or(0, |t| t.steal * STEAL_STEP_US);
        Reading {
            waited_us: pids.iter().filter_map(|p| crate::run_delay::process_run_delay_us(*p)).sum(),
            steal_us: if with_steal { steal() } else { 0 },
        }
    }

    /// What held the device from `self` to `later`.
    fn to(self, later: Reading) -> Hold {
        Hold {
            waited_us: later.waited_us.saturating_sub(self.waited_us),
            paused_us: 0,
            steal_us: later.steal_us.saturating_sub(self.steal_us),
        }
    }

    /// The earlier of two readings, counter by counter (both only grow).
    fn earlier(self, other: Reading) -> Reading {
        Reading { waited_us: self.waited_us.min(other.waited_us), steal_us: self.steal_us.min(other.steal_us) }
    }
}

/// How long [`DeviceProcesses::held`] waits for the reading of the request's end.
const HEARD_READING_WAIT: Duration = Duration::from_millis(100);

impl DeviceProcesses {
    /// The processes other than this one that hold the other end of the pseudo-terminal
    /// `path` (`/dev/pts/N`, or a link to it); `None` where there are none, or they are
    /// not readable (another user's, no `/proc`): then nothing is measured.
    pub fn of_pseudo_terminal(path: &str) -> Option<DeviceProcesses> {
        let real = std::fs::canonicalize(path).ok()?;
        let index: u32 = real.strip_prefix("/dev/pts").ok()?.to_str()?.parse().ok()?;
        let pids = Arc::new(holders(index));
        if pids.is_empty() {
            return None;
        }
        let pauses = super::host_pauses::HostPauses::start();
        let with_steal = pauses.is_none();
        let (heard, deadlines) = mpsc::channel::<(u64, Instant)>();
        let slot: Arc<Slot> = Arc::new((Mutex::new(None), Condvar::new()));
        {
            let (pids, slot) = (pids.clone(), slot.clone());
            // Ends when the line is dropped (the channel closes).
            std::thread::Builder::new()
                .name("device-held".into())
                .spawn(move || {
                    // Punctual where permitted: a late reading only widens the span.
                    crate::sched::real_time_priority();
                    while let Ok((write, at)) = deadlines.recv() {
                        std::thread::sleep(at.saturating_duration_since(Instant::now()));
                        let reading = Reading::of(&pids, with_steal);
                        let (lock, ready) = &*slot;
                        if let Ok(mut s) = lock.lock() {
                            *s = Some((write, reading));
                        }
                        ready.notify_all();
                    }
                })
                .ok()?;
        }
        Some(DeviceProcesses { pids, marked: None, written: 0, heard, slot, pauses })
    }

    /// The processes found.
    pub fn pids(&self) -> &[u32] {
        &self.pids
    }

    /// Note the readings as a request is written, and have them read again when the
    /// device has heard it: `heard_in` from now (its characters and its timeout).
    pub fn mark(&mut self, heard_in: Duration) {
        self.written += 1;
        let reading = Reading::of(&self.pids, self.pauses.is_none());
        let at = Instant::now();
        let marked = Marked { write: self.written, reading, at, heard_at: at + heard_in };
        self.marked = Some(marked);
        let _ = self.heard.send((marked.write, marked.heard_at));
    }

    /// What held the device since [`DeviceProcesses::mark`]: until it had heard the
    /// request, and until now. Zero where it was not marked.
    pub fn held(&mut self) -> DeviceHeld {
        let Some(m) = self.marked.take() else { return DeviceHeld::default() };
        let now = Reading::of(&self.pids, self.pauses.is_none());
        // The reading when the device had heard the request; where it is not there in
        // time (the thread held up), now's, which only widens the span.
        let heard = self.heard_reading(m.write).map_or(now, |r| r.earlier(now));
        let (mut request, mut exchange) = (m.reading.to(heard), m.reading.to(now));
        // Where the sentinels watch the processors, their pauses in each span, to the
        // microsecond, instead of the steal's 10 ms steps.
        if let Some(p) = &self.pauses {
            let end = Instant::now();
            let us = |d: Duration| u64::try_from(d.as_micros()).unwrap_or(u64::MAX);
            request.paused_us = us(p.longest_within(m.at, m.heard_at.min(end)));
            exchange.paused_us = us(p.longest_within(m.at, end));
        }
        DeviceHeld { request, exchange }
    }

    /// How many processors the sentinels watch; `None` where they do not run.
    pub fn processors_watched(&self) -> Option<usize> {
        self.pauses.as_ref().map(|p| p.processors)
    }

    fn heard_reading(&self, write: u64) -> Option<Reading> {
        let (lock, ready) = &*self.slot;
        let guard = lock.lock().ok()?;
        let (guard, _) =
            ready.wait_timeout_while(guard, HEARD_READING_WAIT, |s| s.is_none_or(|(w, _)| w < write)).ok()?;
        guard.filter(|(w, _)| *w == write).map(|(_, r)| r)
    }
}

/// The processes other than this one with a descriptor of `/dev/ptmx` whose
/// pseudo-terminal is `/dev/pts/<index>` (`tty-index` in its fdinfo, Linux 4.14 on).
fn holders(index: u32) -> Vec<u32> {
    let own = std::process::id();
    crate::procfs::pids().filter(|pid| *pid != own && holds(*pid, index)).collect()
}

fn holds(pid: u32, index: u32) -> bool {
    let Ok(fds) = std::fs::read_dir(format!("/proc/{pid}/fd")) else { return false };
    fds.flatten().any(|fd| {
        let is_ptmx = std::fs::read_link(fd.path()).is_ok_and(|t| t.ends_with("ptmx"));
        is_ptmx
            && std::fs::read_to_string(format!("/proc/{pid}/fdinfo/{}", fd.file_name().to_string_lossy()))
                .is_ok_and(|info| tty_index(&info) == Some(index))
    })
}

/// The `tty-index:` line of a descriptor's fdinfo.
fn tty_index(fdinfo: &str) -> Option<u32> {
    fdinfo.lines().find_map(|l| l.strip_prefix("tty-index:")).and_then(|v| v.trim().parse().ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_index_is_read_from_the_fdinfo() {
        let info = "pos:\t0\nflags:\t02100002\nmnt_id:\t24\nino:\t91\ntty-index:\t7\n";
        assert_eq!(tty_index(info), Some(7));
        assert_eq!(tty_index("pos:\t0\n"), None);
        assert_eq!(tty_index("tty-index:\tx\n"), None);
    }

    /// A program at the other end of a pseudo-terminal (Python's `pty.openpty`, which
    /// holds both ends) is found from the path it gives, and this process, which holds
    /// the other end of its own pairs, never is.
    #[test]
    #[cfg(target_os = "linux")]
    fn the_program_at_a_pseudo_terminals_other_end_is_found() {
        use serialport::SerialPort as _;
        use std::io::BufRead;
        let own = crate::line::pty_pair().expect("a pseudo-terminal pair");
        let own_path = own.1.name().expect("its name");
        assert!(DeviceProcesses::of_pseudo_terminal(&own_path).is_none(), "{own_path}");
        let script =
            "import os, pty, sys, time\nm, s = pty.openpty()\nprint(os.ttyname(s), flush=True)\ntime.sleep(30)\n";
        let Ok(mut child) =
            std::process::Command::new("python3").args(["-c", script]).stdout(std::process::Stdio::piped()).spawn()
        else {
            return; // no python3 here: conformance/build.rs requires it where every test runs
        };
        let mut path = String::new();
        let read = std::io::BufReader::new(child.stdout.take().expect("its output")).read_line(&mut path);
        let found = DeviceProcesses::of_pseudo_terminal(path.trim());
        let _ = child.kill();
        let _ = child.wait();
        read.expect("the child's pseudo-terminal");
        let mut found = found.expect("the child holds its other end");
        assert_eq!(found.pids(), &[child.id()]);
        // Unmarked, nothing is measured; marked, the reading of the request's end is
        // taken by the thread (never after the exchange's end).
        assert!(found.held().is_zero());
        found.mark(Duration::from_millis(5));
        std::thread::sleep(Duration::from_millis(20));
        assert!(found.heard_reading(found.written).is_some());
        let held = found.held();
        assert!(held.request.waited_us <= held.exchange.waited_us && held.request.steal_us <= held.exchange.steal_us);
        assert!(found.marked.is_none());
    }
}
