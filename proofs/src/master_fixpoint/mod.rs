//! The reference master with the encoder model, to a fixpoint (docs/src/verification.md,
//! "The reference master to a fixpoint"): the model's reference master
//! (`hiperface_model::master::reference`) runs against the slave model in virtual time,
//! the observer of the master's obligations (`hiperface_model::master::obligations`)
//! watching every character it sends, and at every request the slave answers the
//! encoder may do any of the acts the master scenarios inject (suite/src/master/
//! scenarios.rs, [`acts`]): answer, an error code instead (not instead of Read Encoder
//! Status's reply, [`applies`]), silence, a wrong checksum, a late reply, a pause inside
//! the reply, a position fault from now on, a restart; in each of the scenarios' worlds
//! ([`worlds`]). The search is breadth-first over a canonical joint state and ends when
//! no new one appears. The master must never break a must of its obligations (an
//! observation on a normative clause that binds the edition: what `certify master`
//! FAILs), never panic and never hang (every step moves the clock on; no step stops
//! the master).
//!
//! The line is the one the harness gives the reference master: the exchanges of
//! `BusMaster` (suite/src/exchange.rs: the request once the line has been quiet for the
//! timeout, the reply framed by the timeout, the pause after it), and the encoder's
//! side as the in-process certification serves it (suite/src/master/in_process.rs and
//! encoder/hooks.rs: the reply 300 µs after its earliest start, the act applied to
//! it, the observer told of it). A character that came while the master was not
//! reading is read at once, as a real line gives it (conformance/src/line/clock.rs
//! `read_until`); the harness's virtual line gives it only by its stamp, and there a
//! late reply that arrives during a wait is taken for the next request's reply
//! (docs/src/verification.md says what this search found of it). A test of the harness
//! (conformance/tests/reference_master.rs) checks that, the encoder answering, the
//! master here decides at the instants and asks what it asks on the harness's
//! `BusMaster` over the virtual line.
//!
//! The joint state is taken where the master decides (each action done) and made
//! canonical ([`Joint::canonical`]): the clock moved to [`BASE_US`], every time kept
//! relative to it, a time further back than anything reads it from now on brought
//! forward (`Observer::rebase`, `Slave::rebase`: a power-up long past once the windows
//! of 000:T9 that can still matter are over), and the observer's memory that only the
//! recommendations read forgotten (`Observer::forget_recommendations`): only musts are
//! checked. Nothing else is abstracted: the master's flow (stage, retries, resets, the
//! held reply, the codes read), the slave (stack, faults, locks, power-up), the
//! observer's memory for the musts and the characters on the line stay as they are.
//!
//! Here the acts, the worlds and the master's step; joint.rs the joint state and its
//! step in virtual time (what is explored), search.rs the breadth-first search and
//! what it checks (the musts, a panic, a hang), with its report and counterexamples.

use hiperface_model::fault::{FaultGroup, FAULT_TABLE};
use hiperface_model::master::reference::{Action, Done, Event, ReferenceMaster};
use hiperface_model::slave::act::Act;
use hiperface_model::slave::inputs::{InitFault, PositionFault};
use hiperface_model::{profiles, CommandId, FaultCode, Profile};

mod joint;
mod search;

pub use joint::{Joint, Line};
pub use search::{is_must, play, search, Counterexample, Report, TraceStep, EVENT_KINDS};

/// The error codes the scenarios answer with (0Ah, 0Ch, 09h, 0Bh, 0Dh, 12h, 3Ah).
pub const CATALOGUE_CODES: [u8; 7] = [0x0A, 0x0C, 0x09, 0x0B, 0x0D, 0x12, 0x3A];

/// The acts of the search: the scenarios' (their codes, 30 ms late, a 20 ms and a
/// 4.5 ms pause, the position faults 22h and 20h, a restart) and an error reply with
/// the first code of each fault group of Table 74 that none of them represents
/// (000:T37, 000:T74). `None` first: the model's reply as it is.
pub fn acts() -> Vec<Option<Act>> {
    let mut codes: Vec<FaultCode> = CATALOGUE_CODES.iter().map(|b| FaultCode::decode(*b)).collect();
    for group in
        [FaultGroup::Initialization, FaultGroup::Protocol, FaultGroup::Data, FaultGroup::Position, FaultGroup::Others]
    {
        let represented = |c: &FaultCode| hiperface_model::fault::rows(*c).any(|r| r.group == group);
        if !codes.iter().any(represented) {
            if let Some(row) = FAULT_TABLE.iter().find(|r| r.group == group) {
                codes.push(row.code);
            }
        }
    }
    let mut acts: Vec<Act> = codes.into_iter().map(Act::Error).collect();
    acts.extend([
        Act::Silence,
        Act::CorruptChecksum,
        Act::LateMs(30),
        Act::Gap { before: 3, us: 20_000 },
        Act::Gap { before: 2, us: 4_500 },
        Act::PositionFault(PositionFault::MultiturnSync),
        Act::PositionFault(PositionFault::Singleturn),
        Act::Restart,
    ]);
    core::iter::once(None).chain(acts.into_iter().map(Some)).collect()
}

/// Whether the encoder may do `act` to the reply to `action`'s request: any act to any
/// request, but an error code instead of Read Encoder Status's reply, which reads as
/// a code on the stack (000:T27): what the stack holds is the slave model's, from
/// the worlds' start-up faults and temperature and the position faults injected.
pub fn applies(act: Option<Act>, action: &Action) -> bool {
    match (act, action) {
        (Some(Act::Error(_)), Action::Exchange { request, .. }) => {
            request.request.command() != CommandId::ReadEncoderStatus
        }
        _ => true,
    }
}

/// An encoder at power-on: the scenarios' worlds and encoders.
#[derive(Debug, Clone)]
pub struct World {
    pub name: &'static str,
    pub encoder: Profile,
    pub init_faults: Vec<InitFault>,
    /// Above the profile's temperature limit: 1Eh stacked, the warning bit set.
    pub hot: bool,
}

/// The worlds of the scenarios for an encoder of `profile`: calm; hot (1Eh); four codes
/// stacked (07h, 06h + 08h, 1Eh); a critical start-up fault (04h); type FFh (SKS36
/// with `profile`'s start-up timing, 000:T19); 38400 Bd stored.
pub fn worlds(profile: Profile) -> Vec<World> {
    let world =
        |name, encoder, init_faults: &[InitFault], hot| World { name, encoder, init_faults: init_faults.to_vec(), hot };
    let mut type_ff = profiles::sks36();
    type_ff.init_ms = profile.init_ms;
    type_ff.default_window_ms = profile.default_window_ms;
    type_ff.user_settings_ms = profile.user_settings_ms;
    type_ff.edition = profile.edition;
    let mut stored_38400 = profile;
    stored_38400.settings.baud = hiperface_model::settings::Baud::B38400;
    vec![
        world("calm", profile, &[], false),
        world("hot", profile, &[], true),
        world("four codes stacked", profile, &[InitFault::Watchdog, InitFault::Counter], true),
        world("critical at start", profile, &[InitFault::AnalogLimits], false),
        world("type FFh", type_ff, &[], false),
        world("38400 Bd stored", stored_38400, &[], false),
    ]
}

/// How the master under check steps: the reference master's [`reference_step`], or a
/// mutant's.
pub type MasterStep = fn(&mut ReferenceMaster, Done<'_>, &mut dyn FnMut(Event)) -> Action;

/// The reference master itself.
pub fn reference_step(m: &mut ReferenceMaster, done: Done<'_>, say: &mut dyn FnMut(Event)) -> Action {
    m.next(done, &mut |e| say(e))
}

/// The application's polling period of the search: the reference master's default on
/// the command line (`hiperface master --polling-period-ms`).
pub const POLLING_PERIOD_MS: u64 = 20;

/// The instant the canonical state's clock reads, µs: later than anything the observer
/// looks back (checked when the search starts).
pub const BASE_US: u64 = 10_000_000;

/// Deliberate defects, for showing what the search catches. Never the reference
/// master's behaviour: only a [`MasterStep`] passed to [`search`] runs them.
pub mod mutant {
    use super::*;
    use hiperface_model::master::reference::Aside;

    /// After Encoder Reset the master does not wait the timeout plus the
    /// initialization time (000:T29): it reads the status at once.
    pub fn no_reset_wait(m: &mut ReferenceMaster, done: Done<'_>, say: &mut dyn FnMut(Event)) -> Action {
        let action = m.next(done, &mut |e| say(e));
        match action {
            Action::WaitUntil(_) if m.flow().aside == Aside::ResetWait => {
                let now_us = m.flow().now_us;
                m.next(Done::Waited { now_us }, &mut |e| say(e))
            }
            other => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::master::reference::Stage;

    fn run(profile: Profile, master_step: MasterStep) -> Result<Report, Counterexample> {
        let r = search(profile, master_step, 2_000_000);
        match &r {
            Ok(r) => eprintln!("{r}; {} with a request inside a reply window (DESIGN:reply-window)", r.reply_window),
            Err(c) => eprintln!("{c}"),
        }
        r
    }

    /// Every act changed what the encoder did somewhere, and every reaction of the
    /// master was reached: the search is not vacuous.
    fn covers_every_act_and_reaction(r: &Report) {
        for (act, n) in &r.acts_applied {
            assert!(*n > 0, "{act:?} never applied: {r}");
        }
        for (kind, n) in EVENT_KINDS.iter().zip(r.events) {
            assert!(n > 0, "the master never reached '{kind}': {r}");
        }
        for stage in [
            Stage::StartUpStatus,
            Stage::TypeLabel,
            Stage::ExtendedTypeLabel,
            Stage::Version,
            Stage::Position { attempt: hiperface_model::master::reference::RETRIES },
            Stage::CycleReset,
            Stage::Period,
            Stage::StoppedWait,
            Stage::StoppedStatus,
        ] {
            assert!(r.stages.contains(&stage), "{stage:?} never reached: {r}");
        }
    }

    /// The current edition (SEK37): the reference master never breaks a must, never
    /// panics or hangs, and the search ends because no new joint state appears.
    #[test]
    fn the_reference_master_to_a_fixpoint_current_edition() {
        let r = run(profiles::sek37(), reference_step).unwrap_or_else(|c| panic!("{c}"));
        assert!(r.fixpoint && r.to_string().contains("fixpoint reached"), "{r}");
        covers_every_act_and_reaction(&r);
        documented(&r, "current (SEK37)");
    }

    /// The legacy edition (002).
    #[test]
    fn the_reference_master_to_a_fixpoint_legacy_edition() {
        let r = run(profiles::legacy_srs(), reference_step).unwrap_or_else(|c| panic!("{c}"));
        assert!(r.fixpoint && r.to_string().contains("fixpoint reached"), "{r}");
        covers_every_act_and_reaction(&r);
        documented(&r, "legacy (Legacy-SRS)");
    }

    /// The book's table says what this search finds (docs/src/verification.md).
    fn documented(r: &Report, row: &str) {
        let documented = crate::documented::figures("The reference master to a fixpoint", row).unwrap();
        let found = [r.states as u64, r.transitions, r.depth as u64];
        assert_eq!(documented, found, "the book's figures for {row} (states, transitions, levels) against {r}");
    }

    /// A master that talks at once after Encoder Reset is caught, with a short trace
    /// that ends in its request inside the initialization (000:T29).
    #[test]
    fn a_master_that_does_not_wait_after_reset_is_caught() {
        let c = run(profiles::sek37(), mutant::no_reset_wait).expect_err("the mutant breaks a must");
        assert!(c.what.contains("TooSoonAfterReset") && c.what.contains("000:T29/master"), "{c}");
        let last = c.trace.last().expect("a trace");
        assert!(
            matches!(last.action, Action::Exchange { request, .. } if request.request.command() == CommandId::ReadEncoderStatus),
            "{c}"
        );
        assert!(c.trace.iter().any(|s| s.events.iter().any(|e| matches!(e, Event::Reset(_)))), "{c}");
        assert!(c.trace.len() <= 12, "a short trace: {c}");
    }
}
