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
//!   listed in [`NOT_THE_PROGRAMS`] with its words. The model checker's figures are
//!   checked to CI's depth here, the release depth by an ignored test (`--ignored`).
//!   The README's excerpt of the main command's output is what the command prints.
//!   Measured figures (times, rates, sizes) cannot be derived; the guide gives each its
//!   date and its command.

use std::collections::{HashMap, HashSet};
use std::path::{Component, Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_hiperface");

/// Counts in a checked phrase that are not the program's figure, with the words around
/// them (whitespace collapsed) and the file they are in: each must still be there.
const NOT_THE_PROGRAMS: &[(&str, &str)] = &[
    // A development run's history: the legacy settings that failed part of the catalogue.
    ("docs/src/design.md", "failed 25 cases of the reference's own catalogue"),
    // A measurement's history: the scenarios in which HX-M's first request was read late.
    ("docs/src/design.md", "late by the kernel in 18 scenarios while its interpreter started"),
    // The benchmark's generated input, a parameter of the benchmark.
    ("docs/src/watching-a-live-bus.md", "a generated wire log of 100 000 exchanges"),
];

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

// ---------------------------------------------------------------------------------
// Markdown, as far as links and headings need it
// ---------------------------------------------------------------------------------

/// `text` with its fenced code blocks blanked (every character but a line break made a
/// space): the line numbers stay.
fn without_fences(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    // The open fence's character and length.
    let mut open: Option<(char, usize)> = None;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        let fence = trimmed.chars().next().filter(|c| *c == '`' || *c == '~').map(|c| {
            let n = trimmed.chars().take_while(|x| *x == c).count();
            (c, n, trimmed[n..].trim().is_empty())
        });
        let blank = match (open, fence) {
            (None, Some((c, n, _))) if n >= 3 && indent <= 3 => {
                open = Some((c, n));
                true
            }
            (Some((c, n)), Some((f, m, only))) if f == c && m >= n && only => {
                open = None;
                true
            }
            (Some(_), _) => true,
            (None, _) => false,
        };
        if blank {
            out.extend(line.chars().map(|c| if c == '\n' { '\n' } else { ' ' }));
        } else {
            out.push_str(line);
        }
    }
    out
}

/// `text` with its inline code spans blanked as well: what Markdown reads as prose,
/// line for line. A span does not reach past a blank line; an unmatched run of
/// backticks is text.
fn prose(text: &str) -> String {
    let chars: Vec<char> = without_fences(text).chars().collect();
    let run = |i: usize| chars[i..].iter().take_while(|c| **c == '`').count();
    let mut out = chars.clone();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' {
            i += 1;
            continue;
        }
        let n = run(i);
        // The closing run of exactly n backticks, within the paragraph.
        let mut j = i + n;
        let mut close = None;
        while j < chars.len() {
            if chars[j] == '\n' && chars[j + 1..].iter().take_while(|c| **c != '\n').all(|c| c.is_whitespace()) {
                break;
            }
            if chars[j] == '`' {
                let m = run(j);
                if m == n {
                    close = Some(j + m);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(end) => {
                for c in &mut out[i..end] {
                    if *c != '\n' {
                        *c = ' ';
                    }
                }
                i = end;
            }
            None => i += n,
        }
    }
    out.into_iter().collect()
}

/// A link's destination, and the line it is on.
#[derive(Debug)]
struct Link {
    line: usize,
    target: String,
}

/// Every link of `text` outside code: inline (`[text](target)`, `[text](target "title")`,
/// `[text](<target>)`, images alike) and reference definitions (`[label]: target`).
fn links(text: &str) -> Vec<Link> {
    let prose = prose(text);
    let chars: Vec<char> = prose.chars().collect();
    let mut out = Vec::new();
    let mut line = 1;
    for i in 0..chars.len() {
        if chars[i] == '\n' {
            line += 1;
        }
        if chars[i] != ']' || chars.get(i + 1) != Some(&'(') {
            continue;
        }
        let mut target = String::new();
        let mut j = i + 2;
        if chars.get(j) == Some(&'<') {
            target.extend(chars[j + 1..].iter().take_while(|c| **c != '>'));
        } else {
            let mut depth = 0;
            while let Some(&c) = chars.get(j) {
                match c {
                    '(' => depth += 1,
                    ')' if depth == 0 => break,
                    ')' => depth -= 1,
                    c if c.is_whitespace() => break,
                    _ => {}
                }
                target.push(c);
                j += 1;
            }
        }
        out.push(Link { line, target });
    }
    for (n, l) in prose.lines().enumerate() {
        let t = l.trim_start();
        if l.len() - t.len() > 3 || !t.starts_with('[') {
            continue;
        }
        if let Some(k) = t.find("]:") {
            if let Some(target) = t[k + 2..].split_whitespace().next() {
                out.push(Link { line: n + 1, target: target.trim_matches(['<', '>']).to_string() });
            }
        }
    }
    out
}

/// A heading's anchor as mdBook and GitHub make it: the heading's text (a link's text
/// without its destination, code without its backticks) lower-cased, each whitespace
/// character a '-', every other character but letters, digits, '-' and '_' dropped.
fn slug(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading;
    // A link's destination is not part of the heading's text.
    while let Some(k) = rest.find("](") {
        text.push_str(&rest[..k]);
        let after = &rest[k + 2..];
        rest = after.find(')').map_or("", |e| &after[e + 1..]);
    }
    text.push_str(rest);
    text.trim()
        .chars()
        .flat_map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                c.to_lowercase().collect::<Vec<_>>()
            } else if c.is_whitespace() {
                vec!['-']
            } else {
                vec![]
            }
        })
        .collect()
}

/// The anchors of `text`'s headings (ATX, outside code blocks); a repeated one gets
/// `-1`, `-2`, ... as mdBook and GitHub number them.
fn anchors(text: &str) -> HashSet<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = HashSet::new();
    for line in without_fences(text).lines() {
        let t = line.trim_start();
        let hashes = t.chars().take_while(|c| *c == '#').count();
        let rest = &t[hashes..];
        if line.len() - t.len() > 3 || !(1..=6).contains(&hashes) || !(rest.is_empty() || rest.starts_with(' ')) {
            continue;
        }
        let base = slug(rest.trim().trim_end_matches('#'));
        let n = seen.entry(base.clone()).or_insert(0);
        out.insert(if *n == 0 { base.clone() } else { format!("{base}-{n}") });
        *n += 1;
    }
    out
}

/// `path` with `.` and `..` taken out, without asking the file system (it may not be
/// there).
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

// ---------------------------------------------------------------------------------
// The README, the summary, the links
// ---------------------------------------------------------------------------------

#[test]
fn the_readme_is_a_front_door_with_the_two_commands() {
    let readme = read(&root().join("README.md"));
    let lines = readme.lines().count();
    assert!(lines < 200, "README.md has {lines} lines: it is the front door; move the rest into the guide (docs/src)");
    // CI runs them as "the README's main command" and "the README's test command".
    let ci = read(&root().join(".ci/run"));
    for command in [
        "cargo run --release -p hiperface-conformance -- certify slave --port sim",
        "cargo test --workspace --no-fail-fast",
    ] {
        assert!(readme.contains(&format!("```sh\n{command}\n```")), "README.md does not give `{command}` on its own");
        let shared = command.split(" -- ").last().expect("a command");
        assert!(ci.contains(shared), ".ci/run does not run the README's `{command}`");
    }
}

#[test]
fn every_chapter_is_in_the_summary() {
    let summary = root().join("docs/src/SUMMARY.md");
    let listed: HashSet<String> = links(&read(&summary)).into_iter().map(|l| l.target).collect();
    for chapter in chapters().iter().filter(|p| **p != summary) {
        let name = chapter.strip_prefix(root().join("docs/src")).expect("in docs/src").to_string_lossy().to_string();
        assert!(listed.contains(&name), "docs/src/{name} is not in SUMMARY.md: the built book would not have it");
    }
    for target in &listed {
        assert!(root().join("docs/src").join(target).is_file(), "SUMMARY.md lists {target}, which is not there");
    }
}

/// What is wrong with the relative links of `docs`: a target that is not there, an
/// anchor no heading of the target has, a link of the guide that leads out of it.
fn broken_links(docs: &[Doc]) -> (Vec<String>, usize) {
    let book = root().join("docs/src");
    let mut broken = Vec::new();
    let mut checked = 0;
    for doc in docs {
        for link in links(&doc.text) {
            let t = link.target.as_str();
            if t.is_empty() || ["http://", "https://", "mailto:"].iter().any(|s| t.starts_with(s)) {
                continue;
            }
            checked += 1;
            let at = format!("{}:{}: ({t})", doc.name, link.line);
            let (path, anchor) = t.split_once('#').map_or((t, None), |(p, a)| (p, Some(a)));
            let target = if path.is_empty() {
                doc.path.clone()
            } else {
                lexical(&doc.path.parent().expect("a directory").join(path.replace("%20", " ")))
            };
            if !path.is_empty() && !target.exists() {
                broken.push(format!("{at}: there is no {}", target.display()));
                continue;
            }
            if doc.path.starts_with(&book) && !target.starts_with(&book) {
                broken.push(format!("{at}: leads out of docs/src, so the built book has no such page"));
            }
            if let Some(anchor) = anchor.filter(|_| target.extension().is_some_and(|e| e == "md")) {
                let text = if target == doc.path { doc.text.clone() } else { read(&target) };
                if !anchors(&text).contains(anchor) {
                    broken.push(format!("{at}: {} has no heading with the anchor #{anchor}", target.display()));
                }
            }
        }
    }
    (broken, checked)
}

#[test]
fn every_relative_link_leads_to_a_file_and_a_heading_that_are_there() {
    let (broken, checked) = broken_links(&documents());
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
    // The check sees the links: the README alone links every chapter.
    assert!(checked >= 20, "only {checked} relative links found");
}

#[test]
fn a_broken_link_or_anchor_is_caught() {
    let doc = Doc::new(
        "docs/src/x.md",
        "# A heading\n\n[here](#a-heading), [there](measured.md), [`code`](design.md#kani),\n\
         [gone](nowhere.md), [no anchor](measured.md#nowhere), [out](../../README.md)\n\n\
         ```sh\n# [not a link](nowhere.md)\n```\n`[nor this](nowhere.md)`\n",
    );
    let (broken, checked) = broken_links(&[doc]);
    assert_eq!(checked, 6, "{broken:?}");
    assert_eq!(broken.len(), 3, "{broken:?}");
    assert!(broken[0].contains("x.md:4: (nowhere.md)"), "{broken:?}");
    assert!(broken[1].contains("#nowhere"), "{broken:?}");
    assert!(broken[2].contains("leads out of docs/src"), "{broken:?}");
}

#[test]
fn anchors_follow_the_rule_of_mdbook_and_github() {
    let text = "# Lab lines: echo, RS-485 mode, RFC 2217, parity\n## Live: `hiperface monitor`\n\
                ## Protocol decisions (cited as `DESIGN:…`)\n## Names\n## Names\n```\n# not a heading\n```\n";
    let a = anchors(text);
    for id in
        ["lab-lines-echo-rs-485-mode-rfc-2217-parity", "live-hiperface-monitor", "protocol-decisions-cited-as-design"]
    {
        assert!(a.contains(id), "{id} not in {a:?}");
    }
    assert!(a.contains("names") && a.contains("names-1") && !a.contains("not-a-heading"), "{a:?}");
}

// ---------------------------------------------------------------------------------
// The figures
// ---------------------------------------------------------------------------------

/// What a count is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Figure {
    /// The slave catalogue's cases.
    Cases,
    /// The master catalogue's scenarios.
    Scenarios,
    /// The exchanges of the main command's run (`certify slave --port sim`).
    Exchanges,
    /// The golden vectors in `vectors/`.
    Vectors,
    /// The built-in profiles.
    Profiles,
    /// The normative clauses of the registry (and, in "N of the M normative clauses",
    /// those cited).
    NormativeClauses,
    /// The normative clauses listed as unobservable on the serial line.
    Unobservable,
    /// The model checker's alphabet.
    Actions,
    /// The states and transitions the model checker explores to a depth.
    States,
    Transitions,
    /// An independent peer's defect switches.
    DefectSwitches,
}

/// The phrases a count is recognised by.
const PHRASES: &[(&str, Figure)] = &[
    ("cases", Figure::Cases),
    ("scenarios", Figure::Scenarios),
    ("exchanges", Figure::Exchanges),
    ("vectors", Figure::Vectors),
    ("built-in profiles", Figure::Profiles),
    ("normative clauses", Figure::NormativeClauses),
    ("unobservable clause", Figure::Unobservable),
    ("unobservable clauses", Figure::Unobservable),
    ("actions", Figure::Actions),
    ("states", Figure::States),
    ("transitions", Figure::Transitions),
    ("defect switches", Figure::DefectSwitches),
    ("defects", Figure::DefectSwitches),
];

/// A count a document states.
#[derive(Debug)]
struct Stated {
    doc: String,
    /// Where the number starts in the document, and its line.
    at: usize,
    line: usize,
    figure: Figure,
    number: u64,
    /// The number and its phrase as written, whitespace collapsed ("1 549 mutants").
    words: String,
    /// The paragraph it is in up to the number, whitespace collapsed.
    before: String,
    /// The whole paragraph, whitespace collapsed.
    paragraph: String,
}

/// `text` with each run of whitespace one space, and where each of its bytes was.
fn flatten(text: &str) -> (String, Vec<usize>) {
    let mut flat = String::with_capacity(text.len());
    let mut at = Vec::with_capacity(text.len());
    let mut space = false;
    for (i, c) in text.char_indices() {
        if c.is_whitespace() {
            if !space {
                flat.push(' ');
                at.push(i);
            }
            space = true;
        } else {
            space = false;
            flat.push(c);
            at.extend(std::iter::repeat_n(i, c.len_utf8()));
        }
    }
    (flat, at)
}

/// The number that `flat[..end]` ends with, thousands grouped by spaces ("1 549"),
/// and where it starts; none where it is part of a word or a decimal ("HX-1", "1.5").
fn number_before(flat: &str, end: usize) -> Option<(u64, usize)> {
    let b = flat.as_bytes();
    let digits = |to: usize| b[..to].iter().rev().take_while(|c| c.is_ascii_digit()).count();
    let mut start = end - digits(end);
    if start == end {
        return None;
    }
    let mut group = end - start;
    // "1 549": a group of 1 to 3 digits, a space, then groups of 3.
    while group == 3 && start >= 2 && b[start - 1] == b' ' {
        let n = digits(start - 1);
        if !(1..=3).contains(&n) {
            break;
        }
        start -= 1 + n;
        group = n;
    }
    if start > 0 && (b[start - 1].is_ascii_alphanumeric() || b"-.,/_".contains(&b[start - 1])) {
        return None;
    }
    let number = flat[start..end].replace(' ', "").parse().ok()?;
    Some((number, start))
}

/// Every count `doc` states in one of the [`PHRASES`], code blocks included (a
/// comment states a figure too); the words of a phrase may be split across lines.
fn stated(doc: &Doc) -> Vec<Stated> {
    let mut out = Vec::new();
    let text = &doc.text;
    let (flat, at) = flatten(text);
    for (phrase, figure) in PHRASES {
        for (k, _) in flat.match_indices(&format!(" {phrase}")) {
            let end = k + 1 + phrase.len();
            // A whole word, and not a rate ("vectors/s").
            if flat[end..].chars().next().is_some_and(|c| c.is_alphanumeric() || c == '/' || c == '-') {
                continue;
            }
            let Some((number, start)) = number_before(&flat, k) else { continue };
            let original = at[start];
            let paragraph_start = text[..original].rfind("\n\n").map_or(0, |p| p + 2);
            let paragraph_end = text[original..].find("\n\n").map_or(text.len(), |p| original + p);
            let before = flatten(&text[paragraph_start..original]).0;
            out.push(Stated {
                doc: doc.name.clone(),
                at: original,
                line: text[..original].matches('\n').count() + 1,
                figure: *figure,
                number,
                words: flat[start..end].to_string(),
                before,
                paragraph: flatten(&text[paragraph_start..paragraph_end]).0,
            });
        }
    }
    out.sort_by_key(|s| s.at);
    out
}

/// The program's own figures; a figure that is `None` (or a peer not named) is not
/// checked.
#[derive(Debug, Default)]
struct Program {
    cases: Option<u64>,
    scenarios: Option<u64>,
    exchanges: Option<u64>,
    vectors: Option<u64>,
    profiles: Option<u64>,
    /// Normative clauses: in the registry, cited, listed as unobservable.
    normative: Option<(u64, u64, u64)>,
    actions: Option<u64>,
    /// The model checker is run to the depths the docs name up to this one (a depth
    /// of 20 takes minutes in a debug build).
    model_checker_depth: usize,
    /// An independent peer's defect switches, by its name.
    defect_switches: HashMap<&'static str, u64>,
    /// What the main command printed.
    main_output: String,
}

/// The peers whose defect switches the docs count, and where they are.
const PEERS: &[(&str, &str)] = &[
    ("HX-1", "conformance/tests/independent/hx1_slave.py"),
    ("HX-L", "conformance/tests/independent/hxl_slave.py"),
    ("HX-M", "conformance/tests/independent/hx_master.py"),
    ("HX-E", "python/tests/independent_encoder.py"),
];

/// The model checker's depth in CI (`cargo test -p hiperface-proofs`): a second in a
/// debug build.
const CI_DEPTH: usize = 8;

/// The model checker's states and transitions to a depth, computed once per depth.
fn explored(depth: usize) -> (u64, u64) {
    use std::sync::{Mutex, OnceLock};
    static DONE: OnceLock<Mutex<HashMap<usize, (u64, u64)>>> = OnceLock::new();
    let done = DONE.get_or_init(Default::default);
    if let Some(r) = done.lock().expect("not poisoned").get(&depth) {
        return *r;
    }
    let r = hiperface_proofs::model_check::explore(depth).expect("the model checker's invariants hold");
    let r = (r.states as u64, r.transitions);
    done.lock().expect("not poisoned").insert(depth, r);
    r
}

/// What is wrong with the counts `docs` state, against `program`; and how many of
/// each figure were checked.
fn wrong_figures(docs: &[Doc], program: &Program) -> (Vec<String>, HashMap<Figure, usize>) {
    let mut wrong = Vec::new();
    let mut checked: HashMap<Figure, usize> = HashMap::new();
    let mut excused = HashSet::new();
    for s in docs.iter().flat_map(stated) {
        let at = format!("{}:{}: \"{}\"", s.doc, s.line, s.words);
        if let Some(e) = NOT_THE_PROGRAMS
            .iter()
            .find(|(doc, words)| *doc == s.doc && words.contains(&s.words) && s.paragraph.contains(words))
        {
            excused.insert(e.1);
            continue;
        }
        let expected = match s.figure {
            Figure::Cases => program.cases,
            Figure::Scenarios => program.scenarios,
            Figure::Exchanges => program.exchanges,
            Figure::Vectors => program.vectors,
            Figure::Profiles => program.profiles,
            Figure::Unobservable => program.normative.map(|(_, _, unobservable)| unobservable),
            Figure::Actions => program.actions,
            Figure::NormativeClauses => program.normative.map(|(normative, cited, _)| {
                // "81 of the 82 normative clauses": the first is how many are cited.
                if let Some(of) = s.before.trim_end().strip_suffix(" of the") {
                    match number_before(of, of.len()) {
                        Some((n, _)) if n != cited => {
                            wrong.push(format!("{at}: the program cites {cited} of the {normative}, not {n}"))
                        }
                        _ => {}
                    }
                }
                normative
            }),
            Figure::States | Figure::Transitions if program.model_checker_depth > 0 => {
                // The depth: the last named before the count, "depth 8, 5 184 states" or
                // "HF_MC_DEPTH=20 cargo test ... explores 72 770 states".
                let depth = ["depth ", "HF_MC_DEPTH="]
                    .iter()
                    .filter_map(|key| s.before.rfind(key).map(|i| (i, &s.before[i + key.len()..])))
                    .max_by_key(|(i, _)| *i)
                    .and_then(|(_, d)| d.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok());
                let Some(depth) = depth else {
                    wrong.push(format!("{at}: explored to which depth? (\"depth D, S states, T transitions\")"));
                    continue;
                };
                if depth > program.model_checker_depth {
                    continue;
                }
                let (states, transitions) = explored(depth);
                Some(if s.figure == Figure::States { states } else { transitions })
            }
            Figure::States | Figure::Transitions => None,
            Figure::DefectSwitches => {
                // The peer named last before the count, in its paragraph.
                let peer = PEERS
                    .iter()
                    .filter_map(|(name, _)| s.before.rfind(name).map(|i| (i, *name)))
                    .max()
                    .map(|(_, name)| name);
                let Some(peer) = peer else {
                    wrong
                        .push(format!("{at}: whose defect switches? Name the peer (HX-1, HX-L, HX-M, HX-E) before it"));
                    continue;
                };
                program.defect_switches.get(peer).copied()
            }
        };
        let Some(expected) = expected else { continue };
        *checked.entry(s.figure).or_default() += 1;
        if s.number != expected {
            wrong.push(format!("{at}: the program's figure is {expected}"));
        }
    }
    for (doc, words) in NOT_THE_PROGRAMS {
        if docs.iter().any(|d| d.name == *doc) && !excused.contains(words) {
            wrong.push(format!("{doc}: NOT_THE_PROGRAMS lists \"{words}\", which it no longer says"));
        }
    }
    (wrong, checked)
}

/// Runs the command; what it printed (standard error, where the progress goes, then
/// standard output), and its exit code.
fn run(args: &[&str]) -> (String, Option<i32>) {
    let out = Command::new(BIN).args(args).current_dir(root()).env("NO_COLOR", "1").output().expect("hiperface runs");
    let printed = [out.stderr, out.stdout].map(|s| String::from_utf8_lossy(&s).into_owned()).concat();
    (printed, out.status.code())
}

/// The number of units in a report.json (its `cases` or its `scenarios`), and the sum
/// of their exchanges.
fn units_and_exchanges(report: &Path, units: &str) -> (u64, u64) {
    let report: serde_json::Value = serde_json::from_str(&read(report)).expect("report.json is JSON");
    let cases = report[units].as_array().unwrap_or_else(|| panic!("no {units} in {report}"));
    let exchanges = cases.iter().map(|c| c["exchanges"].as_u64().expect("a count of exchanges")).sum();
    (cases.len() as u64, exchanges)
}

/// The program's figures, each from its own output.
fn program() -> Program {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let report = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let mut p = Program { model_checker_depth: CI_DEPTH, ..Program::default() };

    // The main command: its cases and its exchanges.
    let (out, code) = run(&["certify", "slave", "--port", "sim", "--report", &report("slave")]);
    assert_eq!(code, Some(0), "the main command does not pass:\n{out}");
    let (cases, exchanges) = units_and_exchanges(&dir.path().join("slave/report.json"), "cases");
    (p.cases, p.exchanges, p.main_output) = (Some(cases), Some(exchanges), out);

    // The master catalogue: a master that exits at once ends each scenario early
    // (an ERROR), so the catalogue runs in a moment; the report lists every scenario.
    let (out, code) = run(&["certify", "master", "--exec", "true", "--report", &report("master")]);
    assert_ne!(code, Some(2), "certify master does not start:\n{out}");
    p.scenarios = Some(units_and_exchanges(&dir.path().join("master/report.json"), "scenarios").0);

    let (out, code) = run(&["profiles"]);
    assert_eq!(code, Some(0), "{out}");
    p.profiles = Some(out.lines().filter(|l| !l.trim().is_empty()).count() as u64);

    // "505 vectors verified: ..."
    let (out, code) = run(&["vectors", "verify", "vectors"]);
    assert_eq!(code, Some(0), "{out}");
    let verified = out.lines().find_map(|l| l.split_once(" vectors verified")).expect("vectors verified").0;
    p.vectors = Some(verified.trim().parse().expect("a count"));

    // "81 of 82 normative clauses are cited ...; 1 cannot be observed ...; 0 uncovered."
    let (out, code) = run(&["clauses"]);
    assert_eq!(code, Some(0), "{out}");
    let last = out.lines().rev().find(|l| l.contains("normative clauses are cited")).expect("the coverage line");
    let count = |s: Option<&str>| s.and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok()).expect(last);
    let words: Vec<&str> = last.split_whitespace().collect();
    let (cited, normative) = (count(words.first().copied()), count(words.get(2).copied()));
    p.normative = Some((normative, cited, count(last.split("; ").nth(1))));

    p.actions = Some(hiperface_proofs::model_check::alphabet().len() as u64);
    p
}

/// The lines of the README's excerpt of the main command's output (the `text` block
/// after the command) that the command does not print; "..." leaves lines out, and
/// the wall-time line, a measurement, is compared with its numbers left out.
fn excerpt_not_printed(readme: &str, output: &str) -> Vec<String> {
    let after = readme.split_once("certify slave --port sim\n```\n").expect("the main command in the README").1;
    let excerpt = after
        .split_once("```text\n")
        .and_then(|(_, b)| b.split_once("```"))
        .expect("an excerpt of the main command's output after it in the README")
        .0;
    let numbers_out =
        |l: &str| l.split(|c: char| c.is_ascii_digit()).filter(|s| !s.is_empty()).collect::<Vec<_>>().join("#");
    excerpt
        .lines()
        .filter(|l| l.trim() != "...")
        .filter(|l| {
            // A case run again on a busy machine says so after its id: the same line.
            let again = |o: &str| o.strip_prefix(*l).is_some_and(|rest| rest.starts_with(" ("));
            !output
                .lines()
                .any(|o| o == *l || again(o) || (l.starts_with("wall time ") && numbers_out(o) == numbers_out(l)))
        })
        .map(str::to_string)
        .collect()
}

#[test]
fn every_count_stated_is_the_programs() {
    let mut program = program();
    let printed = std::mem::take(&mut program.main_output);
    let missing = excerpt_not_printed(&read(&root().join("README.md")), &printed);
    assert!(
        missing.is_empty(),
        "lines of the README's excerpt that the main command does not print:\n{}\n\nit printed:\n{printed}",
        missing.join("\n"),
    );
    let (wrong, checked) = wrong_figures(&documents(), &program);
    assert!(wrong.is_empty(), "figures that are not the program's ({program:?}):\n{}", wrong.join("\n"));
    // The docs still state each figure: a check that finds nothing checks nothing.
    for figure in [
        Figure::Cases,
        Figure::Scenarios,
        Figure::Exchanges,
        Figure::Vectors,
        Figure::Profiles,
        Figure::NormativeClauses,
        Figure::Unobservable,
        Figure::Actions,
        Figure::States,
        Figure::Transitions,
    ] {
        assert!(checked.get(&figure).is_some_and(|n| *n > 0), "no count of {figure:?} found: {checked:?}");
    }
    eprintln!("counts checked: {checked:?}");
}

#[test]
#[ignore = "explores to the release depth the docs name (20): minutes in a debug build; \
            cargo test --release -p hiperface-conformance --test docs -- --ignored"]
fn the_deeper_model_checking_figures_are_the_programs() {
    let program = Program { model_checker_depth: usize::MAX, ..Default::default() };
    let (wrong, checked) = wrong_figures(&documents(), &program);
    assert!(wrong.is_empty(), "model-checking figures that are not the program's:\n{}", wrong.join("\n"));
    assert!(checked.get(&Figure::States).is_some_and(|n| *n >= 2), "{checked:?}");
}

/// The peer's defect switches, as it lists them.
fn defect_switches(script: &str) -> u64 {
    let path = root().join(script);
    if script.ends_with("hx_master.py") {
        // HX-M names the ones it knows when given one it does not.
        let out = Command::new("python3").arg(&path).args(["/dev/null", "--defect", "?"]).output().expect("python3");
        let err = String::from_utf8_lossy(&out.stderr);
        let known = err.split_once("known: ").unwrap_or_else(|| panic!("{script}: {err}")).1;
        known.trim().split(", ").count() as u64
    } else {
        let out = Command::new("python3").arg(&path).arg("--list-defects").output().expect("python3");
        assert!(out.status.success(), "{script} --list-defects: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).lines().filter(|l| !l.trim().is_empty()).count() as u64
    }
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn every_count_of_defect_switches_is_the_peers() {
    let defect_switches = PEERS.iter().map(|(name, script)| (*name, defect_switches(script))).collect();
    let program = Program { defect_switches, ..Default::default() };
    let (wrong, checked) = wrong_figures(&documents(), &program);
    assert!(
        wrong.is_empty(),
        "defect switches that are not the peers' ({:?}):\n{}",
        program.defect_switches,
        wrong.join("\n")
    );
    assert!(checked.get(&Figure::DefectSwitches).is_some_and(|n| *n >= 3), "{checked:?}");
}

#[test]
fn a_stale_count_is_caught() {
    let program = Program {
        cases: Some(33),
        scenarios: Some(22),
        exchanges: Some(144),
        defect_switches: [("HX-1", 16), ("HX-M", 17)].into_iter().collect(),
        ..Default::default()
    };
    let doc = Doc::new(
        "docs/src/x.md",
        "The catalogue of 33 cases and\n22 scenarios.\n\nHX-1, with 16 defect switches; HX-M's 17\ndefect switches.\n\n\
         A run of 144 exchanges at 398 000 exchanges/s; HX-1's 14 defect switches, 21 scenarios, \
         about 700 exchanges, 32 cases.\n\n16 defects of whom?\n",
    );
    let (wrong, checked) = wrong_figures(&[doc], &program);
    assert_eq!(wrong.len(), 5, "{wrong:#?}");
    for (w, why) in wrong.iter().zip([
        "x.md:7: \"14 defect switches\": the program's figure is 16",
        "x.md:7: \"21 scenarios\": the program's figure is 22",
        "x.md:7: \"700 exchanges\": the program's figure is 144",
        "x.md:7: \"32 cases\": the program's figure is 33",
        "x.md:9: \"16 defects\": whose defect switches?",
    ]) {
        assert!(w.contains(why), "{w} is not {why}");
    }
    assert_eq!(checked[&Figure::Cases], 2);
    assert_eq!(checked[&Figure::Exchanges], 2);
}

#[test]
fn numbers_are_read_whole_and_not_from_words() {
    let n = |s: &str| number_before(s, s.len()).map(|(n, _)| n);
    assert_eq!(n("explores 72 770"), Some(72_770));
    assert_eq!(n("the 1 549"), Some(1_549));
    assert_eq!(n("of 1 983 070"), Some(1_983_070));
    assert_eq!(n("over 20"), Some(20));
    assert_eq!(n("the HX-1"), None);
    assert_eq!(n("at 1.5"), None);
    assert_eq!(n("Table 10 50"), Some(50));
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
