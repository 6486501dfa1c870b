//! `hiperface monitor` on a live bus: a recorded session replayed in real time into
//! a pseudo-terminal (and through a real ser2net), the monitor listening on the
//! other side. Real time on a shared machine: the timing tolerance is generous
//! (5 ms), the late reply far beyond it (15 ms after the timeout, 000:T10 allows 5),
//! exchanges 60 ms apart, and a replay that was itself late is run again.

mod common;

use common::session::{defective, session, verdicts, Exchange, CT};
use hiperface_conformance::listen::tap::Tap;
use hiperface_conformance::port::PortSpec;
use hiperface_model::UartSettings;
use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::fd::OwnedFd;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_hiperface");

/// Write each frame whole when its last character has ended, as a UART receiver
/// delivers it (sleeping, not spinning: a sleeper is woken promptly on a busy
/// machine, a spinner is preempted). Answers how
/// late the replay itself was at worst (µs): a replay descheduled on a busy machine
/// is not the session any more.
fn replay(bus: &mut File, exchanges: &[Exchange]) -> u64 {
    // A real bus is not slowed by the machine's load: the replay plays it at a
    // real-time priority where permitted (its lateness is checked either way).
    std::thread::scope(|s| s.spawn(|| replay_here(bus, exchanges)).join().unwrap())
}

fn replay_here(bus: &mut File, exchanges: &[Exchange]) -> u64 {
    hiperface_conformance::sched::real_time_priority();
    let start = Instant::now() + Duration::from_millis(200);
    let at = |ms: f64| start + Duration::from_secs_f64(ms / 1000.0);
    let wait_until = |t: Instant| {
        if let Some(d) = t.checked_duration_since(Instant::now()) {
            std::thread::sleep(d);
        }
    };
    let mut late_us = 0;
    let mut write = |t: Instant, bytes: &[u8]| {
        wait_until(t);
        bus.write_all(bytes).unwrap();
        late_us = late_us.max(Instant::now().duration_since(t).as_micros() as u64);
    };
    for x in exchanges {
        write(at(x.request_end_ms), &x.request);
        write(at(x.reply_start_ms + CT * x.reply.len() as f64), &x.reply);
    }
    std::thread::sleep(Duration::from_millis(300));
    late_us
}

/// Run `attempt` until the replay was faithful enough (written within 3 ms of its
/// times: the response times are 2 ms, the tolerance 5 ms, the late reply 15 ms) and
/// the monitor heard it punctually enough for the verdicts this test expects (its
/// reads returned within 4.5 ms: the late reply stays late by more than the tolerance
/// and the lateness; a monitor that read later says UNKNOWN where it could not tell,
/// rightly, see `decode.rs`), as often as `common::faithfully` tries. `attempt`
/// answers both lateness figures, µs.
fn faithfully<T>(mut attempt: impl FnMut() -> ((u64, u64), T)) -> T {
    common::faithfully(|| {
        let ((replay_us, monitor_us), result) = attempt();
        let faithful = replay_us <= 3_000 && monitor_us <= 4_500;
        if !faithful {
            eprintln!("the replay was {replay_us} µs late, the monitor's reads {monitor_us} µs (a busy machine)");
        }
        (faithful, result)
    })
}

/// How late the monitor says its reads returned characters at worst, µs.
fn monitor_late_us(text: &str) -> u64 {
    let figure = text.split("its reads returned characters at most ").nth(1).and_then(|t| t.split(" ms").next());
    let ms: f64 = figure.and_then(|f| f.parse().ok()).unwrap_or_else(|| panic!("no read lateness in: {text}"));
    (ms * 1000.0) as u64
}

fn spawn_monitor(port: &str, extra: &[&str]) -> Child {
    Command::new(BIN)
        .args(["monitor", "--port", port, "--tolerance-ms", "5"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn finish(child: Child, mut stderr: Stderr) -> (i32, String) {
    let out = child.wait_with_output().unwrap();
    let mut text = String::from_utf8_lossy(&out.stdout).to_string();
    stderr.read_to_string(&mut text).unwrap();
    (out.status.code().unwrap_or(-1), text)
}

type Stderr = BufReader<std::process::ChildStderr>;

/// Wait until the monitor says it listens (it has opened and set up the port); its
/// standard error stays open.
fn wait_listening(child: &mut Child) -> Stderr {
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    // Notes may come first (an earlier run's reports moved aside).
    let mut said = String::new();
    loop {
        let mut line = String::new();
        assert!(stderr.read_line(&mut line).unwrap() > 0, "the monitor ended before it listened: {said}");
        if line.starts_with("listening on") {
            return stderr;
        }
        said.push_str(&line);
    }
}

fn fails(v: &[String]) -> Vec<usize> {
    v.iter().enumerate().filter(|(_, v)| *v == "FAIL").map(|(i, _)| i).collect()
}

/// A pseudo-terminal: the bus's end (what the replay writes), the tap's path, and the
/// tap's end held open until the monitor has opened it. Close-on-exec, so that no
/// child inherits the bus's end and keeps it open after the test closed it.
fn pty() -> (File, String, OwnedFd) {
    use nix::fcntl::{fcntl, FcntlArg, FdFlag};
    let p = nix::pty::openpty(None, None).unwrap();
    for fd in [&p.master, &p.slave] {
        fcntl(fd, FcntlArg::F_SETFD(FdFlag::FD_CLOEXEC)).unwrap();
    }
    let path = nix::unistd::ttyname(&p.slave).unwrap().to_string_lossy().to_string();
    (File::from(p.master), path, p.slave)
}

/// Bytes the monitor's side sent to the bus (it must send none).
fn sent_to_bus(bus: &mut File) -> usize {
    use nix::fcntl::{fcntl, FcntlArg, OFlag};
    fcntl(&*bus, FcntlArg::F_SETFL(OFlag::O_NONBLOCK)).unwrap();
    let mut b = [0u8; 256];
    match bus.read(&mut b) {
        Ok(n) => n,
        Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => 0,
        // Nobody holds the tap's side open any more (ser2net closed the device when the
        // monitor went, before this read on a busy machine): what was written to it
        // would still be read first, so nothing was.
        Err(e) if e.raw_os_error() == Some(nix::libc::EIO) => 0,
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn a_replayed_session_is_graded_live_and_the_monitor_never_writes() {
    let _one = common::one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r");
    let capture = dir.path().join("heard.csv");
    let (code, text, sent) = faithfully(|| {
        // A run again (the line was not faithful) writes a new capture: never over one.
        let _ = std::fs::remove_file(&capture);
        let (mut bus, path, tap_end) = pty();
        let mut child =
            spawn_monitor(&path, &["--report", report.to_str().unwrap(), "--capture", capture.to_str().unwrap()]);
        let stderr = wait_listening(&mut child);
        // Only the monitor reads the tap's side from now on.
        drop(tap_end);
        let late = replay(&mut bus, &session(4, 60.0, defective(15.0)));
        let sent = sent_to_bus(&mut bus);
        drop(bus); // the port closes: the monitor ends with its summary
        let (code, text) = finish(child, stderr);
        ((late, monitor_late_us(&text)), (code, text, sent))
    });
    assert_eq!(sent, 0, "the monitor wrote to the bus");
    assert_eq!(code, 1, "{text}");
    let v = verdicts(&text);
    assert_eq!(v.len(), 12, "{text}");
    assert_eq!(fails(&v), vec![3, 7], "{text}");
    assert_eq!(v.iter().filter(|v| *v == "PASS").count(), 10, "{text}");
    assert!(text.contains("the limit is 5 ms (000:T10)") && text.contains("checksum"), "{text}");
    assert!(text.contains("ended by the port closing"), "{text}");
    for f in ["report.json", "junit.xml", "listening.md", "listening.html"] {
        assert!(report.join(f).exists(), "{f}");
    }
    let junit = std::fs::read_to_string(report.join("junit.xml")).unwrap();
    assert!(junit.contains("42h Read Position") && junit.contains("<failure"), "{junit}");

    // Nothing heard is lost: `decode` of the capture gives the same verdicts, with the
    // tolerance the capture states (the monitor's own), no flag needed.
    let head = std::fs::read_to_string(&capture).unwrap();
    assert!(head.starts_with("# hiperface monitor capture: tolerance_us="), "{}", &head[..80.min(head.len())]);
    let out = Command::new(BIN).args(["decode"]).arg(&capture).output().unwrap();
    let decoded = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(verdicts(&decoded), v, "{decoded}");

    // A capture is never written over (issue 55): a second monitor with the same
    // --capture stops with the reason, and the first capture is as it was.
    let (_bus, path, _tap_end) = pty();
    let again = Command::new(BIN)
        .args(["monitor", "--port", &path, "--duration-ms", "100", "--capture"])
        .arg(&capture)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&again.stderr);
    assert_eq!(again.status.code(), Some(2), "{said}");
    assert!(said.contains("a capture is never written over"), "{said}");
    assert_eq!(std::fs::read_to_string(&capture).unwrap(), head);
}

#[test]
fn the_tap_is_opened_read_only() {
    let _one = common::one_at_a_time();
    let (_bus, path, _tap_end) = pty();
    let settings = |p: &str| {
        let f = std::fs::File::open(p).unwrap();
        format!("{:?}", nix::sys::termios::tcgetattr(&f).unwrap())
    };
    let before = settings(&path);
    let tap = Tap::open(&PortSpec::Path(path.clone()), UartSettings::DEFAULT).unwrap();
    assert!(!tap.file_is_writable(), "{path} was opened for writing");
    assert!(tap.marks_errors());
    assert_ne!(settings(&path), before, "the tap sets the port up to listen");
    // Done: the port's settings as the monitor found them (issue 55: a second monitor
    // on it failed).
    drop(tap);
    assert_eq!(settings(&path), before);
    let tap = Tap::open(&PortSpec::Path(path.clone()), UartSettings::DEFAULT).unwrap();
    drop(tap);
    // Not a port the monitor can listen on.
    for spec in ["sim", "virtual", "pty"] {
        let e = Tap::open(&spec.parse().unwrap(), UartSettings::DEFAULT).err().unwrap();
        assert!(e.contains("the monitor listens on"), "{e}");
    }
    let e = Tap::open(&PortSpec::Path("/nonexistent/tty".into()), UartSettings::DEFAULT).err().unwrap();
    assert!(e.contains("cannot open it read-only"), "{e}");
}

/// Through a real ser2net, ended by Ctrl-C (SIGINT): the summary and the reports.
#[test]
#[cfg_attr(not(has_ser2net), ignore = "ser2net is not installed (apt-get install ser2net)")]
fn through_ser2net_until_ctrl_c() {
    let _one = common::one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r");
    let Some((code, text, sent)) = faithfully(|| {
        let (mut bus, path, tap_end) = pty();
        let server = common::Ser2net::bridge(&path, "tap");
        // Wait until ser2net accepts; it serves one connection at a time.
        drop(server.connect());
        std::thread::sleep(Duration::from_millis(300));
        drop(tap_end);
        let mut child = spawn_monitor(&format!("tcp://{}", server.address()), &["--report", report.to_str().unwrap()]);
        let stderr = wait_listening(&mut child);
        // ser2net opens the device when the monitor connects.
        std::thread::sleep(Duration::from_millis(300));
        let late = replay(&mut bus, &session(4, 60.0, defective(15.0)));
        let interrupted = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
        assert!(interrupted.success());
        let (code, text) = finish(child, stderr);
        ((late, monitor_late_us(&text)), Some((code, text, sent_to_bus(&mut bus))))
    }) else {
        return;
    };
    assert_eq!(sent, 0, "something wrote to the bus");
    assert_eq!(code, 1, "{text}");
    let v = verdicts(&text);
    assert_eq!(v.len(), 12, "{text}");
    assert_eq!(fails(&v), vec![3, 7], "{text}");
    assert!(text.contains("ended by Ctrl-C") && text.contains("worst verdict heard: FAIL"), "{text}");
    assert!(text.lines().any(|l| l == "FAILED"), "{text}");
    assert!(report.join("listening.md").exists());
}
