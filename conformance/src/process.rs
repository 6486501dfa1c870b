//! The master under test as a process: `--exec 'CMD {port}'` with the encoder's
//! pseudo-terminal in place of `{port}`. Its start is power-on for the encoder. It is
//! always reaped, whatever it does; what it prints is kept (capped) for the report.

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
/// too. With the `kill` utility: no `unsafe` signal call here.
fn kill_group(pid: u32) {
    let _ = Command::new("kill")
        .args(["-KILL", "--", &format!("-{pid}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
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
