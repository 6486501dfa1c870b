//! The physical world and injected internal faults: explicit inputs of the model.

use crate::fault::FaultCode;

/// What the sensor sees. The caller sets these before the step they apply to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PhysicalInputs {
    /// Raw absolute position in steps (32 per period), before the Set Position offset;
    /// taken modulo the measuring range. The 5 LSBs are the sin/cos phase.
    pub position: u64,
    /// Shaft speed (rpm, or mm/s for linear devices); any non-zero value is motion.
    pub speed: i32,
    pub temperature_c: i16,
    pub led_current_ma: u16,
}

impl Default for PhysicalInputs {
    fn default() -> Self {
        PhysicalInputs { position: 0, speed: 0, temperature_c: 25, led_current_ma: 10 }
    }
}

/// Faults found at initialization (power-on or reset), while injected. // 000:T38-T46, 000:T74
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InitFault {
    /// 01h: singleturn resolution, multiturn range or calibration corrupted.
    AlignmentData,
    /// 02h: position offset or sensor synchronisation corrupted.
    AngularOffset,
    /// 03h: UART settings, memory size or access codes corrupted.
    PartitionTable,
    /// 04h: warning ranges corrupted.
    AnalogLimits,
    /// 05h: encoder type code corrupted.
    TypeCode,
    /// 07h: reset by the watchdog.
    Watchdog,
    /// 08h: counter value corrupted.
    Counter,
    /// 12h: Extended Type Label corrupted.
    ExtendedTypeLabel,
    /// 21h: multiturn parameters corrupted.
    MultiturnParameters,
}

/// What an initialization fault does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InitEffect {
    pub code: FaultCode,
    /// Stored "along with the internal checksum error" (06h), which then locks
    /// non-volatile memory commands. // 000:T44
    pub with_checksum_error: bool,
    /// Read/Set Position answer 02h until reset. // 000:T38, T40, T42, T56
    pub locks_position: bool,
    /// Data field commands answer 03h. // 000:T41
    pub locks_data_fields: bool,
}

impl InitFault {
    pub const ALL: [InitFault; 9] = [
        InitFault::AlignmentData,
        InitFault::AngularOffset,
        InitFault::PartitionTable,
        InitFault::AnalogLimits,
        InitFault::TypeCode,
        InitFault::Watchdog,
        InitFault::Counter,
        InitFault::ExtendedTypeLabel,
        InitFault::MultiturnParameters,
    ];

    /// The initialization fault table.
    pub const fn effect(self) -> InitEffect {
        use FaultCode as F;
        let (code, with_checksum_error, locks_position, locks_data_fields) = match self {
            InitFault::AlignmentData => (F::AlignmentData, true, true, false),
            InitFault::AngularOffset => (F::AngularOffset, true, true, false),
            InitFault::PartitionTable => (F::PartitionTable, true, false, true),
            InitFault::AnalogLimits => (F::AnalogLimits, true, true, false),
            InitFault::TypeCode => (F::I2cBus, true, false, false),
            InitFault::Watchdog => (F::Watchdog, false, false, false),
            InitFault::Counter => (F::CounterOverflow, true, false, false),
            InitFault::ExtendedTypeLabel => (F::WrongFieldNumber, true, true, false),
            InitFault::MultiturnParameters => (F::MultiturnAmplitude, true, false, false),
        };
        InitEffect { code, with_checksum_error, locks_position, locks_data_fields }
    }

    const fn bit(self) -> u16 {
        1 << self as u16
    }

    /// The fault's name in profiles, vectors and command lines.
    pub const fn name(self) -> &'static str {
        match self {
            InitFault::AlignmentData => "alignment-data",
            InitFault::AngularOffset => "angular-offset",
            InitFault::PartitionTable => "partition-table",
            InitFault::AnalogLimits => "analog-limits",
            InitFault::TypeCode => "type-code",
            InitFault::Watchdog => "watchdog",
            InitFault::Counter => "counter",
            InitFault::ExtendedTypeLabel => "extended-type-label",
            InitFault::MultiturnParameters => "multiturn-parameters",
        }
    }

    pub fn from_name(name: &str) -> Option<InitFault> {
        InitFault::ALL.iter().copied().find(|f| f.name() == name)
    }
}

/// Faults of the position measurement, reported on position commands while injected.
/// // 000:T39, T57, T61-T68
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PositionFault {
    /// 01h analog signals outside specification (not locking).
    AnalogSignals,
    /// 1Ch value monitoring analog signals (not locking).
    AnalogMonitoring,
    /// 20h singleturn unreliable (rotary, not locking) / sensor not adjusted (linear, locking).
    Singleturn,
    /// 21h multiturn amplitude / distance to measure too high (not locking).
    MultiturnAmplitude,
    /// 22h multiturn sync (locking).
    MultiturnSync,
    /// 23h vector length / linear position fault (not locking).
    MultiturnVectorLength,
    /// 24h multiturn counter (locking).
    MultiturnCounter,
}

impl PositionFault {
    pub const ALL: [PositionFault; 7] = [
        PositionFault::AnalogSignals,
        PositionFault::AnalogMonitoring,
        PositionFault::Singleturn,
        PositionFault::MultiturnAmplitude,
        PositionFault::MultiturnSync,
        PositionFault::MultiturnVectorLength,
        PositionFault::MultiturnCounter,
    ];

    pub const fn code(self) -> FaultCode {
        match self {
            PositionFault::AnalogSignals => FaultCode::AlignmentData,
            PositionFault::AnalogMonitoring => FaultCode::AnalogMonitoring,
            PositionFault::Singleturn => FaultCode::Singleturn,
            PositionFault::MultiturnAmplitude => FaultCode::MultiturnAmplitude,
            PositionFault::MultiturnSync => FaultCode::MultiturnSync,
            PositionFault::MultiturnVectorLength => FaultCode::MultiturnVectorLength,
            PositionFault::MultiturnCounter => FaultCode::MultiturnCounter,
        }
    }

    /// The fault's name in vectors and command lines.
    pub const fn name(self) -> &'static str {
        match self {
            PositionFault::AnalogSignals => "analog-signals",
            PositionFault::AnalogMonitoring => "analog-monitoring",
            PositionFault::Singleturn => "singleturn",
            PositionFault::MultiturnAmplitude => "multiturn-amplitude",
            PositionFault::MultiturnSync => "multiturn-sync",
            PositionFault::MultiturnVectorLength => "multiturn-vector-length",
            PositionFault::MultiturnCounter => "multiturn-counter",
        }
    }

    pub fn from_name(name: &str) -> Option<PositionFault> {
        PositionFault::ALL.iter().copied().find(|f| f.name() == name)
    }

    /// Whether the fault locks position output until reset (linear 20h does, 000:T62).
    pub const fn locks(self, linear: bool) -> bool {
        match self {
            PositionFault::MultiturnSync | PositionFault::MultiturnCounter => true,
            PositionFault::Singleturn => linear,
            _ => false,
        }
    }

    const fn bit(self) -> u16 {
        1 << self as u16
    }
}

/// The injected faults, as small bit sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct InjectedFaults {
    init: u16,
    position: u16,
    i2c: bool,
}

impl InjectedFaults {
    /// The internal I2C bus to the EEPROM is down: commands that use it answer 05h. // 000:T43
    pub fn set_i2c(&mut self, on: bool) {
        self.i2c = on;
    }

    pub const fn i2c(&self) -> bool {
        self.i2c
    }

    pub fn set_init(&mut self, fault: InitFault, on: bool) {
        if on {
            self.init |= fault.bit()
        } else {
            self.init &= !fault.bit()
        }
    }

    pub fn set_position(&mut self, fault: PositionFault, on: bool) {
        if on {
            self.position |= fault.bit()
        } else {
            self.position &= !fault.bit()
        }
    }

    // Every fault of the table with whether it is injected, rather than only the
    // injected ones: a loop over them has a fixed count, which a bounded model checker
    // bounds whatever it knows of the injected bits (a filtered loop it did not, in
    // the slave-step harnesses).
    pub fn init_faults(&self) -> [(InitFault, bool); InitFault::ALL.len()] {
        InitFault::ALL.map(|f| (f, self.init & f.bit() != 0))
    }

    pub fn position_faults(&self) -> [(PositionFault, bool); PositionFault::ALL.len()] {
        PositionFault::ALL.map(|f| (f, self.position & f.bit() != 0))
    }
}
