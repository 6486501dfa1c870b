//! The vector files' layout on disk, in the shape of Wycheproof's test files: a header,
//! `numberOfTests`, a `notes` dictionary explaining every flag used, and `testGroups`
//! whose tests share a profile and a starting state; each test has a `tcId`, a
//! `comment`, `flags` and a `result` (valid, acceptable, invalid). In memory the
//! vectors are flat ([`super::VectorFile`]); this module converts both ways and checks
//! what the JSON Schema cannot (the count, the tcIds, a note for every flag).

use super::{ChecksumExample, Erratum, Expected, Flag, Setup, TableCase, Vector, VectorFile, VectorStep};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The schema version of the files this build reads and writes.
pub const SCHEMA_VERSION: u32 = 2;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub(super) struct DiskFile {
    schema: String,
    schema_version: u32,
    header: Vec<String>,
    number_of_tests: usize,
    notes: BTreeMap<Flag, Note>,
    test_groups: Vec<Group>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Note {
    description: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Group {
    profile: String,
    #[serde(default, skip_serializing_if = "is_default")]
    setup: Setup,
    tests: Vec<Test>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Test {
    #[serde(rename = "tcId")]
    tc_id: usize,
    id: String,
    comment: String,
    source: String,
    clauses: Vec<String>,
    command: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    steps: Vec<VectorStep>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    checksum_example: Option<ChecksumExample>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    table_case: Option<TableCase>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    flags: Vec<Flag>,
    result: Expected,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    erratum: Option<Erratum>,
}

fn is_default(s: &Setup) -> bool {
    *s == Setup::default()
}

/// Why a file's layout is inconsistent.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LayoutError {
    #[error("schemaVersion {found}: this build reads version {SCHEMA_VERSION}")]
    Version { found: u32 },
    #[error("numberOfTests says {said}, the groups hold {found}")]
    Count { said: usize, found: usize },
    #[error("test `{id}`: tcId {found}, expected {expected} (1, 2, 3, ... in file order)")]
    TcId { id: String, found: usize, expected: usize },
    #[error("test `{id}`: flag `{flag}` has no entry in `notes`")]
    Unexplained { id: String, flag: String },
}

impl Flag {
    /// What the flag means, as the files' `notes` explain it.
    pub const fn note(self) -> &'static str {
        match self {
            Flag::Erratum => "The document prints this frame wrongly; `erratum` gives the printed and the corrected bytes and the reason. A vector with result `invalid` replays the frame as printed.",
            Flag::Legacy => "A legacy-edition profile: 002 is the normative document.",
            Flag::Broadcast => "A request to the broadcast address FFh (000:2.3.1).",
            Flag::Warning => "A response carries the warning bit (000:2.3.4).",
            Flag::BadChecksum => "A request's checksum is wrong on purpose (000:2.3.3).",
            Flag::UartFault => "A request character arrives with a UART fault (parity or framing, 000:T47).",
            Flag::Timed => "The slave starts from power-on and each step happens at its `at_us` (000:T9).",
            Flag::CharacterTiming => "Each request's characters arrive at the times in `chars_at_us` (the end of each stop bit, µs): the slave frames them by its timeout, counted from character end to character end (000:2.2.2, DESIGN:legacy-timeout), and takes the request at `at_us`, the timeout after the last character. A replay that hands over whole frames uses `at_us`.",
            Flag::Latitude => "The documents leave the device a choice here: this answer is acceptable but not the preferred one; a device that gives it is graded NON-STRICT, never FAIL.",
        }
    }
}

impl From<VectorFile> for DiskFile {
    fn from(file: VectorFile) -> DiskFile {
        let mut notes = BTreeMap::new();
        let mut groups: Vec<Group> = Vec::new();
        let number_of_tests = file.vectors.len();
        for (i, v) in file.vectors.into_iter().enumerate() {
            for f in &v.flags {
                notes.insert(*f, Note { description: f.note().into() });
            }
            let test = Test {
                tc_id: i + 1,
                id: v.id,
                comment: v.meaning,
                source: v.source,
                clauses: v.clauses,
                command: v.command,
                steps: v.steps,
                checksum_example: v.checksum_example,
                table_case: v.table_case,
                flags: v.flags,
                result: v.result,
                erratum: v.erratum,
            };
            // Consecutive vectors with one profile and starting state share a group.
            match groups.last_mut() {
                Some(g) if g.profile == v.profile && g.setup == v.setup => g.tests.push(test),
                _ => groups.push(Group { profile: v.profile, setup: v.setup, tests: vec![test] }),
            }
        }
        DiskFile {
            schema: "schema.json".into(),
            schema_version: SCHEMA_VERSION,
            header: file.description.lines().map(str::to_string).collect(),
            number_of_tests,
            notes,
            test_groups: groups,
        }
    }
}

impl TryFrom<DiskFile> for VectorFile {
    type Error = LayoutError;

    fn try_from(d: DiskFile) -> Result<VectorFile, LayoutError> {
        if d.schema_version != SCHEMA_VERSION {
            return Err(LayoutError::Version { found: d.schema_version });
        }
        let mut vectors = Vec::new();
        for g in d.test_groups {
            for t in g.tests {
                let expected = vectors.len() + 1;
                if t.tc_id != expected {
                    return Err(LayoutError::TcId { id: t.id, found: t.tc_id, expected });
                }
                if let Some(f) = t.flags.iter().find(|f| !d.notes.contains_key(f)) {
                    let flag = serde_json::to_value(f).ok().and_then(|v| v.as_str().map(str::to_string));
                    return Err(LayoutError::Unexplained { id: t.id, flag: flag.unwrap_or_default() });
                }
                vectors.push(Vector {
                    id: t.id,
                    source: t.source,
                    clauses: t.clauses,
                    profile: g.profile.clone(),
                    command: t.command,
                    setup: g.setup.clone(),
                    steps: t.steps,
                    checksum_example: t.checksum_example,
                    table_case: t.table_case,
                    result: t.result,
                    flags: t.flags,
                    erratum: t.erratum,
                    meaning: t.comment,
                });
            }
        }
        if d.number_of_tests != vectors.len() {
            return Err(LayoutError::Count { said: d.number_of_tests, found: vectors.len() });
        }
        Ok(VectorFile { description: d.header.join("\n"), vectors })
    }
}
