//! Finds the programs some integration tests need (python3 for the independent peers,
//! Debian's ser2net, sigrok-cli), so that a test that cannot run here is reported as
//! ignored, with the reason, in the test summary instead of passing without running.
//! CI installs them and sets `HIPERFACE_REQUIRE_TOOLS=1`: then a missing one stops the
//! build. The search runs again when PATH or that variable changes, or when a program
//! found before disappears; after installing one, `touch conformance/build.rs`.

use std::path::Path;
use std::process::Command;

/// (cfg name, program, where Debian installs it besides PATH)
const TOOLS: [(&str, &str, &[&str]); 3] = [
    ("has_python3", "python3", &[]),
    ("has_ser2net", "ser2net", &["/usr/sbin/ser2net", "/usr/bin/ser2net"]),
    ("has_sigrok_cli", "sigrok-cli", &[]),
];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // The revision a certificate names: the checkout's commit, where there is one.
    let revision = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|r| !r.is_empty())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=HIPERFACE_REVISION={revision}");
    for head in ["../.git/HEAD", "../.git/logs/HEAD"] {
        if Path::new(head).exists() {
            println!("cargo:rerun-if-changed={head}");
        }
    }
    println!("cargo:rerun-if-env-changed=PATH");
    println!("cargo:rerun-if-env-changed=HIPERFACE_REQUIRE_TOOLS");
    let required = std::env::var_os("HIPERFACE_REQUIRE_TOOLS").is_some_and(|v| v != "0");
    for (cfg, program, places) in TOOLS {
        println!("cargo:rustc-check-cfg=cfg({cfg})");
        match find(program, places) {
            Some(path) => {
                println!("cargo:rerun-if-changed={path}");
                println!("cargo:rustc-cfg={cfg}");
            }
            None if required => {
                panic!("{program} is required (HIPERFACE_REQUIRE_TOOLS is set) and was not found")
            }
            None => println!("cargo:warning={program} not found: the tests that need it are ignored"),
        }
    }
}

/// The program's path, where it is there and runs.
fn find(program: &str, places: &[&str]) -> Option<String> {
    let on_path = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).map(|d| d.join(program)).collect::<Vec<_>>())
        .unwrap_or_default();
    let candidates = on_path.into_iter().chain(places.iter().map(|p| Path::new(p).to_path_buf()));
    for candidate in candidates.filter(|c| c.is_file()) {
        // ser2net has no --version that exits 0 everywhere; its presence is enough.
        let runs = program == "ser2net"
            || Command::new(&candidate).arg("--version").output().is_ok_and(|o| o.status.success());
        if runs {
            return Some(candidate.to_string_lossy().into_owned());
        }
    }
    None
}
