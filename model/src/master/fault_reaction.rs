//! Fault reaction of a master: severity and controller response per fault code and
//! group (000:T73, T74), with the master behaviour seen in 003 and 004.

use crate::fault::{self, FaultCode, FaultGroup, FaultRow, Severity, Variant};

/// What a master should do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reaction {
    pub severity: Severity,
    /// `None` where Table 74 prints "-": no action.
    pub response: Option<&'static str>,
    /// False for codes the table does not know: the worst case applies.
    pub known: bool,
}

/// "A HIPERFACE Master can only react with the worst-case fault reaction to unknown
/// fault codes (i.e. motor stop)." // 000:T74
pub const WORST_CASE: Reaction = Reaction {
    severity: Severity::Critical,
    response: Some("Stop the motor (worst-case reaction to an unknown fault code)."),
    known: false,
};

/// The reaction to `code`, in `group` where the code has several (e.g. 1Dh at
/// start-up, on a position command, or stacked), for a rotary encoder and the code
/// alone. Without a group, the most severe row of the code applies.
pub fn reaction(code: FaultCode, group: Option<FaultGroup>) -> Reaction {
    reaction_to(code, group, Variant::Any)
}

/// As [`reaction`], for the row of `variant`: a linear encoder's row, or 06h stacked
/// together with a narrowing code (000:T74 "06h + 08h"). Where the table has no row of
/// that variant, the code's own row applies.
pub fn reaction_to(code: FaultCode, group: Option<FaultGroup>, variant: Variant) -> Reaction {
    let in_group = |r: &&FaultRow| group.is_none_or(|g| r.group == g);
    let specific = fault::rows(code).filter(|r| variant != Variant::Any && r.variant == variant).find(in_group);
    let primary = || match group {
        Some(_) => fault::rows(code).filter(|r| r.primary()).find(in_group),
        None => fault::rows(code).filter(|r| r.primary()).max_by_key(|r| r.severity),
    };
    let chosen =
        specific.or_else(primary).or_else(|| fault::rows(code).filter(|r| r.primary()).max_by_key(|r| r.severity));
    match chosen {
        Some(r) => Reaction { severity: r.severity, response: r.controller_response, known: true },
        None => WORST_CASE,
    }
}

impl Reaction {
    /// Table 74 asks for a SW reset of the slave at once: a critical fault whose
    /// response begins "SW reset" (the initialization rows).
    pub fn is_reset(&self) -> bool {
        self.known && self.severity == Severity::Critical && self.response.is_some_and(|r| r.starts_with("SW reset"))
    }

    /// Table 74 asks to retry the command first.
    pub fn is_retry(&self) -> bool {
        self.response.is_some_and(|r| r.starts_with("Retry command."))
    }
}

/// The group of a code read from the stack with Read Encoder Status: one found at
/// start-up has its initialization row (000:T74 "SW reset of Slave"), any other its
/// runtime group.
pub fn stacked_group(code: FaultCode) -> Option<FaultGroup> {
    match fault::rows(code).any(|r| r.group == FaultGroup::Initialization) {
        true => Some(FaultGroup::Initialization),
        false => fault::runtime_group(code),
    }
}

/// The reactions to the codes read together from the stack (in any order): 06h stored
/// along with a code of a "06h + xx" row of Table 74 takes that row's reaction, and the
/// code with it has none of its own (000:T74 "06h + 08h: Minor, -").
pub fn stack_reactions(codes: &[FaultCode]) -> impl Iterator<Item = (FaultCode, Reaction)> + '_ {
    let has_pair = |x: FaultCode| fault::rows(FaultCode::InternalChecksum).any(|r| r.variant == Variant::With(x));
    let companion = codes.iter().copied().find(|&x| has_pair(x));
    let paired = codes.contains(&FaultCode::InternalChecksum);
    codes.iter().copied().filter(move |&c| !(paired && Some(c) == companion)).map(move |c| {
        let variant = match (c, companion) {
            (FaultCode::InternalChecksum, Some(x)) => Variant::With(x),
            _ => Variant::Any,
        };
        (c, reaction_to(c, stacked_group(c), variant))
    })
}

/// Master behaviour noted in the masters' manuals.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MasterNote {
    pub source: &'static str,
    pub note: &'static str,
}

pub const MASTER_NOTES: &[MasterNote] = &[
    MasterNote {
        source: "003 §10.2",
        note: "After a sin/cos fault the gateway sends an EMCY and goes on; when the fault clears the position is no longer consistent, and the absolute position is not re-read over RS-485 until a power cycle.",
    },
    MasterNote {
        source: "003 start-up",
        note: "The gateway reads the type label to learn rotary or linear, steps and range, and the absolute position once at power-up; detection takes up to 10 s, and CANopen starts whether it succeeded or not (EMCY on failure).",
    },
    MasterNote {
        source: "004 SinCosVssMin/Max",
        note: "The sin/cos amplitude must stay within 800...1200 mV (defaults), checked after a settle time of 100 ms.",
    },
    MasterNote {
        source: "004 HfErrorCode",
        note: "A missing reply is reported by the module as its own error id 255 (timeout), distinct from the slave's fault codes.",
    },
];

/// The sin/cos amplitude window of 004 (defaults 800...1200 mV, settle 100 ms).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AmplitudeWindow {
    pub min_mv: u32,
    pub max_mv: u32,
    pub settle_ms: u32,
}

impl Default for AmplitudeWindow {
    fn default() -> Self {
        AmplitudeWindow { min_mv: 800, max_mv: 1200, settle_ms: 100 }
    }
}

/// A master-side fault: the slave's code, or one of the master's own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MasterFault {
    Slave(FaultCode),
    /// The sin/cos amplitude (peak-peak, mV) left the window after the settle time.
    Amplitude {
        vpp_mv: u32,
    },
    /// No reply within the response time (004: error id 255).
    Timeout,
}

impl AmplitudeWindow {
    /// Check a peak-peak amplitude `ms` after power-on: `None` while settling or inside.
    pub fn check(&self, vpp_mv: u32, ms_since_power_on: u32) -> Option<MasterFault> {
        let outside = vpp_mv < self.min_mv || vpp_mv > self.max_mv;
        (ms_since_power_on >= self.settle_ms && outside).then_some(MasterFault::Amplitude { vpp_mv })
    }
}

/// The reaction to a master-side fault: the master's own faults are critical.
pub fn master_reaction(f: MasterFault) -> Reaction {
    match f {
        MasterFault::Slave(code) => reaction(code, None),
        MasterFault::Amplitude { .. } => Reaction {
            severity: Severity::Critical,
            response: Some("Sin/cos amplitude outside the window: stop using the incremental position; after it clears, re-reference (003 does not re-read until a power cycle)."),
            known: true,
        },
        MasterFault::Timeout => Reaction { severity: Severity::Major, response: Some("Retry the command; report a timeout (004: error id 255)."),
            known: true, },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use FaultCode as F;

    fn resets(codes: &[FaultCode]) -> bool {
        stack_reactions(codes).any(|(_, r)| r.is_reset())
    }

    #[test]
    fn codes_read_together_take_the_row_of_their_pair() {
        // 000:T74: "06h + 08h" Minor, "-"; "06h + 04h" Critical, "SW reset of Slave.";
        // 06h alone Critical, "SW reset of Slave."; in either order.
        assert!(!resets(&[F::InternalChecksum, F::CounterOverflow]));
        assert!(!resets(&[F::CounterOverflow, F::InternalChecksum]));
        assert!(resets(&[F::InternalChecksum, F::AnalogLimits]));
        assert!(resets(&[F::InternalChecksum]));
        // 08h's own row ("Reset user counter.") does not apply when it is 06h's pair.
        let mut pair = stack_reactions(&[F::InternalChecksum, F::CounterOverflow]);
        assert_eq!(pair.next().map(|(c, r)| (c, r.response)), Some((F::InternalChecksum, None)));
        assert!(pair.next().is_none());
        // 07h "Read and delete message." and 1Eh ask for no reset.
        assert!(!resets(&[F::Watchdog, F::Temperature]));
        assert!(!resets(&[F::Watchdog, F::InternalChecksum, F::CounterOverflow, F::Temperature]));
    }
}
