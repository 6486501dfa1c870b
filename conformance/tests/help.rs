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
    &["export-profile"],
    &["master"],
    &["decode"],
    &["monitor"],
    &["clauses"],
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
