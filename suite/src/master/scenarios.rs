//! The scenario catalogue for certifying a master (what a scenario is: `scenario.rs`).
//! Every scenario is graded by the master's obligations (`model::master::obligations`);
//! its plan makes one situation happen so that the master's reaction can be seen.

use super::scenario::*;
use crate::world::World;
use hiperface_model::clause;
use hiperface_model::settings::Baud;
use hiperface_model::slave::inputs::{InitFault, PhysicalInputs, PositionFault};
use hiperface_model::{CommandId, FaultCode, Profile};

fn calm(_: &Profile) -> World {
    World::default()
}

fn hot(p: &Profile) -> World {
    // Above the profile's limit: the encoder stacks 1Eh and sets the warning bit.
    let inputs = PhysicalInputs { temperature_c: p.temperature_max_c + 5, ..PhysicalInputs::default() };
    World { inputs: Some(inputs), ..World::default() }
}

fn four_stacked(p: &Profile) -> World {
    // Four codes on the stack (000:2.3.4 holds four): 07h (watchdog reset: "Read and
    // delete message"), 06h + 08h (counter value corrupted: "Minor, -") and 1Eh
    // (temperature) — none asks for a reset (000:T74).
    World { init_faults: vec![InitFault::Watchdog, InitFault::Counter], ..hot(p) }
}

/// The run's encoder with 38400 Bd stored (000:T4: the data rate "can be programmed").
/// An encoder of type FFh (its parameters in the Extended Type Label, 000:T19): SKS36,
/// with the start-up timing of the encoder profile under which the run was asked for,
/// so that a master's start-up is graded against the same initialization in every
/// scenario (a master that talks at 90 ms met SKS36's 100 ms here, and the profile's
/// 200 ms elsewhere: its own start-up jitter decided).
fn type_ff(p: Profile) -> Profile {
    let mut e = hiperface_model::profiles::sks36();
    e.init_ms = p.init_ms;
    e.default_window_ms = p.default_window_ms;
    e.user_settings_ms = p.user_settings_ms;
    e
}

fn stored_38400(mut p: Profile) -> Profile {
    p.settings.baud = Baud::B38400;
    p
}

fn broken_at_start(_: &Profile) -> World {
    // 04h at start-up: Critical, "SW reset of Slave." (000:T74).
    World { init_faults: vec![InitFault::AnalogLimits], ..World::default() }
}

const POSITION: CommandId = CommandId::ReadPosition;

macro_rules! scenario {
    ($id:literal, $title:literal, [$($clause:ident),*], $ms:expr, $world:expr, $plan:expr,
     $situation:ident => $reaction:ident) => {
        Scenario {
            id: $id,
            title: $title,
            clauses: const { &[$(clause::$clause.clause()),*] },
            duration_ms: $ms,
            world: $world,
            plan: const { $plan },
            encoder: None,
            situation: Situation::$situation,
            reaction: Reaction::$reaction,
        }
    };
}

/// The scenarios whose id matches `globs` (`*`, `?`, comma-separated; all without),
/// in run order.
pub fn chosen(globs: Option<&str>) -> Vec<Scenario> {
    catalogue().into_iter().filter(|s| globs.is_none_or(|g| crate::verdict::glob_match(g, s.id))).collect()
}

/// Every scenario, in run order.
pub fn catalogue() -> Vec<Scenario> {
    vec![
        scenario!(
            "startup.default",
            "Start-up in default settings, then cyclic polling",
            [MASTER_START_UP, MASTER_READ_STATUS, MASTER_FRAME, MASTER_PAUSE, MASTER_CHARACTER_GAP],
            1500,
            calm,
            &[],
            Talked => GoesOn
        ),
        Scenario {
            encoder: Some(type_ff),
            ..scenario!(
                "startup.extended-type-label",
                "An encoder of type FFh: the master reads the Extended Type Label",
                [MASTER_EXTENDED_TYPE_LABEL, MASTER_START_UP],
                1500,
                calm,
                &[],
                TypeFfSent => ReadsExtendedTypeLabel
            )
        },
        Scenario {
            encoder: Some(stored_38400),
            ..scenario!(
                "startup.user-settings",
                "An encoder with 38400 Bd stored: default settings until the window passes, 38400 Bd from 1100 ms",
                [MASTER_START_UP],
                2000,
                calm,
                &[],
                TalkedAfterWindows => GoesOn
            )
        },
        scenario!(
            "warning.one-code",
            "Replies carry the warning bit (1Eh stacked): the codes are read out",
            [MASTER_WARNING],
            1500,
            hot,
            &[],
            WarningSent => ReadsCodes
        ),
        scenario!(
            "warning.four-codes",
            "Four codes stacked (07h, 06h + 08h, 1Eh): all read out, no reset asked",
            [MASTER_WARNING, MASTER_READ_STATUS, MASTER_FAULT_REACTION],
            1500,
            four_stacked,
            &[],
            WarningSent => ReadsCodes
        ),
        scenario!(
            "protocol.checksum-error",
            "A Read Position is answered with 0Ah: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Error(FaultCode::Checksum))],
            Injected => Retries
        ),
        scenario!(
            "protocol.wrong-length",
            "A Read Position is answered with 0Ch: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Error(FaultCode::WrongLength))],
            Injected => Retries
        ),
        scenario!(
            "protocol.parity",
            "A Read Position is answered with 09h: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Error(FaultCode::Parity))],
            Injected => Retries
        ),
        scenario!(
            "protocol.unknown-command",
            "A Read Position is answered with 0Bh: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Error(FaultCode::UnknownCommand))],
            Injected => Retries
        ),
        scenario!(
            "protocol.argument",
            "A Read Position is answered with 0Dh: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Error(FaultCode::WrongArgument))],
            Injected => Retries
        ),
        scenario!(
            "fault.multiturn-sync",
            "Read Position answers 22h: no further position reads",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::PositionFault(PositionFault::MultiturnSync))],
            Injected => GoesOn
        ),
        scenario!(
            "fault.unknown-code",
            "Read Position answers an unknown code (3Ah): the worst-case reaction",
            [MASTER_UNKNOWN_CODE],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Error(FaultCode::Unknown(0x3A)))],
            Injected => GoesOn
        ),
        scenario!(
            "fault.singleturn-persistent",
            "Read Position answers 20h from now on: retries, then SW resets, bounded",
            [MASTER_FAULT_REACTION],
            2500,
            calm,
            &[Injection::nth(POSITION, 2, Act::PositionFault(PositionFault::Singleturn))],
            Injected => Resets
        ),
        scenario!(
            "fault.critical-at-start",
            "A critical start-up fault (04h) on the stack: a SW reset follows",
            [MASTER_FAULT_REACTION, MASTER_RESET_WAIT],
            2000,
            broken_at_start,
            &[],
            WarningSent => Resets
        ),
        Scenario {
            encoder: Some(type_ff),
            ..scenario!(
                "fault.data-field",
                "Reading the Extended Type Label answers 12h (Data group, \"Check/change number.\"): the master goes on",
                [MASTER_FAULT_REACTION, MASTER_EXTENDED_TYPE_LABEL],
                1500,
                calm,
                &[Injection::nth(CommandId::ReadData, 1, Act::Error(FaultCode::WrongFieldNumber))],
                Injected => GoesOn
            )
        },
        scenario!(
            "reply.silent",
            "A Read Position gets no reply: the master waits out the window, then goes on",
            [MASTER_PAUSE, MASTER_REPLY_WINDOW],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Silence)],
            Injected => GoesOn
        ),
        scenario!(
            "reply.late",
            "A Read Position reply starts 30 ms late (past 000:T10's 10 ms): the master copes",
            [MASTER_CYCLE, MASTER_REPLY_WINDOW],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::LateMs(30))],
            Injected => GoesOn
        ),
        scenario!(
            "reply.corrupt",
            "A Read Position reply with a wrong checksum: the master does not use it",
            [MASTER_FRAME],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::CorruptChecksum)],
            Injected => GoesOn
        ),
        scenario!(
            "reply.gap",
            "A gap of 20 ms (over the timeout) inside a reply: the master takes the first part for a broken reply and goes on",
            [MASTER_CHARACTER_GAP],
            1500,
            calm,
            // 20 ms: far from when any master talks after a broken reply (a conformant
            // one after the timeout, 5.7 ms; one that ends a reply on a short silence
            // sooner), so that whether its next request meets the rest of the reply
            // depends on the master, not on a fraction of a millisecond of scheduling.
            &[Injection::nth(POSITION, 2, Act::Gap { before: 3, us: 20_000 })],
            Injected => GoesOn
        ),
        scenario!(
            "reply.gap-under-timeout",
            "A pause of 4.5 ms (about four characters, under the 5.7 ms timeout) inside a reply: the master waits it out",
            [MASTER_CYCLE, MASTER_PAUSE],
            1500,
            calm,
            &[Injection::nth(POSITION, 2, Act::Gap { before: 2, us: 4_500 })],
            Injected => GoesOn
        ),
        scenario!(
            "encoder.restart",
            "The encoder restarts during polling (no reply, 100 ms of initialization): the master recovers",
            [MASTER_FAULT_REACTION],
            2000,
            calm,
            &[Injection { on: POSITION, nth: 10, act: Act::Restart, or_after_ms: Some(1000) }],
            Injected => GoesOn
        ),
        scenario!(
            "polling.long",
            "Five seconds of cyclic polling",
            [MASTER_CYCLIC, MASTER_FRAME, MASTER_PAUSE, MASTER_CHARACTER_GAP, MASTER_REPLY_WINDOW],
            5000,
            calm,
            &[],
            Talked => GoesOn
        ),
    ]
}
