//! The README and the user guide (`docs/`, an mdBook) as a reader meets them.
//!
//! - The README stays a front door: fewer than 200 lines, with the two commands CI
//!   runs as "the README's" (`.ci/run`).
//! - Every chapter of `docs/src` (its subfolders too) is in `SUMMARY.md`, and every
//!   relative link of the README and the guide leads to a file that is there and, where
//!   it names an anchor, to a heading of that file (mdBook's and GitHub's rule for a
//!   heading's anchor). A link in the guide stays inside `docs/src`, so that it works in
//!   the built book too.
//! - Every count they state about the program is the program's own, read from its
//!   output, so that a figure cannot go stale: a count is recognised by its phrase
//!   ("33 cases", "22 scenarios", "144 exchanges", "505 vectors", "10 built-in
//!   profiles", "81 of the 82 normative clauses", "1 unobservable clause", "31
//!   actions", "depth 8, 5 184 states, 101 680 transitions", and "N defect switches"
//!   after the name of the independent peer, HX-1, HX-L or HX-M). A count in such a
//!   phrase that is not about the program (a run's history in the design notes) is
//!   listed in `figures::NOT_THE_PROGRAMS` with its words. The model checker's figures are
//!   checked to CI's depth here, the release depth by an ignored test (`--ignored`).
//!   The README's excerpt of the main command's output is what the command prints.
//!   Measured figures (times, rates, sizes) cannot be derived; the guide gives each its
//!   date and its command.
//!
//! links.rs the README, the summary and the links (markdown.rs reading Markdown as far
//! as they need), figures.rs the counts a document states, program.rs the program's
//! own figures and the check of one against the other; here the documents and the
//! catalogue page.

use std::path::{Path, PathBuf};
use std::process::Command;

mod figures;
mod links;
mod markdown;
mod program;

const BIN: &str = env!("CARGO_BIN_EXE_hiperface");

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("the workspace").to_path_buf()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A Markdown file of the README or the guide.
struct Doc {
    path: PathBuf,
    /// Its path from the workspace's root, for messages.
    name: String,
    text: String,
}

impl Doc {
    fn new(name: &str, text: &str) -> Doc {
        Doc { path: root().join(name), name: name.to_string(), text: text.to_string() }
    }
}

/// The guide's chapters (`docs/src/**/*.md`, `SUMMARY.md` and the generated protocol
/// reference in `docs/src/reference/` among them), in path order.
fn chapters() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for path in std::fs::read_dir(dir).expect("docs/src").map(|e| e.expect("docs/src").path()) {
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut paths = Vec::new();
    walk(&root().join("docs/src"), &mut paths);
    paths.sort();
    paths
}

/// README.md and every chapter of the guide.
fn documents() -> Vec<Doc> {
    let root = root();
    std::iter::once(root.join("README.md"))
        .chain(chapters())
        .map(|path| {
            let name = path.strip_prefix(&root).expect("in the workspace").display().to_string();
            Doc { text: read(&path), path, name }
        })
        .collect()
}

/// Runs the command; what it printed (standard error, where the progress goes, then
/// standard output), and its exit code.
fn run(args: &[&str]) -> (String, Option<i32>) {
    let out = Command::new(BIN).args(args).current_dir(root()).env("NO_COLOR", "1").output().expect("hiperface runs");
    let printed = [out.stderr, out.stdout].map(|s| String::from_utf8_lossy(&s).into_owned()).concat();
    (printed, out.status.code())
}

/// The book's catalogue page shows what `certify slave --list` and `certify master
/// --list` print, table for table. `HIPERFACE_BLESS=1` writes the tables into the page.
#[test]
fn the_catalogue_page_is_what_list_prints() {
    let path = root().join("docs/src/catalogue.md");
    let mut page = read(&path);
    for (command, marker) in [("slave", "slave cases"), ("master", "master scenarios")] {
        let (listed, code) = run(&["certify", command, "--list"]);
        assert_eq!(code, Some(0), "certify {command} --list: {listed}");
        let (begin, end) = (format!("<!-- {marker}: begin -->\n"), format!("<!-- {marker}: end -->"));
        let from = page.find(&begin).unwrap_or_else(|| panic!("no {begin:?} in catalogue.md")) + begin.len();
        let to = page[from..].find(&end).map(|i| from + i).unwrap_or_else(|| panic!("no {end:?}"));
        let shown = page[from..to].to_string();
        if std::env::var_os("HIPERFACE_BLESS").is_some() {
            page.replace_range(from..to, &format!("{}\n", listed.trim_end()));
        } else {
            assert_eq!(shown.trim_end(), listed.trim_end(), "catalogue.md's {marker} are stale: HIPERFACE_BLESS=1");
        }
    }
    if std::env::var_os("HIPERFACE_BLESS").is_some() {
        std::fs::write(&path, page).expect("write catalogue.md");
    }
}
