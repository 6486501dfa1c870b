//! The certificate of a slave (`certify slave`): its header (what was certified,
//! how), the cases with their clauses and findings, the wire log of every failing
//! case, the safety section and the response times.

use super::Report;
use crate::report::wire::{self, UnderTest};
use crate::report::{escape, junit_suite, page_head, NotRun, Reports};
use crate::verdict::timing::TimingMode;
use crate::verdict::CaseVerdict;
use std::fmt::Write as _;

impl Reports for Report {
    const CERTIFICATE: &'static str = "certificate";

    fn json(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(&crate::report::Summarized::new(self.outcome(), self.attention(), self))
    }

    fn junit(&self) -> String {
        junit_suite(format!("hiperface certify slave ({})", self.profile), &self.cases, UnderTest::Slave)
    }

    fn markdown(&self) -> String {
        markdown(self)
    }

    fn html(&self) -> String {
        html(self)
    }
}

/// The certificate's first line under the title: what, on what, and the counts.
fn outcome_line(r: &Report) -> String {
    let summary: Vec<String> = r.summary.iter().map(|(k, v)| format!("{v} {k}")).collect();
    format!("{} ({} edition) on {}: {}", r.profile, r.edition, r.line, summary.join(", "))
}

/// What the first section says when nothing kept the run from PASSED.
const NOTHING: &str =
    "Nothing failed, and nothing was left unobserved: every case that ran was graded PASS or NON-STRICT.";

fn markdown(r: &Report) -> String {
    let mut s = String::new();
    let verdict = r.outcome().label();
    let _ = writeln!(s, "# HIPERFACE slave certificate: {verdict}\n");
    let _ = writeln!(s, "**{verdict}**: {}\n", outcome_line(r).replace('|', "\\|"));
    if let Some(i) = &r.run_info {
        let _ = writeln!(s, "{}\n", i.line().replace('|', "\\|"));
    }
    if let Some(a) = &r.aborted {
        let _ = writeln!(s, "**Aborted**: {a} (a partial report)\n");
    }
    let _ = writeln!(s, "## Findings to read first\n");
    s.push_str(&crate::report::attention::markdown(&r.attention(), NOTHING));
    s.push_str(&NotRun::markdown(&r.not_run));
    for (title, rows) in [("The device", r.identity.lines()), ("The run", header(r))] {
        let _ = writeln!(s, "\n## {title}\n\n| | |\n|---|---|");
        for (k, v) in rows {
            let _ = writeln!(s, "| {k} | {} |", v.replace('|', "\\|"));
        }
    }
    let _ = writeln!(s, "\n## Cases\n\n| case | verdict | clauses | title |\n|---|---|---|---|");
    for c in &r.cases {
        let _ = writeln!(s, "| `{}` | {} | {} | {} |", c.id, c.verdict.label(), c.clause_list(), c.title);
    }
    let with_findings: Vec<_> =
        r.cases.iter().filter(|c| !c.findings.is_empty() && c.verdict != CaseVerdict::NotApplicable).collect();
    if !with_findings.is_empty() {
        let _ = writeln!(s, "\n## Findings of each case\n");
    }
    for c in with_findings {
        let _ = writeln!(s, "### `{}`: {}\n", c.id, c.verdict.label());
        for f in &c.findings {
            let _ = writeln!(s, "- {}: {f}", f.verdict().label());
        }
        if shows_wire(c) {
            let _ = writeln!(
                s,
                "\nWire log (`<--` marks the frame each finding is about, `^^` a faulty byte in it):\n\n```\n{}```\n",
                wire::text(c, UnderTest::Slave)
            );
        }
    }
    let _ = writeln!(s, "\n## Safety: the device as the run left it\n");
    for line in safety_lines(r) {
        let _ = writeln!(s, "- {line}");
    }
    let _ = writeln!(
        s,
        "\n## Response times\n\n{RESPONSE_TIMES}\n\n| command | replies | limit | fastest | median | slowest | slowest, proven |\n|---|---|---|---|---|---|---|"
    );
    for t in &r.response_times {
        let ms = |us: i64| format!("{:.3} ms", us as f64 / 1000.0);
        let _ = writeln!(
            s,
            "| {} | {} | {} ms | {} | {} | {} | {} |",
            t.command,
            t.count,
            t.limit_ms,
            ms(t.min_us),
            ms(t.median_us),
            ms(t.max_us),
            ms(t.max_least_us)
        );
    }
    let _ = writeln!(s, "\n## Notes\n");
    for n in &r.notes {
        let _ = writeln!(s, "- {n}");
    }
    s.push_str(&crate::report::documents_markdown(&r.cases));
    s
}

/// What the response-time table measures, in words.
const RESPONSE_TIMES: &str = "From the end of the request's timeout to the reply's first character, per command, \
of its own replies (error responses not counted), against its limit (000, Table 10). On a line that cannot tell \
exactly (a pseudo-terminal: the request's end is uncertain by its time on the line) the fastest, median and \
slowest are the most each time can have been, and the last column the least the slowest can have been: that one \
within the limit, with the line's tolerance, is what a PASS rests on. On a UART and in virtual time the two agree.";

/// A case's wire log goes on the certificate where a finding in it needs reading.
fn shows_wire(c: &crate::verdict::CaseResult) -> bool {
    crate::report::attention::read_first(c.verdict)
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
    rows.extend(r.run_info.iter().flat_map(|i| i.rows()));
    rows.push((
        "wall time",
        format!("{:.0} ms (the same exchanges on a real line: {:.0} ms)", r.wall_time_ms, r.line_time_ms),
    ));
    let rerun = r.rerun_cases();
    if !rerun.is_empty() {
        let why = "the harness's own lateness left a verdict untold; each case's result is its last run's. One still \
                   undecided after 3 runs in a row is run again at the end of the run.";
        rows.push(("cases run again", format!("{}: {why}", rerun.join(", "))));
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
    t.push_str(
        ". These are uncertainties of each exchange, not a slack of the run: a reply is FAILed where every \
         reading shows it late, PASSed where the least reading is within its limit with the line's tolerance, and \
         the harness's own lateness never passes one (run again, or UNKNOWN); the response times below give the \
         most and the least",
    );
    // The notes are sentences of their own: each after a full stop, never after "; ".
    for n in &r.line_notes {
        t.push_str(if t.ends_with('.') { " " } else { ". " });
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
    let _ = write!(
        s,
        "<h1>HIPERFACE slave certificate: <span class=\"{verdict}\">{verdict}</span></h1><p><b class=\"{verdict}\">{verdict}</b>: {}</p>",
        escape(&outcome_line(r))
    );
    if let Some(i) = &r.run_info {
        let _ = write!(s, "<p>{}</p>", escape(&i.line()));
    }
    if let Some(a) = &r.aborted {
        let _ = write!(s, "<p class=\"FAIL\">Aborted: {} (a partial report)</p>", escape(a));
    }
    s.push_str("<h2>Findings to read first</h2>");
    s.push_str(&crate::report::attention::html(&r.attention(), NOTHING));
    s.push_str(&NotRun::html(&r.not_run));
    for (title, rows) in [("The device", r.identity.lines()), ("The run", header(r))] {
        let _ = write!(s, "<h2>{title}</h2><table>");
        for (k, v) in rows {
            let _ = write!(s, "<tr><th>{k}</th><td>{}</td></tr>", escape(&v));
        }
        s.push_str("</table>");
    }
    let _ = write!(
        s,
        "<h2>Cases</h2><table><tr><th>case</th><th>verdict</th><th>clauses</th><th>title</th><th>findings</th></tr>"
    );
    for c in &r.cases {
        let findings: String = c.findings.iter().map(|f| format!("{}<br>", escape(&f.to_string()))).collect();
        // The wire log in a row of its own, the table's width: a long frame stays within
        // the page (it scrolls in its box) instead of widening the findings column.
        let wire = if shows_wire(c) {
            format!("<tr class=\"wire\"><td colspan=\"5\"><pre>{}</pre></td></tr>", wire::html(c, UnderTest::Slave))
        } else {
            String::new()
        };
        let _ = write!(
            s,
            "<tr id=\"{id}\"><td><code>{id}</code></td><td class=\"{v}\">{v}</td><td>{}</td><td>{}</td><td>{findings}</td></tr>{wire}",
            c.clause_list(),
            escape(c.title),
            id = c.id,
            v = c.verdict.label(),
        );
    }
    let _ = write!(s, "</table><h2>Safety: the device as the run left it</h2><ul>");
    for line in safety_lines(r) {
        let _ = write!(s, "<li>{}</li>", escape(&line));
    }
    let _ = write!(s, "</ul><h2>Response times</h2><p>{}</p><table><tr><th>command</th><th>replies</th><th>limit</th><th>fastest</th><th>median</th><th>slowest</th><th>slowest, proven</th></tr>", escape(RESPONSE_TIMES));
    for t in &r.response_times {
        let _ = write!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{} ms</td><td>{:.3} ms</td><td>{:.3} ms</td><td>{:.3} ms</td><td>{:.3} ms</td></tr>",
            escape(&t.command),
            t.count,
            t.limit_ms,
            t.min_us as f64 / 1000.0,
            t.median_us as f64 / 1000.0,
            t.max_us as f64 / 1000.0,
            t.max_least_us as f64 / 1000.0
        );
    }
    let _ = write!(s, "</table><h2>Notes</h2><ul>");
    for n in &r.notes {
        let _ = write!(s, "<li>{}</li>", escape(n));
    }
    s.push_str("</ul>");
    s.push_str(&crate::report::documents_html(&r.cases));
    s.push_str("</body></html>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The line's notes are sentences: each follows a full stop, none a "; " after one
    /// ("afterwards.; The processors" was how a certificate read).
    #[test]
    fn the_lines_notes_read_as_sentences() {
        let profile = hiperface_model::profiles::srs50();
        let mut r = Report::empty(&profile, "sim", &super::super::Options::all_allowed());
        r.line_notes = vec!["The first note ends here.".into(), "The second one too.".into()];
        let t = timing_text(&r);
        assert!(t.ends_with("give the most and the least. The first note ends here. The second one too."), "{t}");
        assert!(!t.contains(".;"), "{t}");
    }
}
