//! Golden vectors: every file replays through the model; the generated set is
//! snapshotted (insta), so any change of behaviour shows up as a reviewed diff; bad
//! files are rejected with the file and the vector id.

use hiperface_conformance::vectors::{self, export, Expected};
use rstest::rstest;
use std::path::{Path, PathBuf};
use std::process::Command;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../vectors")
}

#[rstest]
#[case::documents("documents.json")]
#[case::generated_current("generated-current.json")]
#[case::generated_legacy("generated-legacy.json")]
#[case::master_tables("master-tables.json")]
fn every_vector_replays_through_the_model(#[case] name: &str) {
    let file = vectors::load(&dir().join(name)).unwrap_or_else(|e| panic!("{e}"));
    assert!(!file.vectors.is_empty());
    let failures: Vec<String> = file
        .vectors
        .iter()
        .flat_map(|v| vectors::checksum_problems(v).into_iter().map(move |p| format!("{}: {p}", v.id)))
        .chain(file.vectors.iter().filter_map(|v| vectors::replay(v).err().map(|m| m.to_string())))
        .collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn the_files_are_what_the_generator_writes() {
    // documents.json and master-tables.json are sources written from the documents;
    // only the generated files are the generator's.
    for (name, file) in vectors::generate::files() {
        let on_disk = vectors::load(&dir().join(name)).unwrap();
        assert!(on_disk == file, "{name} is out of date: run `hiperface vectors generate vectors`");
    }
}

#[test]
fn the_documents_vectors_cover_what_the_issue_names() {
    let docs = documents();
    let ids: Vec<&str> = docs.vectors.iter().map(|v| v.id.as_str()).collect();
    assert_eq!(ids.iter().filter(|i| i.starts_with("000-t7-")).count(), 2);
    // 19 pairs of 001 §5.1.4 (two errata are shown as printed and as corrected).
    let sections: std::collections::BTreeSet<&str> =
        docs.vectors.iter().filter(|v| v.id.starts_with("001-")).map(|v| v.source.as_str()).collect();
    assert_eq!(sections.len(), 19, "{sections:#?}");
    let printed = docs.vectors.iter().find(|v| v.id == "001-5.1.4.9-data-field-status-as-printed").unwrap();
    assert_eq!(printed.result, Expected::Invalid);
    let legacy = docs.vectors.iter().find(|v| v.id == "002-data-field-example").unwrap();
    assert_eq!(legacy.steps.len(), 6);
    assert_eq!(legacy.erratum.as_ref().map(|e| e.corrected.as_str()), Some("40 4D 01 E0 55 B9"));
}

#[test]
fn generated_set_snapshot() {
    let mut lines = Vec::new();
    for (name, file) in vectors::generate::files() {
        lines.push(format!("# {name}"));
        for v in &file.vectors {
            let steps: Vec<String> =
                v.steps.iter().map(|s| format!("{} -> {}", s.request, s.response.as_deref().unwrap_or("-"))).collect();
            lines.push(format!("{} [{:?}] {}", v.id, v.result, steps.join(" ; ")));
        }
    }
    insta::assert_snapshot!(lines.join("\n"));
}

#[test]
fn every_command_and_error_code_has_a_vector_per_edition() {
    for (name, file) in vectors::generate::files().into_iter().filter(|(n, _)| n.starts_with("generated-")) {
        let legacy = name.contains("legacy");
        let profile =
            if legacy { hiperface_model::profiles::legacy_srs() } else { hiperface_model::profiles::reference() };
        for spec in hiperface_model::COMMAND_TABLE.iter().filter(|s| profile.commands.contains(s.id)) {
            let prefix = format!("{}.{:02x}h.", if legacy { "legacy" } else { "current" }, spec.id.byte());
            assert!(
                file.vectors.iter().any(|v| v.id.starts_with(&prefix) && v.id.ends_with(".ok")),
                "{name}: {prefix} success"
            );
            for code in spec.errors {
                let unproducible = vectors::fixtures::UNPRODUCIBLE.iter().any(|(id, c, _)| *id == spec.id && c == code);
                // 002:47h: a legacy device shows the counter's overflow by the warning
                // bit, not by 08h; its vector says "shows".
                let shown = legacy
                    && spec.id == hiperface_model::CommandId::IncrementCounter
                    && *code == hiperface_model::FaultCode::CounterOverflow;
                let kind = if shown { "shows" } else { "error" };
                let found = file
                    .vectors
                    .iter()
                    .any(|v| v.id.starts_with(&prefix) && v.id.ends_with(&format!("{kind}-{:02x}", code.byte())));
                assert!(found || unproducible, "{name}: {prefix} {code}");
            }
        }
    }
}

/// A character-timed vector is replayed through the data link: a request taken at
/// another time than the model takes it, or characters that the model frames
/// otherwise, do not replay.
#[test]
fn character_timing_is_replayed_through_the_data_link() {
    let file = vectors::load(&dir().join("generated-legacy.json")).unwrap_or_else(|e| panic!("{e}"));
    let short = file.vectors.iter().find(|v| v.id == "legacy.frame-timing.short-timeout").expect("the vector");
    assert!(vectors::replay(short).is_ok());
    // 002's 11 bit times counted from character ends would take it here: not the model.
    let mut early = short.clone();
    let step = &mut early.steps[0];
    step.at_us = step.chars_at_us.last().map(|t| t + 1146);
    let e = vectors::replay(&early).unwrap_err().to_string();
    assert!(e.contains("took the request at"), "{e}");
    // The last character a timeout later: two frames, not one.
    let mut split = short.clone();
    let step = &mut split.steps[0];
    step.chars_at_us[2] = step.chars_at_us[1] + 2292;
    let e = vectors::replay(&split).unwrap_err().to_string();
    assert!(e.contains("frames"), "{e}");
}

/// The documents' examples, as written in the repository.
fn documents() -> vectors::VectorFile {
    vectors::load(&dir().join("documents.json")).unwrap()
}

/// A directory removed when the test ends.
fn temp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn verify_lists_failing_ids_and_exits_non_zero() {
    let tmp = temp();
    let d = tmp.path();
    let mut file = documents();
    let v = file.vectors.iter_mut().find(|v| v.id == "001-5.1.4.1-read-position").unwrap();
    v.steps[0].response = Some("40 42 00 00 00 01 03".into());
    std::fs::write(d.join("x.json"), serde_json::to_string(&file).unwrap()).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface")).args(["vectors", "verify"]).arg(d).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("FAIL x.json: 001-5.1.4.1-read-position: step 1"), "{stdout}");
    assert!(stdout.contains("1 of 24 vectors failed"), "{stdout}");
    // And the shipped files verify.
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface")).args(["vectors", "verify"]).arg(dir()).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
}

#[test]
fn a_malformed_file_names_the_file_and_the_vector() {
    let tmp = temp();
    let d = tmp.path();
    let mut json: serde_json::Value = serde_json::to_value(documents()).unwrap();
    json["testGroups"][1]["tests"][1]["steps"][0]["request"] = "40 4G 02".into();
    let path = d.join("bad.json");
    std::fs::write(&path, json.to_string()).unwrap();
    let e = vectors::load(&path).unwrap_err().to_string();
    assert!(e.starts_with(&format!("{}: vector `", path.display())), "{e}");
    assert!(e.contains("/testGroups/1/tests/1/steps/0/request"), "{e}");
    assert!(e.contains("vector `001-5.1.4.2-set-position`"), "{e}");
    // Not JSON at all.
    std::fs::write(&path, "{").unwrap();
    let e = vectors::load(&path).unwrap_err().to_string();
    assert!(e.contains("bad.json: not JSON"), "{e}");
    // Unknown fields are refused (schema: additionalProperties false).
    json = serde_json::to_value(documents()).unwrap();
    json["testGroups"][0]["tests"][0]["colour"] = "red".into();
    std::fs::write(&path, json.to_string()).unwrap();
    let e = vectors::load(&path).unwrap_err().to_string();
    assert!(e.contains("vector `000-t7-1`"), "{e}");
    // What the schema cannot see: the count, the tcIds, a note for every flag.
    let layout = |edit: fn(&mut serde_json::Value)| {
        let mut json = serde_json::to_value(documents()).unwrap();
        edit(&mut json);
        std::fs::write(&path, json.to_string()).unwrap();
        vectors::load(&path).unwrap_err().to_string()
    };
    let e = layout(|j| j["numberOfTests"] = 99.into());
    assert!(e.contains("numberOfTests says 99, the groups hold 24"), "{e}");
    let e = layout(|j| j["testGroups"][0]["tests"][1]["tcId"] = 7.into());
    assert!(e.contains("test `000-t7-2`: tcId 7, expected 2"), "{e}");
    let e = layout(|j| drop(j["notes"].as_object_mut().unwrap().remove("erratum")));
    assert!(e.contains("flag `erratum` has no entry in `notes`"), "{e}");
}

#[test]
fn export_shows_one_table_per_command_and_errata_as_errata() {
    let files: Vec<_> = vectors::files(&dir()).unwrap().iter().map(|p| vectors::load(p).unwrap()).collect();
    let md = export::markdown(&files);
    assert!(md.contains("\n## 42h\n"), "one table per command");
    assert!(
        md.contains("| `001-5.1.4.9-data-field-status-as-printed` | `40 4C 00 0C` | `40 4C 00 C8 1E` | **invalid** |"),
        "{}",
        &md[..2000]
    );
    assert!(md.contains("**erratum**: printed `40 4C 00 C8 1E`, corrected `40 4C 00 C8 C4`"));
    let tables = export::tables(&files);
    assert!(tables.iter().any(|t| t.command == "checksum"));
    let json = serde_json::to_string(&tables).unwrap();
    assert!(json.contains("\"command\":\"4Dh\""));
}

#[test]
fn master_tables_are_the_printed_tables() {
    // Transcribed by hand: every row of 000 Table 72, the synchronisation table of
    // 3.2.5, the three octant tables of 3.2.4 and Table 74, each citing its row.
    let m = vectors::load(&dir().join("master-tables.json")).unwrap();
    let count = |t: &str| m.vectors.iter().filter(|v| v.table_case.as_ref().is_some_and(|c| c.table == t)).count();
    assert_eq!((count("quadrature"), count("sync")), (16, 16));
    assert_eq!((count("octant"), count("transformation"), count("retransformation")), (8, 8, 8));
    assert_eq!(count("fault-reaction"), 47 + 1, "Table 74's 47 printed rows and the unknown code");
    assert!(m.vectors.iter().all(|v| v.source.contains(" row ") || v.id.contains("unknown")));
    // The evaluator answers in the printed words, so a wrong model is caught: one
    // printed row altered must fail.
    let mut wrong = m.vectors.iter().find(|v| v.id == "master.t72.row02").unwrap().clone();
    wrong.table_case.as_mut().unwrap().output = "-1".into();
    assert!(vectors::replay(&wrong).is_err());
}
