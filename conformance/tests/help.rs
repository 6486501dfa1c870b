//! The command line as a user meets it: `hiperface --help` and every subcommand's
//! `--help`, as snapshots (`tests/snapshots/help__*.snap`). A change of a flag, its
//! unit or its description shows here and is reviewed with the snapshot.

use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_hiperface");

/// Every command path of the CLI.
const COMMANDS: &[&[&str]] = &[
    &[],
    &["certify"],
    &["certify", "slave"],
    &["certify", "master"],
    &["simulate"],
    &["demo"],
    &["profiles"],
    &["check-profile"],
    &["commands"],
    &["vectors"],
    &["vectors", "generate"],
    &["vectors", "verify"],
    &["vectors", "export"],
    &["vectors", "book"],
    &["vectors", "list"],
    &["vectors", "show"],
    &["export-profile"],
    &["master"],
    &["decode"],
    &["compare"],
    &["keygen"],
    &["monitor"],
    &["clauses"],
    &["completions"],
    &["man"],
];

#[test]
fn every_commands_help_is_as_reviewed() {
    for path in COMMANDS {
        let out = Command::new(BIN).args(*path).arg("--help").env("NO_COLOR", "1").output().unwrap();
        assert!(out.status.success(), "{path:?}: {}", String::from_utf8_lossy(&out.stderr));
        let name = if path.is_empty() { "hiperface".to_string() } else { format!("hiperface-{}", path.join("-")) };
        insta::assert_snapshot!(name, String::from_utf8_lossy(&out.stdout));
    }
}

/// Nothing is left out of the list above: every subcommand `--help` names is in it.
#[test]
fn the_list_covers_every_subcommand() {
    for path in COMMANDS {
        let out = Command::new(BIN).args(*path).arg("--help").output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        let Some(commands) = text.split("Commands:\n").nth(1) else { continue };
        for line in commands.lines().take_while(|l| l.starts_with("  ")) {
            let sub = line.split_whitespace().next().unwrap_or("");
            if sub == "help" {
                continue;
            }
            let full: Vec<&str> = path.iter().copied().chain([sub]).collect();
            assert!(COMMANDS.contains(&full.as_slice()), "{full:?} is not in COMMANDS");
        }
    }
}

fn run(args: &[&str]) -> (i32, String) {
    let out = Command::new(BIN).args(args).env("NO_COLOR", "1").output().unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    (out.status.code().unwrap_or(-1), text)
}

/// Every flag in milliseconds takes a decimal and refuses what is no duration, the
/// same way in every subcommand (`certify slave --tolerance-ms` took only integers).
#[rstest::rstest]
#[case(&["certify", "slave", "--port", "virtual", "--tolerance-ms"])]
#[case(&["decode", "capture.log", "--tolerance-ms"])]
#[case(&["monitor", "--port", "/nonexistent", "--tolerance-ms"])]
#[case(&["monitor", "--port", "/nonexistent", "--duration-ms"])]
#[case(&["certify", "master", "--exec", "true", "--polling-period-ms"])]
#[case(&["master", "--port", "virtual", "--polling-period-ms"])]
fn a_flag_in_milliseconds_refuses_a_negative_number(#[case] args: &[&str]) {
    let flag = args.last().unwrap();
    let with_value = format!("{flag}=-1");
    let (code, text) = run(&[&args[..args.len() - 1], &[with_value.as_str()]].concat());
    assert_eq!(code, 2, "{args:?}: {text}");
    assert!(text.contains("invalid value '-1'"), "{args:?}: {text}");
}

#[test]
fn a_tolerance_in_milliseconds_takes_a_decimal() {
    let (code, text) =
        run(&["certify", "slave", "--port", "virtual", "--cases", "protocol.checksum", "--tolerance-ms", "2.5"]);
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("PASSED"), "{text}");
}

/// Renamed flags keep their old name for one release (docs/src/command-line.md).
#[test]
fn the_old_flag_names_still_work() {
    // `master --poll-ms` is `--polling-period-ms`: the reference master on the model in
    // virtual time, for 400 ms of line time.
    let (code, text) = run(&["master", "--port", "virtual", "--poll-ms", "50", "--duration-ms", "400"]);
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("position"), "{text}");
    // `monitor --duration-s` still counts seconds, and is one flag with `--duration-ms`.
    let (code, text) = run(&["monitor", "--port", "/nonexistent", "--duration-s", "1"]);
    assert_eq!(code, 2, "{text}");
    assert!(!text.contains("unexpected argument"), "{text}");
    let (code, text) = run(&["monitor", "--port", "/nonexistent", "--duration-s", "1", "--duration-ms", "5"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("cannot be used with"), "{text}");
    // `clauses --format md` is `--format markdown`.
    let (_, md) = run(&["clauses", "--format", "md"]);
    let (_, markdown) = run(&["clauses", "--format", "markdown"]);
    assert!(md.starts_with('#') || md.starts_with('|'), "{md}");
    assert_eq!(md, markdown);
}

/// A `--port` every subcommand parses the same way; one it cannot serve is refused
/// before anything runs, saying what it takes.
#[rstest::rstest]
#[case(&["simulate", "--port", "tcp://localhost:1"], "the simulator serves a port of its own")]
#[case(&["simulate", "--port", "sim"], "the simulator serves a port of its own")]
#[case(&["certify", "master", "--port", "sim"], "served on a serial port by path")]
#[case(&["certify", "master", "--port", "ftp://x"], "only tcp:// and rfc2217:// are spoken")]
#[case(&["certify", "slave", "--port", "pty"], "give its path")]
fn a_port_a_command_cannot_serve_is_refused_with_why(#[case] args: &[&str], #[case] why: &str) {
    let (code, text) = run(args);
    assert_eq!(code, 2, "{args:?}: {text}");
    assert!(text.contains(why), "{args:?}: {text}");
}

/// Shell completions and manual pages come from the same definition as `--help`.
#[test]
fn completions_and_manual_pages_are_generated() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let (code, text) = run(&["completions", shell]);
        assert_eq!(code, 0, "{shell}: {text}");
        assert!(text.contains("certify") && text.contains("not-used"), "{shell}: {text}");
    }
    let (code, text) = run(&["completions", "bash"]);
    assert!(code == 0 && text.contains("complete -F"), "{text}");
    let (code, page) = run(&["man"]);
    assert_eq!(code, 0, "{page}");
    assert!(page.starts_with(".ie") || page.contains(".TH hiperface 1"), "{page}");
    // On its own it says where the pages it names come from (issue 56).
    assert!(page.contains(".SH FILES") && page.contains("hiperface man \\-\\-out"), "{page}");
    let dir = tempfile::tempdir().unwrap();
    let (code, text) = run(&["man", "--out", dir.path().to_str().unwrap()]);
    assert_eq!(code, 0, "{text}");
    for page in ["hiperface.1", "hiperface-certify.1", "hiperface-certify-slave.1", "hiperface-certify-master.1"] {
        let roff = std::fs::read_to_string(dir.path().join(page)).unwrap_or_else(|e| panic!("{page}: {e}"));
        assert!(roff.contains(".TH"), "{page}");
    }
    assert!(std::fs::read_to_string(dir.path().join("hiperface-certify-master.1")).unwrap().contains("not\\-used"));
}

/// A command whose reader has gone (`| head`) ends quietly: no panic, no backtrace.
#[rstest::rstest]
#[case(&["commands"])]
#[case(&["profiles"])]
#[case(&["clauses"])]
#[case(&["export-profile", "SRS50"])]
#[case(&["completions", "bash"])]
fn a_listing_whose_reader_has_gone_ends_quietly(#[case] args: &[&str]) {
    use std::process::Stdio;
    let mut child = Command::new(BIN).args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    // The reader goes before anything is read: every write of the command meets a
    // closed pipe.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
}

/// The command table in words, not Rust values.
#[test]
fn the_command_table_reads_as_the_document_writes_it() {
    let (code, text) = run(&["commands"]);
    assert_eq!(code, 0);
    assert!(!text.contains("Fixed(") && !text.contains("Range {") && !text.contains("NoFrame"), "{text}");
    let read_data = text.lines().find(|l| l.starts_with("4Ah")).unwrap();
    assert!(read_data.contains("Read Data") && read_data.contains('-'), "{read_data}");
    assert!(text.lines().any(|l| l.starts_with("53h") && l.contains("no frame")), "{text}");
}

/// What is no port is said in words: a regular file, a directory.
#[test]
fn a_file_given_as_a_port_is_named_for_what_it_is() {
    let file = tempfile::NamedTempFile::new().unwrap();
    let (code, text) = run(&["certify", "slave", "--port", file.path().to_str().unwrap()]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("it is a regular file") && !text.contains("typewriter"), "{text}");
    let dir = tempfile::tempdir().unwrap();
    let (code, text) = run(&["monitor", "--port", dir.path().to_str().unwrap(), "--duration-ms", "10"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("it is a directory"), "{text}");
}

/// `--not-used` takes command bytes of Table 10 and refuses anything else.
#[test]
fn a_declaration_of_commands_not_used_is_checked() {
    let (code, text) = run(&["certify", "master", "--exec", "true", "--not-used", "99h"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("not a HIPERFACE command"), "{text}");
    let (code, text) = run(&["certify", "master", "--exec", "true", "--not-used", "4Ah,x"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("not a command byte"), "{text}");
}

/// `clauses --uncovered` with nothing uncovered: the figures, no empty table.
#[test]
fn no_uncovered_clause_prints_no_empty_table() {
    let (code, text) = run(&["clauses", "--uncovered"]);
    assert_eq!(code, 0, "{text}");
    assert!(!text.contains("| clause |"), "{text}");
    assert!(text.contains("0 uncovered"), "{text}");
}
