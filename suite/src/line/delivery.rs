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

/// How long the device's own processor was held while an exchange ran, where the
/// device runs on the harness's machine (a program or an emulator at a
/// pseudo-terminal's other end). Such a device takes a request one character at a time
/// as it runs: held for a timeout between two of them, it hears the request in two
/// parts (000:2.2.2) and answers the first as a damaged frame, or not at all; held
/// later, it replies late. A device with a processor of its own (a real port, a device
/// server) is never held by this machine: zero there.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DeviceHeld {
    /// From the request's write until the device had heard it and its timeout had
    /// elapsed (the request's characters and the longest timeout after them): what
    /// could have split the request.
    #[serde(default)]
    pub request: Hold,
    /// From the request's write to the exchange's end: what could have delayed the
    /// reply, or paused it.
    #[serde(default)]
    pub exchange: Hold,
}

impl DeviceHeld {
    pub const fn is_zero(&self) -> bool {
        self.request.is_zero() && self.exchange.is_zero()
    }
}

/// How long this machine may have held a device over a span, µs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Hold {
    /// Its process's run delay: how long its threads waited for one of this machine's
    /// processors (summed over its threads, an upper bound).
    #[serde(default)]
    pub waited_us: u64,
    /// The longest any of this machine's processors stopped (a sentinel at a real-time
    /// priority on each saw no time pass: the hypervisor's pauses, or whatever else
    /// stopped it): the device's process may have been on it.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub paused_us: u64,
    /// Where no sentinel runs (a real-time priority not permitted): the processor time
    /// this machine's hypervisor took (steal, counted in the kernel's 10 ms steps,
    /// summed over the processors).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub steal_us: u64,
}

/// Whether `n` is zero (a field left out of a record when it is).
pub(crate) fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl Hold {
    pub const fn is_zero(&self) -> bool {
        self.waited_us == 0 && self.paused_us == 0 && self.steal_us == 0
    }

    /// The longest the device may have been held in one piece: its wait, the longest
    /// pause of a processor, and the hypervisor's steal, whose 10 ms steps can stand
    /// for up to one step more.
    pub const fn at_most_us(&self) -> u64 {
        let steal = if self.steal_us > 0 { self.steal_us + STEAL_STEP_US } else { 0 };
        self.waited_us + self.paused_us + steal
    }
}

/// The step `/proc/stat` counts steal in (USER_HZ, 100 a second: proc(5)), µs.
pub const STEAL_STEP_US: u64 = 10_000;

/// What the probe saw over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DeliveryStats {
    pub samples: u64,
    pub max_us: u64,
    /// Samples delayed by more than a millisecond.
    pub over_1ms: u64,
}
