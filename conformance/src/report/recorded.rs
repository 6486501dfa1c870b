//! `decode` of a certify report that holds the record of its wire: the record played
//! back to the catalogue (`slave::record`), the verdicts compared with the report's.
//!
//! Long because: a report is read once (bounded, its kind probed, its signature
//! checked) and then decoded as a slave's or a master's; both decodes share that
//! reading and how they state their verdict.

use crate::command::{CommandError, Ended};
use crate::report::signature;
use hiperface_suite::master::record::{self as master_record, MasterRecord};
use hiperface_suite::slave;
use hiperface_suite::slave::record::{self as slave_record, Record};
use hiperface_suite::verdict::CaseVerdict;
use std::path::Path;

/// The largest report `decode` reads, bytes: 35 times the largest this tool writes in
/// its whole catalogue (a master run, 1.8 MB). A larger one is refused with this figure,
/// never read into memory.
pub const MAX_REPORT_BYTES: u64 = 64 << 20;

/// How much of a file is read to tell a report (JSON) from a capture.
const SNIFF_BYTES: u64 = 4096;

/// What a report states, to be held against what its record gives.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stated {
    /// Each case's or scenario's id and verdict label, in the report's order.
    pub units: Vec<(String, String)>,
    /// The count of each verdict.
    pub summary: std::collections::BTreeMap<String, u64>,
    /// The outcome's label ("PASSED").
    pub outcome: String,
    /// What the report states of how the run was graded (a slave run's timing mode,
    /// tolerance, grading, profile, edition), as written: each must be what the
    /// record's options give.
    pub run: Vec<(&'static str, serde_json::Value)>,
}

/// One case or scenario as a report states it (its other fields are skipped unread).
#[derive(serde::Deserialize)]
struct StatedUnit {
    id: String,
    verdict: String,
}

/// A certify slave report as `decode` reads it: what it states, and its record. Only
/// these fields are taken in; the rest (wire logs, notes) is skipped as it is parsed.
#[derive(serde::Deserialize)]
struct SlaveFile {
    cases: Vec<StatedUnit>,
    #[serde(default)]
    summary: std::collections::BTreeMap<String, u64>,
    #[serde(default)]
    outcome: Option<String>,
    #[serde(default)]
    profile: serde_json::Value,
    #[serde(default)]
    edition: serde_json::Value,
    #[serde(default)]
    timing: serde_json::Value,
    #[serde(default)]
    tolerance_us: serde_json::Value,
    #[serde(default)]
    grading: serde_json::Value,
    record: Record,
}

/// A certify master report as `decode` reads it.
#[derive(serde::Deserialize)]
struct MasterFile {
    scenarios: Vec<StatedUnit>,
    #[serde(default)]
    summary: std::collections::BTreeMap<String, u64>,
    #[serde(default)]
    outcome: Option<String>,
    record: MasterRecord,
}

/// Which report a JSON file is, read without keeping anything but the record's format.
#[derive(serde::Deserialize)]
struct Probe {
    #[serde(default)]
    record: Option<ProbeRecord>,
    #[serde(default)]
    capture: Option<serde::de::IgnoredAny>,
    #[serde(default)]
    summary: Option<serde::de::IgnoredAny>,
    #[serde(default)]
    scenarios: Option<serde::de::IgnoredAny>,
    #[serde(default)]
    cases: Option<serde::de::IgnoredAny>,
}

#[derive(serde::Deserialize)]
struct ProbeRecord {
    #[serde(default)]
    format: Option<String>,
}

impl Stated {
    fn of_units(
        units: Vec<StatedUnit>,
        summary: std::collections::BTreeMap<String, u64>,
        outcome: Option<String>,
    ) -> Stated {
        Stated {
            units: units.into_iter().map(|u| (u.id, u.verdict)).collect(),
            summary,
            outcome: outcome.unwrap_or_else(|| "(none)".into()),
            run: Vec::new(),
        }
    }

    /// What a replayed slave run's report states, in the same terms as a report file's.
    fn of_slave_report(report: &slave::Report) -> Stated {
        let value = |v: Result<serde_json::Value, serde_json::Error>| v.unwrap_or_default();
        Stated {
            units: report.cases.iter().map(|c| (c.id.to_string(), c.verdict.label().to_string())).collect(),
            summary: report.summary.iter().map(|(k, v)| (k.to_string(), *v as u64)).collect(),
            outcome: report.outcome().label().to_string(),
            run: vec![
                ("profile", value(serde_json::to_value(&report.profile))),
                ("edition", value(serde_json::to_value(&report.edition))),
                ("timing", value(serde_json::to_value(report.timing))),
                ("tolerance_us", value(serde_json::to_value(report.tolerance_us))),
                ("grading", value(serde_json::to_value(&report.grading))),
            ],
        }
    }

    /// Where `again` (the record graded again, stated the same way) differs from this:
    /// one line each, empty when the report states what its record gives.
    pub fn differences(&self, again: &Stated) -> Vec<String> {
        let mut d = Vec::new();
        for ((id, was), (id_again, now)) in self.units.iter().zip(&again.units) {
            if id != id_again {
                d.push(format!("{id} in the report where the record gives {id_again}"));
            } else if was != now {
                d.push(format!("{id}: {was} in the report, {now} from the record"));
            }
        }
        if self.units.len() != again.units.len() {
            d.push(format!("{} in the report, {} from the record", self.units.len(), again.units.len()));
        }
        if self.summary != again.summary {
            let show = |m: &std::collections::BTreeMap<String, u64>| {
                m.iter().map(|(k, v)| format!("{v} {k}")).collect::<Vec<_>>().join(", ")
            };
            d.push(format!(
                "the counts: {} in the report, {} from the record",
                show(&self.summary),
                show(&again.summary)
            ));
        }
        if self.outcome != again.outcome {
            d.push(format!("the outcome: {} in the report, {} from the record", self.outcome, again.outcome));
        }
        for ((key, was), (_, now)) in self.run.iter().zip(&again.run) {
            if was != now {
                d.push(format!("`{key}`: {was} in the report, {now} in the record's options"));
            }
        }
        d
    }
}

/// A certify report with its record, and what it states.
pub struct Recorded {
    pub name: String,
    pub record: Record,
    pub stated: Stated,
}

/// A certify master report with its record, and what it states.
pub struct MasterRecorded {
    pub name: String,
    pub record: MasterRecord,
    pub stated: Stated,
}

/// What a report with a record holds: a slave run's or a master run's.
pub enum AnyRecorded {
    Slave(Box<Recorded>),
    Master(Box<MasterRecorded>),
}

/// The file at `path` as a report: `None` for a file that is none (a capture: not
/// `.json` and not beginning with `{`), else its bytes (a byte-order mark taken off),
/// read to at most [`MAX_REPORT_BYTES`].
fn read_report_bytes(path: &Path) -> Result<Option<Vec<u8>>, CommandError> {
    use std::io::Read;
    if path.as_os_str() == "-" {
        return Ok(None);
    }
    let Ok(file) = std::fs::File::open(path) else { return Ok(None) };
    let mut text = Vec::new();
    (&file).take(SNIFF_BYTES).read_to_end(&mut text).map_err(CommandError::file(path))?;
    let body = text.strip_prefix(BOM).unwrap_or(&text);
    let opens_json = body.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{');
    if !opens_json && path.extension().is_none_or(|e| e != "json") {
        return Ok(None);
    }
    read_rest(&file, path, &mut text)?;
    Ok(Some(without_bom(text)))
}

/// The report.json at `path` (`compare`'s input): its bytes, a byte-order mark taken
/// off, read to at most [`MAX_REPORT_BYTES`]; a file that cannot be opened or read is
/// an error that names it.
pub fn read_report(path: &Path) -> Result<Vec<u8>, CommandError> {
    let file = std::fs::File::open(path).map_err(CommandError::file(path))?;
    let mut bytes = Vec::new();
    read_rest(&file, path, &mut bytes)?;
    Ok(without_bom(bytes))
}

/// A byte-order mark, taken off a report before it is parsed.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// `bytes` without a leading byte-order mark.
fn without_bom(mut bytes: Vec<u8>) -> Vec<u8> {
    if bytes.starts_with(BOM) {
        bytes.drain(..BOM.len());
    }
    bytes
}

/// Read the rest of the report `file` (at `path`) into `bytes`, to at most
/// [`MAX_REPORT_BYTES`] in all: more is an error, not read.
fn read_rest(file: &std::fs::File, path: &Path, bytes: &mut Vec<u8>) -> Result<(), CommandError> {
    use std::io::Read;
    let room = (MAX_REPORT_BYTES + 1).saturating_sub(bytes.len() as u64);
    file.take(room).read_to_end(bytes).map_err(CommandError::file(path))?;
    if bytes.len() as u64 > MAX_REPORT_BYTES {
        return Err(CommandError::Input {
            name: path.display().to_string(),
            why: format!("larger than {} MiB, more than any report this tool writes: not read", MAX_REPORT_BYTES >> 20),
        });
    }
    Ok(())
}

/// The report at `path`, if it is a certify report with a record (`None` for a
/// capture). A report that cannot be read is an error that says so, never taken for a
/// capture. Only what `decode` needs is taken in (no tree of the whole file).
pub fn read_any(path: &Path) -> Result<Option<AnyRecorded>, CommandError> {
    let Some(bytes) = read_report_bytes(path)? else { return Ok(None) };
    parse_any(path, &bytes).map(Some)
}

/// The report at `path` whose signature (`report.sig` beside it) holds for `key`,
/// checked on the very bytes then taken in: the signature, then the report. A report
/// whose signature does not hold is [`Unverified`], never decoded.
pub fn read_verified(
    path: &Path,
    key: &Path,
) -> Result<Result<(signature::Verified, AnyRecorded), signature::Unverified>, CommandError> {
    let key = signature::load_public(key)?;
    if path.as_os_str() == "-" {
        return Err(CommandError::Usage(
            "--verify: a report on standard input has no signature beside it; give its path".into(),
        ));
    }
    let file = std::fs::File::open(path).map_err(CommandError::file(path))?;
    let mut raw = Vec::new();
    read_rest(&file, path, &mut raw)?;
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let report_name = path.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
    let verified = match signature::verify(&key, dir, &report_name, &raw) {
        Ok(v) => v,
        Err(why) => return Ok(Err(why)),
    };
    let body = raw.strip_prefix(BOM).unwrap_or(&raw);
    Ok(Ok((verified, parse_any(path, body)?)))
}

/// A report's bytes taken in: a slave's or a master's run with its record.
fn parse_any(path: &Path, bytes: &[u8]) -> Result<AnyRecorded, CommandError> {
    let name = path.display().to_string();
    let unreadable = |why: String| CommandError::Input { name: name.clone(), why };
    let probe: Probe = serde_json::from_slice(bytes).map_err(|e| {
        unreadable(format!(
            "cannot be read as a report (JSON): {e}; a capture is decoded from a CSV, wire log or sigrok file"
        ))
    })?;
    match probe.record.map(|r| r.format) {
        Some(Some(format)) if format == master_record::FORMAT => {
            let file: MasterFile = serde_json::from_slice(bytes)
                .map_err(|e| unreadable(format!("the report or its record cannot be read: {e}")))?;
            let stated = Stated::of_units(file.scenarios, file.summary, file.outcome);
            Ok(AnyRecorded::Master(Box::new(MasterRecorded { name, record: file.record, stated })))
        }
        Some(Some(format)) if format == slave_record::FORMAT => {
            let file: SlaveFile = serde_json::from_slice(bytes)
                .map_err(|e| unreadable(format!("the report or its record cannot be read: {e}")))?;
            let mut stated = Stated::of_units(file.cases, file.summary, file.outcome);
            stated.run = vec![
                ("profile", file.profile),
                ("edition", file.edition),
                ("timing", file.timing),
                ("tolerance_us", file.tolerance_us),
                ("grading", file.grading),
            ];
            Ok(AnyRecorded::Slave(Box::new(Recorded { name, record: file.record, stated })))
        }
        Some(Some(other)) => Err(unreadable(format!(
            "a record of format `{other}`, which this version does not read (it reads `{}` and `{}`): decode it \
             with the version that wrote it (the report's `tool`)",
            slave_record::FORMAT,
            master_record::FORMAT
        ))),
        Some(None) => Err(unreadable("a record without its format: nothing this tool wrote".into())),
        None if probe.capture.is_some() && probe.summary.is_some() => Err(unreadable(
            "a listening report (decode, monitor): what it heard is in its capture; decode the capture \
             (monitor --capture FILE) to grade it again"
                .into(),
        )),
        None if probe.scenarios.is_some() => Err(unreadable(
            "a certify master report without the record of its wire (written by an older version): \
             there is nothing to grade again; certify the master again to get one"
                .into(),
        )),
        None if probe.cases.is_some() => Err(unreadable(
            "a certify report without the record of its wire (written by an older version, or with its record \
             taken out): there is nothing to grade again; certify the device again to get one"
                .into(),
        )),
        None => Err(unreadable("a JSON file that is no report of this tool: nothing to decode".into())),
    }
}

/// Say whether the report states what its record gives, first, with each difference;
/// then which run's record it was (`identified`, on standard error) and what was left
/// unchecked beside it (`beside`).
fn say_verdict_on_report(differences: &[String], agreed: String, identified: String, beside: &[String]) {
    say_differences(differences, agreed);
    eprintln!("{identified}");
    for note in beside {
        say!("note: {note}");
    }
}

fn say_differences(differences: &[String], agreed: String) {
    if differences.is_empty() {
        say!("{agreed}");
    } else {
        let n = differences.len();
        say!(
            "THE REPORT DOES NOT STATE WHAT ITS RECORD GIVES ({n} difference{}): it is no evidence of the run",
            if n == 1 { "" } else { "s" }
        );
        for d in differences {
            say!("  {d}");
        }
    }
}

/// The last line: the played-back outcome, or, where the report states otherwise,
/// that it is no evidence (a CI that reads the last line must not read PASSED there).
fn say_outcome(outcome: hiperface_suite::verdict::Outcome, differences: &[String]) {
    if differences.is_empty() {
        say!("{}", outcome.label());
    } else {
        say!(
            "NOT EVIDENCE: the report does not state what its record gives (its record's run: {}; exit 4)",
            outcome.label()
        );
    }
}

/// Take a master run's record in again, say first whether it gives what the report
/// states, then each scenario; exit as the run did, or 4 where they differ.
pub fn decode_master(recorded: MasterRecorded, quiet: bool, beside: &[String]) -> Result<Ended, CommandError> {
    let MasterRecorded { name, record, stated } = recorded;
    let (profile, again, notes) =
        master_record::replay(&record).map_err(|source| CommandError::Replay { name: name.clone(), source })?;
    let n = again.len();
    let outcome = hiperface_suite::verdict::Outcome::of(again.iter().map(|r| r.verdict), !record.interrupted);
    let mut given = Stated { outcome: outcome.label().to_string(), ..Stated::default() };
    for r in &again {
        given.units.push((r.id.to_string(), r.verdict.label().to_string()));
        *given.summary.entry(r.verdict.label().to_string()).or_insert(0) += 1;
    }
    let differences = stated.differences(&given);
    say_verdict_on_report(
        &differences,
        format!(
            "the report states what its record gives: {n} scenarios graded again, every verdict as the report \
             states it, and its counts and outcome"
        ),
        format!(
            "{name}: the record of a certify master run ({}, {} scenario runs), taken in again",
            record.tool,
            record.runs.len()
        ),
        beside,
    );
    for (i, r) in again.iter().enumerate() {
        if quiet {
            break;
        }
        let mut text = format!("[{:>2}/{n}] {:<16} {}", i + 1, r.verdict.label(), r.id);
        for f in r.findings.iter().filter(|f| matches!(f.verdict(), CaseVerdict::Fail | CaseVerdict::Error)) {
            text.push_str(&format!("\n          {f}"));
        }
        say!("{text}");
    }
    for note in &notes {
        say!("note: {note}");
    }
    let summary: Vec<String> = given.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    say!("master (encoder {}): {}", profile.name, summary.join(", "));
    say_outcome(outcome, &differences);
    Ok(if differences.is_empty() { Ended::Graded(outcome) } else { Ended::Disagrees })
}

/// Play the record back, say first whether it gives what the report states, then each
/// case; write the reports; exit as the run did (the played-back outcome), or 4 where
/// the report states otherwise.
pub fn decode(
    recorded: Recorded,
    report_dir: Option<&Path>,
    quiet: bool,
    beside: &[String],
) -> Result<Ended, CommandError> {
    let Recorded { name, record, stated } = recorded;
    if let Some(dir) = report_dir {
        crate::report::prepare_dir(dir)?;
    }
    let mut lines = Vec::new();
    let report = slave::replay(&record, |i, n, r| {
        if quiet {
            return;
        }
        let mut text = format!("[{i:>2}/{n}] {:<16} {}", r.verdict.label(), r.id);
        for f in r.findings.iter().filter(|f| matches!(f.verdict(), CaseVerdict::Fail | CaseVerdict::Error)) {
            text.push_str(&format!("\n          {f}"));
        }
        lines.push(text);
    })
    .map_err(|e| CommandError::Input { name: name.clone(), why: e.to_string() })?;
    let given = Stated::of_slave_report(&report);
    let differences = stated.differences(&given);
    let exchanges: usize = report.cases.iter().map(|c| c.exchanges).sum();
    say_verdict_on_report(
        &differences,
        format!(
            "the report states what its record gives: {} cases and {exchanges} exchanges graded again, every \
             verdict as the report states it, and its counts, outcome and grading options",
            report.cases.len()
        ),
        format!(
            "{name}: the record of a certify slave run ({}, {} events), played back to this catalogue",
            record.tool,
            record.events.len()
        ),
        beside,
    );
    for line in lines {
        say!("{line}");
    }
    if let Some(why) = &report.aborted {
        say!("the playback stopped: {why}");
    }
    let summary: Vec<String> = report.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    say!("{}: {}", report.profile, summary.join(", "));
    say_outcome(report.outcome(), &differences);
    if let Some(dir) = report_dir {
        crate::report::write_all(&report, dir, None)?;
        eprintln!("reports written to {}", dir.display());
    }
    Ok(if differences.is_empty() { Ended::Graded(report.outcome()) } else { Ended::Disagrees })
}

/// The fuzz target's entry (fuzz/fuzz_targets/report.rs) and its corpus replay: any
/// bytes as a report that `decode` reads, taken in and, where it is a report with a
/// record, its record played back and held against what it states. An error for bad
/// input is fine; a panic, a hang or memory beyond the input's bounds is not.
pub fn fuzz_report(input: &[u8]) {
    let Ok(recorded) = parse_any(Path::new("fuzz"), input) else { return };
    match recorded {
        AnyRecorded::Slave(r) => {
            if let Ok(report) = slave::replay(&r.record, |_, _, _| {}) {
                let _ = r.stated.differences(&Stated::of_slave_report(&report));
            }
        }
        AnyRecorded::Master(r) => {
            let _ = master_record::replay(&r.record);
        }
    }
}
