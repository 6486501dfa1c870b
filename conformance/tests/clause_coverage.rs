//! Clause coverage (`hiperface clauses`): every normative clause of the registry is
//! cited by a slave case, a master scenario or rule, or a vector, or is listed as not
//! observable on the serial line with the reason.

use hiperface_conformance::clauses::{self, UNOBSERVABLE};
use hiperface_model::clause::CLAUSES;

#[test]
fn every_normative_clause_is_covered_or_listed_as_unobservable() {
    let all = clauses::coverage().unwrap();
    let open: Vec<&str> = all.iter().filter(|c| c.uncovered()).map(|c| c.id).collect();
    assert!(open.is_empty(), "normative clauses nothing covers: {open:?}");
    let (cited, listed, normative) = clauses::figures(&all);
    assert_eq!(cited + listed, normative);
    eprintln!("{cited} of {normative} normative clauses cited, {listed} unobservable");
}

#[test]
fn the_unobservable_list_names_registry_clauses_that_nothing_on_the_line_cites() {
    let all = clauses::coverage().unwrap();
    for (id, why) in UNOBSERVABLE {
        assert!(CLAUSES.iter().any(|c| c.id() == *id), "{id} is not in the registry");
        assert!(!why.is_empty());
        let c = all.iter().find(|c| c.id == *id).unwrap();
        // Listed as unobservable, yet a case or a scenario exercises it on the line:
        // the list is wrong.
        assert!(c.slave_cases.is_empty() && c.master_scenarios.is_empty(), "{id} is observed: {c:?}");
    }
}

#[test]
fn a_clause_that_nothing_cites_is_uncovered() {
    // The gate can fail: a normative clause with no citation and no reason is reported.
    let mut all = clauses::coverage().unwrap();
    let c = all.iter_mut().find(|c| c.id == "000:T11").unwrap();
    assert!(!c.uncovered());
    c.slave_cases.clear();
    c.vectors.clear();
    assert!(c.uncovered(), "{c:?}");
    let (cited, listed, normative) = clauses::figures(&all);
    assert_eq!(cited + listed + 1, normative);
}

#[test]
fn the_coverage_sees_the_citations_that_exist() {
    // A clause the checksum cases cite, and a master rule's clause, and a vector's.
    let all = clauses::coverage().unwrap();
    let checksum = all.iter().find(|c| c.id == "000:2.3.3").unwrap();
    assert!(!checksum.slave_cases.is_empty() && !checksum.vectors.is_empty(), "{checksum:?}");
    let cyclic = all.iter().find(|c| c.id == "000:3.2.2/cyclic").unwrap();
    assert!(cyclic.master_scenarios.contains(&"polling.long") && !cyclic.master_rules.is_empty(), "{cyclic:?}");
    assert!(!cyclic.normative);
}

#[test]
fn the_cli_prints_the_table_and_the_uncovered_ones() {
    let exe = env!("CARGO_BIN_EXE_hiperface");
    let out = std::process::Command::new(exe).args(["clauses"]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("| 000:2.3.3 | normative |") && stdout.contains("; 0 uncovered."), "{stdout}");
    let out = std::process::Command::new(exe).args(["clauses", "--uncovered", "--format", "json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(rows.as_array().map(Vec::len), Some(0), "{rows}");
}
