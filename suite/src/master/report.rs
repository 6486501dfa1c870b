//! The certificate of a master (`certify master`): its scenarios with their clauses
//! and findings, and for each a timeline (the master's requests `M>`, the encoder's
//! replies `S<`, the injected faults `!`, the broken rules `×`): as text in Markdown,
//! as an SVG drawing in HTML.

use super::DriveReport;
use crate::report::wire::{self, UnderTest};
use crate::report::{escape, junit_suite, page_head, NotRun, Reports};
use hiperface_model::Profile;
use std::fmt::Write as _;

/// A master's report with the encoder profile its timelines are drawn in.
pub struct MasterCertificate<'a> {
    pub report: &'a DriveReport,
    pub profile: &'a Profile,
}

impl Reports for MasterCertificate<'_> {
    const CERTIFICATE: &'static str = "certificate";

    fn json(&self) -> serde_json::Result<String> {
        let r = self.report;
        let mut summarized = crate::report::Summarized::new(r.outcome(), r.attention(), r);
        summarized.not_run = Some(r.not_run());
        serde_json::to_string_pretty(&summarized)
    }

    fn junit(&self) -> String {
        junit_suite(
            format!("hiperface certify master ({})", self.report.master),
            &self.report.scenarios,
            UnderTest::Master,
        )
    }

    fn markdown(&self) -> String {
        markdown(self.report)
    }

    fn html(&self) -> String {
        html(self.report, self.profile)
    }
}

/// What the first section says when nothing kept the run from PASSED.
const NOTHING: &str =
    "Nothing failed, and nothing was left unobserved: every scenario that ran was graded PASS or NON-STRICT.";

/// The certificate's first line under the title.
fn outcome_line(r: &DriveReport) -> String {
    let summary: Vec<String> = r.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    format!(
        "the master \u{201c}{}\u{201d} against an encoder of profile {} ({} edition): {}",
        r.master,
        r.profile,
        r.edition,
        summary.join(", ")
    )
}

/// The run's rows: what was certified, how, where and when.
fn run_rows(r: &DriveReport) -> Vec<(&'static str, String)> {
    let mut rows = vec![
        ("master", r.master.clone()),
        ("encoder profile", format!("{} ({} edition)", r.profile, r.edition)),
        ("tool", r.tool.clone()),
    ];
    rows.extend(port_rows(r));
    // As the console says it, and as a slave's certificate has it.
    rows.push(("wall time", r.wall_time_text()));
    if let Some(c) = &r.cut_short {
        rows.push(("cut short", c.clone()));
    }
    rows
}

/// The certificate: the outcome and the findings to read first, what was not run,
/// the run, the scenarios, each scenario's findings and timeline (the master's
/// requests `M>`, the encoder's replies `S<`, the injected faults `!`, the broken
/// rules `×`, the harness's own timing `?`), and the re-runs in an appendix.
fn markdown(r: &DriveReport) -> String {
    let verdict = r.outcome().label();
    let mut s = format!("# HIPERFACE master certificate: {verdict}\n\n**{verdict}**: {}\n\n", outcome_line(r));
    if let Some(i) = &r.run_info {
        s += &format!("{}\n\n", i.line());
    }
    s += "## Findings to read first\n\n";
    s += &crate::report::attention::markdown(&r.attention(), NOTHING);
    s += &NotRun::markdown(&r.not_run());
    s += "\n## The run\n\n| | |\n|---|---|\n";
    for (name, value) in run_rows(r) {
        s += &format!("| {name} | {} |\n", value.replace('|', "\\|"));
    }
    if !r.notes.is_empty() {
        s += "\n## Notes\n\n";
        for n in &r.notes {
            s += &format!("- {n}\n");
        }
    }
    s += "\n## Scenarios\n\n| scenario | verdict | runs | clauses |\n|---|---|---|---|\n";
    for c in &r.scenarios {
        s += &format!("| `{}` {} | {} | {} | {} |\n", c.id, c.title, c.verdict.label(), c.attempts, c.clause_list());
    }
    for c in &r.scenarios {
        s += &format!("\n### {} — {}\n\n{}\n\n", c.id, c.title, c.verdict.label());
        for f in &c.findings {
            s += &format!("- {} {f}\n", f.verdict().label());
        }
        s += &format!("\n```\n{}```\n", wire::text(c, UnderTest::Master));
    }
    s += &crate::report::documents_markdown(&r.scenarios);
    if !r.notes_per_scenario.is_empty() {
        s += &format!("\n## Appendix: scenarios run again\n\n{RERUNS}\n\n");
        for n in &r.notes_per_scenario {
            s += &format!("- {n}\n");
        }
    }
    s
}

/// Why the appendix is there, in words.
const RERUNS: &str = "The harness's own timing (a busy machine) disturbed these runs, so they were run again; \
each scenario's verdict above is its last run's. Not a verdict on the master.";

/// What the encoder found of a drive's port: its echo, and the master's characters
/// with UART faults.
fn port_rows(r: &DriveReport) -> Vec<(&'static str, String)> {
    let mut rows: Vec<(&'static str, String)> = r.run_info.iter().flat_map(|i| i.rows()).collect();
    if !r.not_used.is_empty() {
        let what =
            format!("{} (the master's declaration: the scenarios about them were not run)", r.not_used.join(", "));
        rows.push(("declared not used", what));
    }
    if r.echo.is_some() {
        rows.push(("echo", crate::line::echo::describe(r.echo, "reply")));
    }
    if let Some(n) = r.uart_faults {
        let text = match n {
            0 => "none read (the port marks parity and framing errors)".to_string(),
            n => format!("{n} characters of the master read with a parity or framing error (answered 09h, 000:T47; not charged to the master: noise looks the same)"),
        };
        rows.push(("UART faults", text));
    }
    rows
}

/// The whole certificate.
fn html(r: &DriveReport, profile: &Profile) -> String {
    let mut s = String::new();
    let verdict = r.outcome().label();
    s.push_str(&page_head("HIPERFACE master certificate"));
    let _ = write!(
        s,
        "<h1>HIPERFACE master certificate: <span class=\"{verdict}\">{verdict}</span></h1><p><b class=\"{verdict}\">{verdict}</b>: {}</p>",
        escape(&outcome_line(r))
    );
    if let Some(i) = &r.run_info {
        let _ = write!(s, "<p>{}</p>", escape(&i.line()));
    }
    s += "<h2>Findings to read first</h2>";
    s += &crate::report::attention::html(&r.attention(), NOTHING);
    s += &NotRun::html(&r.not_run());
    s += "<h2>The run</h2><table>";
    for (name, value) in run_rows(r) {
        let _ = write!(s, "<tr><th>{name}</th><td>{}</td></tr>", escape(&value));
    }
    s += "</table>";
    if !r.notes.is_empty() {
        s += "<h2>Notes</h2><ul>";
        for n in &r.notes {
            let _ = write!(s, "<li>{}</li>", escape(n));
        }
        s += "</ul>";
    }
    s += "<h2>Scenarios</h2><table><tr><th>scenario</th><th>verdict</th><th>runs</th><th>clauses</th></tr>";
    for c in &r.scenarios {
        let v = c.verdict.label();
        let _ = write!(
            s,
            "<tr><td><a href=\"#{id}\">{id}</a> {}</td><td class=\"{v}\">{v}</td><td>{}</td><td>{}</td></tr>",
            escape(c.title),
            c.attempts,
            escape(&c.clause_list()),
            id = c.id
        );
    }
    s += "</table>";
    for c in &r.scenarios {
        let v = c.verdict.label();
        let _ = write!(s, "<h3 id=\"{}\">{} — {}</h3><p class=\"{v}\">{v}</p><ul>", c.id, c.id, escape(c.title));
        for f in &c.findings {
            let fv = f.verdict().label();
            let _ = write!(s, "<li class=\"{fv}\">{fv} {}</li>", escape(&f.to_string()));
        }
        s += "</ul>";
        s += &crate::master::timeline::svg(c, profile);
    }
    s += &crate::report::documents_html(&r.scenarios);
    if !r.notes_per_scenario.is_empty() {
        let _ = write!(s, "<h2>Appendix: scenarios run again</h2><p>{}</p><ul>", escape(RERUNS));
        for n in &r.notes_per_scenario {
            let _ = write!(s, "<li>{}</li>", escape(n));
        }
        s += "</ul>";
    }
    s += "</body></html>\n";
    s
}
