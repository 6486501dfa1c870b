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
