//! `decode` of a certify report that holds the record of its wire: the record played
//! back to the catalogue (`slave::record`), the verdicts compared with the report's.

use crate::command::{CommandError, Ended};
use hiperface_suite::master::record::{self as master_record, MasterRecord};
use hiperface_suite::slave::record::Record;
use hiperface_suite::slave::{self, CaseVerdict};
use std::path::Path;

/// A certify report with its record, and the verdicts it states.
pub struct Recorded {
    pub name: String,
    pub record: Record,
    /// Each case's id and verdict label, as the report states them.
    pub stated: Vec<(String, String)>,
}

#[derive(serde::Deserialize)]
struct StatedCase {
    id: String,
    verdict: String,
}

#[derive(serde::Deserialize)]
struct Stated {
    cases: Vec<StatedCase>,
    record: Record,
}

/// A certify master report with its record, and the verdicts it states.
pub struct MasterRecorded {
    pub name: String,
    pub record: MasterRecord,
    pub stated: Vec<(String, String)>,
}

#[derive(serde::Deserialize)]
struct StatedMaster {
    scenarios: Vec<StatedCase>,
    record: MasterRecord,
}

/// What a report with a record holds: a slave run's or a master run's.
pub enum AnyRecorded {
    Slave(Box<Recorded>),
    Master(MasterRecorded),
}

/// The report at `path`, if it is a certify report with a record (`None` for any
/// other file: a capture, an older report without one).
pub fn read_any(path: &Path) -> Result<Option<AnyRecorded>, CommandError> {
    if path.as_os_str() == "-" || path.extension().is_none_or(|e| e != "json") {
        return Ok(None);
    }
    let Ok(text) = std::fs::read_to_string(path) else { return Ok(None) };
    let Ok(value) = serde_json::from_str::<serde_json::Value>(&text) else { return Ok(None) };
    let format = value.get("record").and_then(|r| r.get("format")).and_then(|f| f.as_str()).map(str::to_string);
    let name = path.display().to_string();
    match format.as_deref() {
        Some(master_record::FORMAT) => {
            let stated: StatedMaster = serde_json::from_value(value).map_err(|e| CommandError::Input {
                name: name.clone(),
                why: format!("the report's record cannot be read: {e}"),
            })?;
            let stated_cases = stated.scenarios.into_iter().map(|c| (c.id, c.verdict)).collect();
            Ok(Some(AnyRecorded::Master(MasterRecorded { name, record: stated.record, stated: stated_cases })))
        }
        Some(_) => Ok(read(path)?.map(|r| AnyRecorded::Slave(Box::new(r)))),
        None if value.get("capture").is_some() && value.get("summary").is_some() => Err(CommandError::Input {
            name,
            why: "a listening report (decode, monitor): what it heard is in its capture; decode the capture \
                  (monitor --capture FILE) to grade it again"
                .into(),
        }),
        None if value.get("scenarios").is_some() => Err(CommandError::Input {
            name,
            why: "a certify master report without the record of its wire (written by an older version): \
                  there is nothing to grade again; certify the master again to get one"
                .into(),
        }),
        None => Ok(None),
    }
}

/// Take a master run's record in again, print each scenario and whether the verdicts
/// are the report's; exit as the run did.
pub fn decode_master(recorded: MasterRecorded, quiet: bool) -> Result<Ended, CommandError> {
    let MasterRecorded { name, record, stated } = recorded;
    eprintln!(
        "{name}: the record of a certify master run ({}, {} scenario runs), taken in again",
        record.tool,
        record.runs.len()
    );
    let (profile, again, notes) =
        master_record::replay(&record).map_err(|source| CommandError::Replay { name: name.clone(), source })?;
    let n = again.len();
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
    let differing = master_record::compare(&stated, &again);
    if differing.is_empty() && stated.len() == again.len() {
        say!("the run's verdicts: {n} scenarios graded again from the record, every verdict as the report states it");
    } else {
        say!("taken in again, the record gives other verdicts than the report states:");
        for (id, was, now) in &differing {
            say!("  {id}: {was} in the report, {now} taken in again");
        }
    }
    for note in &notes {
        say!("note: {note}");
    }
    let outcome = crate::verdict::Outcome::of(again.iter().map(|r| r.verdict), !record.interrupted);
    let mut summary = std::collections::BTreeMap::new();
    for r in &again {
        *summary.entry(r.verdict.label()).or_insert(0) += 1;
    }
    let summary: Vec<String> = summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    say!("master (encoder {}): {}", profile.name, summary.join(", "));
    say!("{}", outcome.label());
    Ok(Ended::Graded(outcome))
}

/// The report at `path`, if it is a certify slave report with a record.
pub fn read(path: &Path) -> Result<Option<Recorded>, CommandError> {
    if path.as_os_str() == "-" || path.extension().is_none_or(|e| e != "json") {
        return Ok(None);
    }
    let Ok(text) = std::fs::read_to_string(path) else { return Ok(None) };
    let Ok(value) = serde_json::from_str::<serde_json::Value>(&text) else { return Ok(None) };
    let has_record = value.get("record").and_then(|r| r.get("format")).is_some_and(|f| f.is_string());
    if !has_record {
        return Ok(None);
    }
    let name = path.display().to_string();
    let stated: Stated = serde_json::from_value(value).map_err(|e| CommandError::Input {
        name: name.clone(),
        why: format!("the report's record cannot be read: {e}"),
    })?;
    let stated_cases = stated.cases.into_iter().map(|c| (c.id, c.verdict)).collect();
    Ok(Some(Recorded { name, record: stated.record, stated: stated_cases }))
}

/// Play the record back, print each case and whether the verdicts are the report's,
/// write the reports; exit as the run did (the played-back outcome).
pub fn decode(recorded: Recorded, report_dir: Option<&Path>, quiet: bool) -> Result<Ended, CommandError> {
    let Recorded { name, record, stated } = recorded;
    if let Some(dir) = report_dir {
        crate::report::prepare_dir(dir)?;
    }
    eprintln!(
        "{name}: the record of a certify slave run ({}, {} events), played back to this catalogue",
        record.tool,
        record.events.len()
    );
    let report = slave::replay(&record, |i, n, r| {
        if quiet {
            return;
        }
        let mut text = format!("[{i:>2}/{n}] {:<16} {}", r.verdict.label(), r.id);
        for f in r.findings.iter().filter(|f| matches!(f.verdict(), CaseVerdict::Fail | CaseVerdict::Error)) {
            text.push_str(&format!("\n          {f}"));
        }
        say!("{text}");
    })
    .map_err(|e| CommandError::Input { name: name.clone(), why: e.to_string() })?;
    let again: Vec<(String, String)> =
        report.cases.iter().map(|c| (c.id.to_string(), c.verdict.label().to_string())).collect();
    let differing: Vec<String> = stated
        .iter()
        .zip(&again)
        .filter(|(a, b)| a != b)
        .map(|((id, was), (_, now))| format!("{id}: {was} in the report, {now} played back"))
        .collect();
    let exchanges: usize = report.cases.iter().map(|c| c.exchanges).sum();
    if differing.is_empty() && stated.len() == again.len() {
        say!(
            "the run's verdicts: {} cases and {exchanges} exchanges graded again from the record, every verdict as the report states it",
            again.len()
        );
    } else {
        say!("played back, the record gives other verdicts than the report states:");
        for d in &differing {
            say!("  {d}");
        }
        if stated.len() != again.len() {
            say!("  {} cases in the report, {} played back", stated.len(), again.len());
        }
    }
    if let Some(why) = &report.aborted {
        say!("the playback stopped: {why}");
    }
    let summary: Vec<String> = report.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    say!("{}: {}", report.profile, summary.join(", "));
    say!("{}", report.outcome().label());
    if let Some(dir) = report_dir {
        crate::report::write_all(&report, dir)?;
        eprintln!("reports written to {}", dir.display());
    }
    Ok(Ended::Graded(report.outcome()))
}
