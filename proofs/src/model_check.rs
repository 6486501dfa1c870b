//! Explicit-state model checking of the slave: breadth-first over every state
//! reachable with a bounded alphabet of master requests (every command with boundary
//! arguments, codes, field numbers and sizes, broadcast), resets and timeouts,
//! checking the invariants in every state and that every state returns to
//! Operational after a reset.

use crate::invariant::slave_invariant;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{checksum, profiles, Reply, Slave};
use std::collections::{HashSet, VecDeque};

/// An action of the environment.
#[derive(Debug, Clone)]
pub enum Action {
    /// A request (body without checksum), sent broadcast or to 40h, processed at t = 0.
    Request(Vec<u8>),
    /// Time passes beyond every power-up window.
    Settle,
}

fn req(body: &[u8]) -> Action {
    Action::Request(body.to_vec())
}

/// The boundary requests of the data field, access code, status, address and settings
/// commands (4Ah to 57h), after the address byte: both searches send them
/// (`fixpoint::alphabet` too).
pub const FIELDS_TO_SETTINGS: &[&[u8]] = &[
    &[0x4A, 0, 0, 16, 0x55],
    &[0x4A, 0, 15, 2, 0x55], // off the end of a 16-byte field
    &[0x4B, 0, 15, 1, 0x55, 0xA5],
    &[0x4C, 0],
    &[0x4D, 0, 0xC0, 0x55], // create/modify field 0, 16 bytes
    &[0x4D, 0, 0xC7, 0x55], // resize field 0 to 128 bytes
    &[0x4D, 1, 0xF8, 0x56], // field 1, Code3 enabled (needs Code3 = 56h)
    &[0x4D, 1, 0x78, 0x56], // delete field 1
    &[0x4D, 0, 0x40, 0x55], // delete field 0 (16 bytes)
    &[0x4D, 0, 0x47, 0x55], // delete field 0 (128 bytes)
    &[0x4E],
    &[0x4F, 3, 0x55, 0x56],
    &[0x4F, 3, 0x56, 0x55],
    &[0x50],
    &[0x52],
    &[0x53],
    &[0x55, 0x41, 0x55],
    &[0x55, 0x40, 0x55],
    &[0x57, 0xE5, 0x55],
    &[0x57, 0xE4, 0x55],
];

/// A request of [`FIELDS_TO_SETTINGS`] to `address`.
pub fn addressed(address: u8, request: &[u8]) -> Vec<u8> {
    [&[address][..], request].concat()
}

/// The alphabet: every command with boundary arguments, sent broadcast (FFh) so that
/// address changes do not hide the slave.
pub fn alphabet() -> Vec<Action> {
    let b = 0xFF;
    vec![
        req(&[b, 0x42]),
        req(&[b, 0x43, 0, 0, 0, 0, 0x55]),
        req(&[b, 0x43, 0, 0, 0x01, 0xFF, 0x55]), // the last position of SEK37's range
        req(&[b, 0x43, 0, 0, 0x02, 0x00, 0x55]), // one past it: 0Dh
        req(&[b, 0x43, 0, 0, 0, 0, 0x54]),       // wrong code
        req(&[b, 0x44, 0x48]),
        req(&[b, 0x46]),
        req(&[b, 0x47]),
        req(&[b, 0x49, 0x55]),
    ]
    .into_iter()
    .chain(FIELDS_TO_SETTINGS.iter().map(|r| Action::Request(addressed(b, r))))
    .chain([
        req(&[b, 0x45]), // unknown command
        Action::Settle,
    ])
    .collect()
}

pub struct ModelCheckReport {
    pub states: usize,
    pub transitions: u64,
    pub depth: usize,
    pub complete: bool,
}

/// Apply an action.
pub fn apply(s: &mut Slave, a: &Action) {
    match a {
        Action::Request(body) => {
            let mut f = body.clone();
            f.push(checksum::xor(body));
            s.handle_frame(&f, 0);
        }
        Action::Settle => s.settle(),
    }
}

/// Breadth-first search to `max_depth` (SEK37: small memory, 512 steps).
pub fn explore(max_depth: usize) -> Result<ModelCheckReport, String> {
    let mut start = Slave::operational(profiles::sek37());
    // Hot encoder: the temperature warning exercises the stack in every state.
    let mut inputs = start.inputs();
    inputs.temperature_c = 130;
    start.set_inputs(inputs);
    let alphabet = alphabet();
    let mut seen: HashSet<Slave> = HashSet::new();
    let mut queue = VecDeque::from([(start.clone(), 0usize)]);
    seen.insert(start);
    let mut transitions = 0u64;
    let mut depth = 0;
    let mut complete = true;
    while let Some((state, d)) = queue.pop_front() {
        depth = depth.max(d);
        check_state(&state)?;
        if d == max_depth {
            complete = false;
            continue;
        }
        for a in &alphabet {
            let mut next = state.clone();
            apply(&mut next, a);
            transitions += 1;
            if !seen.contains(&next) {
                seen.insert(next.clone());
                queue.push_back((next, d + 1));
            }
        }
    }
    Ok(ModelCheckReport { states: seen.len(), transitions, depth, complete })
}

/// Invariants, and: an Encoder Reset then the power-up windows lead back to
/// Operational, and the slave answers.
fn check_state(s: &Slave) -> Result<(), String> {
    slave_invariant(s).map_err(|v| format!("invariant violated: {v} in {s:?}"))?;
    let mut r = s.clone();
    apply(&mut r, &Action::Request(vec![0xFF, 0x53]));
    if r.state(0) != CommState::Initialization {
        return Err(format!("no Initialization after 53h: {:?}", r.state(0)));
    }
    r.settle();
    if r.state(0) != CommState::OperationalUser {
        return Err("not Operational after the reset's windows".into());
    }
    let mut f = vec![0xFF, 0x42];
    f.push(checksum::xor(&f));
    match r.handle_frame(&f, 0).reply {
        Reply::Frame(_) => Ok(()),
        Reply::Silent(why) => Err(format!("silent after reset: {why:?}")),
    }
}
