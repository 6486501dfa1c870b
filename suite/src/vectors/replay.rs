//! Replaying a vector through the model: the starting state, each step graded by the
//! oracle, and typed reasons where a vector disagrees.

use super::{hex, parse_hex, tables, Expected, Flag, Setup, Vector};
use hiperface_model::slave::inputs::{InitFault, PositionFault};
use hiperface_model::{checksum, profiles, Grading, Oracle, Profile, Reply, Slave, Verdict};

fn init_fault(name: &str) -> Result<InitFault, VectorError> {
    InitFault::from_name(name).ok_or_else(|| VectorError::InitFault(name.to_string()))
}

fn position_fault(name: &str) -> Result<PositionFault, VectorError> {
    PositionFault::from_name(name).ok_or_else(|| VectorError::PositionFault(name.to_string()))
}

/// Why a vector cannot be replayed, or how it disagrees with the model.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum VectorError {
    #[error("`{0}` is not a hex byte")]
    Hex(String),
    #[error("unknown profile `{0}`")]
    Profile(String),
    #[error("unknown start-up fault `{0}`")]
    InitFault(String),
    #[error("unknown position fault `{0}`")]
    PositionFault(String),
    #[error("`{0}` is no settings byte (000:T28)")]
    Settings(String),
    #[error("step {step}: {reason}")]
    Timing { step: usize, reason: ReceiveError },
    #[error("table row `{table}` / `{input}`: {reason}")]
    TableRow { table: String, input: String, reason: tables::RowError },
    #[error("no steps, checksum example or table case")]
    Empty,
    #[error("XOR of {frame} is {computed:02X}h, not {printed}")]
    Checksum { frame: String, computed: u8, printed: String },
    #[error("{table} {input}: the model gives `{got}`, the vector says `{printed}`")]
    Table { table: String, input: String, got: String, printed: String },
    #[error("step {step}: request {request} -> the model answers {got}; the vector says {expected} ({result:?}), graded {grade}")]
    Step { step: usize, request: String, got: String, expected: String, result: Expected, grade: String },
}

/// A vector that does not replay, and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{id}: {error}")]
pub struct Mismatch {
    pub id: String,
    pub error: Box<VectorError>,
}

/// The slave of a vector's setup.
pub fn prepare(v: &Vector) -> Result<Slave, VectorError> {
    let profile = profiles::builtin(&v.profile).ok_or_else(|| VectorError::Profile(v.profile.clone()))?;
    start(profile, &v.setup)
}

/// A slave of `profile` in the starting state `setup` describes.
pub fn start(mut profile: Profile, setup: &Setup) -> Result<Slave, VectorError> {
    if let Some(s) = &setup.settings {
        let byte = u8::from_str_radix(s, 16).map_err(|_| VectorError::Hex(s.clone()))?;
        profile.settings = hiperface_model::UartSettings::decode(byte).map_err(|_| VectorError::Settings(s.clone()))?;
    }
    let mut slave = if setup.power_on { Slave::new(profile) } else { Slave::operational(profile) };
    if let Some(i) = setup.inputs {
        let mut inputs = slave.inputs();
        i.apply(&mut inputs);
        slave.set_inputs(inputs);
    }
    if !setup.init_faults.is_empty() {
        let faults = setup.init_faults.iter().map(|f| init_fault(f)).collect::<Result<Vec<_>, _>>()?;
        slave.power_up_with(faults, !setup.power_on);
    }
    for f in &setup.position_faults {
        slave.inject_position_fault(position_fault(f)?, true);
    }
    slave.inject_i2c_fault(setup.i2c_fault);
    if let Some(c) = setup.counter {
        slave.set_counter(c);
    }
    for r in &setup.requests {
        slave.handle_frame(&parse_hex(r)?, 0);
    }
    Ok(slave)
}

/// Replay a vector through the model.
pub fn replay(v: &Vector) -> Result<(), Mismatch> {
    let fail = |error: VectorError| Mismatch { id: v.id.clone(), error: Box::new(error) };
    if let Some(c) = &v.checksum_example {
        let frame = parse_hex(&c.frame).map_err(fail)?;
        let sum = parse_hex(&c.checksum).map_err(fail)?;
        return if sum == [checksum::xor(&frame)] {
            Ok(())
        } else {
            Err(fail(VectorError::Checksum {
                frame: c.frame.clone(),
                computed: checksum::xor(&frame),
                printed: c.checksum.clone(),
            }))
        };
    }
    if let Some(t) = &v.table_case {
        let row = |reason| VectorError::TableRow { table: t.table.clone(), input: t.input.clone(), reason };
        let got = tables::evaluate(&t.table, &t.input).map_err(|reason| fail(row(reason)))?;
        return if got == t.output {
            Ok(())
        } else {
            Err(fail(VectorError::Table {
                table: t.table.clone(),
                input: t.input.clone(),
                got,
                printed: t.output.clone(),
            }))
        };
    }
    if v.steps.is_empty() {
        return Err(fail(VectorError::Empty));
    }
    let mut slave = prepare(v).map_err(fail)?;
    let oracle = Oracle::new(Grading::Exact);
    for (i, step) in v.steps.iter().enumerate() {
        let last = i + 1 == v.steps.len();
        if let Some(inputs) = step.inputs {
            let mut now = slave.inputs();
            inputs.apply(&mut now);
            slave.set_inputs(now);
        }
        let request = parse_hex(&step.request).map_err(fail)?;
        let expected = step.response.as_deref().map(parse_hex).transpose().map_err(fail)?;
        let at = step.at_us.unwrap_or(0);
        let before = slave.clone();
        let outcome = if step.chars_at_us.is_empty() {
            if step.uart_fault {
                slave.handle_faulty_frame(&request, at)
            } else {
                slave.handle_frame(&request, at)
            }
        } else {
            receive(&mut slave, &request, &step.chars_at_us, at)
                .map_err(|reason| fail(VectorError::Timing { step: i + 1, reason }))?
        };
        let got = match outcome.reply {
            Reply::Frame(f) => Some(f.encode().as_bytes().to_vec()),
            Reply::Silent(_) => None,
        };
        let grade = oracle.grade(&before, &request, at, &outcome, expected.as_deref());
        let want = if last {
            match v.result {
                Expected::Valid => Verdict::Pass,
                Expected::Acceptable => Verdict::NonStrict,
                Expected::Invalid => Verdict::Fail,
            }
        } else {
            Verdict::Pass
        };
        if grade.verdict() != want || (want == Verdict::Pass && got != expected) {
            let shown = |b: &Option<Vec<u8>>| b.as_ref().map_or("no response".to_string(), |b| hex(b));
            return Err(fail(VectorError::Step {
                step: i + 1,
                request: step.request.clone(),
                got: shown(&got),
                expected: shown(&expected),
                result: v.result,
                grade: grade.to_string(),
            }));
        }
    }
    Ok(())
}

/// Where a step's characters, given at their times, and the model's data link part
/// (000:2.2.2).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReceiveError {
    #[error("{times} character times for a request of {bytes} bytes")]
    CharacterTimes { times: usize, bytes: usize },
    #[error("the model took {0} frames of these characters, the vector one")]
    Frames(usize),
    #[error("the model framed [{}]", hex(.0))]
    Framed(Vec<u8>),
    #[error("the model took the request at {model_us} µs, the vector says {vector_us} µs")]
    TakenAt { model_us: u64, vector_us: u64 },
}

/// The request's characters through the slave's data link at their times: it must
/// take them as one frame at `at_us` (the timeout after the last, 000:2.2.2), and its
/// outcome is the step's. `Err` says where the vector and the model part.
pub fn receive(
    slave: &mut Slave,
    request: &[u8],
    chars_at_us: &[u64],
    at_us: u64,
) -> Result<hiperface_model::Outcome, ReceiveError> {
    if chars_at_us.len() != request.len() {
        return Err(ReceiveError::CharacterTimes { times: chars_at_us.len(), bytes: request.len() });
    }
    let mut steps = Vec::new();
    for (b, t) in request.iter().zip(chars_at_us) {
        steps.extend(slave.receive(hiperface_model::datalink::RxChar::ok(*b, *t)));
    }
    // Nothing else arrives: the frame is taken when its timeout elapses.
    let last = chars_at_us.last().copied().unwrap_or(0);
    steps.extend(slave.poll(last.saturating_add(1_000_000)));
    let step = match steps.as_slice() {
        [step] => step,
        // Characters that arrive while the slave does not listen are lost (000:T9):
        // nothing is taken, and the vector says so with the last character's time.
        [] if at_us == last => return Ok(slave.handle_frame(request, last)),
        _ => return Err(ReceiveError::Frames(steps.len())),
    };
    if step.received.bytes.as_bytes() != request {
        return Err(ReceiveError::Framed(step.received.bytes.as_bytes().to_vec()));
    }
    if step.received.complete_us != at_us {
        return Err(ReceiveError::TakenAt { model_us: step.received.complete_us, vector_us: at_us });
    }
    Ok(step.outcome)
}

/// Frames whose checksum must be right: all but those flagged otherwise.
pub fn checksum_problems(v: &Vector) -> Vec<String> {
    let mut out = Vec::new();
    let intentional = v.flags.contains(&Flag::BadChecksum) || v.flags.contains(&Flag::Erratum);
    let mut frames: Vec<(&str, &str)> = v.setup.requests.iter().map(|r| ("setup request", r.as_str())).collect();
    for s in &v.steps {
        frames.push(("request", &s.request));
        if let Some(r) = &s.response {
            frames.push(("response", r));
        }
    }
    for (what, f) in frames {
        match parse_hex(f) {
            Ok(b) if b.len() >= 3 && !checksum::is_valid(&b) && !intentional => {
                out.push(format!("{what} {f} has a wrong checksum and the vector is not flagged"))
            }
            Ok(_) => {}
            Err(e) => out.push(format!("{what} `{f}`: {e}")),
        }
    }
    out
}
