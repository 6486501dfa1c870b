//! The scenario catalogue for certifying a master: what the encoder does and when.
//! Every scenario is graded by the master's obligations (`model::master::obligations`);
//! its plan makes one situation happen so that the master's reaction can be seen.

use crate::certify::World;
use hiperface_model::clause::{self, Clause};
use hiperface_model::settings::Baud;
use hiperface_model::slave::inputs::{InitFault, PhysicalInputs, PositionFault};
use hiperface_model::{CommandId, FaultCode, Profile};

/// What the encoder does to one request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Act {
    /// Answer with this error code instead.
    Error(FaultCode),
    /// No reply at all.
    Silence,
    /// Start the reply this much after its earliest start (past the limit of 000:T10).
    LateMs(u16),
    /// A reply whose checksum is wrong.
    CorruptChecksum,
    /// A pause inside the reply before character `before`.
    Gap { before: usize, us: u64 },
    /// From this request on the encoder has this position fault.
    PositionFault(PositionFault),
    /// The encoder restarts (a brown-out): no reply, initialization, default settings.
    Restart,
}

/// The `nth` request (1, 2, ...) of command `on` gets `act`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Injection {
    pub on: CommandId,
    pub nth: u32,
    pub act: Act,
}

/// One scenario.
#[derive(Debug, Clone, Copy)]
pub struct Scenario {
    pub id: &'static str,
    pub title: &'static str,
    pub clauses: &'static [Clause],
    /// How long the master is watched from power-on, ms.
    pub duration_ms: u64,
    /// The encoder's world at power-on (inputs, start-up faults).
    pub world: fn(&Profile) -> World,
    pub plan: &'static [Injection],
    /// The request the plan waits for (its injection is void if the master never sends
    /// it: the scenario is then not applicable, with the reason).
    pub needs: Option<CommandId>,
    /// The encoder of this scenario, made from the run's profile (e.g. one with type
    /// code FFh, or with stored settings other than the default).
    pub encoder: Option<fn(Profile) -> Profile>,
}

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
    ($id:literal, $title:literal, [$($clause:ident),*], $ms:expr, $world:expr, $plan:expr, $needs:expr) => {
        Scenario {
            id: $id,
            title: $title,
            clauses: const { &[$(clause::$clause.clause()),*] },
            duration_ms: $ms,
            world: $world,
            plan: $plan,
            needs: $needs,
            encoder: None,
        }
    };
}

impl Scenario {
    /// The scenario is about what happens from power-on: the start-up scenarios, and
    /// a critical fault found at start-up.
    pub fn from_power_on(&self) -> bool {
        self.id.starts_with("startup.") || self.id == "fault.critical-at-start"
    }
}

/// The scenarios whose id matches `globs` (`*`, `?`, comma-separated; all without),
/// in run order.
pub fn chosen(globs: Option<&str>) -> Vec<Scenario> {
    catalogue().into_iter().filter(|s| globs.is_none_or(|g| crate::certify::glob_match(g, s.id))).collect()
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
            None
        ),
        Scenario {
            encoder: Some(|_| hiperface_model::profiles::sks36()),
            ..scenario!(
                "startup.extended-type-label",
                "An encoder of type FFh: the master reads the Extended Type Label",
                [MASTER_EXTENDED_TYPE_LABEL, MASTER_START_UP],
                1500,
                calm,
                &[],
                None
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
                None
            )
        },
        scenario!(
            "warning.one-code",
            "Replies carry the warning bit (1Eh stacked): the codes are read out",
            [MASTER_WARNING],
            1500,
            hot,
            &[],
            None
        ),
        scenario!(
            "warning.four-codes",
            "Four codes stacked (07h, 06h + 08h, 1Eh): all read out, no reset asked",
            [MASTER_WARNING, MASTER_READ_STATUS, MASTER_FAULT_REACTION],
            1500,
            four_stacked,
            &[],
            None
        ),
        scenario!(
            "protocol.checksum-error",
            "A Read Position is answered with 0Ah: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Error(FaultCode::Checksum) }],
            Some(POSITION)
        ),
        scenario!(
            "protocol.wrong-length",
            "A Read Position is answered with 0Ch: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Error(FaultCode::WrongLength) }],
            Some(POSITION)
        ),
        scenario!(
            "protocol.parity",
            "A Read Position is answered with 09h: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Error(FaultCode::Parity) }],
            Some(POSITION)
        ),
        scenario!(
            "protocol.unknown-command",
            "A Read Position is answered with 0Bh: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Error(FaultCode::UnknownCommand) }],
            Some(POSITION)
        ),
        scenario!(
            "protocol.argument",
            "A Read Position is answered with 0Dh: the master retries",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Error(FaultCode::WrongArgument) }],
            Some(POSITION)
        ),
        scenario!(
            "fault.multiturn-sync",
            "Read Position answers 22h: no further position reads",
            [MASTER_FAULT_REACTION],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::PositionFault(PositionFault::MultiturnSync) }],
            Some(POSITION)
        ),
        scenario!(
            "fault.unknown-code",
            "Read Position answers an unknown code (3Ah): the worst-case reaction",
            [MASTER_UNKNOWN_CODE],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Error(FaultCode::Unknown(0x3A)) }],
            Some(POSITION)
        ),
        scenario!(
            "fault.singleturn-persistent",
            "Read Position answers 20h from now on: retries, then SW resets, bounded",
            [MASTER_FAULT_REACTION],
            2500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::PositionFault(PositionFault::Singleturn) }],
            Some(POSITION)
        ),
        scenario!(
            "fault.critical-at-start",
            "A critical start-up fault (04h) on the stack: a SW reset follows",
            [MASTER_FAULT_REACTION, MASTER_RESET_WAIT],
            2000,
            broken_at_start,
            &[],
            None
        ),
        Scenario {
            encoder: Some(|_| hiperface_model::profiles::sks36()),
            ..scenario!(
                "fault.data-field",
                "Reading the Extended Type Label answers 12h (Data group, \"Check/change number.\"): the master goes on",
                [MASTER_FAULT_REACTION, MASTER_EXTENDED_TYPE_LABEL],
                1500,
                calm,
                &[Injection { on: CommandId::ReadData, nth: 1, act: Act::Error(FaultCode::WrongFieldNumber) }],
                Some(CommandId::ReadData)
            )
        },
        scenario!(
            "reply.silent",
            "A Read Position gets no reply: the master waits out the window, then goes on",
            [MASTER_PAUSE, MASTER_REPLY_WINDOW],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Silence }],
            Some(POSITION)
        ),
        scenario!(
            "reply.late",
            "A Read Position reply starts 30 ms late (past 000:T10's 10 ms): the master copes",
            [MASTER_CYCLE, MASTER_REPLY_WINDOW],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::LateMs(30) }],
            Some(POSITION)
        ),
        scenario!(
            "reply.corrupt",
            "A Read Position reply with a wrong checksum: the master does not use it",
            [MASTER_FRAME],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::CorruptChecksum }],
            Some(POSITION)
        ),
        scenario!(
            "reply.gap",
            "A gap of the timeout inside a reply",
            [MASTER_CHARACTER_GAP],
            1500,
            calm,
            &[Injection { on: POSITION, nth: 2, act: Act::Gap { before: 3, us: 8_000 } }],
            Some(POSITION)
        ),
        scenario!(
            "encoder.restart",
            "The encoder restarts during polling (no reply, 100 ms of initialization): the master recovers",
            [MASTER_FAULT_REACTION],
            2000,
            calm,
            &[Injection { on: POSITION, nth: 10, act: Act::Restart }],
            Some(POSITION)
        ),
        scenario!(
            "polling.long",
            "Five seconds of cyclic polling",
            [MASTER_CYCLIC, MASTER_FRAME, MASTER_PAUSE, MASTER_CHARACTER_GAP, MASTER_REPLY_WINDOW],
            5000,
            calm,
            &[],
            None
        ),
    ]
}
