//! Markdown, as far as links and headings need it: code blocks and spans blanked,
//! links, headings' anchors as mdBook and GitHub make them.

use std::collections::{HashMap, HashSet};
use std::path::{Component, Path, PathBuf};

/// `text` with its fenced code blocks blanked (every character but a line break made a
/// space): the line numbers stay.
pub(super) fn without_fences(text: &str) -> String {
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
pub(super) fn prose(text: &str) -> String {
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
pub(super) struct Link {
    pub(super) line: usize,
    pub(super) target: String,
}

/// Every link of `text` outside code: inline (`[text](target)`, `[text](target "title")`,
/// `[text](<target>)`, images alike) and reference definitions (`[label]: target`).
pub(super) fn links(text: &str) -> Vec<Link> {
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
pub(super) fn slug(heading: &str) -> String {
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
pub(super) fn anchors(text: &str) -> HashSet<String> {
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
pub(super) fn lexical(path: &Path) -> PathBuf {
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
