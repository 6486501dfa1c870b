//! A master written in C certified: what it does at each moment, what it hears, the
//! master scenarios run against it in virtual time ([`hf_certify_master`]).

use super::report::{HfReport, Run};
use super::{no_report_yet, run_profile};
use crate::{tell, HfStatus, HF_MAX_FRAME};
use core::ffi::{c_char, c_void, CStr};
use hiperface_model::datalink::RxChar;
use hiperface_suite::master::in_process::{self, MasterAction, MasterUnderTest, Transmit};

/// A character of the encoder's reply as it reached the master under test: the byte,
/// and the end of its stop bit (µs on the run's virtual clock).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfHeardChar {
    pub byte: u8,
    pub at_us: u64,
}

/// What the master under test does now. It comes zeroed.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfMasterAction {
    /// Bytes to send; `len` 0: none. Their first character starts at `start_us` (no
    /// earlier than now, nor than the end of what the master sent before: 0 is now),
    /// one character after the other at `bps` (0: 9600, the encoder's delivery rate,
    /// 000:T7). A character is taken as 11 bits (8E1).
    pub data: [u8; HF_MAX_FRAME],
    pub len: usize,
    pub start_us: u64,
    pub bps: u32,
    /// When to be called again if no character comes before (one not after now: 1 µs
    /// from now). 0 asks nothing new: a wake asked earlier and not yet come still
    /// stands (each action's wake replaces the one before).
    pub wake_us: u64,
}

/// A master under test. `step` is called with `context` once at power-on (`now_us` 0,
/// nothing heard); once for each character of the encoder's replies, as its stop bit
/// ends (`heard_len` 1, `now_us` that character's `at_us`); and at the `wake_us` it
/// asked for when no character came first. It writes what it does at `now_us` into
/// `action`. `power_on` (may be null) is called before each scenario: start afresh.
/// (Pinned by `step_is_called_at_power_on_per_character_and_at_its_wake` in the
/// suite's in-process master.)
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfMaster {
    pub power_on: Option<unsafe extern "C" fn(context: *mut c_void)>,
    pub step: Option<
        unsafe extern "C" fn(
            context: *mut c_void,
            now_us: u64,
            heard: *const HfHeardChar,
            heard_len: usize,
            action: *mut HfMasterAction,
        ),
    >,
    pub context: *mut c_void,
}

/// What [`hf_certify_master`] runs; a zeroed struct (or null) runs every scenario.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfCertifyMasterOptions {
    /// The encoder's profile as TOML text, NUL-terminated; null: the built-in profile
    /// named in the call.
    pub profile_toml: *const c_char,
    /// Only the scenarios whose id matches this glob (the grammar of `cases` above and
    /// of the command line's `--scenarios`); null: all.
    pub scenarios: *const c_char,
    /// The application's polling period (000:3.2.2), ms; 0: 1000, as the command's.
    pub polling_period_ms: u32,
    /// The master's name in the report, NUL-terminated; null: "master".
    pub name: *const c_char,
    /// The command bytes the master declares it never sends (`not_used_len` of them;
    /// null: none): the scenarios about them are NOT-APPLICABLE, "declared not used".
    pub not_used: *const u8,
    pub not_used_len: usize,
}

/// The C functions as a master under test.
pub(super) struct CMaster {
    pub(super) power_on: Option<unsafe extern "C" fn(*mut c_void)>,
    pub(super) step: unsafe extern "C" fn(*mut c_void, u64, *const HfHeardChar, usize, *mut HfMasterAction),
    pub(super) context: *mut c_void,
}

impl MasterUnderTest for CMaster {
    fn power_on(&mut self) {
        if let Some(f) = self.power_on {
            // SAFETY: the caller of hf_certify_master promised a function of its context.
            unsafe { f(self.context) };
        }
    }

    fn step(&mut self, now_us: u64, heard: &[RxChar]) -> MasterAction {
        let chars: Vec<HfHeardChar> = heard.iter().map(|c| HfHeardChar { byte: c.byte, at_us: c.at_us }).collect();
        let mut a = HfMasterAction { data: [0; HF_MAX_FRAME], len: 0, start_us: 0, bps: 0, wake_us: 0 };
        // SAFETY: the caller's promise: a function that reads `heard_len` characters at
        // `heard` (valid for the call) and writes `*action`.
        unsafe { (self.step)(self.context, now_us, chars.as_ptr(), chars.len(), &mut a) };
        let data = a.data.get(..a.len.min(HF_MAX_FRAME)).unwrap_or_default();
        let bps = if a.bps == 0 { 9600 } else { a.bps };
        let send = (!data.is_empty()).then(|| Transmit { bytes: data.to_vec(), start_us: a.start_us, bps });
        MasterAction { send, wake_us: (a.wake_us > 0).then_some(a.wake_us) }
    }
}

/// A NUL-terminated option as text: `Ok(None)` for null, `Err` for text that is not
/// UTF-8.
///
/// # Safety
/// `text` is null or NUL-terminated.
pub(super) unsafe fn option_text(text: *const c_char) -> Result<Option<String>, ()> {
    if text.is_null() {
        return Ok(None);
    }
    // SAFETY: not null, NUL-terminated by the caller's promise.
    unsafe { CStr::from_ptr(text) }.to_str().map(|t| Some(t.to_string())).map_err(drop)
}

/// Certify the master `master` with the whole scenario catalogue (as `hiperface
/// certify master --exec` does), in virtual time, for an encoder of the built-in
/// profile named `profile` (or the TOML text in `options->profile_toml`). Each scenario
/// powers the encoder and the master on at time 0; the master hears each reply
/// character as it ends, and what it sends is on the line when it says. The report is
/// the command's; `*out` holds it until [`hf_report_free`] (null where no report was
/// made). A profile that does not load or a glob that selects nothing:
/// `HF_STATUS_UNKNOWN_PROFILE` or `HF_STATUS_INVALID`, with why in `error`.
///
/// # Safety
/// `profile` is null or NUL-terminated; `master` points to a valid struct whose `step`
/// reads `heard` and writes `*action` only; `options` is null or points to a valid
/// struct whose strings are null or NUL-terminated and whose `not_used` is null or
/// points to `not_used_len` readable bytes; `out` is writable; `error` is null
/// or points to `error_len` writable chars.
#[no_mangle]
pub unsafe extern "C" fn hf_certify_master(
    profile: *const c_char,
    master: *const HfMaster,
    options: *const HfCertifyMasterOptions,
    out: *mut *mut HfReport,
    error: *mut c_char,
    error_len: usize,
) -> HfStatus {
    // SAFETY: the caller's promise.
    if let Err(status) = unsafe { no_report_yet(out) } {
        return status;
    }
    // SAFETY: null or valid by the caller's promise.
    let Some(HfMaster { power_on, step: Some(step), context }) = (unsafe { master.as_ref() }).copied() else {
        return HfStatus::Null;
    };
    // SAFETY: null or valid by the caller's promise.
    let o = unsafe { options.as_ref() }.copied();
    // SAFETY: the caller's promise.
    let profile =
        match unsafe { run_profile(profile, o.map_or(core::ptr::null(), |o| o.profile_toml), error, error_len) } {
            Ok(p) => p,
            Err(status) => return status,
        };
    let mut run = in_process::Options::default();
    let mut name = "master".to_string();
    if let Some(o) = o {
        // SAFETY: null or NUL-terminated by the caller's promise.
        let (Ok(scenarios), Ok(given)) = (unsafe { option_text(o.scenarios) }, unsafe { option_text(o.name) }) else {
            // SAFETY: the caller's promise.
            unsafe { tell(error, error_len, "the scenarios' glob or the name is not UTF-8") };
            return HfStatus::Invalid;
        };
        if let Some(glob) = &scenarios {
            if hiperface_suite::master::scenarios::chosen(Some(glob)).is_empty() {
                // SAFETY: the caller's promise.
                unsafe { tell(error, error_len, format!("no scenario matches `{glob}`")) };
                return HfStatus::Invalid;
            }
        }
        run.scenarios = scenarios;
        if !o.not_used.is_null() {
            // SAFETY: `not_used_len` readable bytes by the caller's promise.
            let bytes = unsafe { core::slice::from_raw_parts(o.not_used, o.not_used_len) };
            for &b in bytes {
                match hiperface_suite::master::command_of(b) {
                    Ok(id) => run.not_used.push(id),
                    Err(e) => {
                        // SAFETY: the caller's promise.
                        unsafe { tell(error, error_len, format!("not_used: {e}")) };
                        return HfStatus::Invalid;
                    }
                }
            }
        }
        if o.polling_period_ms > 0 {
            run.polling_period_ms = o.polling_period_ms;
        }
        name = given.unwrap_or(name);
    }
    let mut under_test = CMaster { power_on, step, context };
    // The master is the caller's for the call only: the run ends before this returns.
    let report = in_process::run(&mut under_test, &name, profile, &run);
    let boxed = Box::new(HfReport { run: Run::Master(Box::new((report, profile))), texts: Default::default() });
    // SAFETY: `out` is writable by the caller's promise.
    unsafe { *out = Box::into_raw(boxed) };
    HfStatus::Ok
}
