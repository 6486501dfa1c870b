//! Helpers for the scenario tests.
#![allow(dead_code)]

use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::{checksum, Outcome, Profile, Reply, Slave};

/// Bytes with their XOR checksum appended.
pub fn sealed(body: &[u8]) -> Vec<u8> {
    let mut v = body.to_vec();
    v.push(checksum::xor(body));
    v
}

/// Parse "40 42 02" into bytes.
pub fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace().map(|b| u8::from_str_radix(b, 16).expect("hex byte")).collect()
}

/// Send a whole frame to an operational slave; the reply bytes or `None`.
pub fn ask(slave: &mut Slave, frame: &[u8]) -> Option<Vec<u8>> {
    reply_bytes(&slave.handle_frame(frame, 0))
}

/// As `ask`, with the checksum appended.
pub fn ask_sealed(slave: &mut Slave, body: &[u8]) -> Option<Vec<u8>> {
    ask(slave, &sealed(body))
}

pub fn reply_bytes(outcome: &Outcome) -> Option<Vec<u8>> {
    match outcome.reply {
        Reply::Frame(f) => Some(f.encode().as_bytes().to_vec()),
        Reply::Silent(_) => None,
    }
}

pub fn operational(profile: Profile) -> Slave {
    Slave::operational(profile)
}

pub fn with_inputs(mut slave: Slave, f: impl FnOnce(&mut PhysicalInputs)) -> Slave {
    let mut i = slave.inputs();
    f(&mut i);
    slave.set_inputs(i);
    slave
}

/// The error response `addr 50 code chk` (D0 with a warning).
pub fn error(addr: u8, code: u8) -> Vec<u8> {
    sealed(&[addr, 0x50, code])
}
