//! The core without I/O: neither the suite nor the C and Python libraries it serves
//! have an operating system's port, a terminal, a process or a progress bar in their
//! trees (issue 39). `cargo tree` reads the lock file: no build.

use std::process::Command;

/// Crates of the harness that the core must never pull in.
const HARNESS_ONLY: [&str; 8] =
    ["serialport", "serial2", "nix", "clap", "indicatif", "ctrlc", "thread-priority", "hiperface-conformance"];

fn tree(package: &str) -> Vec<String> {
    tree_in(package, env!("CARGO_MANIFEST_DIR"))
}

/// The tree of `package` in the workspace at `dir`.
fn tree_in(package: &str, dir: &str) -> Vec<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "-p", package, "-e", "normal", "--prefix", "none", "--format", "{p}"])
        .current_dir(dir)
        .output()
        .expect("cargo runs");
    assert!(out.status.success(), "cargo tree -p {package}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}

#[test]
fn the_suite_and_the_c_and_python_libraries_have_no_io_crate_in_their_trees() {
    // The check sees them where they are: the harness has every one.
    let harness = tree("hiperface-conformance");
    let missing: Vec<_> = HARNESS_ONLY[..7].iter().filter(|c| !harness.iter().any(|h| h == *c)).collect();
    assert!(missing.is_empty(), "the harness's tree as read lacks {missing:?}");
    // The Python package is a workspace of its own (python/, built by maturin).
    let python = concat!(env!("CARGO_MANIFEST_DIR"), "/../python");
    for (package, crates) in [
        ("hiperface-suite", tree("hiperface-suite")),
        ("hiperface-ffi", tree("hiperface-ffi")),
        ("hiperface-py", tree_in("hiperface-py", python)),
    ] {
        assert!(crates.iter().any(|c| c == "hiperface-model"), "{package}: the tree was read: {crates:?}");
        let io: Vec<_> = crates.iter().filter(|c| HARNESS_ONLY.contains(&c.as_str())).collect();
        assert!(io.is_empty(), "{package} pulls in {io:?}");
    }
}

/// No `Result<_, String>` at all, public or not, in the model, the suite or the C
/// library (issue 57; issue 39 asked it of the suite's public API, which this covers): a reason is a type whose `Display` says it, so that a caller can
/// tell one from another without reading words. Read from the sources, test modules
/// included, so that a new one fails here.
#[test]
fn the_core_has_no_string_errors_at_all() {
    fn walk(dir: &std::path::Path, found: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).expect("a source directory reads").flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, found);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).expect("a source reads");
                for (n, line) in text.lines().enumerate() {
                    if string_error(line) {
                        found.push(format!("{}:{}: {}", path.display(), n + 1, line.trim()));
                    }
                }
            }
        }
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    for crate_src in ["suite/src", "model/src", "ffi/src"] {
        let dir = root.join(crate_src);
        assert!(dir.is_dir(), "{} is read", dir.display());
        walk(&dir, &mut found);
    }
    assert!(found.is_empty(), "String errors in the core: {found:#?}");
}

/// A line that names a `Result` whose error is `String`, however it is spaced or
/// nested (`Result<Vec<u8>, String>`, `Result<(), std::string::String>`); comments
/// aside.
fn string_error(line: &str) -> bool {
    let code = line.split("//").next().unwrap_or("").replace(char::is_whitespace, "");
    let mut rest = code.as_str();
    while let Some(at) = rest.find("Result<") {
        rest = &rest[at + "Result<".len()..];
        // The error is what follows the comma at depth 0, up to the closing `>`.
        let mut depth = 0;
        let mut comma = None;
        for (i, c) in rest.char_indices() {
            match c {
                '<' | '(' | '[' => depth += 1,
                '>' | ')' | ']' if depth == 0 => {
                    if let Some(start) = comma {
                        let error =
                            rest[start..i].trim_start_matches("std::string::").trim_start_matches("alloc::string::");
                        if error == "String" {
                            return true;
                        }
                    }
                    break;
                }
                '>' | ')' | ']' => depth -= 1,
                ',' if depth == 0 => comma = Some(i + 1),
                _ => {}
            }
        }
    }
    false
}

#[test]
fn string_errors_are_recognised_however_written() {
    for line in [
        "fn f() -> Result<(), String> {",
        "pub fn f() -> Result<Vec<(u8, u16)>, String> {",
        "    let x: Result<u8 , String> = Ok(1);",
        "fn f() -> Result<HashMap<String, u8>, std::string::String>",
        "let names = |p| -> Result<Vec<String>, String> {",
    ] {
        assert!(string_error(line), "{line}");
    }
    for line in [
        "fn f() -> Result<String, RowError> {",
        "fn f() -> Result<HashMap<u8, String>, Error> {",
        "// Result<(), String> in a comment",
        "fn f() -> Result<(), StringError> {",
    ] {
        assert!(!string_error(line), "{line}");
    }
}
