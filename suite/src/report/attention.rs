//! What a certificate puts first: every finding that kept the run from PASSED (FAIL,
//! ERROR, NOT-EXERCISED, UNKNOWN), each with what its reader needs to judge it there and
//! then: the case or scenario, the clause with its sentence, the exchange it is about
//! and the figure measured against its limit. The same list in every form (Markdown,
//! HTML, JSON, the console), so that a customer and a CI log read the same thing.

use crate::report::escape;
use crate::report::wire::{reply_index, request_index};
use crate::verdict::{CaseResult, CaseVerdict, Figure, WireEntry};
use hiperface_model::CommandId;
use serde::Serialize;

/// Whether a unit with verdict `v` is one a certificate puts first (and shows the
/// wire log of).
pub fn read_first(v: CaseVerdict) -> bool {
    FIRST.contains(&v)
}

/// The verdicts a certificate puts first, in the order it lists them.
const FIRST: [CaseVerdict; 4] =
    [CaseVerdict::Fail, CaseVerdict::Error, CaseVerdict::NotExercised, CaseVerdict::Unknown];

/// One finding the reader must see first.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Attention {
    /// The case or scenario id.
    pub unit: &'static str,
    pub title: &'static str,
    pub verdict: CaseVerdict,
    pub finding: String,
    /// The clause id, "" for what the harness states of itself.
    pub clause: &'static str,
    /// The clause's sentence as the registry quotes it.
    pub clause_text: &'static str,
    /// Where on the wire, ms since the run started.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at_ms: Option<f64>,
    /// The request it is about, as sent ("40 42 02"), and its command in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub request: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<String>,
    /// The reply to it, as heard; `None` where none came (or there was no request).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reply: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub figure: Option<Figure>,
    /// Where to start looking, from the clause and the verdict (`report::check`).
    pub check: &'static str,
    /// More findings of the unit with the same verdict and clause, left out of this
    /// list (in the unit's own section).
    pub more: usize,
    /// Other units with the very same finding and no exchange to show (every case not
    /// run after a run was aborted): listed here once, not once each.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub also: Vec<&'static str>,
}

/// The findings of `units` to put first: FAILs, then ERRORs, NOT-EXERCISED and
/// UNKNOWNs, in run order; of a unit's findings with the same verdict and clause, the
/// first, with how many more.
pub fn attention(units: &[CaseResult]) -> Vec<Attention> {
    let mut out: Vec<Attention> = Vec::new();
    for verdict in FIRST {
        for u in units {
            let first = out.len();
            for f in u.findings.iter().filter(|f| f.verdict() == verdict) {
                if let Some(same) = out[first..].iter_mut().find(|a| a.clause == f.clause_id()) {
                    same.more += 1;
                    continue;
                }
                let (request, reply) = f.at_us().map_or((None, None), |t| exchange(u, t));
                if request.is_none() {
                    let same = |a: &&mut Attention| {
                        a.verdict == verdict
                            && a.request.is_none()
                            && a.clause == f.clause_id()
                            && a.finding == f.message()
                            && a.unit != u.id
                    };
                    if let Some(a) = out.iter_mut().find(|a| same(a)) {
                        a.also.push(u.id);
                        continue;
                    }
                }
                out.push(Attention {
                    unit: u.id,
                    title: u.title,
                    verdict,
                    finding: f.message().to_string(),
                    clause: f.clause_id(),
                    clause_text: f.clause().map_or("", |c| c.quote()),
                    at_ms: f.at_us().map(|t| t as f64 / 1000.0),
                    command: request.map(|r| command_of(&r.bytes)),
                    request: request.map(|r| r.bytes.clone()),
                    reply: reply.map(|r| r.bytes.clone()),
                    figure: f.figure(),
                    check: super::check::what_to_check(verdict, f.clause_id()),
                    more: 0,
                    also: Vec::new(),
                });
            }
        }
    }
    out
}

/// The request a finding at `at_us` is about, and the reply to it (before the next
/// request).
fn exchange(u: &CaseResult, at_us: u64) -> (Option<&WireEntry>, Option<&WireEntry>) {
    let Some(i) = request_index(u, at_us) else { return (None, None) };
    (u.wire.get(i), reply_index(u, i).and_then(|r| u.wire.get(r)))
}

/// A frame's command in words, from its hex bytes ("40 42 02" -> "42h Read Position").
fn command_of(hex: &str) -> String {
    let bytes: Vec<u8> = hex.split_whitespace().filter_map(|b| u8::from_str_radix(b, 16).ok()).collect();
    match bytes.len() {
        0 | 1 => "no command byte".to_string(),
        _ => CommandId::of_frame(&bytes).to_string(),
    }
}

impl Attention {
    /// The headline: verdict, unit and finding.
    pub fn headline(&self) -> String {
        format!("{} {} ({}): {}", self.verdict.label(), self.unit, self.title, self.finding)
    }

    /// What follows the headline, in plain words, with the frames' bytes apart.
    pub fn details(&self) -> Vec<Detail> {
        let words = |what, words: String| Detail { what, bytes: None, words };
        let mut rows = Vec::new();
        if !self.clause.is_empty() {
            rows.push(words("clause", format!("{}: \u{201c}{}\u{201d}", self.clause, self.clause_text)));
        }
        if let (Some(request), Some(command)) = (&self.request, &self.command) {
            let at = self.at_ms.map_or(String::new(), |t| format!(", the exchange at {t:.3} ms"));
            rows.push(Detail { what: "request", bytes: Some(request.clone()), words: format!("{command}{at}") });
            rows.push(match &self.reply {
                Some(reply) => Detail { what: "reply", bytes: Some(reply.clone()), words: String::new() },
                None => words("reply", "none heard".to_string()),
            });
        }
        if let Some(f) = self.figure {
            rows.push(words("measured", f.to_string()));
        }
        rows.push(words("check", self.check.to_string()));
        if self.more > 0 {
            let what = if self.more == 1 { "finding" } else { "findings" };
            rows.push(words("more", format!("{} more {what} like it in {}'s own section", self.more, self.unit)));
        }
        if !self.also.is_empty() {
            rows.push(words("also", format!("the same in {} more: {}", self.also.len(), self.also.join(", "))));
        }
        rows
    }

    /// The console's lines: the headline, then the details indented.
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![self.headline()];
        out.extend(
            self.details().iter().map(|d| format!("    {}: {}", d.what, d.render(str::to_string, str::to_string))),
        );
        out
    }
}

/// One line under a finding's headline: what it is, the frame's bytes where it shows
/// one (raw, as sent or heard), and words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Detail {
    pub what: &'static str,
    pub bytes: Option<String>,
    pub words: String,
}

impl Detail {
    /// As one form writes it: `code` for the bytes, `text` for the words, the words in
    /// parentheses after the bytes.
    fn render(&self, code: impl Fn(&str) -> String, text: impl Fn(&str) -> String) -> String {
        match (&self.bytes, self.words.is_empty()) {
            (Some(b), true) => code(b),
            (Some(b), false) => format!("{} ({})", code(b), text(&self.words)),
            (None, _) => text(&self.words),
        }
    }
}

/// The section in Markdown; `nothing`: what to say when the list is empty.
pub fn markdown(items: &[Attention], nothing: &str) -> String {
    let mut s = String::new();
    if items.is_empty() {
        s.push_str(nothing);
        s.push('\n');
    }
    for (i, a) in items.iter().enumerate() {
        s.push_str(&format!(
            "{}. **{}** `{}` ({}): {}\n",
            i + 1,
            a.verdict.label(),
            a.unit,
            a.title,
            a.finding.replace('|', "\\|")
        ));
        for d in a.details() {
            s.push_str(&format!("   - {}: {}\n", d.what, d.render(|b| format!("`{b}`"), str::to_string)));
        }
    }
    s
}

/// The section in HTML.
pub fn html(items: &[Attention], nothing: &str) -> String {
    if items.is_empty() {
        return format!("<p class=\"PASS\">{}</p>", escape(nothing));
    }
    let mut s = String::from("<ol class=\"attention\">");
    for a in items {
        let v = a.verdict.label();
        s.push_str(&format!(
            "<li><span class=\"{v}\">{v}</span> <a href=\"#{id}\"><code>{id}</code></a> ({}): {}<ul>",
            escape(a.title),
            escape(&a.finding),
            id = a.unit
        ));
        for d in a.details() {
            let val = d.render(|b| format!("<code>{}</code>", escape(b)), escape);
            s.push_str(&format!("<li>{}: {val}</li>", d.what));
        }
        s.push_str("</ul></li>");
    }
    s.push_str("</ol>");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verdict::Finding;
    use hiperface_model::clause;
    use hiperface_model::Edition;

    fn unit() -> CaseResult {
        let mut c = CaseResult::named("timing.read-position", "Read Position answered in time", &[]);
        for (t_us, direction, bytes) in [
            (1_000, WireEntry::REQUEST, "40 42 02"),
            (1_500, WireEntry::REPLY, "40 42 00 00 00 00 02"),
            (9_000, WireEntry::REQUEST, "40 42 02"),
            (30_000, WireEntry::REPLY, "40 42 00 00 00 01 03"),
        ] {
            c.wire.push(WireEntry { t_us, direction, bytes: bytes.to_string() });
        }
        c
    }

    #[test]
    fn a_fail_names_its_exchange_clause_and_figure_and_repeats_fold_into_a_count() {
        let mut c = unit();
        let late = Figure { what: "reply start", measured_us: 17_904, limit_us: 10_000, at_most: true };
        for _ in 0..3 {
            c.push(Finding::fail("reply late", clause::COMMANDS, Edition::Current).with_figure(late).at(9_000));
        }
        c.push(Finding::unknown("cannot tell").at(1_000));
        c.push(Finding::non_strict("acceptable", clause::CHECK_ORDER).at(1_000));
        let a = attention(&[c.clone()]);
        assert_eq!(a.len(), 2, "{a:?}");
        assert_eq!((a[0].verdict, a[0].clause, a[0].more), (CaseVerdict::Fail, "000:T10", 2));
        assert_eq!(a[0].request.as_deref(), Some("40 42 02"));
        assert_eq!(a[0].reply.as_deref(), Some("40 42 00 00 00 01 03"), "the reply to the second request");
        assert_eq!(a[0].command.as_deref(), Some("42h Read Position"));
        assert!(a[0].clause_text.starts_with("User command summary"));
        assert_eq!(a[1].verdict, CaseVerdict::Unknown, "FAILs first; NON-STRICT not listed");
        let lines = a[0].lines().join("\n");
        assert!(lines.contains("17.904 ms measured, at most 10.000 ms allowed"), "{lines}");
        assert!(lines.contains("2 more findings like it"), "{lines}");
        // The wire log marks the reply the FAIL is about (the slave's frame), and only it.
        let wire = crate::report::wire::text(&c, crate::report::wire::UnderTest::Slave);
        let marked: Vec<&str> = wire.lines().filter(|l| l.contains("<--")).collect();
        assert_eq!(marked.len(), 2, "{wire}");
        assert!(marked[1].contains("30.000 ms  S<") && marked[1].contains("FAIL 000:T10"), "{wire}");
        assert!(marked[0].contains("1.500 ms  S<"), "{wire}");
        assert!(marked[0].contains("UNKNOWN") && marked[0].contains("NON-STRICT"), "{wire}");
    }

    #[test]
    fn a_masters_rule_is_about_the_frame_that_broke_it_and_a_missed_reaction_about_the_last_request() {
        // A master's broken rule is placed at the start of its frame; the frame's
        // entry is stamped at its end, after it.
        let mut c = unit();
        c.push(Finding::fail("a frame that is no request", clause::CHECKSUM, Edition::Current).at(6_000));
        // A reaction missing after the reply at 30 ms (its situation).
        c.push(Finding::fail("no reset", clause::WARNING_BIT, Edition::Current).at(30_000));
        let a = attention(&[c.clone()]);
        assert_eq!((a[0].request.as_deref(), a[0].at_ms), (Some("40 42 02"), Some(6.0)));
        assert_eq!(a[0].reply.as_deref(), Some("40 42 00 00 00 01 03"), "the one after 9 ms");
        assert_eq!(a[1].reply.as_deref(), Some("40 42 00 00 00 01 03"), "the reply it followed");
        let wire = crate::report::wire::text(&c, crate::report::wire::UnderTest::Master);
        let marked: Vec<&str> = wire.lines().filter(|l| l.contains("<--")).collect();
        assert_eq!(marked.len(), 1, "{wire}");
        assert!(marked[0].contains("9.000 ms") && marked[0].contains("FAIL 000:2.3.3, FAIL 000:2.3.4"), "{wire}");
    }

    #[test]
    fn a_finding_before_any_request_has_no_exchange() {
        let mut c = CaseResult::named("x", "x", &[]);
        c.push(Finding::error("port gone").at(5));
        let a = attention(&[c]);
        assert_eq!((a[0].request.as_deref(), a[0].reply.as_deref()), (None, None));
        let details: Vec<&str> = a[0].details().iter().map(|d| d.what).collect();
        assert_eq!(details, ["check"], "no exchange, only where to look");
        assert!(a[0].check.starts_with("the connection"), "{:?}", a[0].check);
    }
}
