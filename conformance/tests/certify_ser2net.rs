//! The harness through a real serial device server: ser2net (Debian's package,
//! installed by .ci/run) bridges TCP to the simulator's pseudo-terminal.

use hiperface_conformance::certify::{self, CaseVerdict, Options};
use hiperface_conformance::line::tcp::TcpLine;
use hiperface_conformance::simulate::PtySimulator;
use hiperface_model::{profiles, UartSettings};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

struct KillOnDrop(Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn ser2net() -> Option<&'static str> {
    ["/usr/sbin/ser2net", "/usr/bin/ser2net"].into_iter().find(|p| std::path::Path::new(p).exists())
}

#[test]
fn the_catalogue_passes_through_ser2net() {
    let Some(exe) = ser2net() else {
        assert!(std::env::var_os("CI").is_none(), "ser2net is required in CI (.ci/run installs it)");
        eprintln!("SKIPPED: ser2net is not installed (apt-get install ser2net)");
        return;
    };
    let profile = profiles::srs50();
    let (sim, _harness_end) = PtySimulator::start(profile).unwrap();
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let dir = std::env::temp_dir().join(format!("hf-ser2net-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let config = dir.join("ser2net.yaml");
    std::fs::write(
        &config,
        format!(
            "%YAML 1.1\n---\nconnection: &hf\n    accepter: tcp,127.0.0.1,{port}\n    enable: on\n    connector: serialdev,{},9600e81,local\n",
            sim.path
        ),
    )
    .unwrap();
    let _server = KillOnDrop(
        Command::new(exe)
            .args(["-n", "-d", "-c"])
            .arg(&config)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let started = Instant::now();
    let line = loop {
        match TcpLine::connect(&format!("127.0.0.1:{port}"), UartSettings::DEFAULT) {
            // Real time on a shared CI machine: generous timing bounds.
            Ok(l) => break l.with_tolerance(25_000),
            Err(e) if started.elapsed() < Duration::from_secs(10) => {
                let _ = e;
                std::thread::sleep(Duration::from_millis(100));
            }
            Err(e) => panic!("ser2net did not accept connections: {e}"),
        }
    };
    let options = Options { allow_writes: true, allow_counter_change: true, ..Options::default() };
    let report = certify::run(Box::new(line), profile, &options, |_, _, _| {});
    let bad: Vec<_> =
        report.cases.iter().filter(|c| !matches!(c.verdict, CaseVerdict::Pass | CaseVerdict::NotApplicable)).collect();
    assert!(bad.is_empty(), "{bad:#?}");
    assert!(report.line.starts_with("tcp://127.0.0.1:"));
    eprintln!("ser2net run: wall {:.0} ms, physical minimum {:.0} ms", report.wall_time_ms, report.physical_minimum_ms);
    drop(sim);
}
