//! The master under test as a process: `--exec 'CMD {port}'` with the encoder's
//! pseudo-terminal in place of `{port}`. Its start is power-on for the encoder. It is
//! always reaped, whatever it does; what it prints is kept (capped) for the report.
//! It inherits no descriptor of the harness but its standard streams (every descriptor
//! the harness opens is close-on-exec: `line::pty_pair`), and what it started is ended
//! with it: its process group, and any child that left the group or the session
//! (`setsid`), found by parent while it lives and adopted by the harness once its parent
//! ended.

use nix::sys::signal::{kill, killpg, Signal};
use nix::sys::wait::{waitpid, WaitPidFlag};
use nix::unistd::{getpgrp, Pid};
use std::io::Read;
use std::os::unix::process::CommandExt as _;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};

/// Output kept per stream.
const OUTPUT_CAP: usize = 16 * 1024;

/// The process groups of the masters running now: a second interrupt, which ends the
/// harness at once, stops them first (nothing is left running behind it).
static RUNNING: Mutex<Vec<u32>> = Mutex::new(Vec::new());

/// Stop every master still running, with whatever it started. For the path that ends
/// the harness at once (a second Ctrl-C); a normal run stops each when its scenario ends.
pub fn stop_all() {
    let groups = RUNNING.lock().map(|g| g.clone()).unwrap_or_default();
    for pid in groups {
        kill_group(pid);
    }
}

/// Kill a process group (its id is its leader's pid): children a master left behind go
/// too.
fn kill_group(pid: u32) {
    let _ = killpg(Pid::from_raw(pid as i32), Signal::SIGKILL);
}

/// A process as `procfs` gives it: what tells who started it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Proc {
    pid: u32,
    ppid: u32,
    pgrp: u32,
}

/// Every process this harness can see.
fn processes() -> Vec<Proc> {
    crate::procfs::processes().into_iter().map(|p| Proc { pid: p.pid, ppid: p.ppid, pgrp: p.pgrp }).collect()
}

/// The processes a master started that its process group does not hold: every
/// descendant of `master` (by parent), and every process handed to this harness as an
/// orphan (it is the subreaper of its descendants) that is in none of the harness's
/// own groups (a child that left the master's group or session, `setsid`, and whose
/// parent ended). `running`: the groups of the masters still running, not theirs.
fn escaped(all: &[Proc], master: u32, me: Proc, running: &[u32]) -> Vec<Proc> {
    let orphans = all.iter().filter(|p| p.ppid == me.pid && p.pid != master && p.pgrp != me.pgrp);
    let mut out: Vec<Proc> = orphans.filter(|p| !running.contains(&p.pgrp)).copied().collect();
    // And every descendant of the master or of those, by parent.
    let mut frontier: Vec<u32> = out.iter().map(|p| p.pid).chain([master]).collect();
    while let Some(parent) = frontier.pop() {
        let children: Vec<Proc> =
            all.iter().filter(|c| c.ppid == parent && c.pid != master && !out.contains(c)).copied().collect();
        frontier.extend(children.iter().map(|c| c.pid));
        out.extend(children);
    }
    out
}

/// End what `master` started outside its group, and reap what was handed to this
/// harness: a few rounds, as a killed parent hands its children on.
fn end_escaped(master: u32) {
    let me = Proc { pid: std::process::id(), ppid: 0, pgrp: getpgrp().as_raw() as u32 };
    for _ in 0..20 {
        let mut running = RUNNING.lock().map(|g| g.clone()).unwrap_or_default();
        running.retain(|g| *g != master);
        let found = escaped(&processes(), master, me, &running);
        if found.is_empty() {
            return;
        }
        for p in &found {
            // Its group and session go with it, wherever it moved them.
            if p.pgrp != me.pgrp && !running.contains(&p.pgrp) {
                let _ = killpg(Pid::from_raw(p.pgrp as i32), Signal::SIGKILL);
            }
            let _ = kill(Pid::from_raw(p.pid as i32), Signal::SIGKILL);
        }
        for p in found.iter().filter(|p| p.ppid == me.pid) {
            let _ = waitpid(Pid::from_raw(p.pid as i32), Some(WaitPidFlag::WNOHANG));
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// This harness adopts the orphans of its descendants (`PR_SET_CHILD_SUBREAPER`), so
/// that a master's child that left its group and outlived its parent is still found
/// and ended, not handed to init.
fn adopt_orphans() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = nix::sys::prctl::set_child_subreaper(true);
    });
}

/// A running master.
pub struct MasterProcess {
    child: Child,
    output: Arc<Mutex<Vec<u8>>>,
    readers: Vec<std::thread::JoinHandle<()>>,
    reaped: bool,
}

impl MasterProcess {
    /// Start `command` (a shell command line) with `{port}` replaced by `port`.
    pub fn start(command: &str, port: &str) -> std::io::Result<MasterProcess> {
        let line = command.replace("{port}", port);
        adopt_orphans();
        // A process group of its own: the master and whatever it starts (a serial
        // device server, a simulator) are stopped together.
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(format!("exec {line}"))
            .process_group(0)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()?;
        if let Ok(mut running) = RUNNING.lock() {
            running.push(child.id());
        }
        let output = Arc::new(Mutex::new(Vec::new()));
        let mut readers = Vec::new();
        let streams: [Option<Box<dyn Read + Send>>; 2] = [
            child.stdout.take().map(|s| Box::new(s) as Box<dyn Read + Send>),
            child.stderr.take().map(|s| Box::new(s) as Box<dyn Read + Send>),
        ];
        for mut stream in streams.into_iter().flatten() {
            let out = output.clone();
            readers.push(std::thread::spawn(move || {
                let mut buf = [0u8; 1024];
                while let Ok(n) = stream.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    if let Ok(mut o) = out.lock() {
                        let room = OUTPUT_CAP.saturating_sub(o.len());
                        o.extend_from_slice(&buf[..n.min(room)]);
                    }
                }
            }));
        }
        Ok(MasterProcess { child, output, readers, reaped: false })
    }

    /// The master's process id (the shell `exec`s the command line: the master's own).
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// The exit status if the master has ended.
    pub fn exited(&mut self) -> Option<std::process::ExitStatus> {
        self.child.try_wait().ok().flatten()
    }

    /// Stop the master (if it still runs) and everything it started, reap it, and
    /// return what it printed.
    pub fn stop(mut self) -> (Option<std::process::ExitStatus>, String) {
        let status = self.exited();
        self.reap();
        for r in self.readers.drain(..) {
            let _ = r.join();
        }
        let text = self.output.lock().map(|o| String::from_utf8_lossy(&o).into_owned()).unwrap_or_default();
        (status, text)
    }
}

impl MasterProcess {
    /// Stop the master's whole process group (also after the master itself exited:
    /// what it started may live on), and reap the master.
    fn reap(&mut self) {
        if std::mem::replace(&mut self.reaped, true) {
            return;
        }
        let pid = self.child.id();
        kill_group(pid);
        end_escaped(pid);
        if self.child.try_wait().ok().flatten().is_none() {
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
        if let Ok(mut running) = RUNNING.lock() {
            running.retain(|p| *p != pid);
        }
    }
}

impl Drop for MasterProcess {
    fn drop(&mut self) {
        self.reap();
    }
}
