//! Certify an encoder written in C in-process (with the `std` feature): the whole slave
//! catalogue in virtual time against a function that answers each request, the same
//! report as `hiperface certify slave` writes (verdicts, clauses, findings, JSON, JUnit,
//! the certificate as Markdown and HTML), in milliseconds. A firmware's unit tests
//! link their protocol code with this and certify it on every build.

use crate::{c_text, profile, tell, HfStatus, HF_CLAUSE_LEN, HF_MAX_FRAME, HF_REASON_LEN};
use crate::{HfFault, HfInputs, HF_ID_LEN};
use core::ffi::{c_char, c_int, c_void, CStr};
use hiperface_model::datalink::{ReceivedFrame, RxChar};
use hiperface_model::{Frame, Profile, UartFault, UartSettings};
use hiperface_suite::line::frame_encoder::Answer;
use hiperface_suite::master::in_process::{self, MasterAction, MasterUnderTest, Transmit};
use hiperface_suite::master::report::MasterCertificate;
use hiperface_suite::master::DriveReport;
use hiperface_suite::profile_file;
use hiperface_suite::report::Reports;
use hiperface_suite::slave::{self, CaseResult, CaseVerdict, Options, Outcome, Report};
use hiperface_suite::world::World;
use std::ffi::CString;
use std::path::Path;

/// A request as the encoder under test received it: the characters the character
/// timeout delimited (000:2.2.2), and when. Times are µs on the run's virtual clock.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfHeard {
    /// The first `len` characters (at most [`HF_MAX_FRAME`]).
    pub bytes: [u8; HF_MAX_FRAME],
    pub len: usize,
    /// How many characters the frame had (more than `len` if it overflowed).
    pub char_count: usize,
    /// The first UART fault among them (a character sent in other settings than the
    /// encoder listens with arrives with one, 000:T47).
    pub uart_fault: HfFault,
    /// When its first and last characters were received (the end of their stop bits).
    pub first_us: u64,
    pub last_us: u64,
    /// When it was known whole: the timeout after its last character. Now.
    pub complete_us: u64,
}

/// The encoder's answer to a request. It comes zeroed, with `then_settings` -1.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfAnswer {
    /// The reply's characters; `len` 0 is silence.
    pub reply: [u8; HF_MAX_FRAME],
    pub len: usize,
    /// When the reply's first character starts (its start bit), µs. Not before the
    /// request ended; a conformant encoder waits for the timeout (000:2.2.2) and
    /// starts within the command's response time (000:T8).
    pub start_us: u64,
    /// The settings byte (000:T33) the encoder listens with after this answer (67h; the
    /// default settings kept by a request in the default window, 000:T9; the stored
    /// settings after an Encoder Reset), or -1: unchanged. It is taken up once the
    /// reply is out (at once after silence).
    pub then_settings: i16,
    /// The encoder restarts (Encoder Reset, 000:T29): from the answer's end its UART
    /// follows the power-up windows of the profile (000:T9): not listening during the
    /// initialization, the default settings in the default window, none while it
    /// changes them, then `then_settings` (the stored ones; -1: the profile's). An
    /// answer that sets `then_settings` ends the windows: the answer to a request in
    /// the default window sets the default settings (E4h) to keep them.
    pub restarts: bool,
}

/// The encoder under test: answer `heard` into `answer`. `context` is the pointer given
/// to [`hf_certify`].
pub type HfEncoderFn = Option<unsafe extern "C" fn(context: *mut c_void, heard: *const HfHeard, answer: *mut HfAnswer)>;

/// What [`hf_certify`] may do; a zeroed struct (or null) runs every case.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfCertifyOptions {
    /// The encoder's profile as TOML text (the format of `hiperface export-profile`),
    /// NUL-terminated; null: the built-in profile named in the call.
    pub profile_toml: *const c_char,
    /// Only the cases whose id matches this glob (`*`, `?`, `{a,b}`, comma-separated
    /// alternatives, `!` to leave out: the command line's `--cases`); null: all.
    pub cases: *const c_char,
    /// Leave out the cases that write EEPROM (restored after each) ...
    pub skip_writes: bool,
    /// ... and those that change the counter (not restorable). An encoder in a unit
    /// test has nothing to lose: by default both run.
    pub skip_counter_change: bool,
    /// The world the caller put the encoder in; null: its own, which the run does not
    /// know (values of the physical world graded by range, as on a real device).
    pub world: *const HfWorld,
}

/// The world an encoder under test was put in for the run, so that the run grades
/// against the same one: every value exactly, the warning bit and the error stack's
/// codes included (a temperature outside the profile's limits raises 1Eh before
/// every reply, 000:T59; a start-up fault is found at power-up, 000:T38-T46).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfWorld {
    /// Its physical inputs; null: the defaults (25 °C, 10 mA, the shaft at 0 and at
    /// rest).
    pub inputs: *const HfInputs,
    /// The faults it found at start-up, comma-separated, by the names of `hiperface
    /// simulate --init-fault` (`alignment-data`, `angular-offset`, `partition-table`,
    /// `analog-limits`, `type-code`, `watchdog`, `counter`, `extended-type-label`,
    /// `multiturn-parameters`); null or empty: none.
    pub init_faults: *const c_char,
    /// Faults of its position measurement while the run lasts, likewise
    /// (`analog-signals`, `analog-monitoring`, `singleturn`, `multiturn-amplitude`,
    /// `multiturn-sync`, `multiturn-vector-length`, `multiturn-counter`).
    pub position_faults: *const c_char,
    /// Its internal I2C bus is down (000:T43).
    pub i2c_fault: bool,
}

/// Why the world a caller gave cannot be read.
#[derive(Debug)]
enum WorldError {
    /// A list of fault names is not UTF-8; `what` names the list.
    NotUtf8 { what: &'static str },
    /// A name no fault of its kind has.
    Unknown(hiperface_suite::world::UnknownFault),
}

impl core::fmt::Display for WorldError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            WorldError::NotUtf8 { what } => write!(f, "the world's {what} are not UTF-8"),
            WorldError::Unknown(e) => e.fmt(f),
        }
    }
}

/// The world `w` points to, read; why not in the error.
///
/// # Safety
/// `w` is null or points to a valid [`HfWorld`] whose pointers are null or valid
/// (`inputs` readable, the strings NUL-terminated).
unsafe fn read_world(w: *const HfWorld) -> Result<World, WorldError> {
    // SAFETY: the caller's promise.
    let Some(w) = (unsafe { w.as_ref() }) else { return Ok(World::default()) };
    // SAFETY: the caller's promise.
    let inputs = unsafe { w.inputs.as_ref() }.map(|i| (*i).into());
    // SAFETY: null or NUL-terminated by the caller's promise.
    let names = |p: *const c_char, what: &'static str| -> Result<Vec<String>, WorldError> {
        if p.is_null() {
            return Ok(Vec::new());
        }
        // SAFETY: not null, NUL-terminated by the caller's promise.
        let text = unsafe { CStr::from_ptr(p) }.to_str().map_err(|_| WorldError::NotUtf8 { what })?;
        Ok(text.split(',').map(str::trim).filter(|n| !n.is_empty()).map(str::to_string).collect())
    };
    let init = names(w.init_faults, "start-up faults")?;
    let position = names(w.position_faults, "position faults")?;
    World::from_names(inputs, init.iter().map(String::as_str), position.iter().map(String::as_str), w.i2c_fault)
        .map_err(WorldError::Unknown)
}

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
    run: Run,
    /// The forms asked for, kept until the report is freed.
    texts: [std::cell::OnceCell<CString>; 4],
}

/// What was certified.
enum Run {
    Encoder(Box<Report>),
    /// A master's report, and the encoder's profile its certificate names.
    Master(Box<(DriveReport, Profile)>),
}

impl Run {
    fn outcome(&self) -> Outcome {
        match self {
            Run::Encoder(r) => r.outcome(),
            Run::Master(m) => m.0.outcome(),
        }
    }

    /// The cases of an encoder's run, the scenarios of a master's.
    fn cases(&self) -> &[CaseResult] {
        match self {
            Run::Encoder(r) => &r.cases,
            Run::Master(m) => &m.0.scenarios,
        }
    }

    fn text(&self, form: c_int) -> String {
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

fn case_verdict(v: CaseVerdict) -> HfCaseVerdict {
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

fn hf_fault(f: Option<UartFault>) -> HfFault {
    match f {
        None => HfFault::None,
        Some(UartFault::Parity) => HfFault::Parity,
        Some(UartFault::Framing) => HfFault::Framing,
        Some(UartFault::Noise) => HfFault::Noise,
        Some(UartFault::Overrun) => HfFault::Overrun,
    }
}

/// The C function as a frame encoder.
struct CEncoder {
    answer: unsafe extern "C" fn(*mut c_void, *const HfHeard, *mut HfAnswer),
    context: *mut c_void,
}

impl CEncoder {
    fn answer(&mut self, f: &ReceivedFrame) -> Answer {
        let kept = f.bytes.as_bytes();
        let mut heard = HfHeard {
            bytes: [0; HF_MAX_FRAME],
            len: kept.len(),
            char_count: f.char_count,
            uart_fault: hf_fault(f.uart_fault),
            first_us: f.first_us,
            last_us: f.last_us,
            complete_us: f.complete_us,
        };
        heard.bytes[..kept.len()].copy_from_slice(kept);
        let mut a = HfAnswer { reply: [0; HF_MAX_FRAME], len: 0, start_us: 0, then_settings: -1, restarts: false };
        // SAFETY: the caller of hf_certify promised a function that takes these two
        // pointers (valid for the call) and its context.
        unsafe { (self.answer)(self.context, &heard, &mut a) };
        // Settings that do not exist (000:T33) are no change of what it listens with.
        let then_settings = u8::try_from(a.then_settings).ok().and_then(|b| UartSettings::decode(b).ok());
        let reply = a.reply.get(..a.len.min(HF_MAX_FRAME)).filter(|r| !r.is_empty());
        Answer {
            reply: reply.and_then(|r| Frame::from_bytes(r).ok()),
            start_us: a.start_us,
            then_settings,
            restarts: a.restarts,
        }
    }
}

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

/// Certify the encoder `encoder` (called with `context` for each request) with the
/// whole slave catalogue, in virtual time, against the built-in profile named
/// `profile` (or the TOML text in `options->profile_toml`). The report is the same as
/// the command's; `*out` holds it until [`hf_report_free`] (null where no report was
/// made). A profile that does not load or a bad glob: `HF_STATUS_UNKNOWN_PROFILE` or
/// `HF_STATUS_INVALID`, with why in `error` (`error_len` chars; may be null).
///
/// Physical values (the position, the temperature) are graded by range, as on a real
/// device: the encoder's world is its own and the run does not know it, unless
/// `options->world` gives it (then every value is graded exactly). A data field
/// the run creates and reads before writing is expected to hold FFh, erased EEPROM
/// (the project's decision DESIGN:fields, not a rule of 000): other bytes there are
/// NON-STRICT, never FAIL.
///
/// The encoder is handed each request once the character timeout after its last
/// character has passed (000:2.2.2), as a slave's UART driver finds it; it listens
/// from the start in the profile's stored settings, already past its power-up.
///
/// # Safety
/// `profile` is null or NUL-terminated; `encoder` is a function that reads `*heard`
/// and writes `*answer` only; `options` is null or points to a valid struct whose
/// strings are null or NUL-terminated; `out` is writable; `error` is null or points
/// to `error_len` writable chars.
#[no_mangle]
pub unsafe extern "C" fn hf_certify(
    profile: *const c_char,
    encoder: HfEncoderFn,
    context: *mut c_void,
    options: *const HfCertifyOptions,
    out: *mut *mut HfReport,
    error: *mut c_char,
    error_len: usize,
) -> HfStatus {
    // SAFETY: the caller's promise.
    if let Err(status) = unsafe { no_report_yet(out) } {
        return status;
    }
    let Some(answer) = encoder else { return HfStatus::Null };
    // SAFETY: null or valid by the caller's promise.
    let o = unsafe { options.as_ref() }.copied();
    // SAFETY: the caller's promise.
    let profile =
        match unsafe { run_profile(profile, o.map_or(core::ptr::null(), |o| o.profile_toml), error, error_len) } {
            Ok(p) => p,
            Err(status) => return status,
        };
    let mut run = Options::all_allowed();
    if let Some(o) = o {
        run.allow_writes = !o.skip_writes;
        run.allow_counter_change = !o.skip_counter_change;
        if !o.cases.is_null() {
            // SAFETY: not null, NUL-terminated by the caller's promise.
            let Ok(glob) = unsafe { CStr::from_ptr(o.cases) }.to_str() else {
                // SAFETY: the caller's promise.
                unsafe { tell(error, error_len, "the cases' glob is not UTF-8") };
                return HfStatus::Invalid;
            };
            if let Err(none) = slave::check_selection(glob) {
                // SAFETY: the caller's promise.
                unsafe { tell(error, error_len, none) };
                return HfStatus::Invalid;
            }
            run.cases = Some(glob.to_string());
        }
        // SAFETY: the caller's promise.
        match unsafe { read_world(o.world) } {
            Ok(world) => run.world = world,
            Err(why) => {
                // SAFETY: the caller's promise.
                unsafe { tell(error, error_len, why) };
                return HfStatus::Invalid;
            }
        }
    }
    let mut encoder = CEncoder { answer, context };
    // The encoder is the caller's for the call only: the run ends before this returns.
    let report = slave::in_process(move |f: &ReceivedFrame| encoder.answer(f), profile, &run);
    let boxed = Box::new(HfReport { run: Run::Encoder(Box::new(report)), texts: Default::default() });
    // SAFETY: `out` is writable by the caller's promise.
    unsafe { *out = Box::into_raw(boxed) };
    HfStatus::Ok
}

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
struct CMaster {
    power_on: Option<unsafe extern "C" fn(*mut c_void)>,
    step: unsafe extern "C" fn(*mut c_void, u64, *const HfHeardChar, usize, *mut HfMasterAction),
    context: *mut c_void,
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
unsafe fn option_text(text: *const c_char) -> Result<Option<String>, ()> {
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
const fn hf_outcome(o: Outcome) -> HfOutcome {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::names::{hf_fault_name, hf_verdict_name};
    use hiperface_model::Verdict;
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
