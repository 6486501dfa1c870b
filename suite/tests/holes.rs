//! The holes the measure of the catalogue found (docs/src/verification.md, "What a
//! PASS proves"), each closed by a case: an encoder with that one defect, certified
//! in-process, FAILs the case on its clause, and the same encoder without it passes.
//! Defects an encoder writer and a test engineer planted in encoders of their own,
//! which the catalogue let through before:
//!
//! - Set Position acknowledged and never applied (`position.set` preset the position it
//!   had just read);
//! - a code read with 50h never removed, where its cause is gone (only the world given
//!   to the run tells it from a cause that lasts);
//! - Store Data's count byte never checked against the data sent;
//! - Read Data one past the end of a field;
//! - Set Serial Interface accepting a data rate the profile does not offer;
//! - the error stack read newest first where the data sheet says oldest first.

mod common;
use common::failing;

use hiperface_model::datalink::ReceivedFrame;
use hiperface_model::slave::inputs::{InitFault, PhysicalInputs};
use hiperface_model::slave::{Reply, Silence};
use hiperface_model::{checksum, profiles, Frame, Profile, Slave};
use hiperface_suite::line::frame_encoder::Answer;
use hiperface_suite::slave::{self, Options, Report};
use hiperface_suite::verdict::{CaseVerdict, Outcome};
use hiperface_suite::world::World;

/// What the defective encoder does differently.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Defect {
    None,
    /// 43h answered as done, the offset kept.
    SetPositionNotApplied,
    /// 50h answers the oldest code and keeps it.
    StatusNeverRemoved,
    /// 4Bh stores the data sent whatever the count byte says.
    StoreCountUnchecked,
    /// 4Ah one past the end of a field answers the bytes it has and an FFh.
    ReadOnePast,
    /// 57h with a data rate the profile lacks: acknowledged.
    AnyDataRate,
    /// The stack read newest first.
    NewestFirst,
}

/// The reference model behind the frame interface, with one defect.
struct Encoder {
    slave: Slave,
    defect: Defect,
}

fn seal(mut body: Vec<u8>) -> Vec<u8> {
    let sum = checksum::xor(&body);
    body.push(sum);
    body
}

impl Encoder {
    fn new(profile: Profile, world: &World, defect: Defect) -> Encoder {
        let mut p = profile;
        if defect == Defect::NewestFirst {
            p.stack_order = hiperface_model::profile::StackOrder::NewestFirst;
        }
        let mut slave = Slave::operational(p);
        world.apply(&mut slave);
        Encoder { slave, defect }
    }

    /// The request as this encoder takes it in.
    fn taken(&self, bytes: &[u8]) -> Vec<u8> {
        let mut b = bytes.to_vec();
        match (self.defect, b.get(1)) {
            // The count is what was sent, whatever the count byte says.
            (Defect::StoreCountUnchecked, Some(0x4B)) if b.len() > 7 => {
                b[4] = (b.len() - 7) as u8;
                let n = b.len() - 1;
                b[n] = checksum::xor(&b[..n]);
            }
            // One byte less read: the missing one is answered FFh below.
            (Defect::ReadOnePast, Some(0x4A)) if b.len() == 7 && self.one_past(&b) => {
                b[4] -= 1;
                b[6] = checksum::xor(&b[..6]);
            }
            _ => {}
        }
        b
    }

    /// A settings byte 000:T28 defines (whether or not the profile offers its rate).
    fn defined(&self, byte: u8) -> bool {
        hiperface_model::UartSettings::decode(byte).is_ok()
    }

    /// A Read Data that ends one byte past its field.
    fn one_past(&self, b: &[u8]) -> bool {
        let size = self.slave.nonvolatile().fields.status(b[2]).map(|s| s.size_bytes());
        size.is_some_and(|size| b[3] as usize + b[4] as usize == size + 1)
    }

    fn answer(&mut self, f: &ReceivedFrame) -> Answer {
        let asked = f.bytes.as_bytes().to_vec();
        let bytes = self.taken(&asked);
        let before = self.slave.clone();
        let mut outcome = self.slave.handle(&bytes, f.uart_fault.is_some(), f.complete_us);
        let command = asked.get(1).copied();
        let undone = matches!(
            (self.defect, command),
            (Defect::SetPositionNotApplied, Some(0x43)) | (Defect::StatusNeverRemoved, Some(0x50))
        );
        if undone {
            // The reply is the one the request got; the effect is gone.
            self.slave = before;
        }
        let reset = matches!(outcome.reply, Reply::Silent(Silence::Reset));
        let then_settings = outcome.then_settings.or(reset.then(|| self.slave.nonvolatile().settings));
        let Reply::Frame(rf) = &mut outcome.reply else {
            return Answer { then_settings, restarts: reset, ..Answer::SILENT };
        };
        let mut reply = rf.encode().as_bytes().to_vec();
        match (self.defect, command) {
            (Defect::ReadOnePast, Some(0x4A)) if asked.len() == 7 && bytes != asked && reply.len() > 6 => {
                let n = reply.len() - 1;
                reply.truncate(n);
                reply[4] += 1;
                reply.push(0xFF);
                reply = seal(reply);
            }
            (Defect::AnyDataRate, Some(0x57))
                if reply.get(2) == Some(&0x0D) && asked.len() == 5 && self.defined(asked[2]) =>
            {
                reply = seal(vec![asked[0], 0x57 | (reply[1] & 0x80), asked[2]]);
            }
            _ => {}
        }
        let Ok(frame) = Frame::from_bytes(&reply) else { return Answer::SILENT };
        Answer { reply: Some(frame), start_us: f.complete_us + 300, then_settings, restarts: false }
    }
}

fn certify(profile: Profile, world: World, defect: Defect) -> Report {
    let mut encoder = Encoder::new(profile, &world, defect);
    let options = Options { world, ..Options::all_allowed() };
    slave::in_process(move |f: &ReceivedFrame| encoder.answer(f), profile, &options)
}

fn assert_fails(r: &Report, case_and_clause: &str) {
    assert_eq!(r.outcome(), Outcome::Failed, "{:?}", r.summary);
    let f = failing(r);
    assert!(f.iter().any(|x| x == case_and_clause), "expected {case_and_clause}: {f:?}");
}

fn calm() -> World {
    World::default()
}

/// A code found at start-up and read once: its cause is gone (000:T45, "Read and delete
/// message").
fn watchdog_reset() -> World {
    World { init_faults: vec![InitFault::Watchdog], ..World::default() }
}

/// A temperature over the limit: the code is raised again before every reply (000:T59).
fn hot(p: &Profile) -> World {
    let inputs = PhysicalInputs { temperature_c: p.temperature_max_c + 5, ..PhysicalInputs::default() };
    World { inputs: Some(inputs), ..World::default() }
}

#[test]
fn the_encoder_without_a_defect_passes_in_each_world_used_here() {
    let p = profiles::srs50();
    for world in [
        calm(),
        watchdog_reset(),
        hot(&p),
        World { init_faults: vec![InitFault::Watchdog, InitFault::Counter], ..hot(&p) },
    ] {
        let r = certify(p, world.clone(), Defect::None);
        assert_eq!(r.outcome(), Outcome::Passed, "{world:?}: {:?}", failing(&r));
    }
}

#[test]
fn set_position_acknowledged_and_not_applied_fails_position_set() {
    assert_fails(&certify(profiles::srs50(), calm(), Defect::SetPositionNotApplied), "position.set 000:T13");
}

#[test]
fn a_code_never_removed_fails_where_its_cause_is_gone_and_not_where_it_lasts() {
    let p = profiles::srs50();
    let r = certify(p, watchdog_reset(), Defect::StatusNeverRemoved);
    // 07h answered again where the stack is empty, and every reply after it with the
    // warning bit the master has read out.
    assert_fails(&r, "identity.status 000:T27");
    assert_fails(&r, "position.read 000:2.3.4");
    // While the temperature stays over its limit, 1Eh is raised again before every
    // reply: reading it does not remove it for long, and a device that never removes
    // it cannot be told from one that does.
    let r = certify(p, hot(&p), Defect::StatusNeverRemoved);
    assert_eq!(r.outcome(), Outcome::Passed, "{:?}", failing(&r));
}

#[test]
fn a_store_data_count_never_checked_fails_fields_lifecycle() {
    assert_fails(&certify(profiles::srs50(), calm(), Defect::StoreCountUnchecked), "fields.lifecycle 000:T50");
}

#[test]
fn a_read_data_one_past_the_field_fails_fields_lifecycle() {
    assert_fails(&certify(profiles::srs50(), calm(), Defect::ReadOnePast), "fields.lifecycle 000:T55");
}

#[test]
fn a_data_rate_the_profile_lacks_accepted_fails_settings_invalid() {
    assert_fails(&certify(profiles::srs50(), calm(), Defect::AnyDataRate), "settings.invalid 000:T28/settings");
}

#[test]
fn the_stack_read_in_the_other_order_fails_identity_status() {
    let p = profiles::srs50();
    let several = World { init_faults: vec![InitFault::Watchdog, InitFault::Counter], ..hot(&p) };
    assert_fails(&certify(p, several, Defect::NewestFirst), "identity.status 000:T27");
}

/// The world given to an in-process run is what makes these cases exact: without it a
/// code never removed is a warning the harness cannot explain (NON-STRICT), no FAIL.
#[test]
fn without_the_world_a_code_never_removed_is_only_non_strict() {
    let p = profiles::srs50();
    let mut encoder = Encoder::new(p, &watchdog_reset(), Defect::StatusNeverRemoved);
    let r = slave::in_process(move |f: &ReceivedFrame| encoder.answer(f), p, &Options::all_allowed());
    assert!(failing(&r).iter().all(|f| !f.starts_with("identity.status")), "{:?}", failing(&r));
    let status = r.cases.iter().find(|c| c.id == "identity.status").map(|c| c.verdict);
    assert_eq!(status, Some(CaseVerdict::NonStrict));
}
