//! Fault codes and the fault table. // 000:2.4.3, 000:T37-T68, 000:T73-T74

use crate::clause::{self, Normative};
use core::fmt;

/// Declares the fault codes once: the `FaultCode` enum, `ALL`, the byte mapping,
/// decoding and names, from one row per code of 000 chapter 2.4.3.
macro_rules! fault_codes {
    ($( $byte:literal $code:ident $name:literal $clause:ident $(, $doc:literal)?; )*) => {
        /// A warning or error code on the wire (Read Encoder Status byte, error response byte).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum FaultCode {
            $( #[doc = $name] $(#[doc = $doc])? $code, )*
            Unknown(u8),
        }

        impl FaultCode {
            /// Every named code, in code order.
            pub const ALL: &'static [FaultCode] = &[ $( FaultCode::$code, )* ];

            pub const fn byte(self) -> u8 {
                match self {
                    $( FaultCode::$code => $byte, )*
                    FaultCode::Unknown(b) => b,
                }
            }

            pub const fn decode(byte: u8) -> FaultCode {
                match byte {
                    $( $byte => FaultCode::$code, )*
                    b => FaultCode::Unknown(b),
                }
            }

            /// The clause of the code's own table (000:T38-T68); `None` for unknown codes.
            pub const fn clause(self) -> Option<Normative> {
                match self {
                    $( FaultCode::$code => Some(clause::$clause), )*
                    FaultCode::Unknown(_) => None,
                }
            }

            /// Name as 000 chapter 2.4.3 gives it (the rotary meaning where a code has two).
            pub const fn name(self) -> &'static str {
                match self {
                    $( FaultCode::$code => $name, )*
                    FaultCode::Unknown(_) => "Unknown fault code",
                }
            }
        }
    };
}

// One row per code: byte, name (000:2.4.3), the clause of its own table, and where 000
// gives a code a second meaning (linear encoders, operation instead of
// initialization), that meaning.
fault_codes! {
    0x00 NoFault "No fault" READ_ENCODER_STATUS, "Read Encoder Status with an empty stack.";
    0x01 AlignmentData "Incorrect alignment data" INIT_FAULTS, "Also: analog signals outside specification (operation).";
    0x02 AngularOffset "Incorrect internal angular offset" INIT_FAULTS, "Also the answer of a locked position output.";
    0x03 PartitionTable "Data field partitioning table destroyed" INIT_FAULTS;
    0x04 AnalogLimits "Analog limit values not available" INIT_FAULTS;
    0x05 I2cBus "Internal I2C bus not operational" I2C_BUS;
    0x06 InternalChecksum "Internal checksum error" NV_LOCK;
    0x07 Watchdog "Program watchdog fault" INIT_FAULTS;
    0x08 CounterOverflow "Counter overflow" COUNTER_OVERFLOW;
    0x09 Parity "Parity error" PARITY_ERROR, "Any UART fault.";
    0x0A Checksum "Checksum error" CHECKSUM_ERROR;
    0x0B UnknownCommand "Unknown command" UNKNOWN_COMMAND;
    0x0C WrongLength "Wrong command length" WRONG_LENGTH;
    0x0D WrongArgument "Wrong command argument" WRONG_ARGUMENT;
    0x0E ReadOnlyField "Read-only data field" READ_ONLY_FIELD;
    0x0F WrongAccessCode "Incorrect access code" WRONG_ACCESS_CODE;
    0x10 OutOfMemory "Out of memory fault" OUT_OF_MEMORY, "Also: fixed data field size.";
    0x11 WrongOffset "Wrong data field offset" WRONG_OFFSET;
    0x12 WrongFieldNumber "Wrong data field number" WRONG_FIELD_NUMBER;
    0x1C AnalogMonitoring "Value monitoring analog signals" ANALOG_MONITORING;
    0x1D LedCurrent "Transmitter current critical" LED_CURRENT, "The transmitter is the LED.";
    0x1E Temperature "Encoder temperature critical" TEMPERATURE;
    0x1F Speed "Speed too high" SPEED;
    0x20 Singleturn "Singleturn position unreliable" POSITION_FAULTS, "Linear: sensor not adjusted.";
    0x21 MultiturnAmplitude "Multiturn amplitude fault" POSITION_FAULTS, "Linear: distance measure to sensor too high.";
    0x22 MultiturnSync "Multiturn sync fault" POSITION_FAULTS;
    0x23 MultiturnVectorLength "Multiturn vectorlength fault" POSITION_FAULTS, "Linear: position fault.";
    0x24 MultiturnCounter "Multiturn counter fault" POSITION_FAULTS;
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

/// Which encoders, or which companion code, a row of Table 74 is about: the printed
/// table has two rows for one code and group where rotary and linear encoders react
/// differently, and rows "06h + 01h" for an internal checksum error stacked together
/// with the code that narrows it down (000:T44 note).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Variant {
    /// Every encoder.
    Any,
    /// Rotary encoders, where the row has a linear counterpart.
    Rotary,
    /// Linear encoders.
    Linear,
    /// The code stacked together with another.
    With(FaultCode),
}

/// One row of the fault table (000 chapter 2.4.3 merged with Table 74).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultRow {
    pub code: FaultCode,
    pub variant: Variant,
    pub group: FaultGroup,
    pub indication: Indication,
    pub severity: Severity,
    pub reference: &'static str,
    /// `None` where the table prints "-".
    pub controller_response: Option<&'static str>,
}

impl FaultRow {
    /// A row for the code alone on a rotary encoder (the rows a master without more
    /// context reacts by).
    pub const fn primary(&self) -> bool {
        matches!(self.variant, Variant::Any | Variant::Rotary)
    }
}

macro_rules! rows {
    (@variant) => { Variant::Any };
    (@variant rotary) => { Variant::Rotary };
    (@variant linear) => { Variant::Linear };
    (@variant + $with:ident) => { Variant::With(FaultCode::$with) };
    (@response -) => { None };
    (@response $r:literal) => { Some($r) };
    ($( $code:ident $([$($variant:tt)+])?, $group:ident, $ind:ident, $sev:ident, $reference:literal, $resp:tt; )*) => {
        &[ $( FaultRow {
            code: FaultCode::$code,
            variant: rows!(@variant $($($variant)+)?),
            group: FaultGroup::$group,
            indication: Indication::$ind,
            severity: Severity::$sev,
            reference: $reference,
            controller_response: rows!(@response $resp),
        } ),* ]
    };
}

/// The fault table: 000 Table 74 row by row in printed order, with the fault indication
/// of Tables 38-68.
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
    InternalChecksum [+ AlignmentData], Initialization, ErrorResponse, Critical, "CRC error; position invalid", "SW reset of Slave.";
    InternalChecksum [+ AngularOffset], Initialization, ErrorResponse, Critical, "CRC error; position/multi-turn invalid", "SW reset of Slave.";
    InternalChecksum [+ PartitionTable], Initialization, ErrorResponse, Critical, "CRC error; wrong HIPERFACE settings", "SW reset of Slave.";
    InternalChecksum [+ AnalogLimits], Initialization, ErrorResponse, Critical, "CRC error; invalid limit values", "SW reset of Slave.";
    InternalChecksum [+ I2cBus], Initialization, ErrorResponse, Critical, "CRC error; invalid Slave type label", "SW reset of Slave.";
    InternalChecksum [+ CounterOverflow], Initialization, ErrorResponse, Minor, "CRC error; invalid user counter value", -;
    InternalChecksum [+ WrongFieldNumber], Initialization, ErrorResponse, Critical, "CRC error; extended type label invalid", "SW reset of Slave.";
    InternalChecksum [+ MultiturnAmplitude], Initialization, ErrorResponse, Critical, "CRC error; multiturn parameters invalid", "SW reset of Slave.";
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
    Singleturn [rotary], Position, ErrorResponse, Critical, "Singleturn position unreliable", "Retry command. If error persists, SW reset of Slave.";
    Singleturn [linear], Position, ErrorResponse, Critical, "Sensor not adjusted or in adjustment mode", "Check sensor mode. Retry command. If error persists, SW reset of Slave.";
    MultiturnAmplitude, Initialization, ErrorResponse, Critical, "Multiturn amplitude fault", "SW reset of Slave.";
    MultiturnAmplitude [rotary], Position, ErrorResponse, Critical, "Multiturn amplitude fault", "Retry command. If error persists, SW reset of Slave.";
    MultiturnAmplitude [linear], Position, ErrorResponse, Critical, "Distance measure/sensor too high", "Check assembly of sensor.";
    MultiturnSync, Position, ErrorResponse, Critical, "Multiturn sync fault", "Only use sine/cosine based position until shut-down. Replace Slave.";
    MultiturnVectorLength [rotary], Position, ErrorResponse, Critical, "Multiturn vectorlength fault", "Retry command. If error persists, SW reset of Slave.";
    MultiturnVectorLength [linear], Position, ErrorResponse, Critical, "Linear position fault", "Retry command. If error persists, SW reset of Slave.";
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
    fn table_74_has_every_printed_row() {
        // 000:T74 prints 47 rows: 36 for codes alone on any or a rotary encoder, 8 for
        // 06h with a narrowing code, and 3 for linear encoders.
        assert_eq!(FAULT_TABLE.len(), 47);
        assert_eq!(FAULT_TABLE.iter().filter(|r| matches!(r.variant, Variant::With(_))).count(), 8);
        assert_eq!(FAULT_TABLE.iter().filter(|r| r.variant == Variant::Linear).count(), 3);
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
