//! The golden vectors from C (with the `std` feature): a vector file read and checked
//! against its schema, and for each vector what a C test suite needs to replay it
//! through this API as `hiperface vectors verify` replays it: the slave of its setup,
//! its steps (request, the device's reply, the verdict that reply earns), its checksum
//! example or its printed table row.

use crate::{boxed_or_placed, c_text, tell, HfInputs, HfSlave, HfStatus, HfVerdict, HF_MAX_FRAME};
use core::ffi::{c_char, c_void, CStr};
use hiperface_suite::vectors::{self, parse_hex, tables, Expected, Vector};
use std::path::Path;

/// Room for a vector's id in [`HfVector`], with its NUL.
pub const HF_ID_LEN: usize = 96;
/// Room for a profile's name, with its NUL.
pub const HF_NAME_LEN: usize = 32;
/// Room for a table row's text (its input, its printed output), with its NUL.
pub const HF_TEXT_LEN: usize = 192;

/// [`HfVectorStep::inputs_set`]: the step sets the position.
pub const HF_INPUT_POSITION: u8 = 1;
/// ... the speed.
pub const HF_INPUT_SPEED: u8 = 2;
/// ... the temperature.
pub const HF_INPUT_TEMPERATURE: u8 = 4;
/// ... the LED current.
pub const HF_INPUT_LED_CURRENT: u8 = 8;

/// The vectors of one file. Opaque to C.
pub struct HfVectors {
    vectors: Vec<Vector>,
}

/// What a vector holds.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HfVectorKind {
    /// Steps of request and reply, from the slave of its setup ([`hf_vector_start`],
    /// [`hf_vector_step`]).
    Steps = 0,
    /// A frame and its printed checksum ([`hf_vector_checksum_example`]).
    ChecksumExample = 1,
    /// A row of a master-side table ([`hf_vector_table_case`]).
    TableCase = 2,
}

/// The name of an [`HfVectorKind`] ("STEPS", "CHECKSUM_EXAMPLE", "TABLE_CASE"); "?"
/// for any other value. A static NUL-terminated string: never freed.
#[no_mangle]
pub extern "C" fn hf_vector_kind_name(kind: core::ffi::c_int) -> *const c_char {
    crate::names::name(
        &[
            (HfVectorKind::Steps as core::ffi::c_int, c"STEPS"),
            (HfVectorKind::ChecksumExample as core::ffi::c_int, c"CHECKSUM_EXAMPLE"),
            (HfVectorKind::TableCase as core::ffi::c_int, c"TABLE_CASE"),
        ],
        kind,
    )
}

/// A vector's header.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfVector {
    /// NUL-terminated, e.g. "001-5.1.4-example-01".
    pub id: [c_char; HF_ID_LEN],
    /// The built-in profile its slave is (NUL-terminated).
    pub profile: [c_char; HF_NAME_LEN],
    pub kind: HfVectorKind,
    /// How many steps (0 unless `kind` is steps).
    pub steps: usize,
    /// The verdict its last step's reply earns (every earlier step's: PASS); for a
    /// checksum example or a table row, PASS if the printed value is right, FAIL if it
    /// is printed wrong (an erratum).
    pub expected: HfVerdict,
}

/// One step of a vector.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfVectorStep {
    /// When the request's frame ended, µs after power-on (0 for a slave long
    /// operational).
    pub at_us: u64,
    /// Which of `inputs` the step sets before its request ([`HF_INPUT_POSITION`] ...);
    /// the others stay as they are.
    pub inputs_set: u8,
    pub inputs: HfInputs,
    /// A character of the request arrives with a UART fault (000:T47).
    pub uart_fault: bool,
    pub request: [u8; HF_MAX_FRAME],
    pub request_len: usize,
    /// false: the device stays silent.
    pub has_reply: bool,
    pub reply: [u8; HF_MAX_FRAME],
    pub reply_len: usize,
}

/// A frame and the checksum the document prints for it.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfChecksumExample {
    pub frame: [u8; HF_MAX_FRAME],
    pub frame_len: usize,
    pub printed: u8,
}

/// A printed row of a master-side table (000 chapter 3), in the document's words.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HfTableCase {
    /// "quadrature", "sync", "octant", "transformation", "retransformation",
    /// "fault-reaction" (NUL-terminated).
    pub table: [c_char; HF_NAME_LEN],
    pub input: [c_char; HF_TEXT_LEN],
    /// What the document prints (NUL-terminated).
    pub output: [c_char; HF_TEXT_LEN],
}

/// # Safety
/// `s` is null or a NUL-terminated string.
unsafe fn text<'a>(s: *const c_char) -> Result<&'a str, HfStatus> {
    if s.is_null() {
        return Err(HfStatus::Null);
    }
    // SAFETY: not null, NUL-terminated by the caller's promise.
    unsafe { CStr::from_ptr(s) }.to_str().map_err(|_| HfStatus::Invalid)
}

/// Read the vector file at `path` (checked against the vectors' JSON schema); `out`
/// gets the vectors, to free with [`hf_vectors_free`]. A file that cannot be read or
/// is not a vector file: `HF_STATUS_INVALID`, with why in `error` (`error_len`
/// chars; may be null).
///
/// # Safety
/// `path` is a NUL-terminated string; `out` is writable; `error` is null or points to
/// `error_len` writable chars.
#[no_mangle]
pub unsafe extern "C" fn hf_vectors_load(
    path: *const c_char,
    out: *mut *mut HfVectors,
    error: *mut c_char,
    error_len: usize,
) -> HfStatus {
    // SAFETY: the caller's promise.
    let path = match unsafe { text(path) } {
        Ok(p) => p,
        Err(e) => return e,
    };
    if out.is_null() {
        return HfStatus::Null;
    }
    match vectors::load(Path::new(path)) {
        Ok(file) => {
            // SAFETY: not null, writable by the caller's promise.
            unsafe { *out = Box::into_raw(Box::new(HfVectors { vectors: file.vectors })) };
            HfStatus::Ok
        }
        Err(e) => {
            // SAFETY: the caller's promise.
            unsafe { tell(error, error_len, e) };
            HfStatus::Invalid
        }
    }
}

/// Free vectors from [`hf_vectors_load`] (null: nothing to do).
///
/// # Safety
/// `vectors` is null or from `hf_vectors_load`, and not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn hf_vectors_free(vectors: *mut HfVectors) {
    if !vectors.is_null() {
        // SAFETY: made by hf_vectors_load (Box::into_raw), freed once by the caller's promise.
        drop(unsafe { Box::from_raw(vectors) });
    }
}

/// How many vectors the file holds (0 for null).
///
/// # Safety
/// `vectors` is null or from [`hf_vectors_load`].
#[no_mangle]
pub unsafe extern "C" fn hf_vectors_count(vectors: *const HfVectors) -> usize {
    // SAFETY: the caller's promise.
    unsafe { vectors.as_ref() }.map_or(0, |v| v.vectors.len())
}

/// The vector at `index`, or the status to return.
///
/// # Safety
/// `vectors` is null or from [`hf_vectors_load`].
unsafe fn vector<'a>(vectors: *const HfVectors, index: usize) -> Result<&'a Vector, HfStatus> {
    // SAFETY: the caller's promise.
    let v = unsafe { vectors.as_ref() }.ok_or(HfStatus::Null)?;
    v.vectors.get(index).ok_or(HfStatus::Invalid)
}

fn verdict(e: Expected) -> HfVerdict {
    match e {
        Expected::Valid => HfVerdict::Pass,
        Expected::Acceptable => HfVerdict::NonStrict,
        Expected::Invalid => HfVerdict::Fail,
    }
}

/// The header of vector `index` into `out`. `HF_STATUS_INVALID` for an index past the
/// end, `HF_STATUS_SHORT_BUFFER` for an id or profile name too long for its field.
///
/// # Safety
/// `vectors` is null or from [`hf_vectors_load`]; `out` is writable.
#[no_mangle]
pub unsafe extern "C" fn hf_vector_get(vectors: *const HfVectors, index: usize, out: *mut HfVector) -> HfStatus {
    // SAFETY: the caller's promise.
    let v = match unsafe { vector(vectors, index) } {
        Ok(v) => v,
        Err(e) => return e,
    };
    if out.is_null() {
        return HfStatus::Null;
    }
    let kind = match (&v.checksum_example, &v.table_case) {
        (Some(_), _) => HfVectorKind::ChecksumExample,
        (None, Some(_)) => HfVectorKind::TableCase,
        (None, None) => HfVectorKind::Steps,
    };
    let mut h = HfVector {
        id: [0; HF_ID_LEN],
        profile: [0; HF_NAME_LEN],
        kind,
        steps: if kind == HfVectorKind::Steps { v.steps.len() } else { 0 },
        expected: verdict(v.result),
    };
    if !c_text(&mut h.id, &v.id) || !c_text(&mut h.profile, &v.profile) {
        return HfStatus::ShortBuffer;
    }
    // SAFETY: not null, writable by the caller's promise.
    unsafe { *out = h };
    HfStatus::Ok
}

/// The slave of vector `index`'s setup (its profile, power-on or long operational,
/// physical inputs, start-up and position faults, setup requests), in `storage` as
/// [`hf_slave_init`](crate::hf_slave_init) places one, or on the heap (to free with
/// [`hf_slave_free`](crate::hf_slave_free)) where `storage` is null. Grade its steps
/// on it with [`hf_oracle_grade`](crate::hf_oracle_grade). `HF_STATUS_INVALID` for a
/// vector without steps or a setup the model does not know.
///
/// # Safety
/// `vectors` is null or from [`hf_vectors_load`]; `storage` is null or points to `size`
/// writable bytes that outlive the slave; `out` is writable.
#[no_mangle]
pub unsafe extern "C" fn hf_vector_start(
    vectors: *const HfVectors,
    index: usize,
    storage: *mut c_void,
    size: usize,
    out: *mut *mut HfSlave,
) -> HfStatus {
    // SAFETY: the caller's promise.
    let v = match unsafe { vector(vectors, index) } {
        Ok(v) => v,
        Err(e) => return e,
    };
    if out.is_null() {
        return HfStatus::Null;
    }
    if v.steps.is_empty() {
        return HfStatus::Invalid;
    }
    match vectors::prepare(v) {
        // SAFETY: the caller's promise.
        Ok(slave) => unsafe { boxed_or_placed(storage, size, slave, out) },
        Err(_) => HfStatus::Invalid,
    }
}

/// Step `step` (from 0) of vector `index` into `out`. `HF_STATUS_INVALID` past the
/// last step or for a frame that is not hex; `HF_STATUS_SHORT_BUFFER` for a frame
/// longer than [`HF_MAX_FRAME`].
///
/// # Safety
/// `vectors` is null or from [`hf_vectors_load`]; `out` is writable.
#[no_mangle]
pub unsafe extern "C" fn hf_vector_step(
    vectors: *const HfVectors,
    index: usize,
    step: usize,
    out: *mut HfVectorStep,
) -> HfStatus {
    // SAFETY: the caller's promise.
    let v = match unsafe { vector(vectors, index) } {
        Ok(v) => v,
        Err(e) => return e,
    };
    let Some(s) = v.steps.get(step) else { return HfStatus::Invalid };
    if out.is_null() {
        return HfStatus::Null;
    }
    let i = s.inputs.unwrap_or_default();
    let bit = |set: bool, b: u8| if set { b } else { 0 };
    let mut o = HfVectorStep {
        at_us: s.at_us.unwrap_or(0),
        inputs_set: bit(i.position.is_some(), HF_INPUT_POSITION)
            | bit(i.speed.is_some(), HF_INPUT_SPEED)
            | bit(i.temperature_c.is_some(), HF_INPUT_TEMPERATURE)
            | bit(i.led_current_ma.is_some(), HF_INPUT_LED_CURRENT),
        inputs: HfInputs {
            position: i.position.unwrap_or(0),
            speed: i.speed.unwrap_or(0),
            temperature_c: i.temperature_c.unwrap_or(0),
            led_current_ma: i.led_current_ma.unwrap_or(0),
        },
        uart_fault: s.uart_fault,
        request: [0; HF_MAX_FRAME],
        request_len: 0,
        has_reply: s.response.is_some(),
        reply: [0; HF_MAX_FRAME],
        reply_len: 0,
    };
    let Ok(request) = parse_hex(&s.request) else { return HfStatus::Invalid };
    o.request_len = match copy(&request, &mut o.request) {
        Ok(n) => n,
        Err(e) => return e,
    };
    if let Some(r) = &s.response {
        let Ok(reply) = parse_hex(r) else { return HfStatus::Invalid };
        o.reply_len = match copy(&reply, &mut o.reply) {
            Ok(n) => n,
            Err(e) => return e,
        };
    }
    // SAFETY: not null, writable by the caller's promise.
    unsafe { *out = o };
    HfStatus::Ok
}

fn copy(from: &[u8], to: &mut [u8]) -> Result<usize, HfStatus> {
    to.get_mut(..from.len()).ok_or(HfStatus::ShortBuffer)?.copy_from_slice(from);
    Ok(from.len())
}

/// The checksum example of vector `index` into `out`: the frame and the checksum the
/// document prints (000:2.3.3). `HF_STATUS_INVALID` for a vector of another kind.
///
/// # Safety
/// `vectors` is null or from [`hf_vectors_load`]; `out` is writable.
#[no_mangle]
pub unsafe extern "C" fn hf_vector_checksum_example(
    vectors: *const HfVectors,
    index: usize,
    out: *mut HfChecksumExample,
) -> HfStatus {
    // SAFETY: the caller's promise.
    let v = match unsafe { vector(vectors, index) } {
        Ok(v) => v,
        Err(e) => return e,
    };
    let Some(c) = &v.checksum_example else { return HfStatus::Invalid };
    if out.is_null() {
        return HfStatus::Null;
    }
    let (Ok(frame), Ok(printed)) = (parse_hex(&c.frame), parse_hex(&c.checksum)) else { return HfStatus::Invalid };
    let [printed] = printed.as_slice() else { return HfStatus::Invalid };
    let mut o = HfChecksumExample { frame: [0; HF_MAX_FRAME], frame_len: 0, printed: *printed };
    o.frame_len = match copy(&frame, &mut o.frame) {
        Ok(n) => n,
        Err(e) => return e,
    };
    // SAFETY: not null, writable by the caller's promise.
    unsafe { *out = o };
    HfStatus::Ok
}

/// The table row of vector `index` into `out`; answer it with [`hf_table_evaluate`].
/// `HF_STATUS_INVALID` for a vector of another kind.
///
/// # Safety
/// `vectors` is null or from [`hf_vectors_load`]; `out` is writable.
#[no_mangle]
pub unsafe extern "C" fn hf_vector_table_case(
    vectors: *const HfVectors,
    index: usize,
    out: *mut HfTableCase,
) -> HfStatus {
    // SAFETY: the caller's promise.
    let v = match unsafe { vector(vectors, index) } {
        Ok(v) => v,
        Err(e) => return e,
    };
    let Some(t) = &v.table_case else { return HfStatus::Invalid };
    if out.is_null() {
        return HfStatus::Null;
    }
    let mut o = HfTableCase { table: [0; HF_NAME_LEN], input: [0; HF_TEXT_LEN], output: [0; HF_TEXT_LEN] };
    if !(c_text(&mut o.table, &t.table) && c_text(&mut o.input, &t.input) && c_text(&mut o.output, &t.output)) {
        return HfStatus::ShortBuffer;
    }
    // SAFETY: not null, writable by the caller's promise.
    unsafe { *out = o };
    HfStatus::Ok
}

/// The model's answer to a row of a master-side table (000 chapter 3), in the printed
/// table's words: `table` as in [`HfTableCase`], `input` the row's input ("0 1 1 1"
/// for quadrature's A(n-1) B(n-1) A(n) B(n)). The answer (or, with
/// `HF_STATUS_INVALID`, why there is none) goes into `out` (`capacity` chars);
/// `HF_STATUS_SHORT_BUFFER` where it does not fit.
///
/// # Safety
/// `table` and `input` are NUL-terminated strings; `out` points to `capacity` writable
/// chars.
#[no_mangle]
pub unsafe extern "C" fn hf_table_evaluate(
    table: *const c_char,
    input: *const c_char,
    out: *mut c_char,
    capacity: usize,
) -> HfStatus {
    // SAFETY: the caller's promise.
    let (table, input) = match unsafe { (text(table), text(input)) } {
        (Ok(t), Ok(i)) => (t, i),
        (Err(e), _) | (_, Err(e)) => return e,
    };
    if out.is_null() {
        return HfStatus::Null;
    }
    // SAFETY: not null, `capacity` writable chars by the caller's promise.
    let buf = unsafe { core::slice::from_raw_parts_mut(out, capacity) };
    let (status, answer) = match tables::evaluate(table, input) {
        Ok(a) => (HfStatus::Ok, a),
        Err(why) => (HfStatus::Invalid, why.to_string()),
    };
    match c_text(buf, answer) {
        true => status,
        false => HfStatus::ShortBuffer,
    }
}
