//! Reports side by side (`hiperface compare`): the units (slave cases, master
//! scenarios) of any number of certify reports in one matrix, and against a baseline
//! what a CI gate acts on. Sans-IO: the harness reads the files and writes the forms.
//!
//! Long because: the matrix and the regressions against a baseline are one comparison
//! of the same units, and a gate reads them together; under 610 lines without its
//! tests.
//!
//! Against a baseline, a report's regressions are, per unit:
//! - **no longer run**: the baseline ran it (any verdict but NOT-APPLICABLE) and the
//!   report does not (the unit is absent, or NOT-APPLICABLE);
//! - **worse**: both ran it and the report's verdict is more severe
//!   ([`CaseVerdict::worst`]: FAIL > ERROR > NOT-EXERCISED > UNKNOWN > NON-STRICT > PASS);
//! - **newly broken**: a clause a FAIL finding of the report's unit cites that no FAIL
//!   finding of the baseline's same unit cites, where the verdict did not get worse
//!   (FAIL -> FAIL for another reason; a worse verdict names its new clauses in its own
//!   line); a unit the baseline did not run that FAILs breaks its clauses anew.
//!
//! Improvements are the converse (newly run, better, no longer broken). Reports made by
//! other tool revisions compare where their units match; a unit one side has and the
//! other has not is listed as such, never silently dropped.

use super::{escape, page_head};
use crate::verdict::{CaseVerdict, Outcome};
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

/// A certify report as `compare` reads it: only what the matrix needs (every other
/// field, the record included, is passed over).
#[derive(Debug, Clone, Deserialize)]
struct ReportFile {
    tool: String,
    profile: String,
    #[serde(default)]
    outcome: Option<Outcome>,
    #[serde(default)]
    cases: Option<Vec<Unit>>,
    #[serde(default)]
    scenarios: Option<Vec<Unit>>,
    #[serde(default)]
    run_info: Option<super::RunInfo>,
}

/// One graded unit of a report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Unit {
    pub id: String,
    #[serde(default)]
    pub title: String,
    pub verdict: CaseVerdict,
    #[serde(default)]
    pub findings: Vec<UnitFinding>,
}

/// One finding of a unit, as its report states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitFinding {
    pub verdict: CaseVerdict,
    pub message: String,
    pub clause: String,
}

impl Unit {
    /// The clauses its FAIL findings cite.
    fn broken(&self) -> BTreeSet<&str> {
        self.findings.iter().filter(|f| f.verdict == CaseVerdict::Fail).map(|f| f.clause.as_str()).collect()
    }

    fn ran(&self) -> bool {
        self.verdict != CaseVerdict::NotApplicable
    }
}

/// What a report certified: an encoder (slave cases) or a drive (master scenarios).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Slave,
    Master,
}

/// One report: a column of the matrix.
#[derive(Debug, Clone, Serialize)]
pub struct Column {
    /// How the caller names it (its path).
    pub label: String,
    pub kind: Kind,
    pub tool: String,
    /// The tool's source revision, where the report states it.
    pub revision: Option<String>,
    pub profile: String,
    pub outcome: Option<Outcome>,
    pub units: Vec<Unit>,
}

/// Why a file is not a report `compare` can read.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error("not a certify report.json: {0}")]
    Json(#[from] serde_json::Error),
    #[error("a report without cases or scenarios (a listening report of `decode`? those are not compared)")]
    NoUnits,
}

impl Column {
    /// Read the report.json `bytes`, named `label`.
    pub fn read(label: &str, bytes: &[u8]) -> Result<Column, CompareError> {
        let r: ReportFile = serde_json::from_slice(bytes)?;
        let (kind, units) = match (r.cases, r.scenarios) {
            (Some(cases), None) => (Kind::Slave, cases),
            (None, Some(scenarios)) => (Kind::Master, scenarios),
            _ => return Err(CompareError::NoUnits),
        };
        Ok(Column {
            label: label.to_string(),
            kind,
            tool: r.tool,
            revision: r.run_info.map(|i| i.revision),
            profile: r.profile,
            outcome: r.outcome,
            units,
        })
    }

    fn unit(&self, id: &str) -> Option<&Unit> {
        self.units.iter().find(|u| u.id == id)
    }
}

/// How a unit moved between the baseline and a report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ChangeKind {
    NoLongerRun,
    Worse,
    NewlyBroken,
    NewlyRun,
    Better,
    NoLongerBroken,
}

impl ChangeKind {
    pub fn is_regression(self) -> bool {
        matches!(self, ChangeKind::NoLongerRun | ChangeKind::Worse | ChangeKind::NewlyBroken)
    }
}

/// One difference of a report from the baseline.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Change {
    /// The report's label.
    pub report: String,
    pub unit: String,
    pub kind: ChangeKind,
    /// What changed, in words: "PASS -> FAIL", "000:T10 newly broken".
    pub what: String,
}

/// One row of the matrix: a unit and its verdict in each report (`None`: not in it).
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    pub id: String,
    pub title: String,
    pub verdicts: Vec<Option<CaseVerdict>>,
}

/// Reports compared.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// The baseline first where there is one, then the reports in the order given.
    pub reports: Vec<Column>,
    pub baseline: bool,
    pub rows: Vec<Row>,
    /// Against the baseline: regressions, then improvements.
    pub regressions: Vec<Change>,
    pub improvements: Vec<Change>,
    /// Units not in every report, with the reports that have them.
    pub unmatched: Vec<(String, Vec<String>)>,
    /// What the reader should know before the matrix (reports of several tool
    /// revisions, of both sides).
    pub notes: Vec<String>,
}

impl Comparison {
    /// `reports` side by side; against `baseline` where one is given.
    pub fn of(baseline: Option<Column>, reports: Vec<Column>) -> Comparison {
        let has_baseline = baseline.is_some();
        let all: Vec<Column> = baseline.into_iter().chain(reports).collect();
        let mut ids: Vec<(String, String)> = Vec::new();
        for c in &all {
            for u in &c.units {
                if !ids.iter().any(|(id, _)| *id == u.id) {
                    ids.push((u.id.clone(), u.title.clone()));
                }
            }
        }
        let rows: Vec<Row> = ids
            .into_iter()
            .map(|(id, title)| {
                let verdicts = all.iter().map(|c| c.unit(&id).map(|u| u.verdict)).collect();
                Row { id, title, verdicts }
            })
            .collect();
        let unmatched = rows
            .iter()
            .filter(|r| r.verdicts.iter().any(Option::is_none))
            .map(|r| {
                let have = all.iter().zip(&r.verdicts).filter(|(_, v)| v.is_some()).map(|(c, _)| c.label.clone());
                (r.id.clone(), have.collect())
            })
            .collect();
        let mut changes = Vec::new();
        if let Some((base, rest)) = all.split_first().filter(|_| has_baseline) {
            for report in rest {
                changes.extend(against(base, report));
            }
        }
        let (regressions, improvements) = changes.into_iter().partition(|c: &Change| c.kind.is_regression());
        let mut notes = Vec::new();
        let revisions: BTreeSet<&str> = all.iter().filter_map(|c| c.revision.as_deref()).collect();
        if revisions.len() > 1 {
            notes.push(format!(
                "the reports were made by {} tool revisions ({}): units are compared where their ids match",
                revisions.len(),
                revisions.into_iter().collect::<Vec<_>>().join(", ")
            ));
        }
        let profiles: BTreeSet<&str> = all.iter().map(|c| c.profile.as_str()).collect();
        if profiles.len() > 1 {
            notes.push(format!(
                "the reports certify {} profiles ({}): a unit a profile excludes is NOT-APPLICABLE in its report",
                profiles.len(),
                profiles.into_iter().collect::<Vec<_>>().join(", ")
            ));
        }
        if all.iter().any(|c| c.kind == Kind::Slave) && all.iter().any(|c| c.kind == Kind::Master) {
            notes.push("encoders' and drives' reports together: their units never match".to_string());
        }
        Comparison { reports: all, baseline: has_baseline, rows, regressions, improvements, unmatched, notes }
    }

    /// Whether a CI gate fails: a regression against the baseline.
    pub fn regressed(&self) -> bool {
        !self.regressions.is_empty()
    }

    pub fn json(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(self)
    }

    /// The comparison for people, in Markdown: the reports, the regressions and
    /// improvements first, the matrix, the units not in every report, the findings.
    pub fn markdown(&self) -> String {
        let mut s = String::from("# Reports compared\n\n");
        s.push_str("| | report | side | profile | tool | outcome |\n|---|---|---|---|---|---|\n");
        for (i, c) in self.reports.iter().enumerate() {
            s.push_str(&format!(
                "| {} | `{}`{} | {} | {} | {} | {} |\n",
                i + 1,
                c.label,
                if self.baseline && i == 0 { " (baseline)" } else { "" },
                kind_name(c.kind),
                c.profile,
                tool_line(c),
                c.outcome.map_or("?", Outcome::label)
            ));
        }
        for n in &self.notes {
            s.push_str(&format!("\nNote: {n}.\n"));
        }
        if self.baseline {
            s.push_str(&format!("\n## Regressions against the baseline ({})\n\n", self.regressions.len()));
            if self.regressions.is_empty() {
                s.push_str("None.\n");
            }
            for c in &self.regressions {
                s.push_str(&format!("- `{}` in `{}`: {}\n", c.unit, c.report, c.what));
            }
            s.push_str(&format!("\n## Improvements ({})\n\n", self.improvements.len()));
            if self.improvements.is_empty() {
                s.push_str("None.\n");
            }
            for c in &self.improvements {
                s.push_str(&format!("- `{}` in `{}`: {}\n", c.unit, c.report, c.what));
            }
        }
        s.push_str("\n## Matrix\n\n| unit |");
        for i in 1..=self.reports.len() {
            s.push_str(&format!(" {i} |"));
        }
        s.push_str("\n|---|");
        s.push_str(&"---|".repeat(self.reports.len()));
        s.push('\n');
        for r in &self.rows {
            s.push_str(&format!("| `{}` |", r.id));
            for v in &r.verdicts {
                s.push_str(&format!(" {} |", v.map_or("—", CaseVerdict::label)));
            }
            s.push('\n');
        }
        if !self.unmatched.is_empty() {
            s.push_str("\n## Units not in every report\n\n");
            for (id, have) in &self.unmatched {
                s.push_str(&format!("- `{id}`: only in {}\n", quoted(have)));
            }
        }
        s.push_str("\n## Findings\n");
        for (i, c) in self.reports.iter().enumerate() {
            let graded: Vec<&Unit> = c.units.iter().filter(|u| worth_reading(u)).collect();
            if graded.is_empty() {
                continue;
            }
            s.push_str(&format!("\n### {} `{}`\n\n", i + 1, c.label));
            for u in graded {
                s.push_str(&format!("- `{}` {}\n", u.id, u.verdict.label()));
                for f in &u.findings {
                    s.push_str(&format!("  - {} {} [{}]\n", f.verdict.label(), f.message, f.clause));
                }
            }
        }
        s
    }

    /// The comparison as a page a lab can publish: each cell links to its unit's
    /// findings in that report.
    pub fn html(&self) -> String {
        let mut s = page_head("Reports compared");
        s.push_str("<h1>Reports compared</h1><table><tr><th></th><th>report</th><th>side</th><th>profile</th><th>tool</th><th>outcome</th></tr>");
        for (i, c) in self.reports.iter().enumerate() {
            let outcome = c.outcome.map_or("?", Outcome::label);
            s.push_str(&format!(
                "<tr><td>{}</td><td><code>{}</code>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{outcome}\">{outcome}</td></tr>",
                i + 1,
                escape(&c.label),
                if self.baseline && i == 0 { " (baseline)" } else { "" },
                kind_name(c.kind),
                escape(&c.profile),
                escape(&tool_line(c)),
            ));
        }
        s.push_str("</table>");
        for n in &self.notes {
            s.push_str(&format!("<p>Note: {}.</p>", escape(n)));
        }
        if self.baseline {
            for (title, list) in
                [("Regressions against the baseline", &self.regressions), ("Improvements", &self.improvements)]
            {
                s.push_str(&format!("<h2>{title} ({})</h2>", list.len()));
                if list.is_empty() {
                    s.push_str("<p>None.</p>");
                    continue;
                }
                s.push_str("<ul>");
                for c in list {
                    s.push_str(&format!(
                        "<li><code>{}</code> in <code>{}</code>: {}</li>",
                        escape(&c.unit),
                        escape(&c.report),
                        escape(&c.what)
                    ));
                }
                s.push_str("</ul>");
            }
        }
        s.push_str("<h2>Matrix</h2><table><tr><th>unit</th>");
        for i in 1..=self.reports.len() {
            s.push_str(&format!("<th>{i}</th>"));
        }
        s.push_str("</tr>");
        for r in &self.rows {
            s.push_str(&format!("<tr><td><code>{}</code> {}</td>", escape(&r.id), escape(&r.title)));
            for (i, v) in r.verdicts.iter().enumerate() {
                match v {
                    Some(v) => {
                        let l = v.label();
                        s.push_str(&format!(
                            "<td class=\"{l}\"><a class=\"{l}\" href=\"#{}\">{l}</a></td>",
                            anchor(i, &r.id)
                        ))
                    }
                    None => s.push_str("<td>—</td>"),
                }
            }
            s.push_str("</tr>");
        }
        s.push_str("</table>");
        if !self.unmatched.is_empty() {
            s.push_str("<h2>Units not in every report</h2><ul>");
            for (id, have) in &self.unmatched {
                s.push_str(&format!("<li><code>{}</code>: only in {}</li>", escape(id), escape(&quoted(have))));
            }
            s.push_str("</ul>");
        }
        s.push_str("<h2>Findings</h2>");
        for (i, c) in self.reports.iter().enumerate() {
            s.push_str(&format!("<h3>{} <code>{}</code></h3><ul>", i + 1, escape(&c.label)));
            for u in &c.units {
                let l = u.verdict.label();
                s.push_str(&format!(
                    "<li id=\"{}\"><code>{}</code> <span class=\"{l}\">{l}</span>",
                    anchor(i, &u.id),
                    escape(&u.id)
                ));
                if !u.findings.is_empty() {
                    s.push_str("<ul>");
                    for f in &u.findings {
                        let fl = f.verdict.label();
                        s.push_str(&format!(
                            "<li><span class=\"{fl}\">{fl}</span> {} [{}]</li>",
                            escape(&f.message),
                            escape(&f.clause)
                        ));
                    }
                    s.push_str("</ul>");
                }
                s.push_str("</li>");
            }
            s.push_str("</ul>");
        }
        s.push_str("</body></html>\n");
        s
    }

    /// JUnit for a CI: a suite per report, a test case per unit. Against a baseline a
    /// unit fails where it regressed (and only there: a FAIL the baseline had too is
    /// not news to the gate); without one, as its verdict says.
    pub fn junit(&self) -> String {
        use quick_junit::{Report, TestCase, TestCaseStatus, TestSuite};
        let mut report = Report::new("hiperface compare");
        let skip = usize::from(self.baseline);
        for c in self.reports.iter().skip(skip) {
            let mut suite = TestSuite::new(c.label.clone());
            for u in &c.units {
                let status = if self.baseline {
                    let regressed: Vec<&str> = self
                        .regressions
                        .iter()
                        .filter(|r| r.report == c.label && r.unit == u.id)
                        .map(|r| r.what.as_str())
                        .collect();
                    if regressed.is_empty() {
                        TestCaseStatus::success()
                    } else {
                        super::junit_status(CaseVerdict::Fail, &regressed.join("; "))
                    }
                } else {
                    let detail: Vec<String> =
                        u.findings.iter().map(|f| format!("[{}] {}", f.clause, f.message)).collect();
                    super::junit_status(u.verdict, &detail.join("; "))
                };
                let mut t = TestCase::new(u.id.clone(), status);
                t.set_classname(format!("hiperface.{}", u.id.split('.').next().unwrap_or("case")));
                suite.add_test_case(t);
            }
            // Units the baseline ran and this report does not have at all.
            for r in self.regressions.iter().filter(|r| r.report == c.label && c.unit(&r.unit).is_none()) {
                suite.add_test_case(TestCase::new(r.unit.clone(), super::junit_status(CaseVerdict::Fail, &r.what)));
            }
            report.add_test_suite(suite);
        }
        report.to_string().unwrap_or_else(|e| format!("<!-- cannot serialise: {e} -->"))
    }

    /// The console's lines: the regressions first, then one line per report.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        for c in &self.regressions {
            out.push(format!("REGRESSION {} in {}: {}", c.unit, c.report, c.what));
        }
        for c in &self.improvements {
            out.push(format!("improvement {} in {}: {}", c.unit, c.report, c.what));
        }
        for (i, c) in self.reports.iter().enumerate() {
            let count = |v: CaseVerdict| c.units.iter().filter(|u| u.verdict == v).count();
            let counts: Vec<String> = CaseVerdict::ALL
                .iter()
                .rev()
                .filter(|v| count(**v) > 0)
                .map(|v| format!("{} {}", count(*v), v.label()))
                .collect();
            out.push(format!(
                "{} {}{}: {} ({})",
                i + 1,
                c.label,
                if self.baseline && i == 0 { " (baseline)" } else { "" },
                c.outcome.map_or("?", Outcome::label),
                counts.join(", ")
            ));
        }
        for n in &self.notes {
            out.push(format!("note: {n}"));
        }
        if !self.unmatched.is_empty() {
            out.push(format!("{} units are not in every report (listed in the comparison)", self.unmatched.len()));
        }
        out
    }
}

/// How `report` differs from `base`, unit by unit, in the baseline's order and then
/// the report's new units: one change per unit and direction (a verdict that got worse
/// names the clauses it newly breaks in the same line).
fn against(base: &Column, report: &Column) -> Vec<Change> {
    let mut out = Vec::new();
    let change =
        |unit: &str, kind, what: String| Change { report: report.label.clone(), unit: unit.to_string(), kind, what };
    let clauses = |set: Vec<&str>, how: &str| {
        if set.is_empty() {
            String::new()
        } else {
            format!(", {how} {}", set.join(", "))
        }
    };
    let other_profile = (report.profile != base.profile)
        .then(|| format!(" (profile {}, the baseline's {})", report.profile, base.profile));
    for b in &base.units {
        let now = report.unit(&b.id);
        match now {
            Some(n) if n.ran() && b.ran() => {
                let (was, is) = (b.verdict, n.verdict);
                let (broken_was, broken_is) = (b.broken(), n.broken());
                let newly: Vec<&str> = broken_is.difference(&broken_was).copied().collect();
                let mended: Vec<&str> = broken_was.difference(&broken_is).copied().collect();
                let moved = format!("{} -> {}", was.label(), is.label());
                if was != is && was.worst(is) == is {
                    out.push(change(&b.id, ChangeKind::Worse, moved + &clauses(newly, "breaking")));
                } else if !newly.is_empty() {
                    let what = format!("{}{}", clauses(newly, "FAIL on").trim_start_matches(", "), " newly broken");
                    out.push(change(&b.id, ChangeKind::NewlyBroken, what));
                } else if was != is {
                    out.push(change(&b.id, ChangeKind::Better, moved + &clauses(mended, "no longer breaking")));
                } else if !mended.is_empty() {
                    let what = format!("{} no longer broken", mended.join(", "));
                    out.push(change(&b.id, ChangeKind::NoLongerBroken, what));
                }
            }
            _ if b.ran() => {
                let why = now.map_or("not in the report", |_| "NOT-APPLICABLE in the report");
                let what =
                    format!("{} in the baseline, {why}{}", b.verdict.label(), other_profile.as_deref().unwrap_or(""));
                out.push(change(&b.id, ChangeKind::NoLongerRun, what));
            }
            Some(n) if n.ran() => out.push(newly_run(n, "NOT-APPLICABLE in the baseline", &change)),
            _ => {}
        }
    }
    for n in report.units.iter().filter(|n| base.unit(&n.id).is_none() && n.ran()) {
        out.push(newly_run(n, "not in the baseline", &change));
    }
    out
}

/// A unit the baseline did not run: an improvement, or where it FAILs a regression
/// (its clauses are broken anew).
fn newly_run(n: &Unit, before: &str, change: &impl Fn(&str, ChangeKind, String) -> Change) -> Change {
    let broken: Vec<&str> = n.broken().into_iter().collect();
    if broken.is_empty() {
        change(&n.id, ChangeKind::NewlyRun, format!("{before}, {}", n.verdict.label()))
    } else {
        change(
            &n.id,
            ChangeKind::NewlyBroken,
            format!("{before}, {} on {} newly broken", n.verdict.label(), broken.join(", ")),
        )
    }
}

/// A unit whose findings the reader of the comparison will want: anything but a
/// clean PASS or NOT-APPLICABLE.
fn worth_reading(u: &Unit) -> bool {
    match u.verdict {
        CaseVerdict::NotApplicable => false,
        CaseVerdict::Pass => !u.findings.is_empty(),
        _ => true,
    }
}

fn kind_name(k: Kind) -> &'static str {
    match k {
        Kind::Slave => "encoder (slave cases)",
        Kind::Master => "drive (master scenarios)",
    }
}

fn tool_line(c: &Column) -> String {
    match &c.revision {
        Some(r) => format!("{} ({r})", c.tool),
        None => c.tool.clone(),
    }
}

fn quoted(labels: &[String]) -> String {
    labels.iter().map(|l| format!("`{l}`")).collect::<Vec<_>>().join(", ")
}

/// The id of a unit's findings in report `column` on the page.
fn anchor(column: usize, id: &str) -> String {
    let safe: String =
        id.chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '_' }).collect();
    format!("r{}-{safe}", column + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit as the tests write it: id, verdict, its findings (verdict, clause).
    type Spec<'a> = (&'a str, &'a str, &'a [(&'a str, &'a str)]);

    fn report(units: &[Spec]) -> String {
        let units: Vec<serde_json::Value> = units
            .iter()
            .map(|(id, verdict, findings)| {
                let findings: Vec<serde_json::Value> = findings
                    .iter()
                    .map(|(v, clause)| serde_json::json!({"verdict": v, "message": "m", "clause": clause, "at_us": 0}))
                    .collect();
                serde_json::json!({"id": id, "title": "t", "verdict": verdict, "findings": findings, "wire": []})
            })
            .collect();
        serde_json::json!({"tool": "hiperface 0.1.0", "profile": "SRS50", "outcome": "PASSED", "cases": units,
            "record": {"anything": [1, 2, 3]}})
        .to_string()
    }

    fn column(label: &str, units: &[Spec]) -> Column {
        Column::read(label, report(units).as_bytes()).unwrap()
    }

    #[test]
    fn a_worse_verdict_a_unit_no_longer_run_and_a_clause_newly_broken_are_regressions() {
        let base = column(
            "base",
            &[
                ("a", "PASS", &[]),
                ("b", "PASS", &[]),
                ("c", "FAIL", &[("FAIL", "000:T10")]),
                ("d", "PASS", &[]),
                ("e", "NOT-APPLICABLE", &[]),
            ],
        );
        let now = column(
            "now",
            &[
                ("a", "NON-STRICT", &[]),
                ("b", "NOT-APPLICABLE", &[]),
                ("c", "FAIL", &[("FAIL", "000:T10"), ("FAIL", "000:2.3.3")]),
                ("e", "PASS", &[]),
                ("f", "FAIL", &[("FAIL", "000:T12")]),
            ],
        );
        let c = Comparison::of(Some(base), vec![now]);
        let got: Vec<(&str, ChangeKind, &str)> =
            c.regressions.iter().map(|r| (r.unit.as_str(), r.kind, r.what.as_str())).collect();
        assert_eq!(
            got,
            [
                ("a", ChangeKind::Worse, "PASS -> NON-STRICT"),
                ("b", ChangeKind::NoLongerRun, "PASS in the baseline, NOT-APPLICABLE in the report"),
                ("c", ChangeKind::NewlyBroken, "FAIL on 000:2.3.3 newly broken"),
                ("d", ChangeKind::NoLongerRun, "PASS in the baseline, not in the report"),
                ("f", ChangeKind::NewlyBroken, "not in the baseline, FAIL on 000:T12 newly broken"),
            ]
        );
        assert!(c.regressed());
        let better: Vec<(&str, ChangeKind)> = c.improvements.iter().map(|r| (r.unit.as_str(), r.kind)).collect();
        assert_eq!(better, [("e", ChangeKind::NewlyRun)]);
        assert_eq!(c.unmatched, [("d".to_string(), vec!["base".to_string()]), ("f".into(), vec!["now".into()])]);
    }

    #[test]
    fn the_same_verdicts_are_no_regression_and_better_ones_are_improvements() {
        let units: &[Spec] = &[("a", "PASS", &[]), ("b", "FAIL", &[("FAIL", "000:T10")])];
        let same = Comparison::of(Some(column("base", units)), vec![column("now", units)]);
        assert!(!same.regressed() && same.improvements.is_empty());
        let fixed =
            Comparison::of(Some(column("base", units)), vec![column("now", &[("a", "PASS", &[]), ("b", "PASS", &[])])]);
        assert!(!fixed.regressed());
        let kinds: Vec<(ChangeKind, &str)> = fixed.improvements.iter().map(|c| (c.kind, c.what.as_str())).collect();
        assert_eq!(kinds, [(ChangeKind::Better, "FAIL -> PASS, no longer breaking 000:T10")]);
        // A verdict that got worse names what it breaks in the same line; another
        // profile is said where a unit is not run.
        let mut other = column("now", &[("a", "FAIL", &[("FAIL", "000:T10")])]);
        other.profile = "SEK37".into();
        let worse = Comparison::of(Some(column("base", units)), vec![other]);
        let what: Vec<&str> = worse.regressions.iter().map(|c| c.what.as_str()).collect();
        assert_eq!(
            what,
            [
                "PASS -> FAIL, breaking 000:T10",
                "FAIL in the baseline, not in the report (profile SEK37, the baseline's SRS50)"
            ]
        );
    }

    #[test]
    fn without_a_baseline_nothing_is_a_regression_and_every_form_has_every_report() {
        let a = column("a/report.json", &[("x", "PASS", &[])]);
        let b = column("b/report.json", &[("x", "FAIL", &[("FAIL", "000:T10")]), ("y", "PASS", &[])]);
        let c = Comparison::of(None, vec![a, b]);
        assert!(!c.regressed());
        assert_eq!(c.rows.len(), 2);
        assert_eq!(c.rows[1].verdicts, [None, Some(CaseVerdict::Pass)]);
        let md = c.markdown();
        assert!(md.contains("| `x` | PASS | FAIL |") && md.contains("| `y` | — | PASS |"), "{md}");
        let html = c.html();
        assert!(html.contains("href=\"#r2-x\"") && html.contains("id=\"r2-x\""), "the cell links to its findings");
        let junit = c.junit();
        assert!(junit.contains("a/report.json") && junit.contains("<failure"), "{junit}");
        assert!(c.json().unwrap().contains("\"rows\""));
    }

    #[test]
    fn what_is_not_a_certify_report_says_so() {
        assert!(matches!(Column::read("x", b"{\"tool\":\"t\",\"profile\":\"p\"}"), Err(CompareError::NoUnits)));
        assert!(matches!(Column::read("x", b"not json"), Err(CompareError::Json(_))));
        let master = r#"{"tool":"t","profile":"p","outcome":"FAILED","scenarios":[{"id":"s","verdict":"FAIL"}]}"#;
        assert_eq!(Column::read("m", master.as_bytes()).unwrap().kind, Kind::Master);
    }
}
