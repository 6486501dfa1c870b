//! Certify an encoder written in C in-process (with the `std` feature): the whole slave
//! catalogue in virtual time against a function that answers each request, the same
//! report as `hiperface certify slave` writes (verdicts, clauses, findings, JSON, JUnit,
//! the certificate as Markdown and HTML), in milliseconds. A firmware's unit tests
//! link their protocol code with this and certify it on every build.
//!
//! encoder.rs an encoder's certification, master.rs a master's, report.rs the report
//! both give; here what both start with (no report yet, the profile of the run).

use crate::{profile, tell, HfStatus};
use core::ffi::{c_char, CStr};
use hiperface_model::Profile;
use hiperface_suite::profile_file;
use std::path::Path;

mod encoder;
mod master;
mod report;

pub use encoder::*;
pub use master::*;
pub use report::*;

/// The start of a certification: no report at `out` until one is made. `Err` where
/// `out` is null.
///
/// # Safety
/// `out` is null or writable.
unsafe fn no_report_yet(out: *mut *mut HfReport) -> Result<(), HfStatus> {
    if out.is_null() {
        return Err(HfStatus::Null);
    }
    // SAFETY: writable by the caller's promise.
    unsafe { *out = core::ptr::null_mut() };
    Ok(())
}

/// The profile of a run: TOML text, or a built-in one by name (both null: `Null`).
/// Why it does not load is told in `error`.
///
/// # Safety
/// `name` is null or NUL-terminated; `toml` likewise; `error` is null or points to
/// `error_len` writable chars.
unsafe fn run_profile(
    name: *const c_char,
    toml: *const c_char,
    error: *mut c_char,
    error_len: usize,
) -> Result<Profile, HfStatus> {
    if name.is_null() && toml.is_null() {
        return Err(HfStatus::Null);
    }
    let loaded = if toml.is_null() {
        // SAFETY: the caller's promise.
        unsafe { profile(name) }.map_err(|s| (s, "no built-in profile has that name".to_string()))
    } else {
        // SAFETY: not null, NUL-terminated by the caller's promise.
        match unsafe { CStr::from_ptr(toml) }.to_str() {
            Ok(text) => {
                profile_file::parse(text, Path::new("the profile")).map_err(|e| (HfStatus::Invalid, e.to_string()))
            }
            Err(_) => Err((HfStatus::Invalid, "not UTF-8".to_string())),
        }
    };
    loaded.map_err(|(status, why)| {
        // SAFETY: the caller's promise.
        unsafe { tell(error, error_len, why) };
        status
    })
}
#[cfg(test)]
mod tests {
    use super::encoder::hf_fault;
    use super::report::{case_verdict, hf_outcome};
    use super::*;
    use crate::names::{hf_fault_name, hf_verdict_name};
    use crate::HfFault;
    use core::ffi::c_int;
    use hiperface_model::UartFault;
    use hiperface_model::Verdict;
    use hiperface_suite::verdict::{CaseVerdict, Outcome};
    use std::collections::BTreeSet;

    fn text(p: *const c_char) -> String {
        // SAFETY: the name functions return static NUL-terminated strings.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }

    /// One spelling: the C names are the core's (the faults in capitals, as C spells
    /// its constants), and each C mirror maps the core's values one to one.
    #[test]
    fn the_c_names_and_values_are_the_cores() {
        let mut seen = BTreeSet::new();
        for v in CaseVerdict::ALL {
            let c = case_verdict(v) as c_int;
            assert!(seen.insert(c));
            assert_eq!(text(hf_case_verdict_name(c)), v.label());
        }
        seen.clear();
        for v in Verdict::ALL {
            let c = crate::hf_verdict(v) as c_int;
            assert!(seen.insert(c));
            assert_eq!(text(hf_verdict_name(c)), v.name());
        }
        seen.clear();
        for f in UartFault::ALL {
            let c = hf_fault(Some(f)) as c_int;
            assert!(seen.insert(c) && c != HfFault::None as c_int);
            assert_eq!(text(hf_fault_name(c)), f.name().to_ascii_uppercase());
        }
        seen.clear();
        for o in [Outcome::Passed, Outcome::Failed, Outcome::Incomplete] {
            let c = hf_outcome(o) as c_int;
            assert!(seen.insert(c));
            assert_eq!(text(hf_outcome_name(c)), o.label());
        }
    }
}
