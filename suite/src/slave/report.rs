//! The certificate of a slave (`certify slave`): its header (what was certified,
//! how), the cases with their clauses and findings, the wire log of every failing
//! case, the safety section and the response times.

use super::{Report, TimingMode};
use crate::report::{escape, junit_suite, page_head, wire_text, Reports};
use crate::verdict::CaseVerdict;
use std::fmt::Write as _;

impl Reports for Report {
    const CERTIFICATE: &'static str = "certificate";

    fn json(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(self)
    }

    fn junit(&self) -> String {
        junit_suite(format!("hiperface certify slave ({})", self.profile), &self.cases)
    }

    fn markdown(&self) -> String {
        markdown(self)
    }

    fn html(&self) -> String {
        html(self)
    }
}

fn markdown(r: &Report) -> String {
    let mut s = String::new();
    let verdict = r.outcome().label();
    let _ = writeln!(s, "# HIPERFACE slave certificate: {verdict}\n");
    let _ = writeln!(s, "| | |\n|---|---|");
    for (k, v) in header(r) {
        let _ = writeln!(s, "| {k} | {} |", v.replace('|', "\\|"));
    }
    if let Some(a) = &r.aborted {
        let _ = writeln!(s, "| **aborted** | {a} (partial report) |");
    }
    if !r.not_run.is_empty() {
        let _ = writeln!(s, "\n## Not run\n");
        for n in &r.not_run {
            let ids: Vec<String> = n.cases.iter().map(|c| format!("`{c}`")).collect();
            let _ = writeln!(s, "- {} ({}): {}", n.reason, n.cases.len(), ids.join(", "));
        }
    }
    let _ = writeln!(s, "\n## Cases\n\n| case | verdict | clauses | title |\n|---|---|---|---|");
    for c in &r.cases {
        let _ = writeln!(s, "| `{}` | {} | {} | {} |", c.id, c.verdict.label(), c.clause_list(), c.title);
    }
    let _ = writeln!(s, "\n## Findings\n");
    for c in r.cases.iter().filter(|c| !c.findings.is_empty() && c.verdict != CaseVerdict::NotApplicable) {
        let _ = writeln!(s, "### `{}`: {}\n", c.id, c.verdict.label());
        for f in &c.findings {
            let _ = writeln!(s, "- {}: {f}", f.verdict().label());
        }
        if c.verdict == CaseVerdict::Fail {
            let _ = writeln!(s, "\nWire log:\n\n```\n{}```\n", wire_text(c));
        }
    }
    let _ = writeln!(s, "\n## Safety: the device as the run left it\n");
    for line in safety_lines(r) {
        let _ = writeln!(s, "- {line}");
    }
    let _ = writeln!(s, "\n## Response times (at most, after the request's timeout)\n\n| command | n | min | median | max |\n|---|---|---|---|---|");
    for t in &r.response_times {
        let ms = |us: i64| format!("{:.3} ms", us as f64 / 1000.0);
        let _ =
            writeln!(s, "| {} | {} | {} | {} | {} |", t.command, t.count, ms(t.min_us), ms(t.median_us), ms(t.max_us));
    }
    let _ = writeln!(s, "\n## Notes\n");
    for n in &r.notes {
        let _ = writeln!(s, "- {n}");
    }
    s
}

/// The certificate's header: what was certified, how, and what it said of itself.
fn header(r: &Report) -> Vec<(&'static str, String)> {
    let mut rows = vec![
        ("tool", r.tool.clone()),
        ("profile", format!("{} ({} edition)", r.profile, r.edition)),
        ("line", r.line.clone()),
        ("echo", crate::line::echo::describe(r.echo, "request")),
        ("timing", timing_text(r)),
        ("grading of physical values", r.grading.clone()),
    ];
    rows.extend(r.identity.lines());
    rows.extend(r.run_info.iter().flat_map(|i| i.rows()));
    rows.push((
        "wall time",
        format!("{:.0} ms (the same exchanges on a real line: {:.0} ms)", r.wall_time_ms, r.line_time_ms),
    ));
    let summary: Vec<String> = r.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    rows.push(("verdicts", summary.join(", ")));
    let rerun = r.rerun_cases();
    if !rerun.is_empty() {
        let why = "the harness's own lateness left a verdict untold; each case's result is its last run's";
        rows.push(("cases run again", format!("{} ({why})", rerun.join(", "))));
    }
    rows
}

fn timing_text(r: &Report) -> String {
    let mode = match r.timing {
        TimingMode::Strict => "strict: a reply outside its window FAILs",
        TimingMode::Lenient => "lenient: a reply outside its window is NON-STRICT",
        TimingMode::Off => "off: measured, not graded",
    };
    let mut t = format!(
        "{mode}; line tolerance {:.3} ms, plus the harness's own scheduling delay where measured (at most {:.3} ms)",
        r.tolerance_us as f64 / 1000.0,
        r.harness_late_us as f64 / 1000.0
    );
    if let Some(d) = r.delivery {
        t.push_str(&format!(
            ", and the pseudo-terminal's own delivery, measured beside the line (at most {:.3} ms in an exchange, \
             both ways; {} of {} probe writes more than 1 ms late, the latest {:.3} ms)",
            r.line_late_us as f64 / 1000.0,
            d.over_1ms,
            d.samples,
            d.max_us as f64 / 1000.0
        ));
    }
    for n in &r.line_notes {
        t.push_str("; ");
        t.push_str(n);
    }
    t
}

fn safety_lines(r: &Report) -> Vec<String> {
    let s = &r.safety;
    let mut out = vec![if s.restored() {
        "Restored: everything the device reports of its stored state reads as before the run, and the harness's record of what it cannot read agrees.".to_string()
    } else if s.differs() {
        "**Check the device**: the run may have left it changed (not a verdict on the device; see below).".to_string()
    } else {
        "**Not verified**: what is listed below could not be read back after the run; nothing read back differs (not a verdict on the device).".to_string()
    }];
    out.extend(s.changed.iter().map(|c| format!("changed (read back from the device): {c}")));
    out.extend(s.bookkeeping.iter().map(|c| format!("changed by the harness's record (unreadable state): {c}")));
    out.extend(s.unverified.iter().map(|c| format!("not verified: {c}")));
    out.extend(s.verified.iter().map(|c| format!("read back unchanged: {c}")));
    out.push(format!("EEPROM writes: {}; restores run by the harness: {}", s.eeprom_writes, s.restores_run));
    out.extend(s.notes.iter().cloned());
    out
}

fn html(r: &Report) -> String {
    let mut s = String::new();
    s.push_str(&page_head(&format!("HIPERFACE certificate: {}", r.profile)));
    let verdict = r.outcome().label();
    let _ = write!(s, "<h1>HIPERFACE slave certificate: {verdict}</h1><table>");
    let rows = header(r);
    for (k, v) in rows {
        let _ = write!(s, "<tr><th>{k}</th><td>{}</td></tr>", escape(&v));
    }
    s.push_str("</table>");
    if !r.not_run.is_empty() {
        s.push_str("<h2>Not run</h2><ul>");
        for n in &r.not_run {
            let _ =
                write!(s, "<li>{} ({}): <code>{}</code></li>", escape(&n.reason), n.cases.len(), n.cases.join(", "));
        }
        s.push_str("</ul>");
    }
    let _ = write!(
        s,
        "<h2>Cases</h2><table><tr><th>case</th><th>verdict</th><th>clauses</th><th>title</th><th>findings</th></tr>"
    );
    for c in &r.cases {
        let findings: String = c.findings.iter().map(|f| format!("{}<br>", escape(&f.to_string()))).collect();
        let wire = if c.verdict == CaseVerdict::Fail {
            format!("<pre>{}</pre>", escape(&wire_text(c)))
        } else {
            String::new()
        };
        let _ = write!(
            s,
            "<tr><td><code>{}</code></td><td class=\"{}\">{}</td><td>{}</td><td>{}</td><td>{findings}{wire}</td></tr>",
            c.id,
            c.verdict.label(),
            c.verdict.label(),
            c.clause_list(),
            escape(c.title)
        );
    }
    let _ = write!(s, "</table><h2>Safety: the device as the run left it</h2><ul>");
    for line in safety_lines(r) {
        let _ = write!(s, "<li>{}</li>", escape(&line));
    }
    let _ = write!(s, "</ul><h2>Response times (at most, after the request's timeout)</h2><table><tr><th>command</th><th>n</th><th>min ms</th><th>median ms</th><th>max ms</th></tr>");
    for t in &r.response_times {
        let _ = write!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{:.3}</td></tr>",
            escape(&t.command),
            t.count,
            t.min_us as f64 / 1000.0,
            t.median_us as f64 / 1000.0,
            t.max_us as f64 / 1000.0
        );
    }
    let _ = write!(s, "</table><h2>Notes</h2><ul>");
    for n in &r.notes {
        let _ = write!(s, "<li>{}</li>", escape(n));
    }
    s.push_str("</ul></body></html>\n");
    s
}
