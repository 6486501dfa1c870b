//! Certify an encoder written in Python in-process: the whole slave catalogue in
//! virtual time against a callable (or an object with an `answer` method) that is
//! handed each request as the character timeout delimited it (000:2.2.2), and the
//! report as the command writes it. The Python wrapper is `hiperface.certify`.

use crate::{profile_error, Frame, HiperfaceError};
use hiperface_model::datalink::{ReceivedFrame, RxChar};
use hiperface_model::master::obligations::POLLING_PERIOD_MS;
use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::{CommandId, Frame as WireFrame, UartFault, UartSettings};
use hiperface_suite::line::frame_encoder::Answer;
use hiperface_suite::master;
use hiperface_suite::master::in_process::{self, MasterAction, MasterUnderTest, Transmit};
use hiperface_suite::master::report::MasterCertificate;
use hiperface_suite::profile_file;
use hiperface_suite::report::Reports;
use hiperface_suite::slave::{self, Options};
use hiperface_suite::world::World;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyTuple};
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
    f.map(UartFault::name)
}

/// The world an encoder was put in, from a dict: `position`, `speed`,
/// `temperature_c`, `led_current_ma` (the physical inputs; those left out at their
/// defaults, 25 °C, 10 mA, the shaft at 0 and at rest), `init_faults`,
/// `position_faults` (lists of names, as `hiperface simulate --init-fault` spells
/// them) and `i2c_fault`. Any other key is an error.
fn read_world(w: &Bound<'_, PyDict>) -> PyResult<World> {
    const KEYS: [&str; 7] =
        ["position", "speed", "temperature_c", "led_current_ma", "init_faults", "position_faults", "i2c_fault"];
    for key in w.keys() {
        let key: String = key.extract()?;
        if !KEYS.contains(&key.as_str()) {
            return Err(PyValueError::new_err(format!("world: unknown key `{key}` (known: {})", KEYS.join(", "))));
        }
    }
    // Each key's value where given, else its default; `given`: any input was.
    fn value<T: for<'py> FromPyObject<'py>>(w: &Bound<'_, PyDict>, key: &str, or: T) -> PyResult<(T, bool)> {
        match w.get_item(key)? {
            Some(v) => Ok((v.extract()?, true)),
            None => Ok((or, false)),
        }
    }
    let d = PhysicalInputs::default();
    let (position, p) = value(w, "position", d.position)?;
    let (speed, s) = value(w, "speed", d.speed)?;
    let (temperature_c, t) = value(w, "temperature_c", d.temperature_c)?;
    let (led_current_ma, l) = value(w, "led_current_ma", d.led_current_ma)?;
    let inputs = PhysicalInputs { position, speed, temperature_c, led_current_ma };
    let given = p || s || t || l;
    let (init, _): (Vec<String>, _) = value(w, "init_faults", Vec::new())?;
    let (position_faults, _): (Vec<String>, _) = value(w, "position_faults", Vec::new())?;
    let (i2c_fault, _) = value(w, "i2c_fault", false)?;
    World::from_names(
        given.then_some(inputs),
        init.iter().map(String::as_str),
        position_faults.iter().map(String::as_str),
        i2c_fault,
    )
    .map_err(|e| PyValueError::new_err(format!("world: {e}")))
}

/// What the encoder returned, as an answer: None (silence), or a tuple `(reply,
/// start_us)`, `(reply, start_us, then_settings)` or `(reply, start_us,
/// then_settings, restarts)`.
fn answer(returned: &Bound<'_, PyAny>) -> PyResult<Answer> {
    if returned.is_none() {
        return Ok(Answer::SILENT);
    }
    let wrong = || {
        PyTypeError::new_err(
            "an encoder returns None (silence) or (reply, start_us[, then_settings[, restarts]]), reply bytes-like",
        )
    };
    let t = returned.downcast::<PyTuple>().map_err(|_| wrong())?;
    if !(2..=4).contains(&t.len()) {
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
    let restarts: bool = match t.get_item(3).ok() {
        Some(r) => r.extract()?,
        None => false,
    };
    let reply = match reply.0.len() {
        0 => None,
        _ => Some(WireFrame::from_bytes(&reply.0).map_err(|_| PyValueError::new_err("a reply is at most 135 bytes"))?),
    };
    Ok(Answer { reply, start_us, then_settings, restarts })
}

/// Certify `encoder` with the whole slave catalogue in virtual time against `profile`
/// (a built-in name or a profile's TOML file); the report as JSON, JUnit, Markdown and
/// HTML text. The first exception the encoder raises ends its answers (silence
/// after it) and is raised when the run is over.
#[pyfunction]
#[pyo3(signature = (encoder, profile="SRS50", *, cases=None, skip_writes=false, skip_counter_change=false, world=None))]
pub fn certify_encoder(
    encoder: Bound<'_, PyAny>,
    profile: &str,
    cases: Option<String>,
    skip_writes: bool,
    skip_counter_change: bool,
    world: Option<Bound<'_, PyDict>>,
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
        world: world.map(|w| read_world(&w)).transpose()?.unwrap_or_default(),
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

/// A master written in Python, as the core's in-process run calls it: `power_on()`
/// (if it has one) before each scenario, `step(now_us, heard)` (or the object itself,
/// if callable) at power-on, when reply characters have reached it and when the time
/// it asked for has come. The first exception ends its actions (nothing after it) and
/// is raised when the run is over.
struct PyMaster {
    object: Py<PyAny>,
    step: Py<PyAny>,
    failed: Option<PyErr>,
}

impl PyMaster {
    fn note(&mut self, e: PyErr) {
        self.failed.get_or_insert(e);
    }
}

/// What a master's `step` returned, as an action: None (nothing new: a wake asked before still
/// stands), an int (called again then), or `(data, start_us)`,
/// `(data, start_us, wake_us)` or `(data, start_us, wake_us, bps)`.
fn master_action(returned: &Bound<'_, PyAny>) -> PyResult<MasterAction> {
    if returned.is_none() {
        return Ok(MasterAction::default());
    }
    if let Ok(wake_us) = returned.extract::<u64>() {
        return Ok(MasterAction { send: None, wake_us: Some(wake_us) });
    }
    let wrong = || {
        PyTypeError::new_err(
            "a master's step returns None, a time to be called again (µs), or (data, start_us[, wake_us[, bps]])",
        )
    };
    let t = returned.downcast::<PyTuple>().map_err(|_| wrong())?;
    if !(2..=4).contains(&t.len()) {
        return Err(wrong());
    }
    let data: Frame = t.get_item(0)?.extract()?;
    let start_us: u64 = t.get_item(1)?.extract()?;
    let wake_us: Option<u64> = match t.get_item(2) {
        Ok(w) if !w.is_none() => Some(w.extract()?),
        _ => None,
    };
    let bps: u32 = match t.get_item(3) {
        Ok(b) if !b.is_none() => b.extract()?,
        _ => 9600,
    };
    if bps == 0 {
        return Err(PyValueError::new_err("bps: a data rate above 0"));
    }
    let send = (!data.0.is_empty()).then_some(Transmit { bytes: data.0, start_us, bps });
    Ok(MasterAction { send, wake_us })
}

impl MasterUnderTest for PyMaster {
    fn power_on(&mut self) {
        if self.failed.is_some() {
            return;
        }
        let done = Python::with_gil(|py| match self.object.bind(py).getattr("power_on") {
            Ok(f) if f.is_callable() => f.call0().map(drop),
            _ => Ok(()),
        });
        if let Err(e) = done {
            self.note(e);
        }
    }

    fn step(&mut self, now_us: u64, heard: &[RxChar]) -> MasterAction {
        if self.failed.is_some() {
            return MasterAction::default();
        }
        let acted = Python::with_gil(|py| {
            let heard: Vec<(u8, u64)> = heard.iter().map(|c| (c.byte, c.at_us)).collect();
            self.step.call1(py, (now_us, heard)).and_then(|r| master_action(r.bind(py)))
        });
        acted.unwrap_or_else(|e| {
            self.note(e);
            MasterAction::default()
        })
    }
}

/// A command a master declares it never sends: its byte (0x4A) or its text ("4Ah").
fn command(given: &Bound<'_, PyAny>) -> PyResult<CommandId> {
    let parsed = match given.extract::<u8>() {
        Ok(byte) => master::command_of(byte),
        Err(_) => master::parse_command(&given.extract::<String>()?),
    };
    parsed.map_err(|e| PyValueError::new_err(format!("not_used: {e}")))
}

/// Certify `master` with the scenario catalogue in virtual time, for an encoder of
/// `profile` (a built-in name or a profile's TOML file); the report as JSON, JUnit,
/// Markdown and HTML text.
#[pyfunction]
#[pyo3(signature = (master, profile="SRS50", *, scenarios=None, polling_period_ms=POLLING_PERIOD_MS, name=None, not_used=None))]
pub fn certify_master_in_process(
    master: Bound<'_, PyAny>,
    profile: &str,
    scenarios: Option<String>,
    polling_period_ms: u32,
    name: Option<String>,
    not_used: Option<Vec<Bound<'_, PyAny>>>,
) -> PyResult<(String, String, String, String)> {
    let profile = profile_file::resolve(profile).map_err(profile_error)?;
    let step = match master.getattr("step") {
        Ok(method) if method.is_callable() => method,
        _ if master.is_callable() => master.clone(),
        _ => return Err(PyTypeError::new_err("a master is a callable, or an object with a `step` method")),
    }
    .unbind();
    if let Some(glob) = &scenarios {
        if hiperface_suite::master::scenarios::chosen(Some(glob)).is_empty() {
            return Err(PyValueError::new_err(format!("scenarios: no scenario matches `{glob}`")));
        }
    }
    if polling_period_ms == 0 {
        return Err(PyValueError::new_err("polling_period_ms: at least 1"));
    }
    let name = match name {
        Some(n) => n,
        None => master.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "master".into()),
    };
    let not_used = not_used.unwrap_or_default().iter().map(command).collect::<PyResult<Vec<_>>>()?;
    let mut under_test = PyMaster { object: master.unbind(), step, failed: None };
    let options = in_process::Options { scenarios, polling_period_ms, not_used };
    let report = in_process::run(&mut under_test, &name, profile, &options);
    if let Some(e) = under_test.failed.take() {
        return Err(e);
    }
    let certificate = MasterCertificate { report: &report, profile: &profile };
    let json = certificate.json().map_err(|e| HiperfaceError::new_err(e.to_string()))?;
    Ok((json, certificate.junit(), certificate.markdown(), certificate.html()))
}
