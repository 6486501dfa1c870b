//! What the slave decides on one frame: reply or silence (and why), the clause it
//! follows, the acceptable alternatives, and what goes on the wire when.

use crate::clause::Normative;
use crate::datalink::ReceivedFrame;
use crate::fault::FaultCode;
use crate::frame::Frame;
use crate::response::ResponseFrame;
use crate::settings::UartSettings;

/// Why the slave stays silent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Silence {
    /// The first byte is neither the own address nor FFh.
    NotAddressed,
    /// Initialization or change of settings: no UART communication. // 000:T9
    NotListening,
    /// Encoder Reset: no response. // 000:T29
    Reset,
}

/// The slave's decision on one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Reply {
    Frame(ResponseFrame),
    Silent(Silence),
}

/// Error codes, as a set (codes 00h...3Fh).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct CodeSet(u64);

impl CodeSet {
    pub fn insert(&mut self, code: FaultCode) {
        if let Some(bit) = 1u64.checked_shl(code.byte() as u32) {
            self.0 |= bit;
        }
    }

    pub fn contains(&self, code: FaultCode) -> bool {
        1u64.checked_shl(code.byte() as u32).is_some_and(|bit| self.0 & bit != 0)
    }

    pub fn is_empty(&self) -> bool {
        self.0 == 0
    }

    pub fn iter(&self) -> impl Iterator<Item = FaultCode> + '_ {
        (0u8..64).map(FaultCode::decode).filter(|c| self.contains(*c))
    }
}

/// The outcome of one frame: the preferred reply, the clause it follows, and the
/// other error codes whose conditions also hold (acceptable, graded NON-STRICT).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Outcome {
    pub reply: Reply,
    pub clause: Normative,
    pub also: CodeSet,
    /// UART settings that take effect right after this reply (67h). // 000:T33
    pub then_settings: Option<UartSettings>,
}

impl Outcome {
    pub(super) const NOT_LISTENING: Outcome = Outcome {
        reply: Reply::Silent(Silence::NotListening),
        clause: crate::clause::STATE_MACHINE,
        also: CodeSet(0),
        then_settings: None,
    };
}

/// A reply to put on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Transmission {
    pub frame: Frame,
    /// The first byte may start once the request's timeout has elapsed... // 000:2.2.2
    pub earliest_start_us: u64,
    /// ...and must start within the command's maximum response time. // 000:T8
    pub latest_start_us: u64,
    /// Send with these settings.
    pub settings: UartSettings,
    /// Then listen with these (67h).
    pub then_settings: Option<UartSettings>,
}

/// One processed frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    pub received: ReceivedFrame,
    pub outcome: Outcome,
    pub transmission: Option<Transmission>,
}
