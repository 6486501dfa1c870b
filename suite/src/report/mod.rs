//! The reports of every front end, rendered one way as text: JSON for programs, JUnit
//! for CI, and a certificate for people as Markdown and HTML: the forms every front end
//! shares. Each front end's report says what goes into each form (`slave::report`,
//! `master::report`, `listen::report`); the harness writes them to files.

pub mod attention;
pub mod catalogue;
pub mod check;
pub mod compare;
pub mod wire;

pub use attention::{attention, Attention};

use crate::verdict::CaseVerdict;

/// Where and when a run was made, as the harness knows it (the core reads no clock,
/// host or process): for the reader of a certificate, who must tell one run from
/// another and redo it.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct RunInfo {
    /// When the run started, UTC, ISO 8601 ("2026-11-26T07:50:12Z").
    pub started_utc: String,
    pub host: String,
    /// The command line as given.
    pub command_line: String,
    /// The source revision the tool was built from (git), or "unknown".
    pub revision: String,
    /// The profile as TOML, digested (FNV-1a, 64 bits): two certificates of the same
    /// data sheet show the same digest.
    pub profile_digest: String,
    /// What was certified, as the operator said it (`--device`): a model and serial
    /// number, a firmware image and its digest. Signed with the report.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub device: Vec<String>,
    /// How much of the machine's processors its hypervisor took during the run (steal
    /// time), where the machine is a virtual one that says so: a processor paused by the
    /// host is a harness that reads, writes and delivers late, which the harness
    /// measures only in part. What it could explain is UNKNOWN, never charged, and a run
    /// with much of it is a run to repeat on a quieter host.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steal: Option<Steal>,
}

/// The processors' time the hypervisor took over a run (`/proc/stat`'s steal).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Steal {
    /// Time taken, summed over the processors, ms.
    pub steal_ms: u64,
    /// The processors' time over the run (wall time times processors), ms.
    pub processor_ms: u64,
}

impl Steal {
    /// The share taken, in per cent (0 where no time passed).
    pub fn percent(&self) -> f64 {
        if self.processor_ms == 0 {
            0.0
        } else {
            self.steal_ms as f64 * 100.0 / self.processor_ms as f64
        }
    }

    /// Whether it was enough to say so on the console: a pause of the hypervisor is
    /// milliseconds long, and a run's timing is graded to fractions of one.
    pub fn worth_saying(&self) -> bool {
        self.percent() >= 1.0
    }

    /// "the hypervisor took 0.3 % of the processors' time (steal: 0.4 s of 120.0 s)".
    pub fn text(&self) -> String {
        format!(
            "the hypervisor took {:.1} % of the processors' time (steal: {:.1} s of {:.1} s)",
            self.percent(),
            self.steal_ms as f64 / 1000.0,
            self.processor_ms as f64 / 1000.0
        )
    }
}

impl RunInfo {
    /// One line for the top of a certificate: when, where and how.
    pub fn line(&self) -> String {
        let steal = self.steal.map(|s| format!("; {}", s.text())).unwrap_or_default();
        format!(
            "run started {} (UTC) on {}, tool revision {}: {}{steal}",
            self.started_utc, self.host, self.revision, self.command_line
        )
    }

    /// The certificate's rows.
    pub fn rows(&self) -> Vec<(&'static str, String)> {
        let device = self.device.iter().map(|d| ("device", d.clone()));
        device
            .chain([
                ("run started (UTC)", self.started_utc.clone()),
                ("host", self.host.clone()),
                ("command line", self.command_line.clone()),
                ("tool revision", self.revision.clone()),
                ("profile digest", self.profile_digest.clone()),
            ])
            .chain(self.steal.map(|s| ("hypervisor", s.text())))
            .collect()
    }
}

/// The digest of a profile as its TOML reads (FNV-1a, 64 bits, hex).
pub fn profile_digest(profile: &hiperface_model::Profile) -> String {
    let toml = crate::profile_file::to_toml(profile);
    let hash =
        toml.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3));
    format!("fnv1a64:{hash:016x}")
}

/// Units NOT-APPLICABLE for one reason: the reason says what would run them ("writes
/// EEPROM; run with --allow-writes", "declared not used"). Most were never run; `ran`
/// sets apart those that ran and had their replies graded but whose point the line
/// cannot show (a pseudo-terminal carries no data rate): a newcomer read "Not run" over
/// a case that had written the EEPROM.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct NotRun {
    pub reason: String,
    pub cases: Vec<String>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub ran: bool,
}

/// The heading over the units that ran but are NOT-APPLICABLE, and what it means.
const RAN_HEADING: &str = "Ran, not applicable on this line";
const RAN_MEANS: &str = "These ran and their replies were graded (a FAIL among them would show above), but what \
                         they are about cannot be observed on this line.";

impl NotRun {
    /// The NOT-APPLICABLE cases of `cases`, grouped by their reason and by whether
    /// they ran (any exchange), in run order.
    pub fn of(cases: &[crate::verdict::CaseResult]) -> Vec<NotRun> {
        let mut out: Vec<NotRun> = Vec::new();
        for c in cases.iter().filter(|c| c.verdict == CaseVerdict::NotApplicable) {
            let reason = c.findings.first().map_or("not applicable", |f| f.message()).to_string();
            let ran = c.exchanges > 0;
            match out.iter_mut().find(|n| n.reason == reason && n.ran == ran) {
                Some(n) => n.cases.push(c.id.to_string()),
                None => out.push(NotRun { reason, cases: vec![c.id.to_string()], ran }),
            }
        }
        out
    }

    /// The certificate's sections: each heading, what it means where it needs saying,
    /// and its groups; none without a group.
    fn sections(groups: &[NotRun]) -> impl Iterator<Item = (&'static str, Option<&'static str>, Vec<&NotRun>)> {
        [("Not run", None, false), (RAN_HEADING, Some(RAN_MEANS), true)]
            .into_iter()
            .map(|(heading, means, ran)| (heading, means, groups.iter().filter(|n| n.ran == ran).collect::<Vec<_>>()))
            .filter(|(_, _, of)| !of.is_empty())
    }

    /// The certificate's sections, in Markdown ("" where everything ran and applied).
    pub fn markdown(groups: &[NotRun]) -> String {
        let mut s = String::new();
        for (heading, means, of) in NotRun::sections(groups) {
            s.push_str(&format!("\n## {heading}\n\n"));
            if let Some(means) = means {
                s.push_str(&format!("{means}\n\n"));
            }
            for n in of {
                let ids: Vec<String> = n.cases.iter().map(|c| format!("`{c}`")).collect();
                s.push_str(&format!("- {} ({}): {}\n", n.reason, n.cases.len(), ids.join(", ")));
            }
        }
        s
    }

    /// The certificate's sections, in HTML.
    pub fn html(groups: &[NotRun]) -> String {
        let mut s = String::new();
        for (heading, means, of) in NotRun::sections(groups) {
            s.push_str(&format!("<h2>{heading}</h2>"));
            if let Some(means) = means {
                s.push_str(&format!("<p>{}</p>", escape(means)));
            }
            s.push_str("<ul>");
            for n in of {
                s.push_str(&format!(
                    "<li>{} ({}): <code>{}</code></li>",
                    escape(&n.reason),
                    n.cases.len(),
                    n.cases.join(", ")
                ));
            }
            s.push_str("</ul>");
        }
        s
    }

    /// The console's lines.
    pub fn lines(groups: &[NotRun]) -> Vec<String> {
        groups
            .iter()
            .map(|n| {
                let what = if n.ran { "ran, not applicable on this line" } else { "not run" };
                format!("{what} ({}): {}: {}", n.cases.len(), n.reason, n.cases.join(", "))
            })
            .collect()
    }
}

/// The documents a clause id names by its prefix ("000:T10"), for a certificate's
/// reader who has only the certificate.
const DOCUMENTS: [(&str, &str); 4] = [
    ("000", "the SICK HIPERFACE specification: the normative document (the \"current\" edition)"),
    ("001", "the Kübler Sendix S36 HIPERFACE manual: its worked examples"),
    ("002", "the SICK-STEGMANN HIPERFACE description: the \"legacy\" edition"),
    ("DESIGN", "a decision of this project where the documents are silent (the user guide's design notes)"),
];

/// The documents the units' clauses and findings cite, in the order of [`DOCUMENTS`].
pub fn documents_cited(units: &[crate::verdict::CaseResult]) -> Vec<(&'static str, &'static str)> {
    let cited = |prefix: &str| {
        let of = |id: &str| id.split_once(':').is_some_and(|(doc, _)| doc == prefix);
        units.iter().any(|u| u.clauses.iter().any(|c| of(c.id())) || u.findings.iter().any(|f| of(f.clause_id())))
    };
    DOCUMENTS.into_iter().filter(|(prefix, _)| cited(prefix)).collect()
}

/// How a clause id reads, for a reader who has only the certificate.
const CLAUSE_IDS: &str = "A clause id is the document, a colon and the place in it: `000:T10` is Table 10 of \
                          000, `000:2.3.4` its section 2.3.4; a suffix (`/master`) names one rule of several \
                          there. A finding above quotes the sentence of the clause it cites; `hiperface \
                          clauses` lists every clause and what checks it.";

/// The certificate's "Documents cited" section in Markdown.
pub fn documents_markdown(units: &[crate::verdict::CaseResult]) -> String {
    let mut s = format!("\n## Documents cited\n\n{CLAUSE_IDS}\n\n");
    for (prefix, what) in documents_cited(units) {
        s.push_str(&format!("- `{prefix}`: {what}\n"));
    }
    s
}

/// The certificate's "Documents cited" section in HTML.
pub fn documents_html(units: &[crate::verdict::CaseResult]) -> String {
    let mut s = format!("<h2>Documents cited</h2><p>{}</p><ul>", escape(CLAUSE_IDS));
    for (prefix, what) in documents_cited(units) {
        s.push_str(&format!("<li><code>{prefix}</code>: {}</li>", escape(what)));
    }
    s.push_str("</ul>");
    s
}

/// A report as its JSON form has it: the outcome and the findings to read first
/// ahead of everything the report holds, as on the certificate.
#[derive(serde::Serialize)]
pub struct Summarized<'a, R: serde::Serialize> {
    pub outcome: crate::verdict::Outcome,
    pub attention: Vec<Attention>,
    /// What was not run, where the report does not hold it itself.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_run: Option<Vec<NotRun>>,
    #[serde(flatten)]
    pub report: &'a R,
}

impl<'a, R: serde::Serialize> Summarized<'a, R> {
    pub fn new(outcome: crate::verdict::Outcome, attention: Vec<Attention>, report: &'a R) -> Self {
        Summarized { outcome, attention, not_run: None, report }
    }
}

/// A run's report in the four forms every front end writes.
pub trait Reports {
    /// The people's certificate's file name, without extension.
    const CERTIFICATE: &'static str;
    fn json(&self) -> serde_json::Result<String>;
    fn junit(&self) -> String;
    fn markdown(&self) -> String;
    fn html(&self) -> String;
}

/// One JUnit suite of cases (slave cases or master scenarios).
pub fn junit_suite(name: String, cases: &[crate::verdict::CaseResult], under: wire::UnderTest) -> String {
    use quick_junit::{Report as JReport, TestCase, TestSuite};
    let mut suite = TestSuite::new(name);
    for c in cases {
        let detail: String = c.findings.iter().map(|f| format!("[{}] {f}\n", f.verdict().label())).collect();
        let mut status = junit_status(c.verdict, detail.trim());
        if c.verdict == CaseVerdict::Fail {
            status.set_description(wire::text(c, under));
        }
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

/// A unit's JUnit status by its verdict, `detail` its findings: PASS and NON-STRICT
/// succeed, NOT-APPLICABLE is skipped, FAIL is a failure, and what was not observed
/// (ERROR, NOT-EXERCISED, UNKNOWN) is an error: neither a pass nor the device's
/// failure.
pub fn junit_status(verdict: CaseVerdict, detail: &str) -> quick_junit::TestCaseStatus {
    use quick_junit::{NonSuccessKind, TestCaseStatus};
    match verdict {
        CaseVerdict::Pass | CaseVerdict::NonStrict => TestCaseStatus::success(),
        CaseVerdict::NotApplicable => {
            let mut s = TestCaseStatus::skipped();
            s.set_message(detail.to_string());
            s
        }
        CaseVerdict::Fail => {
            let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
            s.set_message(detail.to_string());
            s
        }
        CaseVerdict::Error | CaseVerdict::NotExercised | CaseVerdict::Unknown => {
            let mut s = TestCaseStatus::non_success(NonSuccessKind::Error);
            s.set_message(format!("{}: {detail}", verdict.label()));
            s
        }
    }
}

/// Text made safe as the content of an HTML or SVG element: the one escape of every
/// page and diagram the project writes. No writer puts outside text in an attribute
/// (ids there are the catalogue's own, or made safe by `compare`'s anchors), so
/// quotes stay as they are, and Markdown around the text reads as it did.
pub fn escape(t: &str) -> String {
    t.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// The head of every HTML certificate: one style, a class per verdict.
pub fn page_head(title: &str) -> String {
    format!(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>{}</title>\
         <style>body{{font-family:sans-serif;max-width:75em;margin:2em auto}}table{{border-collapse:collapse}}\
         td,th{{border:1px solid #ccc;padding:.2em .5em;text-align:left}}.PASS{{color:#070}}\
         .FAIL{{color:#b00;font-weight:bold}}.NON-STRICT{{color:#a60}}.ERROR{{color:#b0b}}.NOT-EXERCISED{{color:#b0b}}.UNKNOWN{{color:#066}}\
         .NOT-APPLICABLE{{color:#666}}.PASSED{{color:#070}}.FAILED{{color:#b00}}.INCOMPLETE{{color:#b0b}}\
         td{{vertical-align:top}}\
         pre{{background:#f4f4f4;padding:.5em;white-space:pre;overflow-x:auto;max-width:72em;margin:0}}\
         mark.bad{{background:rgba(220,50,47,.45);color:inherit;font-weight:bold}}\
         svg{{border:1px solid #ddd;max-width:100%;height:auto}}</style></head><body>",
        escape(title)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(steal: Option<Steal>) -> RunInfo {
        RunInfo {
            started_utc: "2026-11-29T16:08:33Z".into(),
            host: "vm".into(),
            command_line: "hiperface certify slave --port sim".into(),
            revision: "863fcee2d11d".into(),
            profile_digest: "fnv1a64:b100389aa1f5a415".into(),
            device: Vec::new(),
            steal,
        }
    }

    #[test]
    fn the_hypervisors_steal_is_on_the_certificate_where_it_was_measured() {
        let s = Steal { steal_ms: 310, processor_ms: 22_670 };
        let with = run(Some(s));
        assert!(with.line().ends_with("; the hypervisor took 1.4 % of the processors' time (steal: 0.3 s of 22.7 s)"));
        assert!(with.rows().contains(&("hypervisor", s.text())));
        // Not measured (no hypervisor that says so, or virtual time): no word of it,
        // and a report of an earlier revision reads as before.
        let without = run(None);
        assert!(!without.line().contains("hypervisor") && without.rows().iter().all(|(k, _)| *k != "hypervisor"));
        let json = serde_json::to_string(&without).unwrap();
        assert!(!json.contains("steal"));
        assert_eq!(serde_json::from_str::<RunInfo>(&json).unwrap(), without);
        // Under a per cent a run is not told about it on the console; nothing passed,
        // nothing taken.
        assert!(s.worth_saying() && !Steal { steal_ms: 9, processor_ms: 1_000 }.worth_saying());
        assert_eq!(Steal::default().percent(), 0.0);
    }
}
