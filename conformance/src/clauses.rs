//! Clause coverage: for every clause of the registry (`hiperface_model::clause`), the
//! slave cases, master scenarios, master rules and vectors that cite it; and the
//! normative clauses that no serial-line test can observe, each with the reason.
//! `hiperface clauses` prints it; a test fails when a normative clause is neither
//! covered nor listed as unobservable.

use hiperface_model::clause::{Clause, Force, CLAUSES};
use hiperface_model::master::obligations::Rule;
use hiperface_model::oracle::REPLY_FORM;
use hiperface_suite::slave::EVERY_EXCHANGE;
use serde::Serialize;
use std::collections::BTreeMap;

/// Normative clauses a test on the serial line cannot observe, and why.
pub const UNOBSERVABLE: &[(&str, &str)] = &[(
    "000:T57",
    "the slave detects 1Ch on its own analog sine/cosine signals, which a test on the serial line cannot \
     disturb; the model's behaviour is checked in its own tests",
)];

/// What cites one clause.
#[derive(Debug, Clone, Serialize)]
pub struct ClauseCoverage {
    pub id: &'static str,
    pub force: &'static str,
    pub normative: bool,
    pub quote: &'static str,
    pub slave_cases: Vec<&'static str>,
    pub master_scenarios: Vec<&'static str>,
    pub master_rules: Vec<&'static str>,
    /// Checked on every exchange of every slave case: by the harness
    /// (`slave::EVERY_EXCHANGE`) or the oracle's check of a reply's form
    /// (`oracle::REPLY_FORM`).
    pub every_exchange: bool,
    /// How many vectors cite it, per file.
    pub vectors: BTreeMap<&'static str, usize>,
    /// Why no serial-line test can observe it, where that is so.
    pub unobservable: Option<&'static str>,
}

impl ClauseCoverage {
    pub fn cited(&self) -> bool {
        !(self.slave_cases.is_empty()
            && !self.every_exchange
            && self.master_scenarios.is_empty()
            && self.master_rules.is_empty()
            && self.vectors.is_empty())
    }

    /// A normative clause that nothing covers and that is not listed as unobservable.
    pub fn uncovered(&self) -> bool {
        self.normative && !self.cited() && self.unobservable.is_none()
    }
}

/// The vector files, as the repository keeps them.
const VECTOR_FILES: &[(&str, &str)] = &[
    ("documents.json", include_str!("../../vectors/documents.json")),
    ("generated-current.json", include_str!("../../vectors/generated-current.json")),
    ("generated-legacy.json", include_str!("../../vectors/generated-legacy.json")),
    ("master-tables.json", include_str!("../../vectors/master-tables.json")),
];

/// The vector files built into the command, read as vectors, each with its file name:
/// what `vectors show` and `vectors book` use where no `--dir` is given (after `cargo
/// install`, outside the repository).
pub fn builtin_vector_files() -> Result<Vec<(String, hiperface_suite::vectors::VectorFile)>, BadBuiltinVectors> {
    VECTOR_FILES
        .iter()
        .map(|(name, text)| {
            serde_json::from_str(text)
                .map(|f| (name.to_string(), f))
                .map_err(|e| BadBuiltinVectors { name, why: e.to_string() })
        })
        .collect()
}

/// A vector file's name, and how many of its tests cite each clause id.
type Citations = (&'static str, BTreeMap<String, usize>);

/// A vector file built into the command that does not read as vectors.
#[derive(Debug, thiserror::Error)]
#[error("the built-in vector file {name}: {why}")]
pub struct BadBuiltinVectors {
    pub name: &'static str,
    pub why: String,
}

/// The clause ids each vector file cites, with how many tests cite each (the files read
/// as `vectors show` reads them).
fn vector_citations() -> Result<Vec<Citations>, BadBuiltinVectors> {
    let files = builtin_vector_files()?;
    Ok(VECTOR_FILES
        .iter()
        .zip(files)
        .map(|((name, _), (_, file))| {
            let mut counts = BTreeMap::new();
            for id in file.vectors.iter().flat_map(|v| &v.clauses) {
                *counts.entry(id.clone()).or_insert(0) += 1;
            }
            (*name, counts)
        })
        .collect())
}

fn force_name(f: Force) -> &'static str {
    match f {
        Force::Normative => "normative",
        Force::Recommended => "recommended",
        Force::Decision => "decision",
        Force::Informative => "informative",
    }
}

/// The coverage of every clause, in registry order.
pub fn coverage() -> Result<Vec<ClauseCoverage>, BadBuiltinVectors> {
    let cases = hiperface_suite::slave::cases::catalogue();
    let scenarios = hiperface_suite::master::scenarios::catalogue();
    let vectors = vector_citations()?;
    let cites = |list: &[Clause], c: &Clause| list.iter().any(|x| x.id() == c.id());
    Ok(CLAUSES
        .iter()
        .map(|c| ClauseCoverage {
            id: c.id(),
            force: force_name(c.force()),
            normative: c.force() == Force::Normative,
            quote: c.quote(),
            slave_cases: cases.iter().filter(|k| cites(k.clauses, c)).map(|k| k.id).collect(),
            master_scenarios: scenarios.iter().filter(|s| cites(s.clauses, c)).map(|s| s.id).collect(),
            master_rules: Rule::ALL.iter().filter(|r| r.clause().id() == c.id()).map(|r| r.text()).collect(),
            every_exchange: EVERY_EXCHANGE.iter().chain(REPLY_FORM.iter()).any(|n| n.id() == c.id()),
            vectors: vectors.iter().filter_map(|(f, counts)| counts.get(c.id()).map(|n| (*f, *n))).collect(),
            unobservable: UNOBSERVABLE.iter().find(|(id, _)| *id == c.id()).map(|(_, why)| *why),
        })
        .collect())
}

/// Normative clauses: (covered or listed, all).
pub fn figures(all: &[ClauseCoverage]) -> (usize, usize, usize) {
    let normative: Vec<&ClauseCoverage> = all.iter().filter(|c| c.normative).collect();
    let cited = normative.iter().filter(|c| c.cited()).count();
    let listed = normative.iter().filter(|c| !c.cited() && c.unobservable.is_some()).count();
    (cited, listed, normative.len())
}

/// A Markdown table of `rows`.
pub fn markdown(rows: &[&ClauseCoverage], all: &[ClauseCoverage]) -> String {
    // No rows (`--uncovered` where every clause is covered): no table, the figures say it.
    let mut out = String::new();
    if !rows.is_empty() {
        out.push_str("| clause | force | slave cases | every exchange | master scenarios | master rules | vectors |\n");
        out.push_str("|---|---|---|---|---|---|---|\n");
    }
    for c in rows {
        let vectors: Vec<String> = c.vectors.iter().map(|(f, n)| format!("{f} ({n})")).collect();
        let rules = match c.unobservable {
            Some(why) if !c.cited() => format!("not observable: {why}"),
            _ => c.master_rules.join(", "),
        };
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            c.id,
            c.force,
            c.slave_cases.join(", "),
            if c.every_exchange { "yes" } else { "" },
            c.master_scenarios.join(", "),
            rules,
            vectors.join(", ")
        ));
    }
    let (cited, listed, normative) = figures(all);
    if !rows.is_empty() {
        out.push('\n');
    }
    out.push_str(&format!(
        "{cited} of {normative} normative clauses are cited by a case, a check of every exchange, a scenario, a \
         rule or a vector; \
         {listed} cannot be observed on the serial line (listed with the reason); {} uncovered.\n",
        normative - cited - listed
    ));
    out
}
