//! Reports of a certification run: JSON and JUnit XML for CI, a Markdown and an HTML
//! certificate for people. The wire log is included for every failing case.

use crate::certify::{Report, TimingMode};
use crate::verdict::CaseVerdict;
use std::fmt::Write as _;
use std::path::Path;

/// Write report.json, junit.xml, certificate.md and certificate.html into `dir`.
/// Create the report directory `dir` and check that files can be written in it, before
/// a run: a run's results are never found unwritable only after it.
pub fn prepare_dir(dir: &Path) -> Result<(), String> {
    let shown = dir.display();
    if dir.exists() && !dir.is_dir() {
        return Err(format!("--report {shown}: it exists and is not a directory"));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("--report {shown}: cannot create the directory: {e}"))?;
    let probe = dir.join(".hiperface-write-check");
    std::fs::write(&probe, b"").map_err(|e| format!("--report {shown}: cannot write in the directory: {e}"))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

pub fn write_all(report: &Report, dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let json = serde_json::to_string_pretty(report).map_err(std::io::Error::other)?;
    std::fs::write(dir.join("report.json"), json)?;
    std::fs::write(dir.join("junit.xml"), junit(report))?;
    let md = markdown(report);
    std::fs::write(dir.join("certificate.md"), &md)?;
    std::fs::write(dir.join("certificate.html"), html(report))?;
    Ok(())
}

pub fn junit(report: &Report) -> String {
    junit_suite(format!("hiperface certify slave ({})", report.profile), &report.cases)
}

/// One JUnit suite of cases (slave cases or master scenarios).
pub fn junit_suite(name: String, cases: &[crate::certify::CaseResult]) -> String {
    use quick_junit::{NonSuccessKind, Report as JReport, TestCase, TestCaseStatus, TestSuite};
    let mut suite = TestSuite::new(name);
    for c in cases {
        let detail: String = c.findings.iter().map(|f| format!("[{}] {f}\n", f.verdict().label())).collect();
        let status = match c.verdict {
            CaseVerdict::Pass | CaseVerdict::NonStrict => TestCaseStatus::success(),
            CaseVerdict::NotApplicable => {
                let mut s = TestCaseStatus::skipped();
                s.set_message(detail.trim().to_string());
                s
            }
            CaseVerdict::Fail => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_message(detail.trim().to_string());
                s.set_description(wire_text(c));
                s
            }
            // Not observed: neither a pass nor the device's failure (INCOMPLETE).
            CaseVerdict::Error | CaseVerdict::NotExercised | CaseVerdict::Unknown => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Error);
                s.set_message(format!("{}: {}", c.verdict.label(), detail.trim()));
                s
            }
        };
        let mut t = TestCase::new(c.id, status);
        t.set_classname(format!("hiperface.{}", c.id.split('.').next().unwrap_or("case")));
        t.set_time(std::time::Duration::from_secs_f64(c.duration_ms / 1000.0));
        if c.verdict == CaseVerdict::NonStrict {
            t.set_system_out(detail);
        }
        suite.add_test_case(t);
    }
    let mut r = JReport::new("hiperface");
    r.add_test_suite(suite);
    r.to_string().unwrap_or_else(|e| format!("<!-- cannot serialise: {e} -->"))
}

pub(crate) fn wire_text(c: &crate::certify::CaseResult) -> String {
    c.wire.iter().map(|w| format!("{:>12.3} ms  {}  {}\n", w.t_us as f64 / 1000.0, w.direction, w.bytes)).collect()
}

pub fn markdown(r: &Report) -> String {
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
        ("timing", timing_text(r)),
        ("grading of physical values", r.grading.clone()),
    ];
    rows.extend(r.identity.lines());
    rows.push((
        "wall time",
        format!("{:.0} ms (physical minimum from the wire log {:.0} ms)", r.wall_time_ms, r.physical_minimum_ms),
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

pub(crate) fn escape(t: &str) -> String {
    t.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

pub fn html(r: &Report) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>HIPERFACE certificate: {}</title>\
         <style>body{{font-family:sans-serif;max-width:70em;margin:2em auto}}table{{border-collapse:collapse}}\
         td,th{{border:1px solid #ccc;padding:.2em .5em;text-align:left}}.PASS{{color:#070}}.FAIL{{color:#b00;font-weight:bold}}\
         .NON-STRICT{{color:#a60}}.ERROR{{color:#b0b}}pre{{background:#f4f4f4;padding:.5em}}</style></head><body>",
        escape(&r.profile)
    );
    let verdict = r.outcome().label();
    let _ = write!(s, "<h1>HIPERFACE slave certificate: {verdict}</h1><table>");
    let rows = header(r);
    for (k, v) in rows {
        let _ = write!(s, "<tr><th>{k}</th><td>{}</td></tr>", escape(&v));
    }
    let _ = write!(s, "</table><h2>Cases</h2><table><tr><th>case</th><th>verdict</th><th>clauses</th><th>title</th><th>findings</th></tr>");
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
