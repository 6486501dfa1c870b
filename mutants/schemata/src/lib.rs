//! Mutant schemata of the model: one copy of `model/src` in which every mutant that
//! cargo-mutants makes of the chosen files is compiled in at once, each behind a
//! switch read at run time (`crate::mutant::on(id)`), so that a thousand defective
//! encoders cost one build instead of a thousand.
//!
//! The operators are cargo-mutants' (27.x), applied to the same places and named as it
//! names them (`replace == with != in ErrorStack::push`), so that a survivor can be
//! looked up in either tool: a function's body replaced by a value of its return type
//! (`FnValue`), a binary operator replaced (`BinaryOperator`), `!` and `-` deleted
//! (`UnaryOperator`), a match arm deleted where a wildcard arm remains
//! (`MatchArm`), a match guard replaced by `true` and `false` (`MatchArmGuard`), a
//! field of a struct expression with a base deleted (`StructField`).
//! Where a mutant cannot be compiled in as a switch (inside a `const fn` a constant
//! needs, or a return type no value is known to fit), it is not generated and is
//! listed in [`Generated::skipped`] with why.
//!
//! How a mutant is switched in:
//!
//! - an operator: `(if crate::mutant::on(7) { a - b } else if crate::mutant::on(8) { a * b } else { a + b })`;
//! - a function's value: `if crate::mutant::on(9) { return 0; }` before its body;
//! - a deleted arm: its guard `if !crate::mutant::on(10)`, so that the value falls
//!   through to the arms after it, as if the arm were not there;
//! - a guard: `if (if crate::mutant::on(11) { true } else if crate::mutant::on(12) { false } else { guard })`;
//! - a deleted field: `S { f: if crate::mutant::on(13) { base.f } else { value }, ..base }`
//!   (a base that is a path: one that can be read twice).
//!
//! The copy is one file with the modules inline; `#[cfg(test)]` items are left out.
//! `const fn`s that no constant needs lose their `const` (a switch is read at run
//! time); the rest keep it, and their mutants are skipped.

mod constness;
mod mutate;
mod names;
mod tree;
mod values;

use std::collections::BTreeSet;
use std::fmt;
use std::path::{Path, PathBuf};

/// Which defective devices a mutant makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Family {
    /// An encoder: the slave and what it is built of.
    Encoder,
    /// A master: the reference master.
    Master,
}

impl Family {
    pub fn name(self) -> &'static str {
        match self {
            Family::Encoder => "encoder",
            Family::Master => "master",
        }
    }
}

/// cargo-mutants' kinds of mutant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Genre {
    FnValue,
    BinaryOperator,
    UnaryOperator,
    MatchArm,
    MatchArmGuard,
    StructField,
}

impl Genre {
    pub fn name(self) -> &'static str {
        match self {
            Genre::FnValue => "FnValue",
            Genre::BinaryOperator => "BinaryOperator",
            Genre::UnaryOperator => "UnaryOperator",
            Genre::MatchArm => "MatchArm",
            Genre::MatchArmGuard => "MatchArmGuard",
            Genre::StructField => "StructField",
        }
    }
}

/// A place in the model's source: the file as cargo-mutants names it
/// (`model/src/slave/stack.rs`), line and column from 1.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Place {
    pub file: String,
    pub line: usize,
    pub column: usize,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

/// A mutant compiled into the copy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mutant {
    /// The switch: `crate::mutant::on(id)`; from 1 (0 is the unmutated model).
    pub id: u32,
    pub family: Family,
    pub genre: Genre,
    pub place: Place,
    /// The function it is in, as cargo-mutants names it (`ErrorStack::push`,
    /// `<impl fmt::Display for Hex<'_>>::fmt`).
    pub function: String,
    /// What it does, in cargo-mutants' words: `replace == with != in ErrorStack::push`.
    pub description: String,
    /// Which of the mutants with the same file and description this is (0, 1, ...) in
    /// source order: with `file` and `description`, a key that survives edits
    /// elsewhere in the file (see [`Mutant::key`]).
    pub occurrence: usize,
}

impl Mutant {
    /// cargo-mutants' name of it: `model/src/slave/stack.rs:42:17: replace == with != in ErrorStack::push`.
    pub fn name(&self) -> String {
        format!("{}: {}", self.place, self.description)
    }

    /// A name without line numbers, for lists kept in the repository:
    /// `model/src/slave/stack.rs: replace == with != in ErrorStack::push` with `#2`
    /// appended for the third of its kind in that file.
    pub fn key(&self) -> String {
        key(&self.place.file, &self.description, self.occurrence)
    }
}

/// The key of the `occurrence`th mutant `description` in `file` ([`Mutant::key`]).
pub fn key(file: &str, description: &str, occurrence: usize) -> String {
    match occurrence {
        0 => format!("{file}: {description}"),
        n => format!("{file}: {description} #{n}"),
    }
}

/// A mutant cargo-mutants makes that the copy does not switch in, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skipped {
    pub place: Place,
    pub genre: Genre,
    pub description: String,
    pub why: &'static str,
}

/// The copy and its mutants.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The model's source, one file, every mutant behind its switch.
    pub code: String,
    pub mutants: Vec<Mutant>,
    pub skipped: Vec<Skipped>,
    /// The model's source files read (for a build script's rerun-if-changed).
    pub files: Vec<PathBuf>,
}

/// Why the copy could not be made.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{path}: {source}")]
    Read { path: PathBuf, source: std::io::Error },
    #[error("{path}: {source}")]
    Parse { path: PathBuf, source: syn::Error },
    #[error("{path}: module `{module}` has no file ({tried})")]
    NoModuleFile { path: PathBuf, module: String, tried: String },
    #[error("{path}: `#[path]` on module `{module}` is not supported")]
    PathAttribute { path: PathBuf, module: String },
}

/// Which files are mutated, and for which family; with functions left out by name.
pub struct Scope<'a> {
    /// The family of a file given relative to the source root (`slave/stack.rs`);
    /// `None`: copied, not mutated.
    pub family_of: &'a dyn Fn(&str) -> Option<Family>,
    /// Functions not mutated, as cargo-mutants names them (`Slave::adopt`).
    pub not_mutated: &'a dyn Fn(&str) -> bool,
}

/// Make the copy of the crate whose root is `src/lib.rs` under `src`; `display` is how
/// files are named in mutants' places (`model/src`).
pub fn generate(src: &Path, display: &str, scope: &Scope<'_>) -> Result<Generated, Error> {
    let mut crate_tree = tree::load(src)?;
    let defaults = values::types_with_default(&crate_tree);
    let keep_const = constness::needed_const(&crate_tree);
    let mut mutants = Vec::new();
    let mut skipped = Vec::new();
    let mut next_id = 1u32;
    for file in &mut crate_tree.files {
        let Some(family) = (scope.family_of)(&file.rel) else { continue };
        let mut m = mutate::Mutator::new(
            format!("{display}/{}", file.rel),
            family,
            &defaults,
            &keep_const,
            scope.not_mutated,
            &mut next_id,
        );
        m.run(&mut file.ast);
        let (found, left) = m.finish();
        mutants.extend(found);
        skipped.extend(left);
    }
    number_occurrences(&mut mutants);
    let files = crate_tree.files.iter().map(|f| f.path.clone()).collect();
    let code = prettyplease::unparse(&tree::inline(crate_tree));
    Ok(Generated { code, mutants, skipped, files })
}

/// Number the mutants that share a file and description in source order.
fn number_occurrences(mutants: &mut [Mutant]) {
    let mut order: Vec<usize> = (0..mutants.len()).collect();
    order.sort_by(|a, b| {
        let (x, y) = (&mutants[*a], &mutants[*b]);
        (&x.place.file, &x.description, x.place.line, x.place.column, x.id).cmp(&(
            &y.place.file,
            &y.description,
            y.place.line,
            y.place.column,
            y.id,
        ))
    });
    let mut last: Option<(String, String)> = None;
    let mut n = 0;
    for i in order {
        let this = (mutants[i].place.file.clone(), mutants[i].description.clone());
        n = if last.as_ref() == Some(&this) { n + 1 } else { 0 };
        mutants[i].occurrence = n;
        last = Some(this);
    }
}

/// The mutants as Rust source: a `&[MutantInfo]` constant's elements, for the copy's
/// table (`crate::mutant::ALL`).
pub fn table_source(mutants: &[Mutant]) -> String {
    let mut s = String::from("[\n");
    for m in mutants {
        s.push_str(&format!(
            "    MutantInfo {{ id: {}, family: \"{}\", genre: \"{}\", file: {:?}, line: {}, column: {}, function: {:?}, description: {:?}, occurrence: {} }},\n",
            m.id,
            m.family.name(),
            m.genre.name(),
            m.place.file,
            m.place.line,
            m.place.column,
            m.function,
            m.description,
            m.occurrence
        ));
    }
    s.push(']');
    s
}

/// The distinct function names of `mutants` (for checks of a list of names).
pub fn functions(mutants: &[Mutant]) -> BTreeSet<String> {
    mutants.iter().map(|m| m.function.clone()).collect()
}
