//! Rules of the workspace's sources, checked as tests (issue 57): a file is read in one
//! sitting, so none is longer than [`MAX_LINES`], and one past [`EXPLAIN_ABOVE`] says
//! in its first [`REASON_WITHIN`] lines why its concept is one file, in a comment
//! beginning `Long because:` (`//! Long because: ...` or `// Long because: ...`).
//! Read from the sources, so that a file that grows past either bound fails here.

use std::path::{Path, PathBuf};

/// No source file is longer.
const MAX_LINES: usize = 800;

/// A source file longer than this says why.
const EXPLAIN_ABOVE: usize = 450;

/// The reason is in the file's first lines, where a reader starts.
const REASON_WITHIN: usize = 15;

/// The words a reason begins with, after `//!` or `//`.
const REASON: &str = "Long because:";

/// Where the workspace's Rust lives: its crates, the Python package's module, the
/// firmware image (outside the workspace, the same rules).
const SOURCES: [&str; 8] =
    ["model", "suite", "conformance", "ffi", "proofs", "mutants", "python/src", "firmware/encoder-rs"];

/// Files known to break the rules and not split yet (issue 57 item 5): each must still
/// break a rule (a stale entry fails), and no other file may.
const PENDING: &[(&str, &str)] = &[];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("the workspace").to_path_buf()
}

/// The `.rs` files under `dir`, build output and fuzzing corpora left out.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())).flatten() {
        let path = entry.path();
        let name = entry.file_name();
        if path.is_dir() {
            if !matches!(name.to_str(), Some("target" | "fuzz" | "corpus" | "regressions")) {
                sources(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// What is wrong with a source's length, if anything.
fn broken_rule(text: &str) -> Option<String> {
    let lines = text.lines().count();
    if lines > MAX_LINES {
        return Some(format!("{lines} lines, more than {MAX_LINES}: split it by concept"));
    }
    let explained = text.lines().take(REASON_WITHIN).any(|line| {
        let line = line.trim_start();
        let comment = line.strip_prefix("//!").or_else(|| line.strip_prefix("//")).map(str::trim_start);
        comment.and_then(|c| c.strip_prefix(REASON)).is_some_and(|why| !why.trim().is_empty())
    });
    (lines > EXPLAIN_ABOVE && !explained).then(|| {
        format!("{lines} lines, more than {EXPLAIN_ABOVE}, and no `{REASON} ...` comment in its first {REASON_WITHIN} lines")
    })
}

#[test]
fn every_source_is_short_or_says_why_and_none_is_past_the_limit() {
    let root = root();
    let mut files = Vec::new();
    for dir in SOURCES {
        let dir = root.join(dir);
        assert!(dir.is_dir(), "{} is read", dir.display());
        sources(&dir, &mut files);
    }
    assert!(files.len() > 100, "the sources were read: {} files", files.len());
    let mut problems = Vec::new();
    for path in &files {
        let name = path.strip_prefix(&root).expect("in the workspace").to_string_lossy().replace('\\', "/");
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let pending = PENDING.iter().any(|(p, _)| *p == name);
        match (broken_rule(&text), pending) {
            (Some(why), false) => problems.push(format!("{name}: {why}")),
            (None, true) => problems.push(format!("{name}: meets the rules now: take it off PENDING")),
            _ => {}
        }
    }
    for (p, _) in PENDING.iter().filter(|(p, _)| !root.join(p).is_file()) {
        problems.push(format!("{p}: on PENDING, but not there"));
    }
    assert!(problems.is_empty(), "the length rules: {problems:#?}");
}

#[test]
fn the_length_rules_are_read_as_stated() {
    let lines = |n: usize, head: &str| format!("{head}{}", "x\n".repeat(n - head.lines().count()));
    assert_eq!(broken_rule(&lines(EXPLAIN_ABOVE, "")), None);
    assert!(broken_rule(&lines(EXPLAIN_ABOVE + 1, "")).is_some());
    assert_eq!(broken_rule(&lines(EXPLAIN_ABOVE + 1, "//! A module.\n//! Long because: one table.\n")), None);
    assert_eq!(broken_rule(&lines(EXPLAIN_ABOVE + 1, "// Long because: one state machine.\n")), None);
    // Said too late, or with nothing after it, is not said.
    let late = format!("{}// Long because: one table.\n", "//!\n".repeat(REASON_WITHIN));
    assert!(broken_rule(&lines(EXPLAIN_ABOVE + 1, &late)).is_some());
    assert!(broken_rule(&lines(EXPLAIN_ABOVE + 1, "//! Long because:\n")).is_some());
    // A reason does not buy more than the limit.
    assert_eq!(broken_rule(&lines(MAX_LINES, "//! Long because: one table.\n")), None);
    assert!(broken_rule(&lines(MAX_LINES + 1, "//! Long because: one table.\n")).is_some());
}
