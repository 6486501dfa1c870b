//! Many mutants on the machine's cores: worker processes (this program's `worker`
//! command), each a list of mutants, each mutant's result a line of JSON; a worker that
//! gives no result for a while is stopped and its mutant recorded as hung, and a new
//! worker takes the rest of its list.

use crate::certify::{Caught, Verdicts};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, VecDeque};
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A family of defective devices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    /// Source mutants of the encoder (the slave model).
    Encoder,
    /// Behavioural mutants at the wire: the conformant encoder's replies changed.
    Wire,
    /// Source mutants of the reference master.
    Master,
}

impl Family {
    pub const ALL: [Family; 3] = [Family::Encoder, Family::Wire, Family::Master];

    pub fn name(self) -> &'static str {
        match self {
            Family::Encoder => "encoder",
            Family::Wire => "wire",
            Family::Master => "master",
        }
    }

    pub fn parse(s: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == s)
    }
}

/// A mutant as a list names it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct MutantName {
    pub family: Family,
    pub id: u32,
    /// Stable across edits elsewhere: `model/src/slave/stack.rs: replace == with != in ErrorStack::push`.
    pub key: String,
    /// The function (source mutants) or the command (wire mutants) it is in.
    pub function: String,
}

/// What certifying one mutant gave.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    #[serde(flatten)]
    pub name: MutantName,
    #[serde(flatten)]
    pub verdicts: Verdicts,
    /// Whether the conformant device ran the mutant's place (source mutants).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub reached: Option<bool>,
    /// A difference at the wire found on random streams (encoder mutants let through).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub witness: Option<String>,
    /// How long its certification took, ms.
    pub ms: f64,
}

/// What a worker prints: one line per mutant.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WorkerLine {
    pub id: u32,
    #[serde(flatten)]
    pub verdicts: Verdicts,
    /// For an encoder mutant the catalogue let through: a difference at the wire from
    /// the conformant device on a random stream, if one was found (`diff`).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub witness: Option<String>,
    pub ms: f64,
}

struct Worker {
    child: Child,
    /// The last lines the worker wrote to its standard error (a stack overflow's
    /// message), for the result of a mutant it died on.
    said: Said,
    /// The ids it has not answered for, the one it works on first.
    left: VecDeque<u32>,
    /// Since its last result (or its start).
    since: OwnTime,
}

/// The time a worker has had since a mark: the wall clock less the time the machine
/// kept it waiting for a processor (its threads' run-queue delay, Linux's
/// `/proc/PID/task/*/schedstat`). A mutant that loops or blocks is hung after the same
/// time of its own on an idle machine and on a loaded one (CI runs the catalogue at
/// nice 19 beside the real-time tests); where that delay cannot be read, the wall
/// clock.
struct OwnTime {
    mark: Instant,
    waited_ns: u64,
}

impl OwnTime {
    fn start(pid: u32) -> OwnTime {
        OwnTime { mark: Instant::now(), waited_ns: run_queue_delay_ns(pid) }
    }

    fn elapsed(&self, pid: u32) -> Duration {
        let waited = run_queue_delay_ns(pid).saturating_sub(self.waited_ns);
        self.mark.elapsed().saturating_sub(Duration::from_nanos(waited))
    }
}

/// The time the threads of process `pid` have waited on a run queue, ns (0 where it
/// cannot be read). Bounded reads: a schedstat line is three numbers.
fn run_queue_delay_ns(pid: u32) -> u64 {
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else { return 0 };
    tasks
        .filter_map(Result::ok)
        .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
        .filter_map(|line| line.split_whitespace().nth(1)?.parse::<u64>().ok())
        .fold(0u64, u64::saturating_add)
}

/// The last lines a worker wrote to its standard error, at most [`SAID_LINES`] of at
/// most [`SAID_CHARS`] characters each: a mutant that overflows the stack or aborts
/// says why there, and it goes into that mutant's result instead of the run's log.
type Said = std::sync::Arc<std::sync::Mutex<VecDeque<String>>>;
const SAID_LINES: usize = 4;
const SAID_CHARS: usize = 200;

fn spawn(
    family: Family,
    ids: &VecDeque<u32>,
    index: usize,
    tx: &mpsc::Sender<(usize, String)>,
) -> std::io::Result<(Child, Said)> {
    let list: Vec<String> = ids.iter().map(u32::to_string).collect();
    let mut child = Command::new(std::env::current_exe()?)
        .args(["worker", "--family", family.name(), "--ids", &list.join(",")])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    let said = Said::default();
    if let Some(err) = child.stderr.take() {
        let said = said.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(err).lines().map_while(Result::ok) {
                let Ok(mut kept) = said.lock() else { break };
                if kept.len() == SAID_LINES {
                    kept.pop_front();
                }
                kept.push_back(line.chars().take(SAID_CHARS).collect());
            }
        });
    }
    if let Some(out) = child.stdout.take() {
        let tx = tx.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                if tx.send((index, line)).is_err() {
                    break;
                }
            }
        });
    }
    Ok((child, said))
}

/// Certify `ids` of `family` on `jobs` workers; a mutant with no result after
/// `timeout` is hung. `progress` sees each result as it comes.
pub fn certify_all(
    family: Family,
    ids: &[u32],
    jobs: usize,
    timeout: Duration,
    mut progress: impl FnMut(usize, usize, u32, &WorkerLine),
) -> std::io::Result<BTreeMap<u32, WorkerLine>> {
    let jobs = jobs.max(1).min(ids.len().max(1));
    let (tx, rx) = mpsc::channel();
    let mut workers: Vec<Worker> = Vec::new();
    // Round robin, so that slow parts of the model (a file's mutants) are shared.
    let mut lists: Vec<VecDeque<u32>> = vec![VecDeque::new(); jobs];
    for (i, id) in ids.iter().enumerate() {
        lists[i % jobs].push_back(*id);
    }
    for (index, left) in lists.into_iter().enumerate() {
        let (child, said) = spawn(family, &left, index, &tx)?;
        let since = OwnTime::start(child.id());
        workers.push(Worker { child, said, left, since });
    }
    let mut results = BTreeMap::new();
    let total = ids.len();
    while workers.iter().any(|w| !w.left.is_empty()) {
        match rx.recv_timeout(Duration::from_millis(200)) {
            Ok((index, line)) => {
                let Ok(found) = serde_json::from_str::<WorkerLine>(&line) else { continue };
                let w = &mut workers[index];
                if w.left.front() == Some(&found.id) {
                    w.left.pop_front();
                }
                // What it says from now on is of its next mutant.
                if let Ok(mut said) = w.said.lock() {
                    said.clear();
                }
                w.since = OwnTime::start(w.child.id());
                progress(results.len() + 1, total, found.id, &found);
                results.insert(found.id, found);
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
        for (index, w) in workers.iter_mut().enumerate() {
            let exited = matches!(w.child.try_wait(), Ok(Some(_)));
            // Read while the process is there (an exited one's delay is gone with it).
            let own = w.since.elapsed(w.child.id());
            let stuck = !exited && own > timeout;
            if w.left.is_empty() || !(exited || stuck) {
                continue;
            }
            // An exit with work left: let its last lines arrive first.
            if exited && !stuck && w.since.mark.elapsed() < Duration::from_secs(1) {
                continue;
            }
            let _ = w.child.kill();
            let _ = w.child.wait();
            if let Some(id) = w.left.pop_front() {
                let why = if stuck {
                    format!(
                        "no result within {} s of its own time: the device never gave the run control back",
                        timeout.as_secs()
                    )
                } else {
                    let said = w.said.lock().map_or_else(
                        |_| String::new(),
                        |s| s.iter().map(|l| l.trim()).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" / "),
                    );
                    if said.is_empty() {
                        "the worker process died on it (a stack overflow or an abort in the device)".to_string()
                    } else {
                        format!("the worker process died on it: {said}")
                    }
                };
                let hung = WorkerLine {
                    id,
                    verdicts: Verdicts {
                        caught: Caught::Hung,
                        config: "-".into(),
                        case: None,
                        clause: None,
                        finding: Some(why.clone()),
                        crashed: Some(why),
                    },
                    witness: None,
                    ms: own.as_secs_f64() * 1000.0,
                };
                progress(results.len() + 1, total, id, &hung);
                results.insert(id, hung);
            }
            if !w.left.is_empty() {
                (w.child, w.said) = spawn(family, &w.left, index, &tx)?;
            }
            w.since = OwnTime::start(w.child.id());
        }
    }
    for mut w in workers {
        let _ = w.child.wait();
    }
    Ok(results)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Twice as many busy threads as processors wait for one about half of the time:
    /// their delay is read and taken off, and a process that is gone reads as no delay.
    #[test]
    fn own_time_leaves_out_the_wait_for_a_processor() {
        let me = std::process::id();
        let start = OwnTime::start(me);
        let busy = || {
            let t = Instant::now();
            let mut x = 0u64;
            while t.elapsed() < Duration::from_millis(300) {
                x = std::hint::black_box(x.wrapping_add(1));
            }
        };
        // More busy threads than processors: some of them wait on a run queue.
        let threads = std::thread::available_parallelism().map_or(2, |n| n.get()) * 2;
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads).map(|_| s.spawn(busy)).collect();
            // Read while the threads are there (an exited thread's delay is gone).
            std::thread::sleep(Duration::from_millis(250));
            let own = start.elapsed(me);
            let wall = start.mark.elapsed();
            // Twice as many busy threads as processors for 250 ms: together they waited
            // about 250 ms per processor; a fifth of one is taken as shown.
            let taken_off = wall.saturating_sub(own);
            assert!(
                taken_off >= Duration::from_millis(50),
                "own {own:?} against wall {wall:?}: the run-queue delay was not taken off"
            );
            for h in handles {
                let _ = h.join();
            }
        });
        assert_eq!(run_queue_delay_ns(u32::MAX), 0);
    }
}
