//! The counts a document states: the phrases they are recognised by, the number before
//! a phrase read whole, and the counts that are not the program's.

use super::Doc;

/// Counts in a checked phrase that are not the program's figure, with the words around
/// them (whitespace collapsed) and the file they are in: each must still be there.
pub(super) const NOT_THE_PROGRAMS: &[(&str, &str)] = &[
    // A development run's history: the legacy settings that failed part of the catalogue.
    ("docs/src/design.md", "failed 25 cases of the reference's own catalogue"),
    // A measurement's history: the scenarios in which HX-M's first request was read late.
    ("docs/src/design-log.md", "late by the kernel in 18 scenarios while its interpreter started"),
    // The benchmark's generated input, a parameter of the benchmark.
    ("docs/src/watching-a-live-bus.md", "a generated wire log of 100 000 exchanges"),
];

/// What a count is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Figure {
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
pub(super) const PHRASES: &[(&str, Figure)] = &[
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
pub(super) struct Stated {
    pub(super) doc: String,
    /// Where the number starts in the document, and its line.
    pub(super) at: usize,
    pub(super) line: usize,
    pub(super) figure: Figure,
    pub(super) number: u64,
    /// The number and its phrase as written, whitespace collapsed ("1 549 mutants").
    pub(super) words: String,
    /// The paragraph it is in up to the number, whitespace collapsed.
    pub(super) before: String,
    /// The whole paragraph, whitespace collapsed.
    pub(super) paragraph: String,
}

/// `text` with each run of whitespace one space, and where each of its bytes was.
pub(super) fn flatten(text: &str) -> (String, Vec<usize>) {
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
pub(super) fn number_before(flat: &str, end: usize) -> Option<(u64, usize)> {
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
pub(super) fn stated(doc: &Doc) -> Vec<Stated> {
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
