//! Running the model: characters fed to a [`Slave`] at the ends of their stop bits,
//! the slave polled at its deadlines, its power-up states read off as phases.

use super::Surprise;
use hiperface_model::datalink::RxChar;
use hiperface_model::request::{Request, RequestFrame};
use hiperface_model::response::Response;
use hiperface_model::settings::UartSettings;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{AddressByte, Profile, Reply, Slave, Step, Transmission};

/// One character on the line: from its start bit's leading edge to its stop bit's end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Char {
    pub(super) byte: u8,
    pub(super) start_us: u64,
    pub(super) end_us: u64,
}

/// `bytes` sent back to back from `start_us` in `settings`. // 000:T4
pub(super) fn characters(bytes: &[u8], start_us: u64, settings: UartSettings) -> Vec<Char> {
    let ct = settings.char_time_us();
    (0u64..)
        .zip(bytes)
        .map(|(i, b)| Char { byte: *b, start_us: start_us + i * ct, end_us: start_us + (i + 1) * ct })
        .collect()
}

/// A request as sent and what the slave made of it.
pub(super) struct Sent {
    pub(super) chars: Vec<Char>,
    pub(super) step: Option<Step>,
}

impl Sent {
    pub(super) fn last_end_us(&self) -> u64 {
        self.chars.last().map_or(0, |c| c.end_us)
    }

    pub(super) fn step(&self) -> Result<Step, Surprise> {
        self.step.ok_or(Surprise("the slave did not process the request"))
    }

    /// The reply the model sends and its characters, drawn from the earliest start it
    /// allows (a device may start anywhere up to the latest).
    pub(super) fn reply(&self) -> Result<(Transmission, Vec<Char>), Surprise> {
        let t = self.step()?.transmission.ok_or(Surprise("the slave did not reply"))?;
        Ok((t, characters(t.frame.as_bytes(), t.earliest_start_us, t.settings)))
    }
}

/// Send `bytes` as a master does: each character reaches the slave when its stop bit
/// ends, the UART's receive interrupt (000:2.2.2); then time advances to the slave's
/// deadlines until it has processed the frame (its timeout after the last character).
pub(super) fn send(slave: &mut Slave, bytes: &[u8], start_us: u64, settings: UartSettings) -> Sent {
    let chars = characters(bytes, start_us, settings);
    let mut step = None;
    for c in &chars {
        step = step.or(slave.receive(RxChar::ok(c.byte, c.end_us)));
    }
    let mut now = chars.last().map_or(start_us, |c| c.end_us);
    // Deadlines are the frame's timeout and the power-up state changes: a handful.
    for _ in 0..8 {
        if step.is_some() {
            break;
        }
        let Some(deadline) = slave.next_deadline(now) else { break };
        step = slave.poll(deadline);
        now = now.max(deadline);
    }
    Sent { chars, step }
}

pub(super) fn request(profile: &Profile, request: Request) -> Vec<u8> {
    RequestFrame::new(AddressByte::Slave(profile.address), request).encode().as_bytes().to_vec()
}

pub(super) fn read_position(profile: &Profile) -> Vec<u8> {
    request(profile, Request::ReadPosition)
}

/// A slave of `profile` that stored `settings` with Set Serial Interface (57h, with
/// the factory Code0) and was then powered on again at t = 0: the stored settings
/// hold from the next power-on (000:T32).
pub(super) fn with_stored_settings(profile: Profile, settings: UartSettings) -> Result<Slave, Surprise> {
    let mut slave = Slave::operational(profile);
    let code0 = slave.nonvolatile().codes[0];
    let frame = request(&profile, Request::SetSerialInterface { settings: settings.byte(), code0 });
    let outcome = slave.handle_frame(&frame, 0);
    match outcome.reply {
        Reply::Frame(r) if !matches!(r.response, Response::Error(_)) => {}
        _ => return Err(Surprise("the slave refused Set Serial Interface (57h)")),
    }
    if slave.nonvolatile().settings != settings {
        return Err(Surprise("Set Serial Interface (57h) did not store the settings"));
    }
    slave.power_cycle(0);
    Ok(slave)
}

/// A stretch of time in one power-up state with the settings the slave listens with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Phase {
    pub(super) from_us: u64,
    pub(super) to_us: u64,
    pub(super) state: CommState,
    pub(super) listening: Option<UartSettings>,
}

/// The slave's states from `from_us` to `to_us` as it stands (no frame in progress):
/// its state and listening settings at each change its deadlines announce (000:T9).
pub(super) fn phases(slave: &Slave, from_us: u64, to_us: u64) -> Vec<Phase> {
    let mut out: Vec<Phase> = Vec::new();
    let mut t = from_us;
    while t < to_us {
        let next = slave.next_deadline(t).filter(|n| *n > t).map_or(to_us, |n| n.min(to_us));
        let (state, listening) = (slave.state(t), slave.listening_settings(t));
        match out.last_mut() {
            Some(last) if last.state == state && last.listening == listening => last.to_us = next,
            _ => out.push(Phase { from_us: t, to_us: next, state, listening }),
        }
        t = next;
    }
    out
}

/// `a` then `b`, a phase continued across the seam merged into one.
pub(super) fn joined(a: Vec<Phase>, b: Vec<Phase>) -> Vec<Phase> {
    let mut out = a;
    for p in b {
        match out.last_mut() {
            Some(last) if last.state == p.state && last.listening == p.listening && last.to_us == p.from_us => {
                last.to_us = p.to_us
            }
            _ => out.push(p),
        }
    }
    out
}
