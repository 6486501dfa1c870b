//! The certificate of a master (`certify master`): its scenarios with their clauses
//! and findings, and for each a timeline (the master's requests `M>`, the encoder's
//! replies `S<`, the injected faults `!`, the broken rules `×`): as text in Markdown,
//! as an SVG drawing in HTML.

use super::DriveReport;
use crate::report::{escape, junit_suite, page_head, wire_text, Reports};
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
        serde_json::to_string_pretty(self.report)
    }

    fn junit(&self) -> String {
        junit_suite(format!("hiperface certify master ({})", self.report.master), &self.report.scenarios)
    }

    fn markdown(&self) -> String {
        markdown(self.report)
    }

    fn html(&self) -> String {
        html(self.report, self.profile)
    }
}

/// The certificate: verdicts, findings with their clauses, and each scenario's timeline
/// (the master's requests `M>`, the encoder's replies `S<`, the injected faults `!`,
/// and the broken rules `×` on one time axis).
fn markdown(r: &DriveReport) -> String {
    let mut s = format!("# HIPERFACE master certificate\n\n| | |\n|---|---|\n| master | `{}` |\n", r.master);
    s += &format!("| encoder profile | {} ({} edition) |\n| tool | {} |\n", r.profile, r.edition, r.tool);
    let summary: Vec<String> = r.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    for (name, value) in port_rows(r) {
        s += &format!("| {name} | {value} |\n");
    }
    s += &format!("| result | {} — {} |\n\n", r.outcome().label(), summary.join(", "));
    for n in &r.notes {
        s += &format!("Note: {n}\n\n");
    }
    for n in &r.notes_per_scenario {
        s += &format!("Run again: {n}\n\n");
    }
    s += "| scenario | verdict | runs | clauses |\n|---|---|---|---|\n";
    for c in &r.scenarios {
        s += &format!("| `{}` {} | {} | {} | {} |\n", c.id, c.title, c.verdict.label(), c.attempts, c.clause_list());
    }
    for c in &r.scenarios {
        s += &format!("\n## {} — {}\n\n{}\n\n", c.id, c.title, c.verdict.label());
        for f in &c.findings {
            s += &format!("- {} {f}\n", f.verdict().label());
        }
        s += &format!("\n```\n{}```\n", wire_text(c));
    }
    s
}

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
        "<h1>HIPERFACE master certificate: {verdict}</h1><table><tr><th>master</th><td><code>{}</code></td></tr>\
         <tr><th>encoder profile</th><td>{} ({} edition)</td></tr><tr><th>tool</th><td>{}</td></tr>",
        escape(&r.master),
        escape(&r.profile),
        escape(&r.edition),
        escape(&r.tool)
    );
    for (name, value) in port_rows(r) {
        let _ = write!(s, "<tr><th>{name}</th><td>{}</td></tr>", escape(&value));
    }
    s += "</table>";
    s += "<h2>Scenarios</h2><table><tr><th>scenario</th><th>verdict</th><th>clauses</th></tr>";
    for c in &r.scenarios {
        let v = c.verdict.label();
        let _ = write!(
            s,
            "<tr><td><a href=\"#{id}\">{id}</a> {}</td><td class=\"{v}\">{v}</td><td>{}</td></tr>",
            escape(c.title),
            escape(&c.clause_list()),
            id = c.id
        );
    }
    s += "</table>";
    for c in &r.scenarios {
        let v = c.verdict.label();
        let _ = write!(s, "<h2 id=\"{}\">{} — {}</h2><p class=\"{v}\">{v}</p><ul>", c.id, c.id, escape(c.title));
        for f in &c.findings {
            let fv = f.verdict().label();
            let _ = write!(s, "<li class=\"{fv}\">{fv} {}</li>", escape(&f.to_string()));
        }
        s += "</ul>";
        s += &crate::master::timeline::svg(c, profile);
    }
    s += "</body></html>\n";
    s
}
