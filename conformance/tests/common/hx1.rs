//! HX-1 (`tests/independent/hx1_slave.py`), the independent slave, as a process on a
//! pseudo-terminal, and its data sheet as a profile.

use hiperface_conformance::profile_file;
use hiperface_model::Profile;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("independent")
}

pub fn profile() -> Profile {
    profile_file::load(&dir().join("hx1.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// A running HX-1; stopped (stdin closed, killed) on drop.
pub struct Hx1 {
    child: Child,
    pub path: String,
}

impl Hx1 {
    /// Start HX-1 (a test that needs it is ignored where the build found no python3),
    /// at a real-time priority where permitted: a device has a processor of its own, and
    /// a peer starved by the machine's other work is really late on the wire, which
    /// the harness rightly FAILs (seen: late-reply's and store-read-only's replies 14 to
    /// 16 ms late in 1 of 3 runs with three busy loops on the two cores).
    pub fn start(args: &[&str]) -> Hx1 {
        let mut command = if super::real_time_permitted() {
            let mut c = Command::new("chrt");
            c.args(["-f", "50", "python3"]);
            c
        } else {
            Command::new("python3")
        };
        let spawned = command
            .arg(dir().join("hx1_slave.py"))
            .arg("--pty")
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn();
        let mut child = spawned.expect("python3, to run HX-1");
        let mut path = String::new();
        BufReader::new(child.stdout.take().expect("piped")).read_line(&mut path).expect("the pty path");
        let path = path.trim().to_string();
        assert!(path.starts_with("/dev/"), "HX-1 did not print its pseudo-terminal: {path:?}");
        // It has just been powered on: past its initialization (000:T9, at most 200 ms)
        // it is operational, as the harness expects a device under test to be.
        std::thread::sleep(Duration::from_millis(250));
        Hx1 { child, path }
    }
}

impl Drop for Hx1 {
    fn drop(&mut self) {
        drop(self.child.stdin.take());
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
