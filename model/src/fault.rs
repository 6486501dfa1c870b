//! Fault codes and the fault table. // 000:2.4.3, 000:T37-T68, 000:T73-T74

use core::fmt;

/// A warning or error code on the wire (Read Encoder Status byte, error response byte).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FaultCode {
    /// 00h: no fault (Read Encoder Status with an empty stack).
    NoFault,
    /// 01h: incorrect alignment data (initialization) / analog signals outside specification.
    AlignmentData,
    /// 02h: incorrect internal angular offset; also the answer of a locked position output.
    AngularOffset,
    /// 03h: data field partitioning table destroyed.
    PartitionTable,
    /// 04h: analog limit values not available.
    AnalogLimits,
    /// 05h: internal I2C bus not operational.
    I2cBus,
    /// 06h: internal checksum error.
    InternalChecksum,
    /// 07h: program watchdog fault.
    Watchdog,
    /// 08h: counter overflow.
    CounterOverflow,
    /// 09h: parity error (any UART fault).
    Parity,
    /// 0Ah: checksum error.
    Checksum,
    /// 0Bh: unknown command.
    UnknownCommand,
    /// 0Ch: wrong command length.
    WrongLength,
    /// 0Dh: wrong command argument.
    WrongArgument,
    /// 0Eh: read-only data field.
    ReadOnlyField,
    /// 0Fh: incorrect access code.
    WrongAccessCode,
    /// 10h: out of memory / fixed data field size.
    OutOfMemory,
    /// 11h: wrong data field offset.
    WrongOffset,
    /// 12h: wrong data field number.
    WrongFieldNumber,
    /// 1Ch: value monitoring analog signals.
    AnalogMonitoring,
    /// 1Dh: transmitter (LED) current critical.
    LedCurrent,
    /// 1Eh: encoder temperature critical.
    Temperature,
    /// 1Fh: speed too high.
    Speed,
    /// 20h: singleturn position unreliable / sensor not adjusted (linear).
    Singleturn,
    /// 21h: multiturn amplitude fault / distance measure to sensor too high (linear).
    MultiturnAmplitude,
    /// 22h: multiturn sync fault.
    MultiturnSync,
    /// 23h: multiturn vector length fault / linear position fault.
    MultiturnVectorLength,
    /// 24h: multiturn counter fault.
    MultiturnCounter,
    Unknown(u8),
}

impl FaultCode {
    /// Every named code, in code order.
    pub const ALL: [FaultCode; 28] = [
        FaultCode::NoFault,
        FaultCode::AlignmentData,
        FaultCode::AngularOffset,
        FaultCode::PartitionTable,
        FaultCode::AnalogLimits,
        FaultCode::I2cBus,
        FaultCode::InternalChecksum,
        FaultCode::Watchdog,
        FaultCode::CounterOverflow,
        FaultCode::Parity,
        FaultCode::Checksum,
        FaultCode::UnknownCommand,
        FaultCode::WrongLength,
        FaultCode::WrongArgument,
        FaultCode::ReadOnlyField,
        FaultCode::WrongAccessCode,
        FaultCode::OutOfMemory,
        FaultCode::WrongOffset,
        FaultCode::WrongFieldNumber,
        FaultCode::AnalogMonitoring,
        FaultCode::LedCurrent,
        FaultCode::Temperature,
        FaultCode::Speed,
        FaultCode::Singleturn,
        FaultCode::MultiturnAmplitude,
        FaultCode::MultiturnSync,
        FaultCode::MultiturnVectorLength,
        FaultCode::MultiturnCounter,
    ];

    pub const fn byte(self) -> u8 {
        match self {
            FaultCode::NoFault => 0x00,
            FaultCode::AlignmentData => 0x01,
            FaultCode::AngularOffset => 0x02,
            FaultCode::PartitionTable => 0x03,
            FaultCode::AnalogLimits => 0x04,
            FaultCode::I2cBus => 0x05,
            FaultCode::InternalChecksum => 0x06,
            FaultCode::Watchdog => 0x07,
            FaultCode::CounterOverflow => 0x08,
            FaultCode::Parity => 0x09,
            FaultCode::Checksum => 0x0A,
            FaultCode::UnknownCommand => 0x0B,
            FaultCode::WrongLength => 0x0C,
            FaultCode::WrongArgument => 0x0D,
            FaultCode::ReadOnlyField => 0x0E,
            FaultCode::WrongAccessCode => 0x0F,
            FaultCode::OutOfMemory => 0x10,
            FaultCode::WrongOffset => 0x11,
            FaultCode::WrongFieldNumber => 0x12,
            FaultCode::AnalogMonitoring => 0x1C,
            FaultCode::LedCurrent => 0x1D,
            FaultCode::Temperature => 0x1E,
            FaultCode::Speed => 0x1F,
            FaultCode::Singleturn => 0x20,
            FaultCode::MultiturnAmplitude => 0x21,
            FaultCode::MultiturnSync => 0x22,
            FaultCode::MultiturnVectorLength => 0x23,
            FaultCode::MultiturnCounter => 0x24,
            FaultCode::Unknown(b) => b,
        }
    }

    pub const fn decode(byte: u8) -> FaultCode {
        let mut i = 0;
        while i < Self::ALL.len() {
            if Self::ALL[i].byte() == byte {
                return Self::ALL[i];
            }
            i += 1;
        }
        FaultCode::Unknown(byte)
    }

    /// Name as 000 chapter 2.4.3 gives it (the rotary meaning where a code has two).
    pub const fn name(self) -> &'static str {
        match self {
            FaultCode::NoFault => "No fault",
            FaultCode::AlignmentData => "Incorrect alignment data",
            FaultCode::AngularOffset => "Incorrect internal angular offset",
            FaultCode::PartitionTable => "Data field partitioning table destroyed",
            FaultCode::AnalogLimits => "Analog limit values not available",
            FaultCode::I2cBus => "Internal I2C bus not operational",
            FaultCode::InternalChecksum => "Internal checksum error",
            FaultCode::Watchdog => "Program watchdog fault",
            FaultCode::CounterOverflow => "Counter overflow",
            FaultCode::Parity => "Parity error",
            FaultCode::Checksum => "Checksum error",
            FaultCode::UnknownCommand => "Unknown command",
            FaultCode::WrongLength => "Wrong command length",
            FaultCode::WrongArgument => "Wrong command argument",
            FaultCode::ReadOnlyField => "Read-only data field",
            FaultCode::WrongAccessCode => "Incorrect access code",
            FaultCode::OutOfMemory => "Out of memory fault",
            FaultCode::WrongOffset => "Wrong data field offset",
            FaultCode::WrongFieldNumber => "Wrong data field number",
            FaultCode::AnalogMonitoring => "Value monitoring analog signals",
            FaultCode::LedCurrent => "Transmitter current critical",
            FaultCode::Temperature => "Encoder temperature critical",
            FaultCode::Speed => "Speed too high",
            FaultCode::Singleturn => "Singleturn position unreliable",
            FaultCode::MultiturnAmplitude => "Multiturn amplitude fault",
            FaultCode::MultiturnSync => "Multiturn sync fault",
            FaultCode::MultiturnVectorLength => "Multiturn vectorlength fault",
            FaultCode::MultiturnCounter => "Multiturn counter fault",
            FaultCode::Unknown(_) => "Unknown fault code",
        }
    }
}

impl fmt::Display for FaultCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:02X}h ({})", self.byte(), self.name())
    }
}

/// Fault groups. // 000:T37
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FaultGroup {
    Initialization,
    Protocol,
    Data,
    Position,
    Others,
}

/// How a fault reaches the master. // 000:2.3.4
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Indication {
    ErrorResponse,
    WarningBit,
}

/// Severity. // 000:T73
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Severity {
    Minor,
    Major,
    Critical,
}

/// One row of the fault table (000 chapter 2.4.3 merged with Table 74).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultRow {
    pub code: FaultCode,
    pub group: FaultGroup,
    pub indication: Indication,
    pub severity: Severity,
    pub reference: &'static str,
    pub controller_response: &'static str,
}

macro_rules! rows {
    ($( $code:ident, $group:ident, $ind:ident, $sev:ident, $reference:literal, $resp:literal; )*) => {
        &[ $( FaultRow {
            code: FaultCode::$code,
            group: FaultGroup::$group,
            indication: Indication::$ind,
            severity: Severity::$sev,
            reference: $reference,
            controller_response: $resp,
        } ),* ]
    };
}

/// The fault table: one row per (code, group) of 000 Table 74, with the fault
/// indication of Tables 38-68.
pub const FAULT_TABLE: &[FaultRow] = rows![
    AlignmentData, Initialization, ErrorResponse, Critical, "Incorrect alignment data", "SW reset of Slave.";
    AlignmentData, Others, ErrorResponse, Major, "Analog signals outside specification", "Retry command. If error persists, SW reset of Slave.";
    AngularOffset, Initialization, ErrorResponse, Critical, "Incorrect internal angular offset", "SW reset of Slave.";
    AngularOffset, Position, ErrorResponse, Critical, "Position error (follow-up to previous error when reading position)", "Retry command. If error persists, SW reset of Slave.";
    PartitionTable, Initialization, ErrorResponse, Critical, "Data field partitioning table destroyed", "SW reset of Slave.";
    PartitionTable, Data, ErrorResponse, Critical, "Data field partitioning table destroyed", "Verify/restore contents of data fields.";
    AnalogLimits, Initialization, ErrorResponse, Critical, "Analog limit values not available", "SW reset of Slave.";
    I2cBus, Initialization, ErrorResponse, Critical, "Internal I2C bus not operational", "SW reset of Slave.";
    I2cBus, Position, ErrorResponse, Critical, "Internal I2C bus not operational", "Retry command. If error persists, SW reset of Slave.";
    InternalChecksum, Initialization, ErrorResponse, Critical, "Internal checksum error", "SW reset of Slave.";
    Watchdog, Initialization, ErrorResponse, Minor, "Program watchdog fault", "Read and delete message.";
    CounterOverflow, Others, ErrorResponse, Major, "Counter overflow", "Reset user counter.";
    Parity, Protocol, ErrorResponse, Major, "Parity error", "Retry command.";
    Checksum, Protocol, ErrorResponse, Major, "Checksum error", "Retry command.";
    UnknownCommand, Protocol, ErrorResponse, Major, "Unknown command", "Retry command.";
    WrongLength, Protocol, ErrorResponse, Major, "Wrong command length", "Retry command.";
    WrongArgument, Protocol, ErrorResponse, Major, "Wrong command argument", "Retry command.";
    ReadOnlyField, Data, ErrorResponse, Major, "Read-only data field", "Check/change status of data field.";
    WrongAccessCode, Data, ErrorResponse, Major, "Incorrect access code", "Check/change access code.";
    OutOfMemory, Data, ErrorResponse, Major, "Out of memory fault", "Reduce data field size.";
    WrongOffset, Data, ErrorResponse, Major, "Wrong data field offset", "Check/change offset.";
    WrongFieldNumber, Data, ErrorResponse, Major, "Wrong data field number", "Check/change number.";
    AnalogMonitoring, Position, ErrorResponse, Major, "Value monitoring analog signals", "Retry command. Alternative: Start position estimation/ride-through. If error persists, SW reset of Slave.";
    AnalogMonitoring, Others, ErrorResponse, Critical, "Value monitoring analog signals", "Retry command. If error persists, SW reset of Slave.";
    LedCurrent, Initialization, ErrorResponse, Critical, "Transmitter current critical", "SW reset of Slave.";
    LedCurrent, Position, ErrorResponse, Critical, "Transmitter current critical", "Retry command. If error persists, SW reset of Slave.";
    LedCurrent, Others, ErrorResponse, Critical, "Transmitter current critical", "Retry command. If error persists, SW reset of Slave.";
    Temperature, Others, WarningBit, Major, "Encoder temperature critical", "Change motion profile to fit temperature range.";
    Speed, Position, ErrorResponse, Major, "Speed too high", "Check that maximum allowed speed for HIPERFACE position read-out is considered.";
    Singleturn, Initialization, ErrorResponse, Critical, "Singleturn position unreliable", "SW reset of Slave.";
    Singleturn, Position, ErrorResponse, Critical, "Singleturn position unreliable / Sensor not adjusted or in adjustment mode", "Retry command. If error persists, SW reset of Slave.";
    MultiturnAmplitude, Initialization, ErrorResponse, Critical, "Multiturn amplitude fault", "SW reset of Slave.";
    MultiturnAmplitude, Position, ErrorResponse, Critical, "Multiturn amplitude fault / Distance measure/sensor too high", "Retry command. If error persists, SW reset of Slave.";
    MultiturnSync, Position, ErrorResponse, Critical, "Multiturn sync fault", "Only use sine/cosine based position until shut-down. Replace Slave.";
    MultiturnVectorLength, Position, ErrorResponse, Critical, "Multiturn vectorlength fault / Linear position fault", "Retry command. If error persists, SW reset of Slave.";
    MultiturnCounter, Position, ErrorResponse, Critical, "Multiturn counter fault", "Retry command. If error persists, SW reset of Slave.";
];

/// The rows for one code (several where the code has several groups).
pub fn rows(code: FaultCode) -> impl Iterator<Item = &'static FaultRow> {
    FAULT_TABLE.iter().filter(move |r| r.code == code)
}

/// The group a code is stacked or answered in during operation (not at start-up).
pub fn runtime_group(code: FaultCode) -> Option<FaultGroup> {
    let mut fallback = None;
    for r in rows(code) {
        if r.group != FaultGroup::Initialization {
            return Some(r.group);
        }
        fallback = Some(r.group);
    }
    fallback
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_for_every_byte() {
        for b in 0..=255u8 {
            assert_eq!(FaultCode::decode(b).byte(), b);
        }
        assert_eq!(FaultCode::decode(0x13), FaultCode::Unknown(0x13));
    }

    #[test]
    fn table_74_has_a_row_for_every_named_code_but_none() {
        for code in FaultCode::ALL.iter().skip(1) {
            assert!(rows(*code).next().is_some(), "{code}");
        }
        assert_eq!(rows(FaultCode::Temperature).next().map(|r| r.indication), Some(Indication::WarningBit));
        assert_eq!(runtime_group(FaultCode::Checksum), Some(FaultGroup::Protocol));
        assert_eq!(runtime_group(FaultCode::InternalChecksum), Some(FaultGroup::Initialization));
    }
}
