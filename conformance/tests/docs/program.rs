//! The program's own figures, each read from its output, and the counts the documents
//! state checked against them.

use super::figures::{number_before, stated, Figure, NOT_THE_PROGRAMS};
use super::{documents, read, root, run, Doc};
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::process::Command;

/// The program's own figures; a figure that is `None` (or a peer not named) is not
/// checked.
#[derive(Debug, Default)]
pub(super) struct Program {
    pub(super) cases: Option<u64>,
    pub(super) scenarios: Option<u64>,
    pub(super) exchanges: Option<u64>,
    pub(super) vectors: Option<u64>,
    pub(super) profiles: Option<u64>,
    /// Normative clauses: in the registry, cited, listed as unobservable.
    pub(super) normative: Option<(u64, u64, u64)>,
    pub(super) actions: Option<u64>,
    /// The model checker is run to the depths the docs name up to this one (a depth
    /// of 20 takes minutes in a debug build).
    pub(super) model_checker_depth: usize,
    /// An independent peer's defect switches, by its name.
    pub(super) defect_switches: HashMap<&'static str, u64>,
    /// What the main command printed.
    pub(super) main_output: String,
}

/// The peers whose defect switches the docs count, and where they are.
pub(super) const PEERS: &[(&str, &str)] = &[
    ("HX-1", "conformance/tests/independent/hx1_slave.py"),
    ("HX-L", "conformance/tests/independent/hxl_slave.py"),
    ("HX-M", "conformance/tests/independent/hx_master.py"),
    ("HX-E", "python/tests/independent_encoder.py"),
    ("HX-3", "conformance/tests/independent/hx3_slave.py"),
    ("HX-M3", "conformance/tests/independent/hxm3_master.py"),
    ("HX-4", "conformance/tests/independent/hx4_slave.py"),
    ("HX-M4", "conformance/tests/independent/hxm4_master.py"),
];

/// The model checker's depth in CI (`cargo test -p hiperface-proofs`): a second in a
/// debug build.
pub(super) const CI_DEPTH: usize = 8;

/// The model checker's states and transitions to a depth, computed once per depth.
pub(super) fn explored(depth: usize) -> (u64, u64) {
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
pub(super) fn wrong_figures(docs: &[Doc], program: &Program) -> (Vec<String>, HashMap<Figure, usize>) {
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
                    wrong.push(format!(
                        "{at}: whose defect switches? Name the peer (HX-1, HX-L, HX-M, HX-E, HX-3, HX-M3, HX-4, HX-M4) before it"
                    ));
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

/// The number of units in a report.json (its `cases` or its `scenarios`), and the sum
/// of their exchanges.
pub(super) fn units_and_exchanges(report: &Path, units: &str) -> (u64, u64) {
    let report: serde_json::Value = serde_json::from_str(&read(report)).expect("report.json is JSON");
    let cases = report[units].as_array().unwrap_or_else(|| panic!("no {units} in {report}"));
    let exchanges = cases.iter().map(|c| c["exchanges"].as_u64().expect("a count of exchanges")).sum();
    (cases.len() as u64, exchanges)
}

/// The program's figures, each from its own output.
pub(super) fn program() -> Program {
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
/// the wall-time line, a measurement, and the first line, which names the
/// pseudo-terminal, are compared with their numbers left out.
pub(super) fn excerpt_not_printed(readme: &str, output: &str) -> Vec<String> {
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
            !output.lines().any(|o| {
                let measured = l.starts_with("wall time ") || l.starts_with("certifying ");
                o == *l || again(o) || (measured && numbers_out(o) == numbers_out(l))
            })
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
pub(super) fn defect_switches(script: &str) -> u64 {
    let path = root().join(script);
    let listed = Command::new("python3").arg(&path).arg("--list-defects").output().expect("python3");
    if script.ends_with("_master.py") && !listed.status.success() {
        // HX-M and HX-M3 name the ones they know when given one they do not (HX-M4
        // lists them as the slaves do).
        let out = Command::new("python3").arg(&path).args(["/dev/null", "--defect", "?"]).output().expect("python3");
        let err = String::from_utf8_lossy(&out.stderr);
        let known = err.split_once("known: ").unwrap_or_else(|| panic!("{script}: {err}")).1;
        known.trim().split(", ").count() as u64
    } else {
        assert!(listed.status.success(), "{script} --list-defects: {}", String::from_utf8_lossy(&listed.stderr));
        String::from_utf8_lossy(&listed.stdout).lines().filter(|l| !l.trim().is_empty()).count() as u64
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
