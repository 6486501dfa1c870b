//! Certify an encoder written in Python in-process: the whole slave catalogue in
//! virtual time against a callable (or an object with an `answer` method) that is
//! handed each request as the character timeout delimited it (000:2.2.2), and the
//! report as the command writes it. The Python wrapper is `hiperface.certify`.

use crate::{profile_error, Frame, HiperfaceError};
use hiperface_model::datalink::ReceivedFrame;
use hiperface_model::{Frame as WireFrame, UartFault, UartSettings};
use hiperface_suite::slave::{self, Options};
use hiperface_suite::line::frame_encoder::Answer;
use hiperface_suite::profile_file;
use hiperface_suite::report::Reports;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use std::cell::RefCell;
use std::rc::Rc;

/// A request as the encoder under test received it. Times are µs on the run's
/// virtual clock.
#[pyclass(module = "hiperface", frozen, get_all)]
pub struct Heard {
    /// The characters (the first 135 of a frame that overflowed).
    bytes: Py<PyBytes>,
    /// How many characters the frame had.
    char_count: usize,
    /// The first UART fault among them ("parity", "framing", "noise", "overrun"), or
    /// None (000:T47).
    uart_fault: Option<&'static str>,
    /// When its first and last characters were received (the end of their stop bits).
    first_us: u64,
    last_us: u64,
    /// When it was known whole: the timeout after its last character (now).
    complete_us: u64,
}

#[pymethods]
impl Heard {
    fn __repr__(&self, py: Python<'_>) -> String {
        let hex: Vec<String> = self.bytes.as_bytes(py).iter().map(|b| format!("{b:02X}")).collect();
        format!("Heard(bytes=[{}], last_us={}, uart_fault={:?})", hex.join(" "), self.last_us, self.uart_fault)
    }
}

fn fault_name(f: Option<UartFault>) -> Option<&'static str> {
    f.map(|f| match f {
        UartFault::Parity => "parity",
        UartFault::Framing => "framing",
        UartFault::Noise => "noise",
        UartFault::Overrun => "overrun",
    })
}

/// What the encoder returned, as an answer: None (silence), or a tuple `(reply,
/// start_us)` or `(reply, start_us, then_settings)`.
fn answer(returned: &Bound<'_, PyAny>) -> PyResult<Answer> {
    if returned.is_none() {
        return Ok(Answer::SILENT);
    }
    let wrong = || {
        PyTypeError::new_err(
            "an encoder returns None (silence) or (reply, start_us[, then_settings]), reply bytes-like",
        )
    };
    let t = returned.downcast::<PyTuple>().map_err(|_| wrong())?;
    if !(2..=3).contains(&t.len()) {
        return Err(wrong());
    }
    let reply: Frame = t.get_item(0)?.extract()?;
    let start_us: u64 = t.get_item(1)?.extract()?;
    let then_settings = match t.get_item(2).ok().filter(|s| !s.is_none()) {
        None => None,
        Some(s) => {
            let byte: u8 = s.extract()?;
            Some(
                UartSettings::decode(byte)
                    .map_err(|e| PyValueError::new_err(format!("then_settings {byte:#04x}: {e:?}")))?,
            )
        }
    };
    let reply = match reply.0.len() {
        0 => None,
        _ => Some(WireFrame::from_bytes(&reply.0).map_err(|_| PyValueError::new_err("a reply is at most 135 bytes"))?),
    };
    Ok(Answer { reply, start_us, then_settings })
}

/// Certify `encoder` with the whole slave catalogue in virtual time against `profile`
/// (a built-in name or a profile's TOML file); the report as JSON, JUnit, Markdown and
/// HTML text. The first exception the encoder raises ends its answers (silence
/// after it) and is raised when the run is over.
#[pyfunction]
#[pyo3(signature = (encoder, profile="SRS50", *, cases=None, skip_writes=false, skip_counter_change=false))]
pub fn certify_encoder(
    encoder: Bound<'_, PyAny>,
    profile: &str,
    cases: Option<String>,
    skip_writes: bool,
    skip_counter_change: bool,
) -> PyResult<(String, String, String, String)> {
    let profile = profile_file::resolve(profile).map_err(profile_error)?;
    let call = match encoder.getattr("answer") {
        Ok(method) if method.is_callable() => method,
        _ if encoder.is_callable() => encoder,
        _ => return Err(PyTypeError::new_err("an encoder is a callable, or an object with an `answer` method")),
    }
    .unbind();
    if let Some(glob) = &cases {
        slave::check_selection(glob).map_err(|e| PyValueError::new_err(format!("cases: {e}")))?;
    }
    let options = Options {
        cases,
        allow_writes: !skip_writes,
        allow_counter_change: !skip_counter_change,
        ..Options::all_allowed()
    };
    let failed: Rc<RefCell<Option<PyErr>>> = Rc::default();
    let raised = failed.clone();
    let on_frame = move |f: &ReceivedFrame| -> Answer {
        if raised.borrow().is_some() {
            return Answer::SILENT;
        }
        Python::with_gil(|py| {
            let heard = Heard {
                bytes: PyBytes::new(py, f.bytes.as_bytes()).unbind(),
                char_count: f.char_count,
                uart_fault: fault_name(f.uart_fault),
                first_us: f.first_us,
                last_us: f.last_us,
                complete_us: f.complete_us,
            };
            match call.call1(py, (heard,)).and_then(|r| answer(r.bind(py))) {
                Ok(a) => a,
                Err(e) => {
                    *raised.borrow_mut() = Some(e);
                    Answer::SILENT
                }
            }
        })
    };
    let report = slave::in_process(on_frame, profile, &options);
    if let Some(e) = failed.borrow_mut().take() {
        return Err(e);
    }
    let json = report.json().map_err(|e| HiperfaceError::new_err(e.to_string()))?;
    Ok((json, report.junit(), report.markdown(), report.html()))
}
