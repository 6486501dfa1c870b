//! Golden vectors: every file replays through the model; the generated set is
//! snapshotted (insta), so any change of behaviour shows up as a reviewed diff; bad
//! files are rejected with the file and the vector id.
//!
//! Long because: the tests share the vector files, the generated set's snapshot and the
//! helpers that corrupt a file, and each bad file is a few lines.

use hiperface_suite::vectors::{self, export, Expected};
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

// ---------------------------------------------------------------------------------
// The protocol reference (docs/src/reference/), generated from the vector files
// ---------------------------------------------------------------------------------

/// The vector files with their names, as `hiperface vectors book` loads them.
fn named_files() -> Vec<(String, vectors::VectorFile)> {
    vectors::load_named(&dir()).unwrap()
}

fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/src/reference")
}

/// The Markdown pages and the style sheet of a folder and the SVG diagrams of its `svg/`, by name
/// (`svg/exchange-42h.svg`).
fn pages_in(dir: &Path) -> Vec<(String, String)> {
    let mut pages = Vec::new();
    for (sub, ext) in [("", "md"), ("", "css"), ("svg", "svg")] {
        let Ok(entries) = std::fs::read_dir(dir.join(sub)) else { continue };
        for p in entries.map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == ext)) {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let name = if sub.is_empty() { name } else { format!("{sub}/{name}") };
            pages.push((name, std::fs::read_to_string(&p).unwrap()));
        }
    }
    pages.sort();
    pages
}

/// The pages written into `dir` as they are named (making `svg/`).
fn write_pages(dir: &Path, pages: &[(String, String)]) {
    for (name, text) in pages {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
}

/// What is stale in the reference at `dir`, against what the generator writes now.
fn stale(dir: &Path) -> Vec<String> {
    let expected = vectors::reference::book(&named_files());
    vectors::reference::differences(&expected, &pages_in(dir))
}

#[test]
fn the_reference_is_what_the_generator_writes() {
    let stale = stale(&reference_dir());
    assert!(
        stale.is_empty(),
        "docs/src/reference is out of date; regenerate it with `{}` (or `cargo run -p hiperface-conformance -- \
         vectors book --out docs/src/reference`):\n{}",
        vectors::reference::REGENERATE,
        stale.join("\n")
    );
    // And the user guide's summary lists every page, as the generator lists them.
    let summary = std::fs::read_to_string(reference_dir().join("../SUMMARY.md")).unwrap();
    let listed = vectors::reference::summary(&vectors::reference::book(&named_files()));
    assert!(
        summary.contains(&format!("# Protocol reference\n\n{listed}")),
        "docs/src/SUMMARY.md does not list the reference's pages under `# Protocol reference` as:\n{listed}"
    );
}

#[test]
fn a_changed_byte_in_the_reference_is_caught() {
    let tmp = temp();
    write_pages(tmp.path(), &pages_in(&reference_dir()));
    assert!(stale(tmp.path()).is_empty(), "the copy is the committed reference");
    // A diagram changed is caught as a page is.
    let svg = tmp.path().join("svg/exchange-42h.svg");
    let drawn = std::fs::read_to_string(&svg).unwrap();
    std::fs::write(&svg, drawn.replacen("</svg>", "<!-- edited --></svg>", 1)).unwrap();
    assert_eq!(stale(tmp.path()).len(), 1, "{:?}", stale(tmp.path()));
    std::fs::write(&svg, drawn).unwrap();
    // One byte of a diagram: 40 42 02 becomes 40 42 03.
    let page = tmp.path().join("42h-read-position.md");
    let text = std::fs::read_to_string(&page).unwrap();
    let cell = "<td class=\"hf-b hf-sum\">02</td>";
    assert!(text.contains(cell), "Read Position's checksum cell");
    std::fs::write(&page, text.replacen(cell, &cell.replace("02", "03"), 1)).unwrap();
    let stale = stale(tmp.path());
    assert_eq!(stale.len(), 1, "{stale:?}");
    assert!(stale[0].starts_with("42h-read-position.md: differs from line "), "{stale:?}");
}

/// A frame a page shows: its caption (request, reply, as printed, corrected), its bytes
/// as the cells give them, and the checksum line after its tables.
#[derive(Debug)]
struct Shown {
    page: String,
    caption: String,
    bytes: Vec<u8>,
    checksum_line: String,
}

/// `s` without its HTML tags.
fn untagged(s: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for c in s.chars() {
        match c {
            '<' => inside = true,
            '>' => inside = false,
            c if !inside => out.push(c),
            _ => {}
        }
    }
    out
}

/// The byte diagrams of a page, read back from their HTML: a frame is a `hf-f` block of
/// tables (sixteen bytes each), the bytes in its `hf-b` cells; a block without a byte
/// is a silence.
fn shown_frames(page: &str, text: &str) -> Vec<Shown> {
    let mut out = Vec::new();
    for part in text.split("<div class=\"hf-f\">").skip(1) {
        let block = part.split_once("</div>").expect("a frame's end").0;
        let mut bytes = Vec::new();
        for cell in block.split("<td class=\"hf-b").skip(1) {
            let value = cell.split_once('>').and_then(|(_, v)| v.split_once("</td>")).expect("a byte cell").0;
            bytes.push(u8::from_str_radix(value, 16).unwrap_or_else(|_| panic!("{page}: a byte cell holds {value}")));
        }
        if bytes.is_empty() {
            continue;
        }
        let caption = block.split_once("<caption>").and_then(|(_, c)| c.split_once("</caption>")).expect("a caption").0;
        let line = block
            .split_once("<p class=\"hf-xor\">")
            .and_then(|(_, l)| l.split_once("</p>"))
            .map_or(String::new(), |(l, _)| untagged(l));
        out.push(Shown { page: page.to_string(), caption: caption.to_string(), bytes, checksum_line: line });
    }
    out
}

/// Every request and every reply of the vector files (setup requests among the
/// requests).
fn vector_frames() -> (std::collections::BTreeSet<Vec<u8>>, std::collections::BTreeSet<Vec<u8>>) {
    let (mut requests, mut replies) = (std::collections::BTreeSet::new(), std::collections::BTreeSet::new());
    for (_, file) in named_files() {
        for v in &file.vectors {
            requests.extend(v.setup.requests.iter().map(|r| vectors::parse_hex(r).unwrap()));
            for s in &v.steps {
                requests.insert(vectors::parse_hex(&s.request).unwrap());
                replies.extend(s.response.iter().map(|r| vectors::parse_hex(r).unwrap()));
            }
        }
    }
    (requests, replies)
}

/// What is wrong with the frames shown: one that is no request or reply of a vector (an
/// erratum's printed and corrected frames are frames of vectors too), a checksum line
/// that does not work out the frame's bytes.
fn wrong_frames(shown: &[Shown]) -> Vec<String> {
    let (requests, replies) = vector_frames();
    let mut wrong = Vec::new();
    for f in shown {
        let hex = vectors::hex(&f.bytes);
        let at = format!("{}: {} [{hex}]", f.page, f.caption);
        let known = match f.caption.as_str() {
            "request" => requests.contains(&f.bytes),
            "reply" => replies.contains(&f.bytes),
            _ => requests.contains(&f.bytes) || replies.contains(&f.bytes),
        };
        if !known {
            wrong.push(format!("{at}: no vector has this frame"));
        }
        let n = f.bytes.len();
        if n < 3 {
            if f.checksum_line.contains("XOR") {
                wrong.push(format!("{at}: a checksum worked out for a frame without one"));
            }
            continue;
        }
        let operands: Vec<String> = f.bytes[..n - 1].iter().map(|b| format!("{b:02X}h")).collect();
        let xor = f.bytes[..n - 1].iter().fold(0, |a, b| a ^ b);
        let mut expected = format!("checksum: {} = {xor:02X}h", operands.join(" XOR "));
        if xor != f.bytes[n - 1] {
            expected.push_str(&format!("; the frame carries {:02X}h: wrong", f.bytes[n - 1]));
        }
        if f.checksum_line != expected {
            wrong.push(format!("{at}: the checksum line says \"{}\", not \"{expected}\"", f.checksum_line));
        }
    }
    wrong
}

/// What is wrong with the XORs a page works out anywhere ("40h XOR 42h = 02h").
fn wrong_xors(page: &str, text: &str) -> (Vec<String>, usize) {
    let text = untagged(text);
    let words: Vec<&str> = text.split_whitespace().collect();
    let byte = |w: &str| {
        let w = w.trim_end_matches([',', ';', '.', ')']);
        (w.len() == 3 && w.ends_with('h')).then(|| u8::from_str_radix(&w[..2], 16).ok()).flatten()
    };
    let (mut wrong, mut checked) = (Vec::new(), 0);
    for (i, w) in words.iter().enumerate() {
        if *w != "=" || i < 3 || words[i - 2] != "XOR" {
            continue;
        }
        let mut j = i - 1;
        let mut operands = vec![byte(words[j])];
        while j >= 2 && words[j - 1] == "XOR" {
            j -= 2;
            operands.push(byte(words[j]));
        }
        let (Some(operands), Some(result)) =
            (operands.into_iter().collect::<Option<Vec<u8>>>(), words.get(i + 1).and_then(|w| byte(w)))
        else {
            wrong.push(format!("{page}: an XOR not of bytes: {}", words[j..=i + 1].join(" ")));
            continue;
        };
        checked += 1;
        if operands.iter().fold(0, |a, b| a ^ b) != result {
            wrong.push(format!("{page}: {} is wrong", words[j..=i + 1].join(" ")));
        }
    }
    (wrong, checked)
}

#[test]
fn every_frame_of_the_reference_is_a_vectors_and_every_checksum_is_right() {
    let pages = pages_in(&reference_dir());
    let shown: Vec<Shown> = pages.iter().flat_map(|(p, t)| shown_frames(p, t)).collect();
    let wrong = wrong_frames(&shown);
    assert!(wrong.is_empty(), "frames of the reference:\n{}", wrong.join("\n"));
    let mut xors = 0;
    for (page, text) in &pages {
        let (wrong, checked) = wrong_xors(page, text);
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
        xors += checked;
    }
    // Not vacuous: every frame of 3 bytes or more has its checksum worked out, and the
    // index works out 000 Table 7's two.
    let with_checksum = shown.iter().filter(|f| f.bytes.len() >= 3).count();
    assert!(with_checksum > 200, "only {with_checksum} frames found");
    assert_eq!(xors, with_checksum + 2);
    // Every example of the documents is there (001's 19 pairs, 002's sequence), each
    // erratum with its printed and its corrected frame.
    let all: String = pages.iter().map(|(_, t)| t.as_str()).collect();
    for v in documents().vectors.iter() {
        assert!(all.contains(&format!("`{}`", v.id)), "the reference does not show {}", v.id);
    }
    let errata = shown.iter().filter(|f| f.caption == "as printed").count();
    assert_eq!(errata, 3, "001's 4Ch and 57h, 002's 4Dh");
}

#[test]
fn a_frame_no_vector_has_or_a_wrong_checksum_is_caught() {
    let page = "<div class=\"hf-f\"><table class=\"hf-frame\"><caption>request</caption>\n<tr>\
                <td class=\"hf-b hf-addr\">40</td><td class=\"hf-b hf-cmd\">42</td><td class=\"hf-b hf-sum\">02</td>\
                </tr></table>\n<p class=\"hf-xor\">checksum: <code>40h XOR 42h = 02h</code></p>\n</div>";
    assert!(wrong_frames(&shown_frames("x.md", page)).is_empty());
    let unknown = page.replace(">42<", ">43<");
    let wrong = wrong_frames(&shown_frames("x.md", &unknown));
    assert_eq!(wrong.len(), 2, "{wrong:?}");
    assert!(wrong[0].ends_with("x.md: request [40 43 02]: no vector has this frame"), "{wrong:?}");
    assert!(wrong[1].contains("not \"checksum: 40h XOR 43h = 03h; the frame carries 02h: wrong\""), "{wrong:?}");
    let (wrong, checked) = wrong_xors("x.md", "<code>40h XOR 4Eh XOR 70h XOR 00h = 7Eh</code>, 40h XOR 42h = 03h.");
    assert_eq!(checked, 2);
    assert_eq!(wrong, ["x.md: 40h XOR 42h = 03h. is wrong"]);
}

#[test]
fn vectors_book_writes_the_reference() {
    let tmp = temp();
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface"))
        .args(["vectors", "book", "--dir"])
        .arg(dir())
        .arg("--out")
        .arg(tmp.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains(" pages (the index, a chapter per command, timing, "), "{stdout}");
    assert!(stdout.contains(" diagrams\n"), "{stdout}");
    assert!(stale(tmp.path()).is_empty(), "the command writes what the generator gives");
}

#[test]
fn every_diagram_of_the_reference_is_well_formed_svg_and_shown() {
    let pages = pages_in(&reference_dir());
    let diagrams: Vec<&(String, String)> = pages.iter().filter(|(n, _)| n.ends_with(".svg")).collect();
    assert!(diagrams.len() >= 5, "exchange, power-up of both editions, 53h, 67h: {diagrams:?}");
    let markdown: String = pages.iter().filter(|(n, _)| n.ends_with(".md")).map(|(_, t)| t.as_str()).collect();
    for (name, svg) in diagrams {
        let doc = roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("{name} is not well-formed XML: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg", "{name}");
        assert_eq!(doc.root_element().tag_name().namespace(), Some("http://www.w3.org/2000/svg"), "{name}");
        assert!(markdown.contains(&format!("]({name})")), "no page shows {name}");
    }
    // The check itself fails on a broken document.
    assert!(
        roxmltree::Document::parse("<svg xmlns=\"http://www.w3.org/2000/svg\"><text>a &amp b</text></svg>").is_err()
    );
}

#[test]
fn every_hex_frame_the_reference_prints_is_a_vectors() {
    // Byte diagrams are checked above; frames also appear as hex in code spans (the
    // starting state's requests, the editions' table).
    let (requests, replies) = vector_frames();
    let mut checked = 0;
    for (page, text) in pages_in(&reference_dir()).iter().filter(|(n, _)| n.ends_with(".md")) {
        for span in text.split('`').skip(1).step_by(2) {
            let Ok(bytes) = vectors::parse_hex(span) else { continue };
            if bytes.len() < 3 {
                continue;
            }
            checked += 1;
            assert!(
                requests.contains(&bytes) || replies.contains(&bytes),
                "{page}: `{span}` is no request or reply of a vector"
            );
        }
    }
    assert!(checked > 20, "only {checked} frames in code spans");
}

#[test]
fn vectors_show_exports_one_example_or_diagram() {
    let show = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_hiperface"))
            .args(["vectors", "show", "--dir"])
            .arg(dir())
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    // An example in Markdown, as the book has it: no style in its text (the book's
    // frames.css styles its classes).
    let (code, md, _) = show(&["001-5.1.4.1-read-position"]);
    assert_eq!(code, Some(0));
    assert!(!md.contains("<style>") && md.contains("class=\"hf-frame\""), "{md}");
    assert!(md.contains("`001-5.1.4.1-read-position`"), "{md}");
    assert!(md.contains("<code>40h XOR 42h = 02h</code>"), "{md}");
    // A standalone page.
    let (code, html, _) = show(&["001-5.1.4.1-read-position", "--format", "html"]);
    assert_eq!(code, Some(0));
    assert!(html.starts_with("<!DOCTYPE html>"), "{html}");
    assert!(html.contains("<h3>") && html.contains("<table class=\"hf-frame\">"), "{html}");
    assert!(html.contains("table.hf-frame td.hf-bad"), "a standalone page carries the style: {html}");
    // A diagram as SVG, the same as the book's file.
    let (code, svg, _) = show(&["exchange-42h"]);
    assert_eq!(code, Some(0));
    let book = std::fs::read_to_string(reference_dir().join("svg/exchange-42h.svg")).unwrap();
    assert_eq!(svg, book);
    // What cannot be: an unknown id, an example as SVG.
    let (code, _, err) = show(&["no-such-id"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("no vector or diagram has the id \"no-such-id\"") && err.contains("exchange-42h"), "{err}");
    let (code, _, err) = show(&["001-5.1.4.1-read-position", "--format", "svg"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("SVG is for the timing diagrams"), "{err}");
    // Anywhere, as after `cargo install`: the vector files built into the command, the
    // same pieces (issue 56: "error: vectors: No such file or directory").
    let elsewhere = temp();
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface"))
        .current_dir(elsewhere.path())
        .args(["vectors", "show", "001-5.1.4.1-read-position"])
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&out.stdout), md, "{}", String::from_utf8_lossy(&out.stderr));
    // A folder that is not there is named as the flag it came from.
    let (code, _, err) = {
        let out = Command::new(env!("CARGO_BIN_EXE_hiperface"))
            .args(["vectors", "show", "exchange-42h", "--dir", "/nonexistent/vectors"])
            .output()
            .unwrap();
        (out.status.code(), (), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    assert_eq!(code, Some(2));
    assert!(err.contains("--dir /nonexistent/vectors"), "{err}");
    // Every id there is, listed, each one `show` takes.
    let out = Command::new(env!("CARGO_BIN_EXE_hiperface")).args(["vectors", "list"]).output().unwrap();
    let listed = String::from_utf8_lossy(&out.stdout).into_owned();
    let ids: Vec<&str> = listed.lines().filter_map(|l| l.split('\t').next()).collect();
    let vectors: usize = named_files().iter().map(|(_, f)| f.vectors.len()).sum();
    assert_eq!(ids.len(), vectors + 5, "{listed}");
    assert!(ids.contains(&"001-5.1.4.1-read-position") && ids.contains(&"exchange-42h"), "{listed}");
    let (code, _, err) = show(&["no-such-id"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("`hiperface vectors list` lists every id"), "{err}");
}
