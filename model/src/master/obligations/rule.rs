//! The rules of the master's obligations, what a broken one is reported as, and the
//! figures the rules are measured against.

use crate::clause::{self, Clause};
use crate::command::CommandId;

/// A rule of the master's obligations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Rule {
    /// A frame that is no request: too short, bad checksum, unknown command or wrong
    /// length for its command. // 000:2.3
    Malformed,
    /// The command byte's error bit is set: faults go from slave to master only.
    ErrorBit,
    /// The address byte has fixed bits wrong (and is not FFh). // 000:T5
    AddressFormat,
    /// A gap of at least the timeout inside one request split it. // 000:2.2.2
    GapInRequest,
    /// Two requests without the timeout's pause between them. // 000:2.2.2
    NoPause,
    /// A request while the encoder was still sending a reply that came in time.
    /// // 000:2.2
    TalksOverReply,
    /// A request before the reply window of the previous request closed, with no reply
    /// seen: a late reply would collide with it. // DESIGN:reply-window
    ReplyWindow,
    /// A character during initialization after power-on. // 000:T9, 000:3.3.1
    DuringInitialization,
    /// A character before the timeout plus the initialization time after Encoder Reset.
    /// // 000:T29
    TooSoonAfterReset,
    /// A request while the encoder changes its settings (no UART communication).
    /// // 000:T9, 000:3.3.1
    DuringSettingsChange,
    /// Position read before the status after power-on. // 000:3.3.1 (recommended)
    StatusNotRead,
    /// Replies carried the warning bit, and the master went on without reading the
    /// codes (50h) or resetting (53h). // 000:2.3.4 (recommended)
    WarningIgnored,
    /// A protocol error (09h...0Dh) was answered and the master did not retry.
    /// // 000:T74 "Retry command."
    NoRetry,
    /// The same request failed again and again without a reset. // 000:T74 "If error
    /// persists, SW reset of Slave."
    UnboundedRetry,
    /// A critical fault whose reaction is a SW reset, and the master went on without
    /// one. // 000:T74
    NoResetAfterCriticalFault,
    /// Position read again after a multiturn sync fault (22h: "Only use sine/cosine
    /// based position until shut-down"). // 000:T74
    PositionAfterSyncFault,
    /// An unknown fault code, and the master kept reading position without a reset.
    /// // 000:3.3.4
    UnknownCodeIgnored,
    /// The type label said FFh and the master read the position without reading the
    /// Extended Type Label (field FFh), where the encoder's parameters are. // 000:T19
    ExtendedTypeLabelNotRead,
    /// No request for longer than the polling period once the master has begun: faults
    /// go unseen, for the slave only indicates them in replies. // 000:3.2.2 (should)
    NoCyclicRequest,
    /// A request at a data rate other than the one the encoder listens at: the default
    /// settings until the default window has passed, the stored ones after it.
    /// // 000:3.3.1, 000:T9
    DataRate,
    /// A Read Data outside its data field: the offset past the field's end, or the
    /// offset plus the count over its size. Told by an encoder that knows its fields
    /// (the one `certify master` serves), never by a listener. // 000:T21
    ReadOutsideField,
    /// A Store Data outside its data field, as for Read Data. // 000:T22
    StoreOutsideField,
}

impl Rule {
    /// Every rule.
    pub const ALL: [Rule; 22] = [
        Rule::Malformed,
        Rule::ErrorBit,
        Rule::AddressFormat,
        Rule::GapInRequest,
        Rule::NoPause,
        Rule::TalksOverReply,
        Rule::ReplyWindow,
        Rule::DuringInitialization,
        Rule::TooSoonAfterReset,
        Rule::DuringSettingsChange,
        Rule::StatusNotRead,
        Rule::WarningIgnored,
        Rule::NoRetry,
        Rule::UnboundedRetry,
        Rule::NoResetAfterCriticalFault,
        Rule::PositionAfterSyncFault,
        Rule::UnknownCodeIgnored,
        Rule::ExtendedTypeLabelNotRead,
        Rule::NoCyclicRequest,
        Rule::DataRate,
        Rule::ReadOutsideField,
        Rule::StoreOutsideField,
    ];

    /// The clause the rule rests on; a FAIL only where it is normative.
    pub const fn clause(self) -> Clause {
        match self {
            Rule::Malformed => clause::MASTER_FRAME.clause(),
            Rule::ErrorBit => clause::MASTER_NO_FAULTS.clause(),
            Rule::AddressFormat => clause::ADDRESS.clause(),
            Rule::GapInRequest => clause::MASTER_CHARACTER_GAP.clause(),
            Rule::NoPause => clause::MASTER_PAUSE.clause(),
            Rule::TalksOverReply => clause::MASTER_CYCLE.clause(),
            Rule::ReplyWindow => clause::MASTER_REPLY_WINDOW,
            Rule::DuringInitialization | Rule::DuringSettingsChange | Rule::DataRate => {
                clause::MASTER_START_UP.clause()
            }
            Rule::TooSoonAfterReset => clause::MASTER_RESET_WAIT.clause(),
            Rule::StatusNotRead => clause::MASTER_READ_STATUS,
            Rule::WarningIgnored => clause::MASTER_WARNING,
            Rule::NoRetry | Rule::UnboundedRetry | Rule::NoResetAfterCriticalFault | Rule::PositionAfterSyncFault => {
                clause::MASTER_FAULT_REACTION
            }
            Rule::UnknownCodeIgnored => clause::MASTER_UNKNOWN_CODE,
            Rule::NoCyclicRequest => clause::MASTER_CYCLIC,
            Rule::ExtendedTypeLabelNotRead => clause::MASTER_EXTENDED_TYPE_LABEL,
            Rule::ReadOutsideField => clause::READ_DATA.clause(),
            Rule::StoreOutsideField => clause::STORE_DATA.clause(),
        }
    }

    /// What the rule says, for a report.
    pub const fn text(self) -> &'static str {
        match self {
            Rule::Malformed => "a frame that is no request",
            Rule::ErrorBit => "a request with the error bit set",
            Rule::AddressFormat => "an address byte that is no address",
            Rule::GapInRequest => "a gap of at least the timeout inside a request",
            Rule::NoPause => "no pause of the timeout between two requests",
            Rule::TalksOverReply => "a request while the encoder was replying",
            Rule::ReplyWindow => "a request before the reply window closed",
            Rule::DuringInitialization => "a request during the encoder's initialization",
            Rule::TooSoonAfterReset => "a request before the timeout plus 100 ms after Encoder Reset",
            Rule::DuringSettingsChange => "a request while the encoder changes its settings",
            Rule::StatusNotRead => "position read before the status after power-on",
            Rule::WarningIgnored => "the warning bit's codes not read out",
            Rule::NoRetry => "no retry after a protocol error",
            Rule::UnboundedRetry => "a failing request retried without bound",
            Rule::NoResetAfterCriticalFault => "no SW reset after a critical fault",
            Rule::PositionAfterSyncFault => "position read after a multiturn sync fault",
            Rule::UnknownCodeIgnored => "position read on after an unknown fault code",
            Rule::ExtendedTypeLabelNotRead => "type FFh, and position read without the Extended Type Label",
            Rule::DataRate => "a request at a data rate other than the encoder's",
            Rule::NoCyclicRequest => "no request within the polling period",
            Rule::ReadOutsideField => "a Read Data outside its data field (offset plus count over its size)",
            Rule::StoreOutsideField => "a Store Data outside its data field (offset plus count over its size)",
        }
    }
}

/// One broken rule: when, and the figure measured where there is one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Observation {
    pub rule: Rule,
    /// When the offending frame began (or the character, for timing rules), µs.
    pub at_us: u64,
    /// The gap, pause or lead measured, µs, where the rule is about time.
    pub measured_us: Option<u64>,
    /// The command of the offending request, where it has one.
    pub command: Option<CommandId>,
    /// The data rates, where the rule is about them.
    pub data_rates: Option<DataRates>,
}

/// The master's data rate against the encoder's, bits per second.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DataRates {
    pub master_bps: u32,
    pub encoder_bps: u32,
    /// The master's rate before, where its settings changed as it sent: the frame
    /// went out at this one or at `master_bps`, both other than the encoder's.
    pub changed_from_bps: Option<u32>,
}

/// How many requests a master may make after a reply before it reacts (reads the
/// warning's codes, resets after a critical fault).
pub const REACTION_REQUESTS: u8 = 3;
/// The polling period unless the user sets the application's: a request at least this
/// often is "a sufficient cyclic request" (000:3.2.2); the figure is a decision of
/// this project (docs/src/design.md).
pub const POLLING_PERIOD_MS: u32 = 1000;
/// How many times in a row the same request may fail before the master resets.
pub const RETRY_BOUND: u8 = 8;
