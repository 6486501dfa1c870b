//! The names of the API's enums, for messages and logs: what C cannot print of an enum
//! by itself. Each takes the value as an `int`, so that a value outside the enum (read
//! from a file, a cast) is answered with "?" rather than being undefined behaviour.

use super::{HfFault, HfStatus, HfVerdict};
use core::ffi::{c_char, c_int, CStr};

/// The name of `value` in `names`, or "?".
pub(crate) fn name(names: &[(c_int, &'static CStr)], value: c_int) -> *const c_char {
    names.iter().find(|(v, _)| *v == value).map_or(c"?", |(_, n)| n).as_ptr()
}

/// The name of an [`HfStatus`] as the header spells its constant without the prefix
/// ("OK", "NULL", "SHORT_BUFFER", "INVALID", "UNKNOWN_PROFILE", "NOTHING"); "?" for
/// any other value. A static NUL-terminated string: never freed.
#[no_mangle]
pub extern "C" fn hf_status_name(status: c_int) -> *const c_char {
    name(
        &[
            (HfStatus::Ok as c_int, c"OK"),
            (HfStatus::Null as c_int, c"NULL"),
            (HfStatus::ShortBuffer as c_int, c"SHORT_BUFFER"),
            (HfStatus::Invalid as c_int, c"INVALID"),
            (HfStatus::UnknownProfile as c_int, c"UNKNOWN_PROFILE"),
            (HfStatus::Nothing as c_int, c"NOTHING"),
        ],
        status,
    )
}

/// The name of an [`HfVerdict`] as the reports write it ("PASS", "NON-STRICT",
/// "FAIL"); "?" for any other value. A static NUL-terminated string: never freed.
#[no_mangle]
pub extern "C" fn hf_verdict_name(verdict: c_int) -> *const c_char {
    name(
        &[
            (HfVerdict::Pass as c_int, c"PASS"),
            (HfVerdict::NonStrict as c_int, c"NON-STRICT"),
            (HfVerdict::Fail as c_int, c"FAIL"),
        ],
        verdict,
    )
}

/// The name of an [`HfFault`] ("NONE", "PARITY", "FRAMING", "NOISE", "OVERRUN",
/// 000:T47); "?" for any other value. A static NUL-terminated string: never freed.
#[no_mangle]
pub extern "C" fn hf_fault_name(fault: c_int) -> *const c_char {
    name(
        &[
            (HfFault::None as c_int, c"NONE"),
            (HfFault::Parity as c_int, c"PARITY"),
            (HfFault::Framing as c_int, c"FRAMING"),
            (HfFault::Noise as c_int, c"NOISE"),
            (HfFault::Overrun as c_int, c"OVERRUN"),
        ],
        fault,
    )
}
