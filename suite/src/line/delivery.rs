//! How much a line itself may have delayed an exchange, as measured beside it (the
//! harness's delivery probe beside a pseudo-terminal): what the timing grades take off
//! a device's lateness, so that what the line could explain is never charged to the
//! device.

/// How much the line itself may have delayed an exchange, each way, as measured beside
/// it, µs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct LineLate {
    /// The request on its way to the device.
    pub request_us: u64,
    /// The reply on its way back.
    pub reply_us: u64,
}

impl LineLate {
    pub const fn both_ways_us(self) -> u64 {
        self.request_us + self.reply_us
    }
}

/// What the probe saw over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DeliveryStats {
    pub samples: u64,
    pub max_us: u64,
    /// Samples delayed by more than a millisecond.
    pub over_1ms: u64,
}
