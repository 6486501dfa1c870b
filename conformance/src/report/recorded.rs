//! `decode` of a certify report that holds the record of its wire: the record played
//! back to the catalogue (`crate::record`), the verdicts compared with the report's.

use crate::certify::{self, CaseVerdict};
use crate::record::Record;
use std::path::Path;
use std::process::ExitCode;

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

/// The report at `path`, if it is a certify report with a record (`None` for any
/// other file: a capture, an older report without one).
pub fn read(path: &Path) -> Result<Option<Recorded>, String> {
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
    let stated: Stated =
        serde_json::from_value(value).map_err(|e| format!("{name}: the report's record cannot be read: {e}"))?;
    let stated_cases = stated.cases.into_iter().map(|c| (c.id, c.verdict)).collect();
    Ok(Some(Recorded { name, record: stated.record, stated: stated_cases }))
}

/// Play the record back, print each case and whether the verdicts are the report's,
/// write the reports; exit as the run did (the played-back outcome).
pub fn decode(recorded: Recorded, report_dir: Option<&Path>, quiet: bool) -> Result<ExitCode, String> {
    let Recorded { name, record, stated } = recorded;
    if let Some(dir) = report_dir {
        crate::report::prepare_dir(dir)?;
    }
    eprintln!(
        "{name}: the record of a certify slave run ({}, {} events), played back to this catalogue",
        record.tool,
        record.events.len()
    );
    let report = certify::replay(&record, |i, n, r| {
        if quiet {
            return;
        }
        let mut text = format!("[{i:>2}/{n}] {:<16} {}", r.verdict.label(), r.id);
        for f in r.findings.iter().filter(|f| matches!(f.verdict(), CaseVerdict::Fail | CaseVerdict::Error)) {
            text.push_str(&format!("\n          {f}"));
        }
        println!("{text}");
    })
    .map_err(|e| format!("{name}: {e}"))?;
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
        println!(
            "the run's verdicts: {} cases and {exchanges} exchanges graded again from the record, every verdict as the report states it",
            again.len()
        );
    } else {
        println!("played back, the record gives other verdicts than the report states:");
        for d in &differing {
            println!("  {d}");
        }
        if stated.len() != again.len() {
            println!("  {} cases in the report, {} played back", stated.len(), again.len());
        }
    }
    if let Some(why) = &report.aborted {
        println!("the playback stopped: {why}");
    }
    let summary: Vec<String> = report.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    println!("{}: {}", report.profile, summary.join(", "));
    println!("{}", report.outcome().label());
    if let Some(dir) = report_dir {
        crate::report::write_all(&report, dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        eprintln!("reports written to {}", dir.display());
    }
    Ok(report.outcome().exit())
}
