//! An encoder written in C certified: the request as it heard it, its answer, the
//! world it lives in, the whole slave catalogue run against it ([`hf_certify`]).

use super::report::{HfReport, Run};
use super::{no_report_yet, run_profile};
use crate::{tell, HfStatus, HF_MAX_FRAME};
use crate::{HfFault, HfInputs};
use core::ffi::{c_char, c_void, CStr};
use hiperface_model::datalink::ReceivedFrame;
use hiperface_model::{Frame, UartFault, UartSettings};
use hiperface_suite::line::frame_encoder::Answer;
use hiperface_suite::slave::{self, Options};
use hiperface_suite::world::World;

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
pub(super) enum WorldError {
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
pub(super) unsafe fn read_world(w: *const HfWorld) -> Result<World, WorldError> {
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

pub(super) fn hf_fault(f: Option<UartFault>) -> HfFault {
    match f {
        None => HfFault::None,
        Some(UartFault::Parity) => HfFault::Parity,
        Some(UartFault::Framing) => HfFault::Framing,
        Some(UartFault::Noise) => HfFault::Noise,
        Some(UartFault::Overrun) => HfFault::Overrun,
    }
}

/// The C function as a frame encoder.
pub(super) struct CEncoder {
    pub(super) answer: unsafe extern "C" fn(*mut c_void, *const HfHeard, *mut HfAnswer),
    pub(super) context: *mut c_void,
}

impl CEncoder {
    pub(super) fn answer(&mut self, f: &ReceivedFrame) -> Answer {
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
