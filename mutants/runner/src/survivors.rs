//! The committed list of mutants the catalogue lets through (`mutants/survivors.toml`),
//! each with its class and reason, and the table of a run against it: a survivor not
//! listed, or a listed one that is now told, is a difference the list must take up.

use crate::certify::Caught;
use crate::run::{Family, Outcome};
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

/// Why a mutant the catalogue lets through may stay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Class {
    /// No behaviour on the wire differs from the conformant device's (argued).
    Equivalent,
    /// The behaviour differs only where the documents say "should", leave latitude,
    /// or where the decision is ours: no FAIL is earned.
    NotAMust,
    /// A must-clause forbids it and no case tells it yet.
    Hole,
}

impl Class {
    pub fn label(self) -> &'static str {
        match self {
            Class::Equivalent => "equivalent",
            Class::NotAMust => "not a must",
            Class::Hole => "hole",
        }
    }
}

/// One mutant listed.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Listed {
    pub family: Family,
    pub key: String,
    pub class: Class,
    #[serde(default)]
    pub clause: Option<String>,
    pub reason: String,
}

/// Every mutant of a function listed at once (a function no device runs, or one whose
/// results never reach the wire).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ListedFunction {
    pub family: Family,
    pub function: String,
    /// The file, where two functions share the name (`be32` of requests and replies).
    #[serde(default)]
    pub file: Option<String>,
    pub class: Class,
    pub reason: String,
    /// The claim that the conformant device never runs the function: checked, every
    /// mutant of it must be unreached.
    #[serde(default)]
    pub never_run: bool,
}

impl ListedFunction {
    /// Whether the entry covers the mutant: its family, function and (where given) file.
    pub fn covers(&self, o: &Outcome) -> bool {
        self.family == o.name.family
            && self.function == o.name.function
            && self.file.as_ref().is_none_or(|f| o.name.key.starts_with(&format!("{f}: ")))
    }

    fn name(&self) -> String {
        match &self.file {
            Some(f) => format!("{f}: {}", self.function),
            None => self.function.clone(),
        }
    }
}

/// The list.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Survivors {
    #[serde(default, rename = "function")]
    pub functions: Vec<ListedFunction>,
    #[serde(default, rename = "mutant")]
    pub mutants: Vec<Listed>,
}

/// The list's file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ListError {
    #[error("{0}")]
    Toml(#[from] toml::de::Error),
    #[error("{family} mutant `{key}` is listed twice")]
    Twice { family: &'static str, key: String },
}

impl Survivors {
    pub fn parse(text: &str) -> Result<Survivors, ListError> {
        let s: Survivors = toml::from_str(text)?;
        let mut seen = BTreeSet::new();
        for m in &s.mutants {
            if !seen.insert((m.family, m.key.clone())) {
                return Err(ListError::Twice { family: m.family.name(), key: m.key.clone() });
            }
        }
        Ok(s)
    }

    /// How the list classes a mutant, if it does: by its key, else by its function.
    pub fn class_of(&self, o: &Outcome) -> Option<(Class, &str)> {
        let by_key = self.mutants.iter().find(|m| m.family == o.name.family && m.key == o.name.key);
        if let Some(m) = by_key {
            return Some((m.class, m.reason.as_str()));
        }
        self.functions.iter().find(|f| f.covers(o)).map(|f| (f.class, f.reason.as_str()))
    }
}

/// Whether the catalogue told a mutant from a conformant device (FAIL, ERROR, hung).
pub fn told(c: Caught) -> bool {
    matches!(c, Caught::Fail | Caught::Error | Caught::Hung)
}

/// A family's run, counted.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Table {
    pub mutants: usize,
    pub fail: usize,
    pub error: usize,
    pub hung: usize,
    pub non_strict: usize,
    pub survived: usize,
    pub equivalent: usize,
    pub not_a_must: usize,
    /// Listed as holes.
    pub holes: usize,
    /// Let through, and seen to differ from the conformant device at the wire on a
    /// random stream (`diff`): never equivalent.
    pub witnessed: usize,
    /// Let through and not listed.
    pub unlisted: Vec<String>,
    /// Listed (by key or function), but told now, or no such mutant.
    pub stale: Vec<String>,
}

impl Table {
    /// The mutants a must-clause forbids: all but the equivalent and the not-a-must.
    pub fn must_mutants(&self) -> usize {
        self.mutants - self.equivalent - self.not_a_must
    }

    /// Of those, the part the catalogue told (FAIL, ERROR or hung), in per cent.
    pub fn score(&self) -> f64 {
        let must = self.must_mutants();
        if must == 0 {
            return 100.0;
        }
        100.0 * (self.fail + self.error + self.hung) as f64 / must as f64
    }

    /// The table as Markdown rows under [`Table::HEADER`].
    pub const HEADER: &'static str = "| family | mutants | FAIL | ERROR | hung | NON-STRICT only | survived | equivalent | not a must | holes | unlisted | score |\n|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|";

    pub fn row(&self, family: Family) -> String {
        format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} % |",
            family.name(),
            self.mutants,
            self.fail,
            self.error,
            self.hung,
            self.non_strict,
            self.survived,
            self.equivalent,
            self.not_a_must,
            self.holes,
            self.unlisted.len(),
            self.score()
        )
    }
}

/// Count a family's outcomes against the list. `complete`: every mutant of the family
/// was run (only then is a listed mutant that did not run stale).
pub fn table(family: Family, outcomes: &[Outcome], list: &Survivors, complete: bool) -> Table {
    let mut t = Table { mutants: outcomes.len(), ..Table::default() };
    let mut functions_used: BTreeMap<String, bool> = BTreeMap::new();
    for o in outcomes {
        match o.verdicts.caught {
            Caught::Fail => t.fail += 1,
            Caught::Error => t.error += 1,
            Caught::Hung => t.hung += 1,
            Caught::NonStrict => t.non_strict += 1,
            Caught::Survived => t.survived += 1,
        }
        let by_key = list.mutants.iter().find(|m| m.family == family && m.key == o.name.key);
        let by_fn = list.functions.iter().find(|f| f.covers(o));
        if told(o.verdicts.caught) {
            if let Some(m) = by_key {
                t.stale.push(format!(
                    "listed as {} but told now ({}): {}",
                    m.class.label(),
                    o.verdicts.caught.label(),
                    m.key
                ));
            }
            continue;
        }
        let class = match (by_key, by_fn) {
            (Some(m), _) => Some(m.class),
            (None, Some(f)) => {
                functions_used.insert(f.name(), true);
                if f.never_run && o.reached == Some(true) {
                    t.stale.push(format!(
                        "function listed as never run, but the device ran it: {} ({})",
                        f.function, o.name.key
                    ));
                }
                Some(f.class)
            }
            (None, None) => None,
        };
        if let (Some(Class::Equivalent), Some(w)) = (class, &o.witness) {
            t.stale.push(format!("listed as equivalent, but it {w}: {}", o.name.key));
        }
        if o.witness.is_some() {
            t.witnessed += 1;
        }
        match class {
            Some(Class::Equivalent) => t.equivalent += 1,
            Some(Class::NotAMust) => t.not_a_must += 1,
            Some(Class::Hole) => t.holes += 1,
            None => t.unlisted.push(format!(
                "{} ({}{})",
                o.name.key,
                o.verdicts.caught.label(),
                o.verdicts.finding.as_deref().map(|f| format!(": {f}")).unwrap_or_default()
            )),
        }
    }
    if complete {
        let keys: BTreeSet<&str> = outcomes.iter().map(|o| o.name.key.as_str()).collect();
        for m in list.mutants.iter().filter(|m| m.family == family) {
            if !keys.contains(m.key.as_str()) {
                t.stale.push(format!("listed, but there is no such mutant: {}", m.key));
            }
        }
        for f in list.functions.iter().filter(|f| f.family == family) {
            if !functions_used.contains_key(&f.name()) {
                t.stale.push(format!("function listed, but none of its mutants is let through: {}", f.name()));
            }
        }
    }
    t
}

/// The differences between a run and the list, as lines for the console.
pub fn differences(family: Family, t: &Table) -> String {
    let mut s = String::new();
    for u in &t.unlisted {
        let _ = writeln!(s, "{}: let through and not listed: {u}", family.name());
    }
    for u in &t.stale {
        let _ = writeln!(s, "{}: {u}", family.name());
    }
    s
}
