//! `hiperface decode`, end to end: wire logs, CSV, and the round trip through a VCD
//! waveform and the real sigrok-cli's UART decoder (Debian's package; ignored where
//! it is not installed, required in CI: see `conformance/build.rs`).
//!
//! Long because: the tests run the one command end to end, a capture format each, over
//! fixtures written here and shared.

mod common;

use common::session::{defective, verdicts, wirelog, CT};
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_hiperface");

fn decode(file: &Path, extra: &[&str]) -> (i32, String) {
    let out = Command::new(BIN).arg("decode").arg(file).args(extra).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), text)
}

#[test]
fn a_clean_wire_log_passes_and_a_defective_one_fails_exactly_where_it_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let clean = dir.path().join("clean.log");
    std::fs::write(&clean, wirelog(4, |_, _| None)).unwrap();
    let (code, text) = decode(&clean, &[]);
    assert_eq!(code, 0, "{text}");
    assert_eq!(verdicts(&text), vec!["PASS"; 12], "{text}");

    let bad = dir.path().join("bad.log");
    std::fs::write(&bad, wirelog(4, defective(12.0))).unwrap();
    let (code, text) = decode(&bad, &["--report", dir.path().join("r").to_str().unwrap()]);
    assert_eq!(code, 1, "{text}");
    let v = verdicts(&text);
    let fails: Vec<usize> = v.iter().enumerate().filter(|(_, v)| *v == "FAIL").map(|(i, _)| i).collect();
    assert_eq!(fails, vec![3, 7], "{text}");
    assert!(text.contains("the limit is 5 ms (000:T10)"), "{text}");
    assert!(text.contains("checksum"), "{text}");
    let md = std::fs::read_to_string(dir.path().join("r/listening.md")).unwrap();
    assert!(md.contains("Result: **FAILED**") && md.contains("| 42h Read Position |"), "{md}");
}

#[test]
fn malformed_input_is_rejected_with_its_line_number() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("x.log");
    std::fs::write(&f, "      10.000 ms  M> 40 42 02\n      17.000 ms  S< 40 42 zz\n").unwrap();
    let (code, text) = decode(&f, &["--format", "wirelog"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("line 2"), "{text}");
}

/// An empty capture (no byte, or blanks only) is INCOMPLETE, exit 3, as the guide says:
/// nothing was heard, which is no input error (issue 55: it was exit 2).
#[test]
fn an_empty_capture_is_incomplete() {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in [("empty.csv", ""), ("blank.log", "\n  \n")] {
        let f = dir.path().join(name);
        std::fs::write(&f, text).unwrap();
        let (code, said) = decode(&f, &[]);
        assert_eq!(code, 3, "{name}: {said}");
        assert!(said.contains("INCOMPLETE: nothing could be graded"), "{name}: {said}");
    }
}

/// One channel, no direction: requests and replies told apart by timing and structure.
#[test]
fn a_single_channel_csv_is_graded_like_the_wire_log() {
    let dir = tempfile::tempdir().unwrap();
    let log = wirelog(4, defective(12.0));
    let mut csv = String::from("Time [s],Value,Parity Error,Framing Error\n");
    for l in log.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        let t: f64 = w[0].parse().unwrap();
        let bytes = &w[3..];
        // The CSV stamps each character's start bit.
        let first_start = if w[2] == "M>" { t - CT * bytes.len() as f64 } else { t };
        for (i, b) in bytes.iter().enumerate() {
            csv += &format!("{:.6},0x{b},,\n", (first_start + CT * i as f64) / 1000.0);
        }
    }
    let f = dir.path().join("cap.csv");
    std::fs::write(&f, csv).unwrap();
    let (code, text) = decode(&f, &[]);
    assert_eq!(code, 1, "{text}");
    let (_, from_log) = decode(
        &{
            let p = dir.path().join("bad.log");
            std::fs::write(&p, &log).unwrap();
            p
        },
        &[],
    );
    assert_eq!(verdicts(&text), verdicts(&from_log), "{text}\n---\n{from_log}");
}

/// What a live tap on a busy machine heard (`monitor --capture`): the request of the
/// 15 ms-late reply was read 11 ms late and stamped so, which made the reply look
/// 4 ms after the timeout. With the lateness the monitor measured (its `Read Late`
/// column) that exchange cannot be told: UNKNOWN, never PASS; a reply read late
/// cannot hide an early one either. Without it, the same stamps would PASS.
#[test]
fn what_a_late_read_could_hide_is_unknown() {
    let dir = tempfile::tempdir().unwrap();
    let log = wirelog(4, defective(15.0));
    let csv = |late_request_ms: f64, column: bool| {
        let mut csv = String::from("Time [s],Value,Parity Error,Framing Error,Read Late [s]\n");
        for (n, l) in log.lines().enumerate() {
            let w: Vec<&str> = l.split_whitespace().collect();
            let t: f64 = w[0].parse().unwrap();
            let bytes = &w[3..];
            // The 4th request (line 7 of the log) was read late and stamped at its read.
            let (t, late) = if n == 6 { (t + late_request_ms, late_request_ms) } else { (t, 0.0) };
            let late = if column { format!("{:.6}", late / 1000.0) } else { String::new() };
            let first_start = if w[2] == "M>" { t - CT * bytes.len() as f64 } else { t };
            for (i, b) in bytes.iter().enumerate() {
                csv += &format!("{:.6},0x{b},,,{late}\n", (first_start + CT * i as f64) / 1000.0);
            }
        }
        let f = dir.path().join(format!("cap-{late_request_ms}-{column}.csv"));
        std::fs::write(&f, csv).unwrap();
        f
    };
    let (_, text) = decode(&csv(11.0, false), &[]);
    assert_eq!(verdicts(&text)[3], "PASS", "without the lateness the stamps look on time: {text}");
    let (code, text) = decode(&csv(11.0, true), &[]);
    let v = verdicts(&text);
    assert_eq!((v[3].as_str(), v[7].as_str()), ("UNKNOWN", "FAIL"), "{text}");
    assert!(text.contains("cannot tell whether the reply was on time"), "{text}");
    assert_eq!(v.iter().filter(|v| *v == "PASS").count(), 10, "{text}");
    assert_eq!(code, 1, "{text}");
    // Read only 1 ms late: the late reply is late whatever the truth.
    let (_, text) = decode(&csv(1.0, true), &[]);
    assert_eq!(verdicts(&text)[3], "FAIL", "{text}");
}

/// Session → VCD → sigrok-cli's UART decoder → `decode`: the same verdicts as the
/// wire log's, a parity error seen as such, a break counted.
#[test]
#[cfg_attr(not(has_sigrok_cli), ignore = "sigrok-cli is not installed (apt-get install sigrok-cli)")]
fn the_sigrok_round_trip_reproduces_the_verdicts() {
    let dir = tempfile::tempdir().unwrap();
    let log_path = dir.path().join("bad.log");
    std::fs::write(&log_path, wirelog(4, defective(12.0))).unwrap();
    let vcd = dir.path().join("cap.vcd");
    let (code, text) = decode(&log_path, &["--vcd", vcd.to_str().unwrap()]);
    assert_eq!(code, 0, "{text}");
    let (_, from_log) = decode(&log_path, &[]);
    let decoded = sigrok(&vcd);
    let ann = dir.path().join("ann.txt");
    std::fs::write(&ann, &decoded).unwrap();
    let (code, text) = decode(&ann, &["--samplerate", "1000000", "--master-channel", "uart-1"]);
    assert_eq!(code, 1, "{text}\n{decoded}");
    assert_eq!(verdicts(&text), verdicts(&from_log), "{text}\n---\n{from_log}");

    // A parity error in a reply, and a break on the line after the session.
    let mut ann_text = decoded.clone();
    let line =
        decoded.lines().find(|l| l.starts_with(|c: char| c.is_ascii_digit()) && l.contains("uart-2: 50")).unwrap();
    let end: u64 = line.split(['-', ' ']).nth(1).unwrap().parse().unwrap();
    ann_text = ann_text.replacen(line, &format!("{line}\n{}-{} uart-2: Parity error", end, end + 104), 1);
    let last_end: u64 = decoded.lines().filter_map(|l| l.split(['-', ' ']).nth(1)?.parse().ok()).max().unwrap();
    ann_text += &format!("{}-{} uart-1: Break condition\n", last_end + 50_000, last_end + 53_000);
    std::fs::write(&ann, &ann_text).unwrap();
    let (_, text) = decode(&ann, &["--samplerate", "1000000", "--master-channel", "uart-1"]);
    assert!(text.contains("1 breaks"), "{text}");
    assert!(text.contains("parity or framing error as captured"), "{text}");
}

fn sigrok(vcd: &Path) -> String {
    let out = Command::new("sigrok-cli")
        .args(["-I", "vcd", "-i"])
        .arg(vcd)
        .args([
            "-P",
            "uart:baudrate=9600:parity=even:rx=master",
            "-P",
            "uart:baudrate=9600:parity=even:rx=slave",
            "-A",
            "uart=rx-data:rx-parity-err:rx-warnings:rx-break",
            "--protocol-decoder-samplenum",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// `decode` of a `certify slave --port sim` report plays the record of its wire back:
/// the run's verdicts and exit code. With `--listen` it grades the wire log as a
/// listener would: the run found no deviation of the reference encoder, and the
/// listener, knowing only what it heard, finds none either.
#[test]
fn decoding_a_certify_report_reproduces_its_slave_verdicts() {
    let _one = common::one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("run");
    let out = Command::new(BIN)
        .args(["certify", "slave", "--port", "sim", "--tolerance-ms", "20", "--report"])
        .arg(&report)
        .output()
        .unwrap();
    // Both streams: the summary is on standard output, each FAIL and its finding on
    // standard error.
    let said = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{said}");
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(report.join("report.json")).unwrap()).unwrap();
    let cases = json["cases"].as_array().unwrap();
    let replies: usize =
        cases.iter().map(|c| c["wire"].as_array().unwrap().iter().filter(|w| w["direction"] == "M>").count()).sum();
    assert!(cases.iter().all(|c| c["verdict"] == "PASS" || c["verdict"] == "NOT-APPLICABLE"));
    // The record played back: the run's verdicts and its exit code.
    let (code, text) = decode(&report.join("report.json"), &["--quiet"]);
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("every verdict as the report states it") && text.contains("PASSED"), "{text}");
    // As a listener on the bus hears it: every reply PASSes; the requests the harness
    // malformed on purpose are what a listener hears as a master's FAILs.
    let (code, text) = decode(&report.join("report.json"), &["--quiet", "--listen"]);
    assert_eq!(code, 1, "{text}");
    assert!(text.contains(&format!("{replies} exchanges ({replies} PASS)")), "{replies} exchanges: {text}");
    assert!(text.contains("master: FAIL a frame that is no request"), "{text}");
    assert!(text.contains("note: the master on this wire is the harness"), "said, not left to the reader: {text}");
}

/// A certify report is evidence only where its record gives what it states: each
/// edit below (issue 55) once decoded "PASSED" with exit 0, or was graded as a capture;
/// now each is exit 4 with the difference on the first line, or an error that says
/// what is wrong (exit 2), and the input is never replaced by the output.
#[test]
fn a_report_that_does_not_state_what_its_record_gives_is_no_evidence() {
    let _one = common::one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let out = Command::new(BIN)
        .args(["certify", "slave", "--port", "virtual", "--cases", "position.*", "--report"])
        .arg(&run)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let original = std::fs::read(run.join("report.json")).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&original).unwrap();
    let edited = |name: &str, edit: &dyn Fn(&mut serde_json::Value)| {
        let mut j = json.clone();
        edit(&mut j);
        let path = dir.path().join(format!("{name}.json"));
        std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
        path
    };
    let first_line =
        |text: &str| text.lines().find(|l| !l.contains("played back to this catalogue")).unwrap_or("").to_string();
    // Untouched: it states what its record gives.
    let (code, text) = decode(&run.join("report.json"), &["--quiet"]);
    assert_eq!(code, 0, "{text}");
    assert!(first_line(&text).starts_with("the report states what its record gives"), "{text}");
    // The certificate files beside it are said to be unchecked (a newcomer edited
    // certificate.md, decoded, and took the exit 0 for it).
    assert!(
        text.contains(
            "certificate.md, certificate.html, junit.xml beside it are written from a report and not checked"
        ),
        "{text}"
    );
    // A NOT-APPLICABLE case turned PASS (and its count with it).
    let na = json["cases"].as_array().unwrap().iter().position(|c| c["verdict"] == "NOT-APPLICABLE");
    let na = na.expect("position.sync does not apply to SRS50");
    let turned = edited("turned", &|j| {
        j["cases"][na]["verdict"] = "PASS".into();
    });
    let (code, text) = decode(&turned, &["--quiet"]);
    assert_eq!(code, 4, "{text}");
    assert!(first_line(&text).starts_with("THE REPORT DOES NOT STATE WHAT ITS RECORD GIVES"), "{text}");
    assert!(text.contains("PASS in the report, NOT-APPLICABLE from the record"), "{text}");
    // Its last line is no "PASSED" for a CI that reads the last line.
    assert!(text.contains("NOT EVIDENCE: the report does not state what its record gives"), "{text}");
    assert!(!text.lines().any(|l| l == "PASSED"), "{text}");
    // The counts inflated, the case list left alone.
    let counted = edited("counted", &|j| {
        j["summary"]["PASS"] = 800.into();
    });
    let (code, text) = decode(&counted, &["--quiet"]);
    assert_eq!(code, 4, "{text}");
    assert!(text.contains("the counts: "), "{text}");
    // The record's grading options edited: the report still says strict.
    let lenient = edited("lenient", &|j| {
        j["record"]["options"]["timing"] = "off".into();
    });
    let (code, text) = decode(&lenient, &["--quiet"]);
    assert_eq!(code, 4, "{text}");
    assert!(text.contains("`timing`: \"strict\" in the report, \"off\" in the record's options"), "{text}");
    // One byte that is no UTF-8: an unreadable report, not a capture.
    let mut broken = original.clone();
    let at = broken.windows(7).position(|w| w == b"\"cases\"").unwrap();
    broken[at + 1] = 0xFF;
    let broken_path = dir.path().join("broken.json");
    std::fs::write(&broken_path, &broken).unwrap();
    let (code, text) = decode(&broken_path, &["--quiet"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("cannot be read as a report (JSON)"), "{text}");
    // A record of a format this version does not read: named, not "missing field".
    let older = edited("older", &|j| {
        j["record"]["format"] = "hiperface-master-record/0".into();
    });
    let (code, text) = decode(&older, &["--quiet"]);
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("a record of format `hiperface-master-record/0`, which this version does not read"),
        "{text}"
    );
    // A byte-order mark in front: still the report.
    let bom = dir.path().join("bom.json");
    std::fs::write(&bom, [b"\xEF\xBB\xBF".as_slice(), &original].concat()).unwrap();
    let (code, text) = decode(&bom, &["--quiet"]);
    assert_eq!(code, 0, "{text}");
    // The input is never the output.
    let (code, text) = decode(&run.join("report.json"), &["--quiet", "--report", run.to_str().unwrap()]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("would be replaced"), "{text}");
    assert_eq!(std::fs::read(run.join("report.json")).unwrap(), original);
    // An uncertainty that would call a late reply on time, or overflow.
    for ms in ["60", "1e17"] {
        let (code, text) = decode(&run.join("report.json"), &["--quiet", "--tolerance-ms", ms]);
        assert_eq!(code, 2, "{ms}: {text}");
    }
}

/// A master report whose scenarios are listed again (its counts with them) is no
/// evidence: exit 4, though every listed verdict is PASS.
#[test]
fn a_master_report_listing_its_scenarios_twice_is_no_evidence() {
    let _one = common::one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let master = format!("{BIN} master --port {{port}}");
    let out = Command::new(BIN)
        .args(["certify", "master", "--scenarios", "startup.*", "--exec", &master, "--report"])
        .arg(&run)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(run.join("report.json")).unwrap()).unwrap();
    let (code, text) = decode(&run.join("report.json"), &["--quiet"]);
    assert_eq!(code, 0, "{text}");
    let scenarios = json["scenarios"].as_array().unwrap().clone();
    let n = scenarios.len() as u64;
    json["scenarios"].as_array_mut().unwrap().extend(scenarios);
    json["summary"]["PASS"] = (2 * n).into();
    let twice = dir.path().join("twice.json");
    std::fs::write(&twice, serde_json::to_vec(&json).unwrap()).unwrap();
    let (code, text) = decode(&twice, &["--quiet"]);
    assert_eq!(code, 4, "{text}");
    assert!(text.contains(&format!("{} in the report, {n} from the record", 2 * n)), "{text}");
}

/// An encoder whose Code0 is not the factory 55h takes a new address (55h, 000:T30:
/// the reply already comes from the new address) and answers there. The listener
/// does not know the code; the encoder's acceptance tells it. A reply from the old
/// address after the change is a FAIL.
#[test]
fn an_address_change_with_an_unknown_code0_is_followed() {
    let dir = tempfile::tempdir().unwrap();
    let log = |reply3: &str| {
        [
            ("10.000", "40 42 02", Some("40 42 00 00 00 00 02")),
            ("50.000", "40 55 5F 3C 76", Some("5F 55 0A")),
            ("90.000", "5F 42 1D", Some(reply3)),
            ("130.000", "40 42 02", None),
        ]
        .iter()
        .map(|(t, req, reply)| {
            let t: f64 = t.parse().unwrap();
            let reply = reply.map_or(String::new(), |r| format!("{:.3} ms  S< {r}\n", t + 7.73));
            format!("{t:.3} ms  M> {req}\n{reply}")
        })
        .collect::<String>()
    };
    let good = dir.path().join("good.log");
    std::fs::write(&good, log("5F 42 00 00 00 00 1D")).unwrap();
    let (code, text) = decode(&good, &[]);
    assert_eq!(verdicts(&text), vec!["PASS"; 4], "{text}");
    assert_eq!(code, 0, "{text}");

    let bad = dir.path().join("bad.log");
    std::fs::write(&bad, log("40 42 00 00 00 00 02")).unwrap();
    let (code, text) = decode(&bad, &[]);
    assert_eq!(verdicts(&text), vec!["PASS", "PASS", "FAIL", "PASS"], "{text}");
    assert!(text.contains("000:T30") || text.contains("000:2.3.1"), "{text}");
    assert_eq!(code, 1, "{text}");
}

/// Wire-log lines `(request end ms, request, reply)`, each reply starting `after_ms`
/// after its request ended.
fn exchanges(lines: &[(f64, &str, Option<&str>, f64)]) -> String {
    lines
        .iter()
        .map(|(t, req, reply, after_ms)| {
            let reply = reply.map_or(String::new(), |r| format!("{:.3} ms  S< {r}\n", t + after_ms));
            format!("{t:.3} ms  M> {req}\n{reply}")
        })
        .collect()
}

/// 57h stores a shorter timeout (A4h: 2*11 bit times, 000:T32) with a Code0 the
/// listener does not know; after Encoder Reset and the default window the encoder
/// answers after that timeout. Graded against the old one, the reply would start
/// before the request's timeout had ended; graded against the new one it is on time.
#[test]
fn a_settings_change_takes_effect_after_the_reset() {
    let dir = tempfile::tempdir().unwrap();
    let short = 2.0 * 11.0 / 9.6 + 2.0;
    let f = dir.path().join("57h.log");
    std::fs::write(
        &f,
        exchanges(&[
            (10.0, "40 57 A4 3C 8F", Some("40 57 A4 B3"), 7.73),
            (50.0, "40 53 13", None, 0.0),
            // Past the default window after the reset (000:T9): the stored settings apply.
            (1300.0, "40 42 02", Some("40 42 00 00 00 00 02"), short),
            (1340.0, "40 42 02", Some("40 42 00 00 00 00 02"), short),
        ]),
    )
    .unwrap();
    let (code, text) = decode(&f, &[]);
    assert_eq!(verdicts(&text), vec!["PASS"; 4], "{text}");
    assert_eq!(code, 0, "{text}");
}

/// A signed certificate (issue 55): `keygen`, `certify … --sign`, `decode --verify`.
/// It verifies with the signer's public key; a byte changed in the verdicts, in the
/// record, in a certificate beside it or in the signature, or another lab's key, is
/// exit 5 with the reason first, and nothing is played back. A key made by OpenSSL
/// signs and verifies the same.
#[test]
fn a_signed_certificate_verifies_and_one_changed_byte_anywhere_does_not() {
    let tmp = tempfile::tempdir().unwrap();
    let at = |p: &str| tmp.path().join(p);
    let run = |args: &[&std::ffi::OsStr]| {
        let out = Command::new(BIN).args(args).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
        (out.status.code().unwrap_or(-1), text)
    };
    let os = |s: &str| std::ffi::OsString::from(s);
    let (code, text) = run(&[&os("keygen"), &os("--out"), at("lab.pem").as_os_str()]);
    assert_eq!(code, 0, "{text}");
    let (code, text) = run(&[&os("keygen"), &os("--out"), at("lab.pem").as_os_str()]);
    assert_eq!(code, 2, "a key is never overwritten: {text}");
    let certify = |dir: &str, key: &str| {
        run(&[
            &os("certify"),
            &os("slave"),
            &os("--port"),
            &os("virtual"),
            &os("--cases"),
            &os("position.*,identity.*"),
            &os("--report"),
            at(dir).as_os_str(),
            &os("--sign"),
            at(key).as_os_str(),
        ])
    };
    let (code, text) = certify("run", "lab.pem");
    assert_eq!(code, 0, "{text}");
    let report = at("run/report.json");
    let verify =
        |key: &str| run(&[&os("decode"), report.as_os_str(), &os("--quiet"), &os("--verify"), at(key).as_os_str()]);
    let (code, text) = verify("lab.pem.pub");
    assert_eq!(code, 0, "{text}");
    assert!(text.starts_with("the signature holds: report.json"), "first: {text}");
    assert!(text.contains("every verdict as the report states it"), "then played back: {text}");
    // Without --verify the signature beside it is named as not checked.
    let (code, text) = run(&[&os("decode"), report.as_os_str(), &os("--quiet")]);
    assert_eq!(code, 0, "{text}");
    assert!(
        text.contains("report.sig beside it: the run was signed, and the signature is checked only with --verify"),
        "{text}"
    );
    let original = std::fs::read(&report).unwrap();
    let text_of = String::from_utf8(original.clone()).unwrap();
    // One byte changed: in a verdict, in the record's events, in the options; then in a
    // certificate beside it and in the signature itself.
    let places = [
        text_of.find("\"PASS\"").unwrap() + 1,
        text_of.find("\"events\"").unwrap() + 40,
        text_of.find("\"record\"").unwrap() + 200,
        original.len() - 3,
    ];
    for i in places {
        let mut changed = original.clone();
        changed[i] = if changed[i] == b'A' { b'B' } else { b'A' };
        std::fs::write(&report, &changed).unwrap();
        let (code, text) = verify("lab.pem.pub");
        assert_eq!(code, 5, "byte {i}: {text}");
        assert!(text.starts_with("THE SIGNATURE DOES NOT HOLD: report.json changed"), "byte {i}: {text}");
        assert!(!text.contains("PASSED"), "nothing played back: {text}");
    }
    std::fs::write(&report, &original).unwrap();
    let md = at("run/certificate.md");
    let certificate = std::fs::read_to_string(&md).unwrap();
    std::fs::write(&md, certificate.replacen("PASSED", "PASSES", 1)).unwrap();
    let (code, text) = verify("lab.pem.pub");
    assert!(code == 5 && text.contains("certificate.md changed"), "{text}");
    std::fs::write(&md, &certificate).unwrap();
    let sig = at("run/report.sig");
    let signature = std::fs::read_to_string(&sig).unwrap();
    let at_sig = signature.find("\"signature\": \"").unwrap() + 20;
    let mut edited = signature.clone().into_bytes();
    edited[at_sig] = if edited[at_sig] == b'0' { b'1' } else { b'0' };
    std::fs::write(&sig, &edited).unwrap();
    let (code, text) = verify("lab.pem.pub");
    assert!(code == 5 && text.contains("the signature does not hold"), "{text}");
    std::fs::write(&sig, &signature).unwrap();
    assert_eq!(verify("lab.pem.pub").0, 0, "restored, it verifies again");
    // Another lab's key.
    run(&[&os("keygen"), &os("--out"), at("other.pem").as_os_str()]);
    let (code, text) = verify("other.pem.pub");
    assert!(code == 5 && text.contains("signed with another key"), "{text}");
    // No signature beside it.
    std::fs::remove_file(&sig).unwrap();
    let (code, text) = verify("lab.pem.pub");
    assert!(code == 5 && text.contains("no signature"), "{text}");
    // A private key where a public one belongs, and the reverse: errors before anything.
    assert_eq!(verify("lab.pem").0, 2);
    assert_eq!(certify("run2", "lab.pem.pub").0, 2);
    assert!(!at("run2/report.json").exists(), "a bad key stops the run before it starts");
    // OpenSSL's keys, where OpenSSL is installed.
    let openssl =
        |args: &[&std::ffi::OsStr]| Command::new("openssl").args(args).output().is_ok_and(|o| o.status.success());
    if openssl(&[&os("genpkey"), &os("-algorithm"), &os("ed25519"), &os("-out"), at("o.pem").as_os_str()])
        && openssl(&[
            &os("pkey"),
            &os("-in"),
            at("o.pem").as_os_str(),
            &os("-pubout"),
            &os("-out"),
            at("o.pub").as_os_str(),
        ])
    {
        assert_eq!(certify("run3", "o.pem").0, 0);
        let (code, text) = run(&[
            &os("decode"),
            at("run3/report.json").as_os_str(),
            &os("--quiet"),
            &os("--verify"),
            at("o.pub").as_os_str(),
        ]);
        assert_eq!(code, 0, "{text}");
    }
}
