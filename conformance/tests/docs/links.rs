//! The README, the summary, the links: a front door, every chapter in the summary,
//! every relative link leading to a file and a heading that are there.

use super::markdown::{anchors, lexical, links};
use super::{chapters, documents, read, root, Doc};
use std::collections::HashSet;

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
pub(super) fn broken_links(docs: &[Doc]) -> (Vec<String>, usize) {
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
