//! The reports of a listening run (`decode`, `monitor`): report.json for programs,
//! junit.xml for CI (a test case per command heard and per master rule broken),
//! listening.md and listening.html for people.

use super::ListeningReport;
use crate::report::{escape, page_head, Reports};
use crate::verdict::CaseVerdict;
use std::fmt::Write as _;

impl Reports for ListeningReport {
    const CERTIFICATE: &'static str = "listening";

    fn json(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(self)
    }

    fn junit(&self) -> String {
        junit(self)
    }

    fn markdown(&self) -> String {
        markdown(self)
    }

    fn html(&self) -> String {
        html(self)
    }
}

/// The report for people.
fn markdown(r: &ListeningReport) -> String {
    let s = &r.summary;
    let mut m = String::new();
    let _ = writeln!(m, "# Listening report: {}\n", r.capture);
    let _ = writeln!(m, "- Result: **{}**; worst verdict heard: {}", r.outcome.label(), r.verdict.label());
    if let Some(why) = &r.incomplete {
        let _ = writeln!(m, "- Not PASSED: {why}");
    }
    let _ = writeln!(m, "- Format: {}; channels: {}", r.format, r.channels.join(", "));
    let _ = writeln!(m, "- Profile: {}; {} Bd; timing tolerance {} µs", r.profile, r.baud, r.tolerance_us);
    let _ = writeln!(
        m,
        "- {} characters ({} with a line error), {} exchanges, {} frames not attributed ({} characters), {} breaks",
        s.characters, s.flagged, s.exchanges, s.unattributed, s.unattributed_characters, s.breaks
    );
    for (k, v) in &s.verdicts {
        let _ = writeln!(m, "  - {k}: {v}");
    }
    for (k, v) in r.run_info.iter().flat_map(|i| i.rows()) {
        let _ = writeln!(m, "- {k}: {v}");
    }
    for a in &r.assumptions {
        let _ = writeln!(m, "- Assumed: {a}");
    }
    let _ = writeln!(
        m,
        "\nUNKNOWN is what a listener cannot tell (the encoder's stored state, a corrupted capture), never a charge.\n"
    );
    if !s.master.is_empty() {
        let _ = writeln!(m, "## The master\n\n| verdict | rule | times | first |\n|---|---|---|---|");
        for x in &s.master {
            let _ = writeln!(m, "| {} | {} | {} | {} |", x.first.verdict().label(), x.rule, x.count, x.first);
        }
    }
    let _ = writeln!(m, "\n## Response times per command (ms)\n");
    let head: Vec<String> = crate::listen::BUCKETS_MS.iter().map(|b| format!("≤{b}")).collect();
    let _ = writeln!(m, "| command | n | min | mean | max | {} | more |", head.join(" | "));
    let _ = writeln!(m, "|---|---|---|---|---|{}---|", "---|".repeat(head.len()));
    for (c, t) in &s.response_times {
        let h: Vec<String> = t.histogram.iter().map(|n| n.to_string()).collect();
        let _ = writeln!(
            m,
            "| {c} | {} | {:.3} | {:.3} | {:.3} | {} |",
            t.count,
            t.min_ms,
            t.mean_ms,
            t.max_ms,
            h.join(" | ")
        );
    }
    if !s.exchanges_kept.is_empty() {
        let _ = writeln!(m, "\n## Exchanges not PASS (the first {})\n\n```", s.exchanges_kept.len());
        for h in &s.exchanges_kept {
            let _ = writeln!(m, "{h}");
        }
        let _ = writeln!(m, "```");
    }
    if !s.notes.is_empty() {
        let _ = writeln!(m, "\n## Notes\n");
        for n in &s.notes {
            let _ = writeln!(m, "- {n}");
        }
    }
    m
}

/// Suite "slave": a case per command heard, failed when one of its exchanges FAILed,
/// skipped when none could be graded (all UNKNOWN). Suite "master": a case per rule
/// the master broke, failed where the rule is normative.
fn junit(r: &ListeningReport) -> String {
    use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};
    let s = &r.summary;
    let mut slave = TestSuite::new(format!("slave heard on {}", r.capture));
    for (command, counts) in &s.per_command {
        let n = |h: CaseVerdict| counts.get(h.label()).copied().unwrap_or(0);
        let first = s.exchanges_kept.iter().find(|h| h.command == *command && h.verdict == CaseVerdict::Fail);
        let status = if n(CaseVerdict::Fail) > 0 {
            let mut st = TestCaseStatus::non_success(NonSuccessKind::Failure);
            st.set_message(format!("{} of {} exchanges FAIL", n(CaseVerdict::Fail), counts.values().sum::<u64>()));
            if let Some(h) = first {
                st.set_description(h.to_string());
            }
            st
        } else if n(CaseVerdict::Pass) + n(CaseVerdict::NonStrict) == 0 {
            let mut st = TestCaseStatus::skipped();
            st.set_message("no exchange could be graded (UNKNOWN)");
            st
        } else {
            TestCaseStatus::success()
        };
        let mut t = TestCase::new(command.to_string(), status);
        t.set_classname("hiperface.listen.slave");
        let tally: Vec<String> = counts.iter().map(|(k, v)| format!("{v} {k}")).collect();
        t.set_system_out(tally.join(", "));
        slave.add_test_case(t);
    }
    let mut master = TestSuite::new(format!("master heard on {}", r.capture));
    for m in &s.master {
        let status = match m.first.verdict() {
            CaseVerdict::Fail => {
                let mut st = TestCaseStatus::non_success(NonSuccessKind::Failure);
                st.set_message(format!("{} ({} times)", m.first, m.count));
                st
            }
            _ => TestCaseStatus::success(),
        };
        let mut t = TestCase::new(m.rule.clone(), status);
        t.set_classname("hiperface.listen.master");
        t.set_system_out(format!("[{}] {} ({} times)", m.first.verdict().label(), m.first, m.count));
        master.add_test_case(t);
    }
    let mut report = Report::new("hiperface listen");
    report.add_test_suites([slave, master]);
    report.to_string().unwrap_or_else(|e| format!("<!-- cannot serialise: {e} -->"))
}

/// The report for people, as a page.
fn html(r: &ListeningReport) -> String {
    let s = &r.summary;
    let mut h = String::new();
    h.push_str(&page_head(&format!("HIPERFACE listening report: {}", r.capture)));
    let (o, v) = (r.outcome.label(), r.verdict.label());
    let _ = write!(h, "<h1>HIPERFACE listening report: {o}</h1>");
    if let Some(why) = &r.incomplete {
        let _ = write!(h, "<p>Not PASSED: {}</p>", escape(why));
    }
    let _ = write!(h, "<p>Worst verdict heard: <span class=\"{v}\">{v}</span></p><table>");
    let rows = [
        ("capture", r.capture.clone()),
        ("format", format!("{}; channels: {}", r.format, r.channels.join(", "))),
        ("profile", format!("{}; {} Bd; timing tolerance {} µs", r.profile, r.baud, r.tolerance_us)),
        (
            "heard",
            format!(
                "{} characters, {} exchanges, {} frames not attributed, {} breaks",
                s.characters, s.exchanges, s.unattributed, s.breaks
            ),
        ),
    ];
    for (k, v) in rows.into_iter().chain(r.run_info.iter().flat_map(|i| i.rows())) {
        let _ = write!(h, "<tr><th>{k}</th><td>{}</td></tr>", escape(&v));
    }
    for (k, n) in &s.verdicts {
        let _ = write!(h, "<tr><th class=\"{k}\">{k}</th><td>{n}</td></tr>");
    }
    h.push_str("</table><ul>");
    for a in &r.assumptions {
        let _ = write!(h, "<li>Assumed: {}</li>", escape(a));
    }
    h.push_str("<li>UNKNOWN is what a listener cannot tell (the encoder's stored state, a corrupted capture), never a charge.</li></ul>");
    if !s.master.is_empty() {
        h.push_str("<h2>The master</h2><table><tr><th>verdict</th><th>rule</th><th>times</th><th>first</th></tr>");
        for m in &s.master {
            let v = m.first.verdict().label();
            let _ = write!(
                h,
                "<tr><td class=\"{v}\">{v}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&m.rule),
                m.count,
                escape(&m.first.to_string())
            );
        }
        h.push_str("</table>");
    }
    h.push_str("<h2>Response times per command (ms)</h2><table><tr><th>command</th><th>n</th><th>min</th><th>mean</th><th>max</th>");
    for b in crate::listen::BUCKETS_MS {
        let _ = write!(h, "<th>≤{b}</th>");
    }
    h.push_str("<th>more</th></tr>");
    for (c, t) in &s.response_times {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{:.3}</td>",
            escape(&c.to_string()),
            t.count,
            t.min_ms,
            t.mean_ms,
            t.max_ms
        );
        for n in &t.histogram {
            let _ = write!(h, "<td>{n}</td>");
        }
        h.push_str("</tr>");
    }
    h.push_str("</table>");
    if !s.exchanges_kept.is_empty() {
        let _ = write!(h, "<h2>Exchanges not PASS (the first {})</h2><pre>", s.exchanges_kept.len());
        for x in &s.exchanges_kept {
            let _ = writeln!(h, "<span class=\"{}\">{}</span>", x.verdict.label(), escape(&x.to_string()));
        }
        h.push_str("</pre>");
    }
    if !s.notes.is_empty() {
        h.push_str("<h2>Notes</h2><ul>");
        for n in &s.notes {
            let _ = write!(h, "<li>{}</li>", escape(n));
        }
        h.push_str("</ul>");
    }
    h.push_str("</body></html>\n");
    h
}
