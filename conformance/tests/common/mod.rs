//! Test helpers shared by the integration tests: a real ser2net, and HX-1 (the
//! independent slave) on a pseudo-terminal.

#![allow(dead_code)]

pub mod hx1;
pub mod line_emulator;
pub mod master;
// The record played back is the core's (`hiperface_suite`); its check is the suite's
// tests' own, shared with the harness's tests from there.
#[path = "../../../suite/tests/common/replay.rs"]
pub mod replay;
pub mod session;

use hiperface_conformance::line::tcp::TcpLine;
use hiperface_model::UartSettings;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// One real-time test at a time in a test binary: a bench certifies one device at a
/// time, and on a two-core machine parallel certifications (each with real-time
/// threads: the encoder, the master under test) starve one another's timing; and a
/// child spawned by one test would inherit another's pseudo-terminal, whose end would
/// then not close when that test drops it.
pub fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// `run` applied to each of `items`, two at a time, the results in the items' order: for
/// a test that certifies one slave process after another over pseudo-terminals, while
/// it holds [`one_at_a_time`]. A certification of a slave over a pseudo-terminal takes
/// a few per cent of a processor (HX-1: 0.4 s in 10.9 s of real time), its harness's
/// thread at a real-time priority where permitted, and each slave has a process of its
/// own: two at once leave both processors mostly idle, and a run the machine made late
/// is taken again as every other (`faithfully`). Not for masters: the harness's encoder
/// and the master under test take more, and the master's own timing is graded.
pub fn two_at_a_time<T: Sync, R: Send>(items: &[T], run: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let done = std::sync::Mutex::new(Vec::with_capacity(items.len()));
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                let r = run(item);
                done.lock().unwrap_or_else(|e| e.into_inner()).push((i, r));
            });
        }
    });
    let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    done.sort_by_key(|(i, _)| *i);
    assert_eq!(done.len(), items.len(), "a run of two_at_a_time panicked");
    done.into_iter().map(|(_, r)| r).collect()
}

/// A child process, killed when dropped.
pub struct KillOnDrop(pub Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A ser2net (Debian's package) bridging a TCP port on loopback to a pseudo-terminal.
pub struct Ser2net {
    _server: KillOnDrop,
    port: u16,
    /// Its configuration, removed with it.
    _config: tempfile::TempDir,
}

/// Run `attempt` with a fresh test rig (a device or a line of the test's own, on this
/// machine, and the harness) until the rig kept time throughout: a device has a
/// processor of its own, and a run in which the test machine made the rig late, or
/// kept the harness from seeing (an UNKNOWN), is no sample of the rig's behaviour.
/// `attempt` returns whether the run is a sample, and the result.
///
/// At least [`FAITHFUL_ATTEMPTS`] attempts, and more while they have taken less than
/// [`FAITHFUL_PATIENCE`]: this machine is a virtual one whose host now and then holds
/// it back for milliseconds at a time, in bursts that can last a minute (CI saw five
/// runs in a row disturbed), and a test that gave up within one burst would say
/// nothing about the rig. Never more than [`FAITHFUL_MOST`].
pub fn faithfully<T>(mut attempt: impl FnMut() -> (bool, T)) -> T {
    let started = Instant::now();
    let mut attempts = 0;
    while attempts < FAITHFUL_MOST && (attempts < FAITHFUL_ATTEMPTS || started.elapsed() < FAITHFUL_PATIENCE) {
        attempts += 1;
        let (faithful, result) = attempt();
        if faithful {
            return result;
        }
        eprintln!("attempt {attempts}: the test's device, line or harness was not on time; taken again");
    }
    panic!(
        "the test's device, line or harness was never on time in {attempts} attempts over {:.0} s: the machine is too busy \
         for a real-time test",
        started.elapsed().as_secs_f64()
    );
}

/// The attempts [`faithfully`] makes at least.
pub const FAITHFUL_ATTEMPTS: u32 = 5;
/// How long [`faithfully`] goes on past its first attempts.
pub const FAITHFUL_PATIENCE: Duration = Duration::from_secs(180);
/// The attempts [`faithfully`] makes at most.
pub const FAITHFUL_MOST: u32 = 30;

/// Whether a process may be started at a real-time priority here (`chrt -f`).
pub fn real_time_permitted() -> bool {
    Command::new("chrt").args(["-f", "1", "true"]).status().is_ok_and(|s| s.success())
}

/// Where ser2net is. A test that needs it is ignored where the build found none
/// (`build.rs`); run anyway, it stops here with the reason.
pub fn ser2net_program() -> &'static str {
    ["/usr/sbin/ser2net", "/usr/bin/ser2net"]
        .into_iter()
        .find(|p| std::path::Path::new(p).exists())
        .expect("ser2net is not installed (apt-get install ser2net)")
}

/// `chrt -f 50 ` where a process may be started at a real-time priority, else nothing:
/// the prefix for a command line of a device with a processor of its own.
pub fn real_time_prefix() -> &'static str {
    if real_time_permitted() {
        "chrt -f 50 "
    } else {
        ""
    }
}

/// A ser2net configuration relaying TCP `port` to `device` at 9600 8E1, as a serial
/// device server for HIPERFACE is set up: no character delay and no Nagle's
/// algorithm, so that characters are passed on as they come (with them the server
/// passes a reply on in bursts further apart than the timeout).
pub fn ser2net_yaml(name: &str, port: u16, device: &str) -> String {
    ser2net_yaml_with(name, &format!("tcp(nodelay),127.0.0.1,{port}"), device)
}

/// The same with another accepter (e.g. `telnet(rfc2217),tcp(nodelay),127.0.0.1,PORT`).
pub fn ser2net_yaml_with(name: &str, accepter: &str, device: &str) -> String {
    format!(
        "%YAML 1.1\n---\nconnection: &{name}\n    accepter: {accepter}\n    enable: on\n    \
         options:\n      chardelay: false\n    connector: serialdev,{device},9600e81,local\n"
    )
}

/// A free TCP port on 127.0.0.1.
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

impl Ser2net {
    /// Start one for `pty_path` at 9600 8E1.
    pub fn bridge(pty_path: &str, name: &str) -> Ser2net {
        Ser2net::start(pty_path, name, false)
    }

    /// Start one for `pty_path` that takes UART settings through RFC 2217.
    pub fn bridge_rfc2217(pty_path: &str, name: &str) -> Ser2net {
        Ser2net::start(pty_path, name, true)
    }

    fn start(pty_path: &str, name: &str, rfc2217: bool) -> Ser2net {
        let exe = ser2net_program();
        let port = free_port();
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("ser2net.yaml");
        let yaml = if rfc2217 {
            ser2net_yaml_with(name, &format!("telnet(rfc2217),tcp(nodelay),127.0.0.1,{port}"), pty_path)
        } else {
            ser2net_yaml(name, port, pty_path)
        };
        std::fs::write(&config, yaml).unwrap();
        // A device server is a device with a processor of its own: where permitted it
        // runs at a real-time priority, so that a busy test machine does not delay its
        // chunks by more than a reply's timing limit (it did, under load).
        let mut command = if real_time_permitted() {
            let mut c = Command::new("chrt");
            c.args(["-f", "50", exe]);
            c
        } else {
            Command::new(exe)
        };
        let server =
            command.args(["-n", "-d", "-c"]).arg(&config).stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap();
        Ser2net { _server: KillOnDrop(server), port, _config: dir }
    }

    /// Its address, `127.0.0.1:PORT`.
    pub fn address(&self) -> String {
        format!("127.0.0.1:{}", self.port)
    }

    /// Connect, waiting up to 10 s for the server to accept.
    pub fn connect(&self) -> TcpLine {
        let started = Instant::now();
        loop {
            match TcpLine::connect(&format!("127.0.0.1:{}", self.port), UartSettings::DEFAULT) {
                Ok(l) => return l,
                Err(_) if started.elapsed() < Duration::from_secs(10) => std::thread::sleep(Duration::from_millis(100)),
                Err(e) => panic!("ser2net did not accept connections: {e}"),
            }
        }
    }
}

/// A "drive" on `port`: the reference master (Read Position every 20 ms), running on
/// its own until its line goes (or 120 s, so that a broken test cannot hang), at a
/// real-time priority where permitted as a drive's processor would be.
pub fn reference_drive(
    port: Box<dyn serialport::SerialPort>,
    profile: hiperface_model::Profile,
) -> std::thread::JoinHandle<()> {
    use hiperface_conformance::{line::serial::SerialLine, master};
    use hiperface_suite::exchange::BusMaster;
    std::thread::spawn(move || {
        hiperface_conformance::sched::real_time_priority();
        let line = SerialLine::from_port(port, "drive".into(), profile.settings, true);
        let mut master = BusMaster::new(line, profile.edition);
        let options = hiperface_model::master::reference::Options { polling_period_ms: 20, duration_ms: Some(120_000) };
        let _ = master::reference::run(&mut master, profile, options, &mut |_: &str| {});
    })
}
