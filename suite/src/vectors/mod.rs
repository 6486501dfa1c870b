//! Golden vectors: language-neutral JSON files (schema in `vectors/schema.json`) that
//! any implementation can replay, in the manner of Wycheproof. Each vector names its
//! source, clauses and profile, the setup that brings a slave into the needed state,
//! and one or more timed steps of request and expected response.

mod disk;
pub mod export;
pub mod fixtures;
pub mod generate;
pub mod reference;
mod replay;
pub mod tables;

use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::Hex;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use disk::{LayoutError, SCHEMA_VERSION};
pub use replay::{checksum_problems, prepare, replay, start, Mismatch, VectorError};

/// A file of vectors, flat in memory; on disk in Wycheproof's shape (see `disk`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(into = "disk::DiskFile", try_from = "disk::DiskFile")]
pub struct VectorFile {
    /// The file's header, one line per line.
    pub description: String,
    pub vectors: Vec<Vector>,
}

/// What a vector's expected responses are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Expected {
    /// A conforming slave answers exactly this (the preferred answer).
    Valid,
    /// The last step's response is allowed, though not preferred (NON-STRICT).
    Acceptable,
    /// The last step's response is not allowed (e.g. a response printed with a wrong checksum).
    Invalid,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Flag {
    /// Taken from a document that prints it wrongly; see `erratum`.
    Erratum,
    Legacy,
    Broadcast,
    /// The response carries the warning bit.
    Warning,
    /// The request's checksum is wrong on purpose.
    BadChecksum,
    /// A request character has a UART fault (parity, framing).
    UartFault,
    /// Steps happen at given times after power-on.
    Timed,
    /// Each request's characters arrive at given times: the slave frames them by its
    /// timeout (000:2.2.2).
    CharacterTiming,
    /// The documents leave the device a choice; the answer is acceptable (NON-STRICT).
    Latitude,
}

#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Erratum {
    pub printed: String,
    pub corrected: String,
    pub reason: String,
}

/// Physical inputs, as in the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inputs {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<i32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<i16>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub led_current_ma: Option<u16>,
}

impl Inputs {
    fn apply(&self, to: &mut PhysicalInputs) {
        to.position = self.position.unwrap_or(to.position);
        to.speed = self.speed.unwrap_or(to.speed);
        to.temperature_c = self.temperature_c.unwrap_or(to.temperature_c);
        to.led_current_ma = self.led_current_ma.unwrap_or(to.led_current_ma);
    }
}

/// How to bring a slave into the vector's starting state.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Setup {
    /// Start from power-on at t = 0 (steps are timed); otherwise the slave has long
    /// been operational with its stored settings.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub power_on: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<Inputs>,
    /// Faults found at start-up: alignment-data, angular-offset, partition-table,
    /// analog-limits, type-code, watchdog, counter, extended-type-label, multiturn-parameters.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub init_faults: Vec<String>,
    /// Position faults present: analog-signals, analog-monitoring, singleturn,
    /// multiturn-amplitude, multiturn-sync, multiturn-vector-length, multiturn-counter.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_faults: Vec<String>,
    /// The internal I2C bus to the EEPROM is down.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub i2c_fault: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counter: Option<u32>,
    /// The stored settings byte (hex), where not the profile's: the settings the slave
    /// listens with once operational (000:T28).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<String>,
    /// Requests (hex, checksum included) sent first; their responses are not part of the vector.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub requests: Vec<String>,
}

/// One request and the expected response.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VectorStep {
    /// Time after power-on (timed vectors), µs; when the request's timeout elapsed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_us: Option<u64>,
    /// When each of the request's characters ended (its stop bit), µs: the request as
    /// the line delivers it. Where given, `at_us` is when the slave took it, the
    /// timeout after the last (000:2.2.2); a replay of whole frames uses `at_us`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chars_at_us: Vec<u64>,
    /// New physical inputs before this step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<Inputs>,
    /// A character of the request arrives with a UART fault.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub uart_fault: bool,
    pub request: String,
    /// `null`: no response.
    pub response: Option<String>,
    /// What the step shows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A row of a master-side table (000 chapter 3), as the spec table writes it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableCase {
    /// `quadrature` (000:T72), `sync` (000:3.2.5), `octant`, `transformation`,
    /// `retransformation` (000:3.2.4), `fault-reaction` (000:T74).
    pub table: String,
    /// quadrature: `A(n-1) B(n-1) A(n) B(n)` as 4 bits; sync: `f(i:i-1) a(4:3)`;
    /// octant: `sin>=0 cos>=0 |sin|<|cos|` as T/F; fault-reaction: `code group`.
    pub input: String,
    /// quadrature: `+1`, `-1`, `none`, `invalid`; sync: `a`, `a+1`, `a-1`, `invalid`;
    /// octant: `N: X=... Y=... phi=...`; fault-reaction: `Severity: response`.
    pub output: String,
}

/// A checksum example (000:T7): the XOR of `frame` is `checksum`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChecksumExample {
    pub frame: String,
    pub checksum: String,
}

/// One vector, flat: the group's profile and setup with the test (see `disk` for the
/// layout on disk).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Vector {
    pub id: String,
    /// Document file and section, or "generated".
    pub source: String,
    pub clauses: Vec<String>,
    /// A built-in profile name (`hiperface profiles`).
    pub profile: String,
    /// The command the vector is about (for the documentation tables).
    pub command: String,
    pub setup: Setup,
    pub steps: Vec<VectorStep>,
    pub checksum_example: Option<ChecksumExample>,
    pub table_case: Option<TableCase>,
    pub result: Expected,
    pub flags: Vec<Flag>,
    pub erratum: Option<Erratum>,
    /// What the vector shows, in a sentence.
    pub meaning: String,
}

impl Vector {
    /// A valid vector with no setup, steps, flags or erratum yet.
    pub fn new(
        id: String,
        source: String,
        clauses: &[&str],
        profile: &str,
        command: String,
        meaning: String,
    ) -> Vector {
        Vector {
            id,
            source,
            clauses: clauses.iter().map(|c| c.to_string()).collect(),
            profile: profile.into(),
            command,
            setup: Setup::default(),
            steps: Vec::new(),
            checksum_example: None,
            table_case: None,
            result: Expected::Valid,
            flags: Vec::new(),
            erratum: None,
            meaning,
        }
    }
}

/// Parse `40 42 02`.
pub fn parse_hex(s: &str) -> Result<Vec<u8>, VectorError> {
    s.split_whitespace().map(|b| u8::from_str_radix(b, 16).map_err(|_| VectorError::Hex(b.to_string()))).collect()
}

pub fn hex(bytes: &[u8]) -> String {
    Hex(bytes).to_string()
}

/// A vector file that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    /// Nothing verified is not a pass.
    #[error("{}: no vectors to verify (no *.json vector file)", path.display())]
    NoVectors { path: PathBuf },
}

/// The JSON Schema of vector files.
pub const SCHEMA: &str = include_str!("../../../vectors/schema.json");

/// The largest vector file read, bytes: 128 times this project's largest (128 KB). A
/// larger one, or anything that is not a regular file (a link to `/dev/zero`), is
/// refused before it is read.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// Read a vector file: JSON Schema first (with the `schema` feature; errors name the
/// vector id where there is one), then the types.
pub fn load(path: &Path) -> Result<VectorFile, LoadError> {
    use std::io::Read;
    let invalid = |message: String| LoadError::Invalid { path: path.into(), message };
    let io = |source| LoadError::Io { path: path.into(), source };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(invalid("not a regular file: a vector file is read from a file".into()));
    }
    let too_large =
        || invalid(format!("larger than {} MiB, more than any vector file: not read", MAX_FILE_BYTES >> 20));
    if meta.len() > MAX_FILE_BYTES {
        return Err(too_large());
    }
    let mut text = String::new();
    std::fs::File::open(path).map_err(io)?.take(MAX_FILE_BYTES + 1).read_to_string(&mut text).map_err(io)?;
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large());
    }
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| invalid(format!("not JSON: {e}")))?;
    #[cfg(feature = "schema")]
    check_schema(&json).map_err(|e| invalid(e.to_string()))?;
    serde_json::from_value(json).map_err(|e| invalid(e.to_string()))
}

/// Why a file does not pass [`SCHEMA`].
#[cfg(feature = "schema")]
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
enum SchemaError {
    /// The schema itself does not read (the build's copy of vectors/schema.json).
    #[error("schema: {0}")]
    Schema(String),
    /// The file's first departure from the schema, with the vector it lies in.
    #[error("{}at {pointer}: {message}", vector.as_ref().map_or(String::new(), |i| format!("vector `{i}` ")))]
    Departure { vector: Option<String>, pointer: String, message: String },
}

/// The file against [`SCHEMA`]: the first error, naming the vector where there is one.
#[cfg(feature = "schema")]
fn check_schema(json: &serde_json::Value) -> Result<(), SchemaError> {
    let schema: serde_json::Value = serde_json::from_str(SCHEMA).map_err(|e| SchemaError::Schema(e.to_string()))?;
    let validator = jsonschema::validator_for(&schema).map_err(|e| SchemaError::Schema(e.to_string()))?;
    let first = validator.iter_errors(json).next().map(|e| (e.instance_path.to_string(), e.to_string()));
    match first {
        Some((pointer, message)) => {
            Err(SchemaError::Departure { vector: vector_id_at(json, &pointer), pointer, message })
        }
        None => Ok(()),
    }
}

/// The id of the test that a JSON pointer such as `/testGroups/1/tests/3/steps/0`
/// points into.
#[cfg(feature = "schema")]
fn vector_id_at(json: &serde_json::Value, pointer: &str) -> Option<String> {
    let mut parts = pointer.strip_prefix("/testGroups/")?.split('/');
    let group: usize = parts.next()?.parse().ok()?;
    let test: usize = parts.nth(1)?.parse().ok()?;
    json.get("testGroups")?.get(group)?.get("tests")?.get(test)?.get("id")?.as_str().map(str::to_string)
}

/// The vector files of a directory, sorted.
pub fn files(dir: &Path) -> Result<Vec<PathBuf>, LoadError> {
    let rd = std::fs::read_dir(dir).map_err(|source| LoadError::Io { path: dir.into(), source })?;
    let mut out: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json") && p.file_name().is_some_and(|n| n != "schema.json"))
        .collect();
    out.sort();
    Ok(out)
}

/// The vector files of a directory, loaded, each with its file name (the reference
/// names the file an example comes from).
pub fn load_named(dir: &Path) -> Result<Vec<(String, VectorFile)>, LoadError> {
    files(dir)?
        .into_iter()
        .map(|p| Ok((p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(), load(&p)?)))
        .collect()
}

/// What is wrong with one vector: its printed checksums, then its replay against the
/// model (empty: it agrees).
pub fn verify(v: &Vector) -> Vec<String> {
    let mut problems = checksum_problems(v);
    if let Err(m) = replay(v) {
        problems.push(m.error.to_string());
    }
    problems
}

/// Verify every file of a directory: schema, checksums, agreement with the model.
/// Returns how many vectors were verified and the failing ones, one line each (file,
/// id, every reason): a vector with two problems is one failing vector. A directory
/// without a vector is an error (`LoadError::NoVectors`): nothing verified is no pass.
pub fn verify_dir(dir: &Path) -> Result<(usize, Vec<String>), LoadError> {
    let mut count = 0;
    let mut failures = Vec::new();
    for path in files(dir)? {
        let file = load(&path)?;
        let name = path.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        let mut seen = std::collections::BTreeSet::new();
        for v in &file.vectors {
            count += 1;
            let mut problems = verify(v);
            if !seen.insert(v.id.clone()) {
                problems.insert(0, "duplicate id".into());
            }
            if !problems.is_empty() {
                failures.push(format!("{name}: {}: {}", v.id, problems.join("; ")));
            }
        }
    }
    if count == 0 {
        return Err(LoadError::NoVectors { path: dir.into() });
    }
    Ok((count, failures))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hostile vector files are refused before they are read (issue 55: a 113 MB file
    /// took 1.37 GB, a `*.json` link to `/dev/zero` ran out of memory).
    #[test]
    fn a_vector_file_is_read_only_when_it_is_a_file_of_bounded_size() {
        let dir = tempfile::tempdir().unwrap();
        let zero = dir.path().join("zero.json");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let e = load(&zero).err().unwrap().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let huge = dir.path().join("huge.json");
        std::fs::File::create(&huge).unwrap().set_len(MAX_FILE_BYTES + 1).unwrap();
        let e = load(&huge).err().unwrap().to_string();
        assert!(e.contains("larger than 16 MiB"), "{e}");
        // This project's own files load.
        let ours = Path::new(env!("CARGO_MANIFEST_DIR")).join("../vectors/generated-current.json");
        assert!(load(&ours).is_ok());
    }
}
