//! The kernel's process table as `/proc/PID/stat` gives it, read one way: for ending
//! what a master under test started (`process`) and for raising the kernel's workers
//! that deliver a pseudo-terminal's characters (`sched`). And the machine's processor
//! times (`/proc/stat`), for what its hypervisor took during a run.

/// The fields of one process's stat line the harness uses.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stat {
    pub pid: u32,
    /// The command, as the kernel names it (`kworker/u8:2-events_unbound`).
    pub comm: String,
    pub ppid: u32,
    pub pgrp: u32,
    pub nice: i32,
    /// The real-time priority (0 for an ordinary thread) and the scheduling policy
    /// (0 ordinary, 1 FIFO, 2 round-robin, …): the 40th and 41st fields, 0 where the
    /// line is shorter.
    pub rt_priority: u32,
    pub policy: u32,
}

/// One stat line of process `pid`. The command is in parentheses and may hold spaces
/// and parentheses itself: the fields after the last `)` are the state, ppid, pgrp,
/// and 14 more to the nice (the 17th).
pub fn parse(pid: u32, stat: &str) -> Option<Stat> {
    let (open, close) = (stat.find('(')?, stat.rfind(')')?);
    let fields: Vec<&str> = stat.get(close + 1..)?.split_ascii_whitespace().collect();
    Some(Stat {
        pid,
        comm: stat.get(open + 1..close)?.to_string(),
        ppid: fields.get(1)?.parse().ok()?,
        pgrp: fields.get(2)?.parse().ok()?,
        nice: fields.get(16)?.parse().ok()?,
        rt_priority: fields.get(37).and_then(|f| f.parse().ok()).unwrap_or(0),
        policy: fields.get(38).and_then(|f| f.parse().ok()).unwrap_or(0),
    })
}

/// Every process this harness can see.
pub fn processes() -> Vec<Stat> {
    pids().filter_map(|pid| parse(pid, &std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?)).collect()
}

/// The ids of the processes this harness can see (`/proc`'s numbered entries).
pub fn pids() -> impl Iterator<Item = u32> {
    std::fs::read_dir("/proc")
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| e.file_name().to_str().and_then(|n| n.parse::<u32>().ok()))
}

/// The machine's processor times, summed over its processors, in the kernel's clock
/// ticks: all of them, and those its hypervisor took (steal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CpuTimes {
    pub total: u64,
    pub steal: u64,
}

/// `/proc/stat` counts in USER_HZ, which the kernel fixes at 100 a second for what it
/// shows user space (proc(5)), whatever its own tick.
const TICKS_PER_S: u64 = 100;

impl CpuTimes {
    /// Now; `None` where `/proc/stat` does not say (not Linux, or a kernel without
    /// steal time).
    pub fn now() -> Option<CpuTimes> {
        parse_cpu_line(std::fs::read_to_string("/proc/stat").ok()?.lines().next()?)
    }

    /// What the hypervisor took from `earlier` to `self`.
    pub fn steal_since(&self, earlier: CpuTimes) -> hiperface_suite::report::Steal {
        let ms = |ticks: u64| ticks * 1000 / TICKS_PER_S;
        hiperface_suite::report::Steal {
            steal_ms: ms(self.steal.saturating_sub(earlier.steal)),
            processor_ms: ms(self.total.saturating_sub(earlier.total)),
        }
    }
}

/// The first line of `/proc/stat`: "cpu  user nice system idle iowait irq softirq steal
/// guest guest_nice". A guest's time is counted in user and nice already: the total is
/// the first eight.
fn parse_cpu_line(line: &str) -> Option<CpuTimes> {
    let mut fields = line.split_ascii_whitespace();
    if fields.next()? != "cpu" {
        return None;
    }
    let ticks: Vec<u64> = fields.take(8).map(str::parse).collect::<Result<_, _>>().ok()?;
    if ticks.len() != 8 {
        return None;
    }
    Some(CpuTimes { total: ticks.iter().sum(), steal: *ticks.get(7)? })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_processors_times_and_the_steal_are_read_from_the_first_line() {
        let a = parse_cpu_line("cpu  11616518 34228 909170 4523508 58269 0 7550 170076 0 0").unwrap();
        assert_eq!(a.steal, 170_076);
        assert_eq!(a.total, 11_616_518 + 34_228 + 909_170 + 4_523_508 + 58_269 + 7_550 + 170_076);
        let b = parse_cpu_line("cpu  11616536 34228 909416 4524077 58269 0 7551 170321 0 0").unwrap();
        // About five seconds on two processors (as sampled on this machine), near a
        // quarter of them taken.
        let s = b.steal_since(a);
        assert_eq!((s.steal_ms, s.processor_ms), (2_450, 10_790));
        assert!((s.percent() - 22.706).abs() < 0.001 && s.worth_saying());
        // A kernel without steal time, another line, a garbled figure: nothing said.
        assert_eq!(parse_cpu_line("cpu  1 2 3 4 5 6 7"), None);
        assert_eq!(parse_cpu_line("cpu0 1 2 3 4 5 6 7 8 0 0"), None);
        assert_eq!(parse_cpu_line("cpu  1 2 3 4 5 6 7 x 0 0"), None);
        // Counters that went back (a restored snapshot) give nothing, not a wrap.
        assert_eq!(a.steal_since(b).steal_ms, 0);
    }

    #[test]
    fn a_stat_line_is_read_past_a_command_with_parentheses() {
        let stat = "48 (kworker/u9:0-events (highpri)) I 2 0 0 0 -1 69238880 0 0 0 0 0 0 0 0 0 -20 1 0 30 0 0";
        let s = parse(48, stat).unwrap();
        assert_eq!((s.comm.as_str(), s.ppid, s.pgrp, s.nice), ("kworker/u9:0-events (highpri)", 2, 0, -20));
        let init = parse(1, "1 (init) S 0 1 1 0 -1 0 0 0 0 0 0 0 0 0 20 0 1 0").unwrap();
        assert_eq!((init.comm.as_str(), init.ppid, init.pgrp, init.nice), ("init", 0, 1, 0));
        assert_eq!(parse(7, "garbage"), None);
        assert_eq!(parse(7, "7 (short) S 1 7"), None, "no nice");
        assert_eq!((s.rt_priority, s.policy), (0, 0), "not on the line: ordinary");
        // A worker at SCHED_FIFO 51, as `/proc/PID/stat` of Linux 6.18 gives it.
        let fifo = "2046 (kworker/u8:1-events_unbound) I 2 0 0 0 -1 69238880 0 0 0 0 0 403 0 0 -52 0 1 0 7478509 0 \
                    0 18446744073709551615 0 0 0 0 0 0 0 2147483647 0 1 0 0 17 1 51 1 0 0 0 0 0 0 0 0 0 0 0 0 0";
        let f = parse(2046, fifo).unwrap();
        assert_eq!((f.nice, f.rt_priority, f.policy), (0, 51, 1));
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn this_process_is_in_the_table() {
        let me = std::process::id();
        assert!(processes().iter().any(|p| p.pid == me && p.ppid != 0), "pid {me}");
    }
}
