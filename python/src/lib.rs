//! `hiperface._hiperface`: the model and its oracle for Python test benches. The
//! package `hiperface` (python/hiperface) re-exports it with typing stubs and adds the
//! certification report reader.
//!
//! Long because: a PyO3 module is one file of bindings, each class or function a thin
//! wrapper of the model; the certification is in certify.rs.

use hiperface_model::checksum::{is_valid as xor_is_zero, xor};
use hiperface_model::{Grading, Oracle as ModelOracle, RequestFrame, RxChar, Step, UartFault};
use hiperface_suite::capture::Format;
use hiperface_suite::listen::decode::{grade_capture, DecodeOptions};
use hiperface_suite::verdict::CaseVerdict;
use hiperface_suite::{profile_file, vectors};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyFileNotFoundError, PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyMemoryView, PyTuple};
use std::path::Path;

mod certify;

create_exception!(_hiperface, HiperfaceError, PyException, "An error of the hiperface package.");
create_exception!(
    _hiperface,
    MalformedRequest,
    HiperfaceError,
    "A request a slave refuses: args are (message, fault code) with the code a slave answers \
     (0x0A checksum, 0x0B unknown command, 0x0C too short or wrong length; 000:2.3.3, 000:T48-T49)."
);
create_exception!(
    _hiperface,
    ProfileError,
    HiperfaceError,
    "A profile that cannot be loaded: the file, line and field."
);

/// Any bytes-like object a test bench holds a frame in: `bytes`, `bytearray` or a
/// `memoryview` (copied: frames are short). Anything else is a `TypeError`.
pub(crate) struct Frame(pub(crate) Vec<u8>);

impl<'py> FromPyObject<'py> for Frame {
    fn extract_bound(ob: &Bound<'py, PyAny>) -> PyResult<Self> {
        if let Ok(b) = ob.downcast::<PyBytes>() {
            return Ok(Frame(b.as_bytes().to_vec()));
        }
        if let Ok(b) = ob.downcast::<PyByteArray>() {
            return Ok(Frame(b.to_vec()));
        }
        if ob.is_instance_of::<PyMemoryView>() {
            let copy = ob.call_method0("tobytes")?;
            return Ok(Frame(copy.downcast::<PyBytes>()?.as_bytes().to_vec()));
        }
        let name = ob.get_type().name().map(|n| n.to_string()).unwrap_or_default();
        Err(PyTypeError::new_err(format!("a bytes-like object (bytes, bytearray, memoryview) is required, not {name}")))
    }
}

/// A file that could not be read: `FileNotFoundError` where it is missing (as
/// `open` raises), another `OSError` for other reasons of the system.
fn io_error(e: &std::io::Error, message: String) -> PyErr {
    match e.kind() {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

pub(crate) fn profile_error(e: profile_file::ProfileLoadError) -> PyErr {
    match &e {
        profile_file::ProfileLoadError::Io { source, .. } => io_error(source, e.to_string()),
        _ => ProfileError::new_err(e.to_string()),
    }
}

fn vectors_error(e: vectors::LoadError) -> PyErr {
    match &e {
        vectors::LoadError::Io { source, .. } => io_error(source, e.to_string()),
        _ => HiperfaceError::new_err(e.to_string()),
    }
}

/// The XOR checksum of `data` (000:2.3.3).
#[pyfunction]
fn checksum(data: Frame) -> u8 {
    xor(&data.0)
}

/// `frame` with its checksum appended (000:2.3.3).
#[pyfunction]
fn seal<'py>(py: Python<'py>, frame: Frame) -> Bound<'py, PyBytes> {
    let mut sealed = frame.0;
    sealed.push(xor(&sealed));
    PyBytes::new(py, &sealed)
}

/// Whether `frame` (checksum included, 2 bytes or more) XORs to 0 (000:2.3.3).
#[pyfunction]
fn is_valid(frame: Frame) -> bool {
    frame.0.len() >= 2 && xor_is_zero(&frame.0)
}

/// A decoded request.
#[pyclass(module = "hiperface", frozen, get_all)]
struct Request {
    /// The address byte as sent (0x40...0x5F, 0xFF broadcast: 000:T5).
    address: u8,
    /// The command byte.
    command: u8,
    /// The data bytes between command byte and checksum.
    data: Py<PyBytes>,
}

#[pymethods]
impl Request {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Request(address=0x{:02X}, command=0x{:02X}, data={:02X?})",
            self.address,
            self.command,
            self.data.as_bytes(py)
        )
    }
}

/// Decode a request; raises `MalformedRequest(message, code)` for one a slave refuses.
#[pyfunction]
fn decode_request(py: Python<'_>, frame: Frame) -> PyResult<Request> {
    let frame = frame.0.as_slice();
    match RequestFrame::decode(frame) {
        Ok(rf) => Ok(Request {
            address: rf.address.byte(),
            command: rf.request.command().byte(),
            data: PyBytes::new(py, frame.get(2..frame.len().saturating_sub(1)).unwrap_or(&[])).unbind(),
        }),
        Err(e) => Err(MalformedRequest::new_err((e.to_string(), e.fault_code().byte()))),
    }
}

/// What the slave sends, and when (µs on the slave's clock).
#[pyclass(module = "hiperface", frozen, get_all)]
struct Transmission {
    frame: Py<PyBytes>,
    /// The first character may start once the request's timeout has passed (000:2.2.2)...
    earliest_start_us: u64,
    /// ...and must start by the command's maximum response time (000:T8).
    latest_start_us: u64,
}

#[pymethods]
impl Transmission {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Transmission(frame={:02X?}, earliest_start_us={}, latest_start_us={})",
            self.frame.as_bytes(py),
            self.earliest_start_us,
            self.latest_start_us
        )
    }
}

/// The reference model of an encoder: fed the master's characters with their time,
/// it says what to send and when.
#[pyclass(module = "hiperface")]
struct Slave {
    slave: hiperface_model::Slave,
    /// A frame the last character closed, for the next `poll`.
    pending: Option<Step>,
}

fn uart_fault(fault: Option<&str>) -> PyResult<Option<UartFault>> {
    let Some(name) = fault else { return Ok(None) };
    UartFault::from_name(name).map(Some).ok_or_else(|| {
        let known: Vec<String> = UartFault::ALL.iter().map(|f| format!("{:?}", f.name())).collect();
        PyValueError::new_err(format!("fault `{name}`: expected None, {}", known.join(", ")))
    })
}

fn transmission(py: Python<'_>, step: &Step) -> Option<Transmission> {
    let tx = step.transmission.as_ref()?;
    Some(Transmission {
        frame: PyBytes::new(py, tx.frame.as_bytes()).unbind(),
        earliest_start_us: tx.earliest_start_us,
        latest_start_us: tx.latest_start_us,
    })
}

#[pymethods]
impl Slave {
    /// An operational slave of `profile`: a built-in name ("SRS50", ...) or the path
    /// of a profile's TOML file. Raises `ProfileError` naming the file, line and field.
    #[new]
    fn new(profile: &str) -> PyResult<Slave> {
        let p = profile_file::resolve(profile).map_err(profile_error)?;
        Ok(Slave { slave: hiperface_model::Slave::operational(p), pending: None })
    }

    /// A character from the master, its stop bit ending at `at_us`, with its UART
    /// fault (000:T47). Call `poll` after each character.
    #[pyo3(signature = (byte, at_us, fault=None))]
    fn receive(&mut self, byte: u8, at_us: u64, fault: Option<&str>) -> PyResult<()> {
        let fault = uart_fault(fault)?;
        if let Some(step) = self.slave.receive(RxChar { byte, at_us, fault }) {
            self.pending = Some(step);
        }
        Ok(())
    }

    /// What the slave sends by `now_us`, or None (nothing ended, or it stays silent).
    fn poll(&mut self, py: Python<'_>, now_us: u64) -> Option<Transmission> {
        let step = self.pending.take().or_else(|| self.slave.poll(now_us))?;
        transmission(py, &step)
    }

    /// The reply to a whole frame ended at `at_us`, or None for silence.
    fn handle_frame<'py>(&mut self, py: Python<'py>, frame: Frame, at_us: u64) -> Option<Bound<'py, PyBytes>> {
        match self.slave.handle_frame(&frame.0, at_us).reply {
            hiperface_model::Reply::Frame(f) => Some(PyBytes::new(py, f.encode().as_bytes())),
            hiperface_model::Reply::Silent(_) => None,
        }
    }

    /// The physical inputs: position (steps, 32 per period), speed, temperature_c,
    /// led_current_ma.
    #[getter]
    fn inputs(&self) -> (u64, i32, i16, u16) {
        let i = self.slave.inputs();
        (i.position, i.speed, i.temperature_c, i.led_current_ma)
    }

    /// Change some of the physical inputs.
    #[pyo3(signature = (*, position=None, speed=None, temperature_c=None, led_current_ma=None))]
    fn set_inputs(
        &mut self,
        position: Option<u64>,
        speed: Option<i32>,
        temperature_c: Option<i16>,
        led_current_ma: Option<u16>,
    ) {
        let mut i = self.slave.inputs();
        i.position = position.unwrap_or(i.position);
        i.speed = speed.unwrap_or(i.speed);
        i.temperature_c = temperature_c.unwrap_or(i.temperature_c);
        i.led_current_ma = led_current_ma.unwrap_or(i.led_current_ma);
        self.slave.set_inputs(i);
    }

    fn __repr__(&self) -> String {
        format!("Slave(profile={:?})", self.slave.profile().name.as_str())
    }
}

/// A grade: "PASS", "NON-STRICT" or "FAIL", the clause id it rests on, and the reason.
#[pyclass(module = "hiperface", frozen, get_all)]
struct Grade {
    verdict: &'static str,
    clause: String,
    reason: String,
}

#[pymethods]
impl Grade {
    fn __repr__(&self) -> String {
        format!("Grade({} [{}] {})", self.verdict, self.clause, self.reason)
    }
}

/// The oracle. `exact`: the device is the model's own world (every value graded
/// exactly); otherwise a real device, whose position, temperature and LED current are
/// unknown (graded by their range).
#[pyclass(module = "hiperface", frozen)]
struct Oracle {
    oracle: ModelOracle,
}

#[pymethods]
impl Oracle {
    #[new]
    #[pyo3(signature = (exact=false))]
    fn new(exact: bool) -> Oracle {
        Oracle { oracle: ModelOracle::new(if exact { Grading::Exact } else { Grading::Range }) }
    }

    /// Grade a device's `reply` (None: silence) to `request`, whose frame ended at
    /// `at_us`, against `slave`, which then takes the request itself (lockstep).
    #[pyo3(signature = (slave, request, at_us, reply, uart_fault=false))]
    fn grade(&self, slave: &mut Slave, request: Frame, at_us: u64, reply: Option<Frame>, uart_fault: bool) -> Grade {
        let (request, reply) = (request.0.as_slice(), reply.as_ref().map(|r| r.0.as_slice()));
        let before = slave.slave.clone();
        let expected = if uart_fault {
            slave.slave.handle_faulty_frame(request, at_us)
        } else {
            slave.slave.handle_frame(request, at_us)
        };
        let g = self.oracle.grade(&before, request, at_us, &expected, reply);
        Grade {
            verdict: g.verdict().name(),
            clause: g.clause().to_string(),
            reason: g.deviation().map(|d| d.to_string()).unwrap_or_default(),
        }
    }
}

/// Verify a directory of golden vectors as `hiperface vectors verify` does: returns
/// (vectors checked, mismatches), each mismatch a line naming the vector. A directory
/// without a vector raises `HiperfaceError` (nothing verified is no pass), a missing
/// one `FileNotFoundError`.
#[pyfunction]
fn verify_vectors(path: &str) -> PyResult<(usize, Vec<String>)> {
    vectors::verify_dir(Path::new(path)).map_err(vectors_error)
}

/// One golden vector of a file (`load_vectors`): what it is about, and `verify()`.
#[pyclass(module = "hiperface", frozen)]
struct Vector {
    vector: vectors::Vector,
}

#[pymethods]
impl Vector {
    /// The vector's id, e.g. "001-5.1.4-example-01".
    #[getter]
    fn id(&self) -> &str {
        &self.vector.id
    }
    /// Document file and section, or "generated".
    #[getter]
    fn source(&self) -> &str {
        &self.vector.source
    }
    /// The clause ids it rests on.
    #[getter]
    fn clauses(&self) -> Vec<String> {
        self.vector.clauses.clone()
    }
    /// The built-in profile its slave is.
    #[getter]
    fn profile(&self) -> &str {
        &self.vector.profile
    }
    /// The command it is about.
    #[getter]
    fn command(&self) -> &str {
        &self.vector.command
    }
    /// What it shows, in a sentence.
    #[getter]
    fn meaning(&self) -> &str {
        &self.vector.meaning
    }
    /// "valid", "acceptable" or "invalid": what its last reply is.
    #[getter]
    fn result(&self) -> &'static str {
        match self.vector.result {
            vectors::Expected::Valid => "valid",
            vectors::Expected::Acceptable => "acceptable",
            vectors::Expected::Invalid => "invalid",
        }
    }
    /// How many steps of request and reply it has (0 for a checksum example or a
    /// table row).
    #[getter]
    fn steps(&self) -> usize {
        self.vector.steps.len()
    }
    /// Replay it against the model, with its printed checksums: what is wrong, one
    /// line each (an empty list: it agrees), as `vectors verify` checks it.
    fn verify(&self) -> Vec<String> {
        vectors::verify(&self.vector)
    }
    fn __repr__(&self) -> String {
        format!("Vector(id={:?}, profile={:?}, result={:?})", self.vector.id, self.vector.profile, self.result())
    }
}

/// The vectors of one file, schema-checked, in order. A missing file raises
/// `FileNotFoundError`; one that is not a vector file `HiperfaceError`.
#[pyfunction]
fn load_vectors(path: &str) -> PyResult<Vec<Vector>> {
    let file = vectors::load(Path::new(path)).map_err(vectors_error)?;
    Ok(file.vectors.into_iter().map(|vector| Vector { vector }).collect())
}

/// Grade a capture file as `hiperface decode` does: `on_exchange(json)` is called with
/// each exchange heard (JSON text), and the report comes back as the JSON text `decode
/// --report` writes. The Python wrapper is `hiperface.decode`.
#[pyfunction]
#[pyo3(signature = (path, on_exchange, *, profile="SRS50", baud=9600, format=None, samplerate=None,
                    tolerance_ms=None, master_channel=None, polling_period_ms=None))]
#[allow(clippy::too_many_arguments)]
fn decode_capture(
    path: &str,
    on_exchange: Bound<'_, PyAny>,
    profile: &str,
    baud: u32,
    format: Option<&str>,
    samplerate: Option<u64>,
    tolerance_ms: Option<f64>,
    master_channel: Option<String>,
    polling_period_ms: Option<u32>,
) -> PyResult<String> {
    let profile = profile_file::resolve(profile).map_err(profile_error)?;
    let format = match format {
        None | Some("auto") => None,
        Some("wirelog") => Some(Format::Wirelog),
        Some("csv") => Some(Format::Csv),
        Some("sigrok") => Some(Format::Sigrok),
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "format `{other}`: expected None, \"auto\", \"wirelog\", \"csv\" or \"sigrok\""
            )))
        }
    };
    // As `decode --polling-period-ms`: at least 1 ms.
    let polling_period_ms = match polling_period_ms {
        None => hiperface_model::master::obligations::POLLING_PERIOD_MS,
        Some(0) => return Err(PyValueError::new_err("polling_period_ms: at least 1 ms")),
        Some(ms) => ms,
    };
    let options = DecodeOptions {
        profile,
        baud,
        format,
        samplerate_hz: samplerate,
        tolerance_ms,
        master_channel,
        polling_period_ms,
    };
    let file = std::fs::File::open(path).map_err(|e| io_error(&e, format!("{path}: {e}")))?;
    let input = Box::new(std::io::BufReader::with_capacity(1 << 16, file));
    // The first error of the callback stops the calls and is raised at the end.
    let mut failed: Option<PyErr> = None;
    let report = grade_capture(input, path, &options, &mut |h| {
        if failed.is_some() {
            return;
        }
        let call = serde_json::to_string(h)
            .map_err(|e| HiperfaceError::new_err(e.to_string()))
            .and_then(|json| on_exchange.call1((json,)).map(drop));
        failed = call.err();
    })
    .map_err(|e| HiperfaceError::new_err(e.to_string()))?;
    if let Some(e) = failed {
        return Err(e);
    }
    serde_json::to_string(&report).map_err(|e| HiperfaceError::new_err(e.to_string()))
}

/// The catalogue of `side` ("slave": the cases `certify` runs, "master": the scenarios
/// `certify_master` runs) as a Markdown table (id, what it checks, clauses): what
/// `hiperface certify slave --list` and `certify master --list` print.
#[pyfunction]
fn catalogue(side: &str) -> PyResult<String> {
    use hiperface_suite::report::catalogue;
    match side {
        "slave" => Ok(catalogue::slave_cases()),
        "master" => Ok(catalogue::master_scenarios()),
        other => Err(PyValueError::new_err(format!("catalogue `{other}`: expected `slave` or `master`"))),
    }
}

#[pymodule]
fn _hiperface(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(checksum, m)?)?;
    m.add_function(wrap_pyfunction!(catalogue, m)?)?;
    m.add_function(wrap_pyfunction!(seal, m)?)?;
    m.add_function(wrap_pyfunction!(is_valid, m)?)?;
    m.add_function(wrap_pyfunction!(decode_request, m)?)?;
    m.add_function(wrap_pyfunction!(verify_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(load_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(decode_capture, m)?)?;
    m.add_function(wrap_pyfunction!(certify::certify_encoder, m)?)?;
    m.add_function(wrap_pyfunction!(certify::certify_master_in_process, m)?)?;
    m.add_class::<certify::Heard>()?;
    m.add_class::<Request>()?;
    m.add_class::<Transmission>()?;
    m.add_class::<Slave>()?;
    m.add_class::<Grade>()?;
    m.add_class::<Oracle>()?;
    m.add_class::<Vector>()?;
    // The names as the core spells them, the worst verdict first (the reports' order).
    let verdicts: Vec<&str> = CaseVerdict::ALL.iter().rev().map(|v| v.label()).collect();
    m.add("CASE_VERDICTS", PyTuple::new(m.py(), verdicts)?)?;
    let faults: Vec<&str> = UartFault::ALL.iter().map(|f| f.name()).collect();
    m.add("UART_FAULTS", PyTuple::new(m.py(), faults)?)?;
    m.add("HiperfaceError", m.py().get_type::<HiperfaceError>())?;
    m.add("MalformedRequest", m.py().get_type::<MalformedRequest>())?;
    m.add("ProfileError", m.py().get_type::<ProfileError>())?;
    Ok(())
}
