//! Nothing graded is never PASSED, in every command: a selection of no case, a capture
//! with nothing in it or nothing readable, a directory with no vector. And a broken
//! vector is one failure, however many things are wrong with it.

use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_hiperface");

fn run(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(BIN).args(args).output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr))
}

#[test]
fn a_case_selection_that_matches_nothing_is_an_error() {
    let (code, text) = run(&["certify", "slave", "--port", "virtual", "--cases", "nomatch*"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("no case matches `nomatch*`") && !text.contains("PASSED"), "{text}");
    // A selection that matches runs and passes.
    let (code, text) = run(&["certify", "slave", "--port", "virtual", "--cases", "identity.*"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("PASSED"), "{text}");
}

#[test]
fn an_empty_capture_is_not_passed() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.log");
    std::fs::write(&empty, "").unwrap();
    let (code, text) = run(&["decode", empty.to_str().unwrap(), "--format", "wirelog"]);
    assert_eq!(code, Some(3), "{text}");
    assert!(text.contains("INCOMPLETE: nothing could be graded"), "{text}");
}

#[test]
fn a_capture_of_nonsense_is_not_passed_and_its_line_errors_are_counted() {
    // A logic-analyzer CSV of random bytes on one channel, a third with a framing or
    // parity error flag: frames that are neither requests nor replies.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("noise.csv");
    let mut text = String::from("time,value,parity error,framing error\n");
    let mut x: u32 = 0x1234_5678;
    let mut flagged = 0;
    for i in 0..3000u32 {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        let (parity, framing) = (x % 6 == 0, x % 6 == 1);
        flagged += usize::from(parity || framing);
        // Bursts of 12 characters, a pause of 10 ms between bursts.
        let t = i as f64 * 0.001_2 + (i / 12) as f64 * 0.010;
        text += &format!("{t:.6},0x{:02X},{},{}\n", x >> 24, u8::from(parity), u8::from(framing));
    }
    std::fs::write(&path, text).unwrap();
    let (code, out) = run(&["decode", path.to_str().unwrap(), "--format", "csv", "--quiet"]);
    assert_eq!(code, Some(3), "{out}");
    assert!(out.contains("INCOMPLETE") && !out.contains("PASSED"), "{out}");
    assert!(out.contains(&format!("({flagged} with a line error)")), "{flagged} flagged: {out}");
}

#[test]
fn verifying_no_vector_is_an_error_and_a_broken_vector_counts_once() {
    let dir = tempfile::tempdir().unwrap();
    let (code, text) = run(&["vectors", "verify", dir.path().to_str().unwrap()]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("no vectors to verify"), "{text}");
    // One vector of the documents' file with its reply corrupted: wrong checksum and
    // wrong contents, two reasons, one failing vector.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../vectors");
    let original = std::fs::read_to_string(root.join("documents.json")).unwrap();
    let corrupted = original.replacen("\"40 42 00 00 00 00 02\"", "\"40 42 00 00 00 01 02\"", 1);
    assert_ne!(corrupted, original, "the documents hold the Read Position example");
    std::fs::write(dir.path().join("documents.json"), corrupted).unwrap();
    std::fs::copy(root.join("schema.json"), dir.path().join("schema.json")).unwrap();
    let (code, text) = run(&["vectors", "verify", dir.path().to_str().unwrap()]);
    assert_eq!(code, Some(1), "{text}");
    assert_eq!(text.lines().filter(|l| l.starts_with("FAIL ")).count(), 1, "{text}");
    assert!(text.contains("1 of "), "{text}");
}
