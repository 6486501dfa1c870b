//! The schemata's mutants against cargo-mutants' own list of the same files: the
//! operators are meant to be cargo-mutants', at the same places, under the same names
//! (spaces aside: the two print tokens slightly differently).

use hiperface_model_mutated::mutant;
use std::collections::BTreeSet;
use std::path::Path;
use std::process::{Command, ExitCode};

/// A name without spaces, for comparing the two tools' printing.
fn squeeze(s: &str) -> String {
    s.chars().filter(|c| !c.is_whitespace()).collect()
}

/// Run the comparison; `list`: cargo-mutants' JSON, or `None` to run it.
pub fn run(list: Option<&Path>) -> Result<ExitCode, String> {
    let text = match list {
        Some(p) => std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?,
        None => {
            let out = Command::new("cargo")
                .args(["mutants", "--list", "--json", "--no-config"])
                .output()
                .map_err(|e| format!("cargo mutants: {e} (install it: cargo install --locked cargo-mutants)"))?;
            if !out.status.success() {
                return Err(format!("cargo mutants --list failed: {}", String::from_utf8_lossy(&out.stderr)));
            }
            String::from_utf8(out.stdout).map_err(|e| e.to_string())?
        }
    };
    let theirs: Vec<serde_json::Value> =
        serde_json::from_str(&text).map_err(|e| format!("cargo-mutants' list: {e}"))?;
    let files: BTreeSet<&str> = mutant::ALL
        .iter()
        .map(|m| m.file)
        .chain(mutant::SKIPPED.iter().filter_map(|s| s.place.split(':').next()))
        .collect();
    let ours: BTreeSet<String> = mutant::ALL
        .iter()
        .map(|m| squeeze(&format!("{}:{}:{}: {}", m.file, m.line, m.column, m.description)))
        .collect();
    let skipped_places: BTreeSet<&str> = mutant::SKIPPED.iter().map(|s| s.place).collect();
    let mut theirs_in_scope = BTreeSet::new();
    let mut missing = Vec::new();
    for m in &theirs {
        let (Some(file), Some(name)) = (m["file"].as_str(), m["name"].as_str()) else { continue };
        if !files.contains(file) {
            continue;
        }
        let squeezed = squeeze(name);
        theirs_in_scope.insert(squeezed.clone());
        let place = name.split(": ").next().unwrap_or("");
        if !ours.contains(&squeezed) && !skipped_places.contains(place) {
            missing.push(name.to_string());
        }
    }
    let extra: Vec<String> = mutant::ALL
        .iter()
        .map(|m| format!("{}:{}:{}: {}", m.file, m.line, m.column, m.description))
        .filter(|n| !theirs_in_scope.contains(&squeeze(n)))
        .collect();
    println!(
        "cargo-mutants makes {} mutants of the {} files; {} are compiled in, {} places skipped with their reasons",
        theirs_in_scope.len(),
        files.len(),
        mutant::ALL.len(),
        skipped_places.len()
    );
    for m in &missing {
        println!("made by cargo-mutants, neither compiled in nor skipped: {m}");
    }
    for m in &extra {
        println!("compiled in, not made by cargo-mutants: {m}");
    }
    Ok(if missing.is_empty() && extra.is_empty() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
