//! `hiperface compare`: certify reports side by side (the matrix of
//! `hiperface_suite::report::compare`), and the gate of a CI against a baseline. The
//! files are read here, each to the bound of any report, and the forms written.

use super::recorded::read_report;
use crate::command::{CommandError, Ended};
use hiperface_suite::report::compare::{Column, Comparison};
use std::path::{Path, PathBuf};

/// The comparison's files in `--report DIR`.
pub const MARKDOWN: &str = "comparison.md";
pub const HTML: &str = "comparison.html";
pub const JSON: &str = "comparison.json";
pub const JUNIT: &str = "comparison-junit.xml";

/// `hiperface compare`.
#[derive(clap::Args, Debug, Clone)]
pub struct CompareArgs {
    /// The reports (report.json of `certify slave` or `certify master`, any profile), in
    /// the matrix's order.
    #[arg(required = true, value_name = "REPORT.json")]
    pub reports: Vec<PathBuf>,
    /// The report to compare against: exit 1 when a report regressed (a unit's verdict
    /// worse than the baseline's, a unit the baseline ran and the report does not, a
    /// clause newly broken); regressions are listed first, improvements after.
    #[arg(long, value_name = "REPORT.json")]
    pub baseline: Option<PathBuf>,
    /// Write comparison.md, comparison.html (a page to publish: each cell links to its
    /// findings), comparison.json and comparison-junit.xml into DIR (made if need be; an
    /// earlier run's files are moved aside, never mixed).
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
}

/// Compare the reports; [`Ended::Regressed`] when one regressed against the baseline.
pub fn compare(args: &CompareArgs) -> Result<Ended, CommandError> {
    let column = |path: &Path| {
        let bytes = read_report(path)?;
        Column::read(&path.display().to_string(), &bytes)
            .map_err(|e| CommandError::Input { name: path.display().to_string(), why: e.to_string() })
    };
    let baseline = args.baseline.as_deref().map(column).transpose()?;
    let reports = args.reports.iter().map(|p| column(p)).collect::<Result<Vec<_>, _>>()?;
    let comparison = Comparison::of(baseline, reports);
    if let Some(dir) = &args.report {
        for input in args.reports.iter().chain(&args.baseline) {
            super::refuse_overwriting(input, dir)?;
        }
        super::prepare_dir(dir)?;
        write(&comparison, dir).map_err(|source| CommandError::WriteReport { dir: dir.clone(), source })?;
    }
    for line in comparison.lines() {
        say!("{line}");
    }
    if let Some(dir) = &args.report {
        say!("comparison written to {}", dir.display());
    }
    Ok(if comparison.regressed() { Ended::Regressed } else { Ended::Done })
}

fn write(c: &Comparison, dir: &Path) -> std::io::Result<()> {
    std::fs::write(dir.join(MARKDOWN), c.markdown())?;
    std::fs::write(dir.join(HTML), c.html())?;
    std::fs::write(dir.join(JSON), c.json().map_err(std::io::Error::other)? + "\n")?;
    std::fs::write(dir.join(JUNIT), c.junit())
}
