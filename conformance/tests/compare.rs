//! `hiperface compare` as a CI gate: an independent slave (HX-1) certified clean and
//! with a defect, compared against the clean run as the baseline. The defective run's
//! regression is named and exits 1; the clean run against itself exits 0; what is not
//! a certify report is an input error (exit 2) that says so.

mod common;

use common::hx1::Hx1;
use std::path::Path;
use std::process::{Command, Output};

const CASES: &str = "identity.version,counter.read,position.read";

fn hiperface(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hiperface")).args(args).output().unwrap()
}

/// Certify HX-1 started with `defects` into `dir`.
fn certify_hx1(defects: &[&str], dir: &Path) {
    let hx1 = Hx1::start(defects);
    let profile = common::hx1::dir().join("hx1.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface"))
        .args(["certify", "slave", "--port", &hx1.path, "--allow-writes", "--allow-counter-change"])
        .args(["--cases", CASES])
        .arg("--profile")
        .arg(&profile)
        .arg("--report")
        .arg(dir)
        .output()
        .unwrap();
    drop(hx1);
    assert!(dir.join("report.json").is_file(), "{}", String::from_utf8_lossy(&out.stdout));
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn a_defective_run_regresses_against_the_clean_baseline_and_the_gate_says_where() {
    let _one = common::one_at_a_time();
    let tmp = tempfile::tempdir().unwrap();
    let (clean, defective, out_dir) = (tmp.path().join("clean"), tmp.path().join("defective"), tmp.path().join("cmp"));
    certify_hx1(&[], &clean);
    certify_hx1(&["--defect", "reply-checksum"], &defective);
    let (c, d) = (clean.join("report.json"), defective.join("report.json"));
    let (c, d) = (c.to_str().unwrap(), d.to_str().unwrap());

    let out = hiperface(&["compare", "--baseline", c, c, d, "--report", out_dir.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "a regression: {stdout}{}", String::from_utf8_lossy(&out.stderr));
    // The regression first, naming the case, the report and the clause it now breaks.
    let first = stdout.lines().next().unwrap_or_default();
    assert!(first.starts_with("REGRESSION identity.version in") && first.contains(d), "{stdout}");
    assert!(first.contains("PASS -> FAIL, breaking 000:2.3.3"), "{stdout}");
    assert!(!stdout.lines().any(|l| l.starts_with("REGRESSION") && !l.contains("identity.version")), "{stdout}");
    // Every form, the clean report against itself with no regression in them.
    let md = std::fs::read_to_string(out_dir.join("comparison.md")).unwrap();
    assert!(md.find("## Regressions against the baseline (") < md.find("## Matrix"), "regressions first: {md}");
    assert!(md.lines().any(|l| l.starts_with("| `identity.version` | PASS | PASS | FAIL |")), "{md}");
    let html = std::fs::read_to_string(out_dir.join("comparison.html")).unwrap();
    assert!(html.contains("href=\"#r3-identity.version\"") && html.contains("id=\"r3-identity.version\""), "{html}");
    let junit = std::fs::read_to_string(out_dir.join("comparison-junit.xml")).unwrap();
    assert_eq!(junit.matches("<failure").count(), 1, "one case regressed: {junit}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("comparison.json")).unwrap()).unwrap();
    assert_eq!(json["regressions"][0]["unit"], "identity.version", "{json}");
    assert_eq!(json["regressions"][0]["kind"], "worse", "{json}");

    // The clean run against itself: nothing regressed; a second --report into the same
    // directory moves the first comparison aside.
    let out = hiperface(&["compare", "--baseline", c, c, "--report", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
    assert!(out_dir.join("earlier-run-1").join("comparison.md").is_file(), "the earlier comparison kept");

    // Without a baseline: a matrix, never a gate.
    let out = hiperface(&["compare", c, d]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
}

#[test]
fn what_is_not_a_certify_report_is_an_input_error() {
    let tmp = tempfile::tempdir().unwrap();
    let listening = tmp.path().join("listening.json");
    std::fs::write(&listening, r#"{"tool":"hiperface","profile":"SRS50","summary":{}}"#).unwrap();
    let out = hiperface(&["compare", listening.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("without cases or scenarios"), "{stderr}");
    let out = hiperface(&["compare", tmp.path().join("missing.json").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.json"));
}
