//! What a scenario of master certification is: the encoder's acts on the master's
//! requests, when they happen, the situation they make, and the reaction a master
//! should show. The catalogue itself is `scenarios.rs`.

use crate::world::World;
use hiperface_model::clause::{self, Clause};
use hiperface_model::master::obligations::Rule;
use hiperface_model::request::Request;
use hiperface_model::request::RequestFrame;
use hiperface_model::{CommandId, Profile};

/// What the encoder does to one request: the model's definition, shared with the
/// search of the reference master to a fixpoint (proofs/src/master_fixpoint/).
pub use hiperface_model::slave::act::Act;

/// The `nth` request (1, 2, ...) of command `on` gets `act`, or, where `or_after_ms`
/// is given and comes first, the first request of `on` from that time (ms since
/// power-on): a master polling slowly, as 000 allows up to the application's period,
/// meets the situation all the same.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Injection {
    pub on: CommandId,
    pub nth: u32,
    pub act: Act,
    pub or_after_ms: Option<u32>,
}

impl Injection {
    /// The `nth` request of `on` gets `act`.
    pub const fn nth(on: CommandId, nth: u32, act: Act) -> Injection {
        Injection { on, nth, act, or_after_ms: None }
    }

    /// Whether the `n`th request of `command`, received at `at_us`, gets the act;
    /// `done`: it was given already in this run.
    pub fn due(&self, command: CommandId, n: u32, at_us: u64, done: bool) -> bool {
        let by_time = self.or_after_ms.is_some_and(|t| at_us >= u64::from(t) * 1000);
        command == self.on && !done && (n == self.nth || by_time)
    }
}

/// What a scenario is about: the situation its plan or world creates. Until it has
/// arisen nothing about it was seen, and the scenario is NOT-EXERCISED.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Situation {
    /// The master talked to the encoder (its start-up).
    Talked,
    /// The master talked once the start-up windows had passed (the stored settings).
    TalkedAfterWindows,
    /// A reply carried the warning bit.
    WarningSent,
    /// The type label said FFh.
    TypeFfSent,
    /// The plan's injection took place.
    Injected,
}

impl Situation {
    /// What did not happen, for the certificate.
    pub fn missing(self, s: &Scenario) -> String {
        match self {
            Situation::Talked => "the master never sent a request".into(),
            Situation::TalkedAfterWindows => "the master sent no request after the start-up windows".into(),
            Situation::WarningSent => "no reply with the warning bit went out: the master sent no request".into(),
            Situation::TypeFfSent => "the master never read the type label (52h), so never saw type FFh".into(),
            Situation::Injected => match s.plan.first() {
                Some(i) => match i.or_after_ms {
                    Some(t) => format!(
                        "the master sent neither request {} of {} nor one from {t} ms on, which the fault is injected on",
                        i.nth, i.on
                    ),
                    None => {
                        format!("the master never sent request {} of {}, which the fault is injected on", i.nth, i.on)
                    }
                },
                None => "nothing was injected".into(),
            },
        }
    }
}

/// The reaction a scenario expects once its situation has arisen, each from a
/// recommendation of 000 (NON-STRICT when not seen, by the force of its clause).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reaction {
    /// The master goes on talking (polling resumes): 000:3.2.2.
    GoesOn,
    /// The same command again: "Retry command." (000:T74).
    Retries,
    /// The codes read out (50h) or the encoder reset (53h): 000:2.3.4.
    ReadsCodes,
    /// A SW reset of the encoder (53h): 000:T74, 000:3.3.4.
    Resets,
    /// The Extended Type Label read (4Ah on field FFh): 000:T19.
    ReadsExtendedTypeLabel,
}

impl Reaction {
    pub fn clause(self) -> Clause {
        match self {
            Reaction::GoesOn => clause::MASTER_CYCLIC.clause(),
            Reaction::Retries | Reaction::Resets => clause::MASTER_FAULT_REACTION.clause(),
            Reaction::ReadsCodes => clause::MASTER_WARNING.clause(),
            Reaction::ReadsExtendedTypeLabel => clause::MASTER_EXTENDED_TYPE_LABEL.clause(),
        }
    }

    /// The observer's rules that judge this reaction already once the master talks
    /// on: where one of them was broken, "not seen" would say it twice.
    pub fn judged_by(self) -> &'static [Rule] {
        match self {
            Reaction::GoesOn => &[Rule::NoCyclicRequest],
            Reaction::Retries => &[Rule::NoRetry],
            Reaction::ReadsCodes => &[Rule::WarningIgnored],
            Reaction::Resets => &[Rule::NoResetAfterCriticalFault, Rule::UnboundedRetry],
            Reaction::ReadsExtendedTypeLabel => &[Rule::ExtendedTypeLabelNotRead],
        }
    }

    /// Whether `request` (after the situation) is the reaction; `on`: the command the
    /// plan injects on.
    pub fn seen_in(self, request: &RequestFrame, on: Option<CommandId>) -> bool {
        let command = request.request.command();
        match self {
            Reaction::GoesOn => true,
            Reaction::Retries => Some(command) == on,
            Reaction::ReadsCodes => matches!(command, CommandId::ReadEncoderStatus | CommandId::EncoderReset),
            Reaction::Resets => command == CommandId::EncoderReset,
            Reaction::ReadsExtendedTypeLabel => matches!(request.request, Request::ReadData { field: 0xFF, .. }),
        }
    }

    pub fn text(self) -> &'static str {
        match self {
            Reaction::GoesOn => "a request after it (polling goes on)",
            Reaction::Retries => "the request retried",
            Reaction::ReadsCodes => "the codes read out (50h) or a reset (53h)",
            Reaction::Resets => "a SW reset (53h)",
            Reaction::ReadsExtendedTypeLabel => "the Extended Type Label read (4Ah, field FFh)",
        }
    }
}

/// How long after its situation a scenario goes on at least, beyond the polling
/// period: time for the reaction, and for the polling rule to see a silence.
pub const REACTION_MARGIN_MS: u64 = 300;

/// One scenario.
#[derive(Debug, Clone, Copy)]
pub struct Scenario {
    pub id: &'static str,
    pub title: &'static str,
    pub clauses: &'static [Clause],
    /// How long the master is watched from power-on at least, ms; longer where the
    /// situation arises late ([`Scenario::end_ms`]).
    pub duration_ms: u64,
    /// The encoder's world at power-on (inputs, start-up faults).
    pub world: fn(&Profile) -> World,
    pub plan: &'static [Injection],
    /// The encoder of this scenario, made from the run's profile (e.g. one with type
    /// code FFh, or with stored settings other than the default).
    pub encoder: Option<fn(Profile) -> Profile>,
    /// What the scenario is about: until it arises, the scenario is NOT-EXERCISED.
    pub situation: Situation,
    /// What a master should do once it has.
    pub reaction: Reaction,
}

impl Scenario {
    /// When the scenario ends, ms since power-on: its duration, or later when its
    /// situation arose at `situation_ms`, so that the reaction and a polling period
    /// after it are seen.
    ///
    /// Until then, a plan that injects by time waits for a master polling at the
    /// period: its time, a period and the margin.
    pub fn end_ms(&self, situation_ms: Option<u64>, polling_period_ms: u32) -> u64 {
        let period = polling_period_ms as u64;
        let after = match situation_ms {
            Some(t) => t + period + REACTION_MARGIN_MS,
            None => self
                .plan
                .iter()
                .filter_map(|i| i.or_after_ms)
                .map(|t| u64::from(t) + period + REACTION_MARGIN_MS)
                .max()
                .unwrap_or(0),
        };
        self.duration_ms.max(after)
    }

    /// The commands this scenario needs the master to send: those its plan acts on,
    /// and those its situation and reaction are about. A master that declares it never
    /// sends one of them (`--not-used`) has the scenario NOT-APPLICABLE.
    pub fn commands(&self) -> Vec<CommandId> {
        let mut c: Vec<CommandId> = self.plan.iter().map(|i| i.on).collect();
        if self.situation == Situation::TypeFfSent {
            c.push(CommandId::ReadTypeLabel);
        }
        if self.reaction == Reaction::ReadsExtendedTypeLabel {
            c.push(CommandId::ReadData); // 000:T19: the Extended Type Label is data field FFh
        }
        c.dedup();
        c
    }

    /// The scenario is about what happens from power-on: the start-up scenarios, and
    /// a critical fault found at start-up.
    pub fn from_power_on(&self) -> bool {
        self.id.starts_with("startup.") || self.id == "fault.critical-at-start"
    }
}
