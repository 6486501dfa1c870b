//! A slave of a profile written as TOML (with the `std` feature): the encoder a
//! firmware team describes in the same file `hiperface --profile` reads.

use crate::{boxed_or_placed, tell, HfSlave, HfStatus};
use core::ffi::{c_char, c_void, CStr};
use hiperface_model::Slave;
use hiperface_suite::profile_file;
use std::path::Path;

/// An operational slave of the profile in the TOML text `toml` (the format of
/// `hiperface export-profile`), in `storage` as [`hf_slave_init`](crate::hf_slave_init)
/// places one, or on the heap (to free with [`hf_slave_free`](crate::hf_slave_free))
/// where `storage` is null. A profile that does not load: `HF_STATUS_INVALID`, with the
/// line, the field and why in `error` (`error_len` chars; may be null).
///
/// # Safety
/// `toml` is a NUL-terminated string; `storage` is null or points to `size` writable
/// bytes that outlive the slave; `out` is writable; `error` is null or points to
/// `error_len` writable chars.
#[no_mangle]
pub unsafe extern "C" fn hf_slave_from_toml(
    toml: *const c_char,
    storage: *mut c_void,
    size: usize,
    out: *mut *mut HfSlave,
    error: *mut c_char,
    error_len: usize,
) -> HfStatus {
    if toml.is_null() || out.is_null() {
        return HfStatus::Null;
    }
    // SAFETY: not null, NUL-terminated by the caller's promise.
    let Ok(text) = (unsafe { CStr::from_ptr(toml) }).to_str() else {
        // SAFETY: the caller's promise.
        unsafe { tell(error, error_len, "the profile is not UTF-8 text") };
        return HfStatus::Invalid;
    };
    match profile_file::parse(text, Path::new("profile")) {
        // SAFETY: the caller's promise.
        Ok(p) => unsafe { boxed_or_placed(storage, size, Slave::operational(p), out) },
        Err(e) => {
            // SAFETY: the caller's promise.
            unsafe { tell(error, error_len, e) };
            HfStatus::Invalid
        }
    }
}
