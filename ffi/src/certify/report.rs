//! A certification's report as C reads it: the outcome, the cases and their findings,
//! the report's forms (JSON, JUnit, Markdown, HTML), the names of the values.

use crate::HF_ID_LEN;
use crate::{c_text, HfStatus, HF_CLAUSE_LEN, HF_REASON_LEN};
use core::ffi::{c_char, c_int};
use hiperface_model::Profile;
use hiperface_suite::master::report::MasterCertificate;
use hiperface_suite::master::DriveReport;
use hiperface_suite::report::Reports;
use hiperface_suite::slave::Report;
use hiperface_suite::verdict::{CaseResult, CaseVerdict, Outcome};
use std::ffi::CString;

/// What a whole run adds up to.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HfOutcome {
    /// Every case graded, none failed.
    Passed = 0,
    /// A case FAILed: the encoder broke a normative clause.
    Failed = 1,
    /// Nothing failed, but not everything was observed (UNKNOWN, NOT-EXERCISED,
    /// ERROR, or nothing graded): not a pass.
    Incomplete = 2,
}

/// The verdict of a case (the reports' labels: [`hf_case_verdict_name`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HfCaseVerdict {
    Pass = 0,
    NonStrict = 1,
    Fail = 2,
    NotApplicable = 3,
    NotExercised = 4,
    Unknown = 5,
    Error = 6,
}

/// A case of a report.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfCase {
    /// NUL-terminated, e.g. "position.read".
    pub id: [c_char; HF_ID_LEN],
    pub verdict: HfCaseVerdict,
    /// How many findings ([`hf_report_finding`]).
    pub findings: usize,
}

/// A finding of a case: its verdict, the clause it rests on, and what was seen.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfFinding {
    pub verdict: HfCaseVerdict,
    /// NUL-terminated, e.g. "000:2.3.3".
    pub clause: [c_char; HF_CLAUSE_LEN],
    /// NUL-terminated; cut where it does not fit.
    pub message: [c_char; HF_REASON_LEN],
}

/// The forms of a report, as `hiperface certify slave --report` writes them.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HfReportForm {
    /// report.json: everything, with the record `hiperface decode` plays back.
    Json = 0,
    /// junit.xml, for CI.
    Junit = 1,
    /// The certificate for people.
    Markdown = 2,
    Html = 3,
}

/// A certification's report, of an encoder ([`hf_certify`]) or of a master
/// ([`hf_certify_master`]). Opaque to C; freed with [`hf_report_free`].
pub struct HfReport {
    pub(super) run: Run,
    /// The forms asked for, kept until the report is freed.
    pub(super) texts: [std::cell::OnceCell<CString>; 4],
}

/// What was certified.
pub(super) enum Run {
    Encoder(Box<Report>),
    /// A master's report, and the encoder's profile its certificate names.
    Master(Box<(DriveReport, Profile)>),
}

impl Run {
    pub(super) fn outcome(&self) -> Outcome {
        match self {
            Run::Encoder(r) => r.outcome(),
            Run::Master(m) => m.0.outcome(),
        }
    }

    /// The cases of an encoder's run, the scenarios of a master's.
    pub(super) fn cases(&self) -> &[CaseResult] {
        match self {
            Run::Encoder(r) => &r.cases,
            Run::Master(m) => &m.0.scenarios,
        }
    }

    pub(super) fn text(&self, form: c_int) -> String {
        fn of(r: &impl Reports, form: c_int) -> String {
            match form {
                f if f == HfReportForm::Json as c_int => r.json().unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}")),
                f if f == HfReportForm::Junit as c_int => r.junit(),
                f if f == HfReportForm::Markdown as c_int => r.markdown(),
                _ => r.html(),
            }
        }
        match self {
            Run::Encoder(r) => of(r.as_ref(), form),
            Run::Master(m) => of(&MasterCertificate { report: &m.0, profile: &m.1 }, form),
        }
    }
}

pub(super) fn case_verdict(v: CaseVerdict) -> HfCaseVerdict {
    match v {
        CaseVerdict::Pass => HfCaseVerdict::Pass,
        CaseVerdict::NonStrict => HfCaseVerdict::NonStrict,
        CaseVerdict::Fail => HfCaseVerdict::Fail,
        CaseVerdict::NotApplicable => HfCaseVerdict::NotApplicable,
        CaseVerdict::NotExercised => HfCaseVerdict::NotExercised,
        CaseVerdict::Unknown => HfCaseVerdict::Unknown,
        CaseVerdict::Error => HfCaseVerdict::Error,
    }
}

/// Free a report (null: nothing). Every string it gave is freed with it.
///
/// # Safety
/// `report` is null or came from [`hf_certify`] or [`hf_certify_master`] and was not
/// freed.
#[no_mangle]
pub unsafe extern "C" fn hf_report_free(report: *mut HfReport) {
    if !report.is_null() {
        // SAFETY: from Box::into_raw in hf_certify, freed once by the caller's promise.
        drop(unsafe { Box::from_raw(report) });
    }
}

/// What the run adds up to; `HF_OUTCOME_INCOMPLETE` for a null report.
///
/// # Safety
/// `report` is null or a live report.
#[no_mangle]
pub unsafe extern "C" fn hf_report_outcome(report: *const HfReport) -> HfOutcome {
    // SAFETY: the caller's promise.
    unsafe { report.as_ref() }.map_or(HfOutcome::Incomplete, |r| hf_outcome(r.run.outcome()))
}

/// The C mirror of a run's outcome.
pub(super) const fn hf_outcome(o: Outcome) -> HfOutcome {
    match o {
        Outcome::Passed => HfOutcome::Passed,
        Outcome::Failed => HfOutcome::Failed,
        Outcome::Incomplete => HfOutcome::Incomplete,
    }
}

/// How many cases the report has, or scenarios for a master's (0 for a null report).
///
/// # Safety
/// `report` is null or a live report.
#[no_mangle]
pub unsafe extern "C" fn hf_report_case_count(report: *const HfReport) -> usize {
    // SAFETY: the caller's promise.
    unsafe { report.as_ref() }.map_or(0, |r| r.run.cases().len())
}

/// Case (a master's: scenario) `index` of the report into `out`.
///
/// # Safety
/// `report` is null or a live report; `out` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn hf_report_case(report: *const HfReport, index: usize, out: *mut HfCase) -> HfStatus {
    // SAFETY: the caller's promise.
    let (Some(r), false) = (unsafe { report.as_ref() }, out.is_null()) else { return HfStatus::Null };
    let Some(c) = r.run.cases().get(index) else { return HfStatus::Invalid };
    let mut case = HfCase { id: [0; HF_ID_LEN], verdict: case_verdict(c.verdict), findings: c.findings.len() };
    c_text(&mut case.id, c.id);
    // SAFETY: writable by the caller's promise.
    unsafe { *out = case };
    HfStatus::Ok
}

/// Finding `finding` of case `index` into `out`.
///
/// # Safety
/// `report` is null or a live report; `out` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn hf_report_finding(
    report: *const HfReport,
    index: usize,
    finding: usize,
    out: *mut HfFinding,
) -> HfStatus {
    // SAFETY: the caller's promise.
    let (Some(r), false) = (unsafe { report.as_ref() }, out.is_null()) else { return HfStatus::Null };
    let Some(f) = r.run.cases().get(index).and_then(|c| c.findings.get(finding)) else { return HfStatus::Invalid };
    let mut found =
        HfFinding { verdict: case_verdict(f.verdict()), clause: [0; HF_CLAUSE_LEN], message: [0; HF_REASON_LEN] };
    c_text(&mut found.clause, f.clause_id());
    c_text(&mut found.message, f.message());
    // SAFETY: writable by the caller's promise.
    unsafe { *out = found };
    HfStatus::Ok
}

/// The report in the form `form` (an [`HfReportForm`] as an int), NUL-terminated and
/// kept by the report until [`hf_report_free`]; null for a null report or another
/// form.
///
/// # Safety
/// `report` is null or a live report, not used from another thread meanwhile.
#[no_mangle]
pub unsafe extern "C" fn hf_report_text(report: *const HfReport, form: c_int) -> *const c_char {
    // SAFETY: the caller's promise.
    let Some(r) = (unsafe { report.as_ref() }) else { return core::ptr::null() };
    let Some(slot) = usize::try_from(form).ok().and_then(|i| r.texts.get(i)) else { return core::ptr::null() };
    let made = slot.get_or_init(|| {
        let text = r.run.text(form);
        // No NUL inside a report's text; were there one, the text ends there.
        CString::new(text).unwrap_or_else(|e| {
            let end = e.nul_position();
            let mut bytes = e.into_vec();
            bytes.truncate(end);
            CString::new(bytes).unwrap_or_default()
        })
    });
    made.as_ptr()
}

/// The name of an [`HfOutcome`] ("PASSED", "FAILED", "INCOMPLETE"); "?" for any other
/// value. A static NUL-terminated string: never freed.
#[no_mangle]
pub extern "C" fn hf_outcome_name(outcome: c_int) -> *const c_char {
    crate::names::name(
        &[
            (HfOutcome::Passed as c_int, c"PASSED"),
            (HfOutcome::Failed as c_int, c"FAILED"),
            (HfOutcome::Incomplete as c_int, c"INCOMPLETE"),
        ],
        outcome,
    )
}

/// The name of an [`HfCaseVerdict`] as the reports write it ("PASS", "NON-STRICT",
/// "FAIL", "NOT-APPLICABLE", "NOT-EXERCISED", "UNKNOWN", "ERROR"); "?" for any other
/// value. A static NUL-terminated string: never freed.
#[no_mangle]
pub extern "C" fn hf_case_verdict_name(verdict: c_int) -> *const c_char {
    crate::names::name(
        &[
            (HfCaseVerdict::Pass as c_int, c"PASS"),
            (HfCaseVerdict::NonStrict as c_int, c"NON-STRICT"),
            (HfCaseVerdict::Fail as c_int, c"FAIL"),
            (HfCaseVerdict::NotApplicable as c_int, c"NOT-APPLICABLE"),
            (HfCaseVerdict::NotExercised as c_int, c"NOT-EXERCISED"),
            (HfCaseVerdict::Unknown as c_int, c"UNKNOWN"),
            (HfCaseVerdict::Error as c_int, c"ERROR"),
        ],
        verdict,
    )
}

/// The name of an [`HfReportForm`] ("JSON", "JUNIT", "MARKDOWN", "HTML"); "?" for any
/// other value. A static NUL-terminated string: never freed.
#[no_mangle]
pub extern "C" fn hf_report_form_name(form: c_int) -> *const c_char {
    crate::names::name(
        &[
            (HfReportForm::Json as c_int, c"JSON"),
            (HfReportForm::Junit as c_int, c"JUNIT"),
            (HfReportForm::Markdown as c_int, c"MARKDOWN"),
            (HfReportForm::Html as c_int, c"HTML"),
        ],
        form,
    )
}

/// A catalogue of the suite, as `hf_catalogue` gives it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HfCatalogue {
    /// The slave cases `hf_certify` runs (`HfCertifyOptions.cases` selects by their id).
    SlaveCases = 0,
    /// The master scenarios `hf_certify_master` runs (`HfCertifyMasterOptions.scenarios`).
    MasterScenarios = 1,
}

/// The catalogue `which` as a Markdown table (id, what it checks, clauses), the text
/// `hiperface certify slave --list` and `certify master --list` print: NUL-terminated,
/// owned by the library for the life of the process (never freed by the caller). Null
/// for a value that names no catalogue.
#[no_mangle]
pub extern "C" fn hf_catalogue(which: c_int) -> *const c_char {
    use std::sync::OnceLock;
    static SLAVE: OnceLock<CString> = OnceLock::new();
    static MASTER: OnceLock<CString> = OnceLock::new();
    let text = |cell: &'static OnceLock<CString>, make: fn() -> String| {
        // The table holds no NUL: ids, titles and clause ids are text of the catalogue.
        cell.get_or_init(|| CString::new(make()).unwrap_or_default()).as_ptr()
    };
    match which {
        0 => text(&SLAVE, hiperface_suite::report::catalogue::slave_cases),
        1 => text(&MASTER, hiperface_suite::report::catalogue::master_scenarios),
        _ => core::ptr::null(),
    }
}
