//! Generates the mutated copy of the model (hiperface-schemata) into OUT_DIR: the
//! model's source with every mutant of the scope below behind its switch, and the
//! table of mutants.

use hiperface_schemata::{generate, table_source, Family, Scope};
use std::path::Path;

/// What is mutated, and as which family of devices: the slave and what it is built of
/// make defective encoders; the reference master, defective masters. The grading
/// oracle, the clause registry, the master's own obligations (its oracle), the
/// built-in profiles (data sheets, not behaviour) and the test encoder's acts (the
/// harness's) are copied unmutated.
fn family_of(rel: &str) -> Option<Family> {
    const ENCODER: [&str; 10] = [
        "address.rs",
        "checksum.rs",
        "command.rs",
        "datalink.rs",
        "fault.rs",
        "frame.rs",
        "profile.rs",
        "request.rs",
        "response.rs",
        "settings.rs",
    ];
    if ENCODER.contains(&rel) || (rel.starts_with("slave/") && rel != "slave/act.rs") {
        return Some(Family::Encoder);
    }
    if rel == "master/reference.rs" || rel == "master/fault_reaction.rs" {
        return Some(Family::Master);
    }
    None
}

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into());
    let src = Path::new(&manifest).join("../../model/src");
    let not_mutated = |_: &str| false;
    let scope = Scope { family_of: &family_of, not_mutated: &not_mutated };
    let generated = match generate(&src, "model/src", &scope) {
        Ok(g) => g,
        Err(e) => {
            println!("cargo::error=the mutated copy of the model could not be made: {e}");
            return;
        }
    };
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-changed={}", src.display());
    for f in &generated.files {
        println!("cargo::rerun-if-changed={}", f.display());
    }
    let out = std::env::var("OUT_DIR").unwrap_or_else(|_| ".".into());
    let out = Path::new(&out);
    let skipped: Vec<String> = generated
        .skipped
        .iter()
        .map(|s| {
            format!(
                "    Skipped {{ place: {:?}, description: {:?}, why: {:?} }},\n",
                s.place.to_string(),
                s.description,
                s.why
            )
        })
        .collect();
    for (name, text) in [
        ("model.rs", generated.code),
        ("mutants.rs", table_source(&generated.mutants)),
        ("skipped.rs", format!("[\n{}]", skipped.concat())),
    ] {
        if let Err(e) = std::fs::write(out.join(name), text) {
            println!("cargo::error=writing {name}: {e}");
        }
    }
}
