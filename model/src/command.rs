//! The command byte and the command table. // 000:T6, 000:T8, 000:T10, 002 command overview

use crate::clause::{self, Normative};
use crate::fault::FaultCode::{self, *};
use core::fmt;

/// A command identifier (command byte without the error bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CommandId {
    ReadPosition,
    SetPosition,
    ReadAnalogValue,
    ReadCounter,
    IncrementCounter,
    ResetCounter,
    ReadData,
    StoreData,
    DataFieldStatus,
    CreateDataField,
    MemoryStatus,
    SetAccessCode,
    ReadEncoderStatus,
    ReadTypeLabel,
    EncoderReset,
    SetEncoderAddress,
    ReadVersion,
    SetSerialInterface,
    /// 63h, legacy edition only. // 002:63h
    SetPositionInternalSync,
    TemporarilySetSerialInterface,
    SetPositionWithSync,
    SensorAdjustment,
    ReadSyncOffset,
    Unknown(u8),
}

impl CommandId {
    pub const fn byte(self) -> u8 {
        match self {
            CommandId::ReadPosition => 0x42,
            CommandId::SetPosition => 0x43,
            CommandId::ReadAnalogValue => 0x44,
            CommandId::ReadCounter => 0x46,
            CommandId::IncrementCounter => 0x47,
            CommandId::ResetCounter => 0x49,
            CommandId::ReadData => 0x4A,
            CommandId::StoreData => 0x4B,
            CommandId::DataFieldStatus => 0x4C,
            CommandId::CreateDataField => 0x4D,
            CommandId::MemoryStatus => 0x4E,
            CommandId::SetAccessCode => 0x4F,
            CommandId::ReadEncoderStatus => 0x50,
            CommandId::ReadTypeLabel => 0x52,
            CommandId::EncoderReset => 0x53,
            CommandId::SetEncoderAddress => 0x55,
            CommandId::ReadVersion => 0x56,
            CommandId::SetSerialInterface => 0x57,
            CommandId::SetPositionInternalSync => 0x63,
            CommandId::TemporarilySetSerialInterface => 0x67,
            CommandId::SetPositionWithSync => 0x6A,
            CommandId::SensorAdjustment => 0x6B,
            CommandId::ReadSyncOffset => 0x6C,
            CommandId::Unknown(b) => b,
        }
    }

    /// Decode a command identifier (a command byte with the error bit cleared).
    pub const fn decode(byte: u8) -> CommandId {
        match byte {
            0x42 => CommandId::ReadPosition,
            0x43 => CommandId::SetPosition,
            0x44 => CommandId::ReadAnalogValue,
            0x46 => CommandId::ReadCounter,
            0x47 => CommandId::IncrementCounter,
            0x49 => CommandId::ResetCounter,
            0x4A => CommandId::ReadData,
            0x4B => CommandId::StoreData,
            0x4C => CommandId::DataFieldStatus,
            0x4D => CommandId::CreateDataField,
            0x4E => CommandId::MemoryStatus,
            0x4F => CommandId::SetAccessCode,
            0x50 => CommandId::ReadEncoderStatus,
            0x52 => CommandId::ReadTypeLabel,
            0x53 => CommandId::EncoderReset,
            0x55 => CommandId::SetEncoderAddress,
            0x56 => CommandId::ReadVersion,
            0x57 => CommandId::SetSerialInterface,
            0x63 => CommandId::SetPositionInternalSync,
            0x67 => CommandId::TemporarilySetSerialInterface,
            0x6A => CommandId::SetPositionWithSync,
            0x6B => CommandId::SensorAdjustment,
            0x6C => CommandId::ReadSyncOffset,
            b => CommandId::Unknown(b),
        }
    }

    /// This command's row of the command table; `None` for unknown commands.
    pub fn spec(self) -> Option<&'static CommandSpec> {
        COMMAND_TABLE.iter().find(|s| s.id == self)
    }
}

impl fmt::Display for CommandId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.spec() {
            Some(s) => write!(f, "{:02X}h {}", self.byte(), s.name),
            None => write!(f, "{:02X}h (unknown command)", self.byte()),
        }
    }
}

/// The command byte: bits 0-5 command value, bit 6 fixed 1, bit 7 error bit. // 000:T6
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CommandByte {
    pub id: CommandId,
    /// Bit 7: in a response, the warning bit (or D0h error-with-warning). // 000:2.3.4
    pub error_bit: bool,
}

impl CommandByte {
    pub const ERROR_BIT: u8 = 0x80;
    pub const FIXED_ONE: u8 = 0x40;

    /// Decode; `None` when the fixed bit 6 is 0.
    pub const fn decode(byte: u8) -> Option<CommandByte> {
        if byte & Self::FIXED_ONE == 0 {
            return None;
        }
        Some(CommandByte { id: CommandId::decode(byte & !Self::ERROR_BIT), error_bit: byte & Self::ERROR_BIT != 0 })
    }

    pub const fn byte(self) -> u8 {
        self.id.byte() | if self.error_bit { Self::ERROR_BIT } else { 0 }
    }
}

/// A data length in bytes (without address, command and checksum). // 000:T8
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataLength {
    Fixed(u8),
    /// Variable within `min..=max` (4Ah reply, 4Bh request).
    Range {
        min: u8,
        max: u8,
    },
    /// No frame at all (53h reply).
    NoFrame,
}

impl DataLength {
    pub const fn accepts(self, len: usize) -> bool {
        match self {
            DataLength::Fixed(n) => len == n as usize,
            DataLength::Range { min, max } => len >= min as usize && len <= max as usize,
            DataLength::NoFrame => false,
        }
    }
}

/// Which editions define a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Editions {
    Both,
    CurrentOnly,
    LegacyOnly,
}

/// Whether a command needs an access code byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AccessCodeRule {
    None,
    Code0,
    /// Code0...Code3 depending on the data field.
    FieldCode,
}

/// One row of the command table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommandSpec {
    pub id: CommandId,
    pub name: &'static str,
    pub access: AccessCodeRule,
    /// Maximum response time after the request's timeout, in ms; `None` when there is
    /// no reply (53h) or the data sheet sets it (6Bh: the profile gives it).
    pub max_response_ms: Option<u16>,
    /// A tighter figure where the documents disagree (6Ch: 30 ms in Table 10, 10 ms in
    /// Table 36); a device between the two grades NON-STRICT.
    pub strict_response_ms: Option<u16>,
    pub master_data: DataLength,
    pub slave_data: DataLength,
    /// Error codes the table lists for the command (without 09h-0Ch, common to all).
    pub errors: &'static [FaultCode],
    pub optional: bool,
    pub editions: Editions,
    pub clause: Normative,
}

impl CommandSpec {
    /// True when the error code may be answered to this command: a listed one, a
    /// protocol error common to all commands (000:2.4.2), or a wrong argument.
    pub fn may_answer(&self, code: FaultCode) -> bool {
        matches!(code, Parity | Checksum | UnknownCommand | WrongLength) || self.errors.contains(&code)
    }

    /// Whether the command writes non-volatile memory (DESIGN: safety on real devices).
    pub const fn writes_eeprom(&self) -> bool {
        matches!(
            self.id,
            CommandId::SetPosition
                | CommandId::IncrementCounter
                | CommandId::ResetCounter
                | CommandId::StoreData
                | CommandId::CreateDataField
                | CommandId::SetAccessCode
                | CommandId::SetEncoderAddress
                | CommandId::SetSerialInterface
                | CommandId::SetPositionWithSync
                | CommandId::SensorAdjustment
                | CommandId::SetPositionInternalSync
        )
    }
}

const POSITION_ERRORS: &[FaultCode] = &[
    AngularOffset,
    WrongArgument,
    LedCurrent,
    Speed,
    Singleturn,
    MultiturnAmplitude,
    MultiturnSync,
    MultiturnVectorLength,
];
const SET_POSITION_ERRORS: &[FaultCode] = &[
    AngularOffset,
    I2cBus,
    InternalChecksum,
    WrongArgument,
    WrongAccessCode,
    LedCurrent,
    Speed,
    Singleturn,
    MultiturnAmplitude,
    MultiturnSync,
    MultiturnVectorLength,
];

macro_rules! spec {
    ($id:ident, $name:literal, $access:ident, $resp:expr, $strict:expr, $m:expr, $s:expr, $errors:expr, $opt:literal, $ed:ident, $clause:expr) => {
        CommandSpec {
            id: CommandId::$id,
            name: $name,
            access: AccessCodeRule::$access,
            max_response_ms: $resp,
            strict_response_ms: $strict,
            master_data: $m,
            slave_data: $s,
            errors: $errors,
            optional: $opt,
            editions: Editions::$ed,
            clause: $clause,
        }
    };
}

use DataLength::{Fixed, NoFrame, Range};

/// The command table: 000 Table 10 with Tables 12-36, and 002's 63h.
/// Set Position lists 1Fh (000:T60: shaft motion during Set Position) although
/// Table 13 does not.
pub const COMMAND_TABLE: &[CommandSpec] = &[
    spec!(
        ReadPosition,
        "Read Position",
        None,
        Some(10),
        None,
        Fixed(0),
        Fixed(4),
        POSITION_ERRORS,
        false,
        Both,
        clause::READ_POSITION
    ),
    spec!(
        SetPosition,
        "Set Position",
        Code0,
        Some(40),
        None,
        Fixed(5),
        Fixed(0),
        SET_POSITION_ERRORS,
        false,
        Both,
        clause::SET_POSITION
    ),
    spec!(
        ReadAnalogValue,
        "Read Analog Value",
        None,
        Some(5),
        None,
        Fixed(1),
        Fixed(3),
        &[WrongArgument],
        false,
        Both,
        clause::READ_ANALOG
    ),
    spec!(
        ReadCounter,
        "Read Counter",
        None,
        Some(5),
        None,
        Fixed(0),
        Fixed(3),
        &[InternalChecksum],
        false,
        Both,
        clause::READ_COUNTER
    ),
    spec!(
        IncrementCounter,
        "Increment Counter",
        None,
        Some(30),
        None,
        Fixed(0),
        Fixed(0),
        &[I2cBus, InternalChecksum, CounterOverflow],
        false,
        Both,
        clause::INCREMENT_COUNTER
    ),
    spec!(
        ResetCounter,
        "Reset Counter",
        Code0,
        Some(30),
        None,
        Fixed(1),
        Fixed(0),
        &[I2cBus, InternalChecksum, WrongAccessCode],
        false,
        Both,
        clause::RESET_COUNTER
    ),
    spec!(
        ReadData,
        "Read Data",
        FieldCode,
        Some(30),
        None,
        Fixed(4),
        Range { min: 4, max: 131 },
        &[PartitionTable, I2cBus, WrongAccessCode, WrongOffset, WrongFieldNumber],
        false,
        Both,
        clause::READ_DATA
    ),
    spec!(
        StoreData,
        "Store Data",
        FieldCode,
        Some(250),
        None,
        Range { min: 5, max: 132 },
        Fixed(3),
        &[PartitionTable, I2cBus, InternalChecksum, ReadOnlyField, WrongAccessCode, WrongOffset, WrongFieldNumber],
        false,
        Both,
        clause::STORE_DATA
    ),
    spec!(
        DataFieldStatus,
        "Data Field Status",
        None,
        Some(5),
        None,
        Fixed(1),
        Fixed(2),
        &[PartitionTable, I2cBus, WrongFieldNumber],
        false,
        Both,
        clause::FIELD_STATUS
    ),
    spec!(
        CreateDataField,
        "Create Data Field",
        FieldCode,
        Some(70),
        None,
        Fixed(3),
        Fixed(2),
        &[PartitionTable, I2cBus, InternalChecksum, WrongAccessCode, OutOfMemory, WrongFieldNumber],
        false,
        Both,
        clause::CREATE_FIELD
    ),
    spec!(
        MemoryStatus,
        "Memory Status",
        None,
        Some(5),
        None,
        Fixed(0),
        Fixed(2),
        &[InternalChecksum],
        false,
        Both,
        clause::MEMORY_STATUS
    ),
    spec!(
        SetAccessCode,
        "Set Access Code",
        None,
        Some(40),
        None,
        Fixed(3),
        Fixed(1),
        &[I2cBus, InternalChecksum, WrongArgument, WrongAccessCode],
        false,
        Both,
        clause::SET_ACCESS_CODE
    ),
    spec!(
        ReadEncoderStatus,
        "Read Encoder Status",
        None,
        Some(5),
        None,
        Fixed(0),
        Fixed(1),
        &[],
        false,
        Both,
        clause::READ_ENCODER_STATUS
    ),
    spec!(
        ReadTypeLabel,
        "Read Type Label",
        None,
        Some(5),
        None,
        Fixed(0),
        Fixed(4),
        &[I2cBus],
        false,
        Both,
        clause::READ_TYPE_LABEL
    ),
    spec!(EncoderReset, "Encoder Reset", None, None, None, Fixed(0), NoFrame, &[], false, Both, clause::ENCODER_RESET),
    spec!(
        SetEncoderAddress,
        "Set Encoder Address",
        Code0,
        Some(40),
        None,
        Fixed(2),
        Fixed(0),
        &[I2cBus, InternalChecksum, WrongArgument, WrongAccessCode],
        false,
        Both,
        clause::SET_ADDRESS
    ),
    spec!(
        ReadVersion,
        "Read Version",
        None,
        Some(5),
        None,
        Fixed(0),
        Fixed(37),
        &[I2cBus],
        false,
        Both,
        clause::READ_VERSION
    ),
    spec!(
        SetSerialInterface,
        "Set Serial Interface",
        Code0,
        Some(40),
        None,
        Fixed(2),
        Fixed(1),
        &[I2cBus, InternalChecksum, WrongArgument, WrongAccessCode],
        false,
        Both,
        clause::SET_SERIAL
    ),
    spec!(
        SetPositionInternalSync,
        "Set Position with Internal Track Synchronisation",
        Code0,
        Some(40),
        None,
        Fixed(5),
        Fixed(0),
        SET_POSITION_ERRORS,
        true,
        LegacyOnly,
        clause::LEGACY_SET_POSITION_SYNC
    ),
    spec!(
        TemporarilySetSerialInterface,
        "Temporarily Set Serial Interface",
        None,
        Some(5),
        None,
        Fixed(1),
        Fixed(1),
        &[WrongArgument, WrongAccessCode],
        true,
        CurrentOnly,
        clause::TEMP_SERIAL
    ),
    spec!(
        SetPositionWithSync,
        "Set Position with Synchronization",
        Code0,
        Some(40),
        None,
        Fixed(5),
        Fixed(4),
        SET_POSITION_ERRORS,
        true,
        CurrentOnly,
        clause::SET_POSITION_SYNC
    ),
    spec!(
        SensorAdjustment,
        "Sensor Adjustment",
        Code0,
        None,
        None,
        Fixed(2),
        Fixed(2),
        &[WrongArgument, WrongAccessCode],
        true,
        CurrentOnly,
        clause::SENSOR_ADJUSTMENT
    ),
    spec!(
        ReadSyncOffset,
        "Read Synchronization Offset",
        None,
        Some(30),
        Some(10),
        Fixed(0),
        Fixed(1),
        &[WrongArgument],
        true,
        CurrentOnly,
        clause::READ_SYNC_OFFSET
    ),
];

/// A set of command identifiers (40h...7Fh), e.g. the commands a profile supports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct CommandSet(u64);

impl CommandSet {
    pub const EMPTY: CommandSet = CommandSet(0);

    /// Every command the table defines for an edition.
    pub fn all_for(legacy: bool) -> CommandSet {
        let mut set = CommandSet::EMPTY;
        for s in COMMAND_TABLE {
            let defined = match s.editions {
                Editions::Both => true,
                Editions::CurrentOnly => !legacy,
                Editions::LegacyOnly => legacy,
            };
            if defined {
                set.insert(s.id);
            }
        }
        set
    }

    fn bit(id: CommandId) -> Option<u64> {
        let b = id.byte();
        (0x40..=0x7F).contains(&b).then(|| 1u64 << (b - 0x40))
    }

    pub fn insert(&mut self, id: CommandId) {
        if let Some(bit) = Self::bit(id) {
            self.0 |= bit;
        }
    }

    pub fn remove(&mut self, id: CommandId) {
        if let Some(bit) = Self::bit(id) {
            self.0 &= !bit;
        }
    }

    pub fn contains(&self, id: CommandId) -> bool {
        Self::bit(id).is_some_and(|bit| self.0 & bit != 0)
    }

    pub fn iter(&self) -> impl Iterator<Item = CommandId> + '_ {
        (0x40u8..=0x7F).map(CommandId::decode).filter(|id| self.contains(*id))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_10_commands_and_response_times() {
        // 000:T10
        let expected: [(u8, Option<u16>); 22] = [
            (0x42, Some(10)),
            (0x43, Some(40)),
            (0x44, Some(5)),
            (0x46, Some(5)),
            (0x47, Some(30)),
            (0x49, Some(30)),
            (0x4A, Some(30)),
            (0x4B, Some(250)),
            (0x4C, Some(5)),
            (0x4D, Some(70)),
            (0x4E, Some(5)),
            (0x4F, Some(40)),
            (0x50, Some(5)),
            (0x52, Some(5)),
            (0x53, None),
            (0x55, Some(40)),
            (0x56, Some(5)),
            (0x57, Some(40)),
            (0x67, Some(5)),
            (0x6A, Some(40)),
            (0x6B, None),
            (0x6C, Some(30)),
        ];
        for (byte, ms) in expected {
            let spec = CommandId::decode(byte).spec().expect("in table");
            assert_eq!(spec.max_response_ms, ms, "{byte:02X}");
            assert_eq!(spec.id.byte(), byte);
        }
        assert_eq!(COMMAND_TABLE.len(), 23, "22 of 000 Table 10 and legacy 63h");
    }

    #[test]
    fn command_byte_codec() {
        for b in 0..=255u8 {
            match CommandByte::decode(b) {
                Some(cb) => assert_eq!(cb.byte(), b),
                None => assert_eq!(b & 0x40, 0),
            }
        }
        let d0 = CommandByte::decode(0xD0).unwrap();
        assert_eq!(d0.id, CommandId::ReadEncoderStatus);
        assert!(d0.error_bit);
    }

    #[test]
    fn command_sets_per_edition() {
        let current = CommandSet::all_for(false);
        let legacy = CommandSet::all_for(true);
        assert!(current.contains(CommandId::ReadSyncOffset) && !current.contains(CommandId::SetPositionInternalSync));
        assert!(
            legacy.contains(CommandId::SetPositionInternalSync)
                && !legacy.contains(CommandId::TemporarilySetSerialInterface)
        );
        assert_eq!(current.iter().count(), 22);
        assert_eq!(legacy.iter().count(), 19);
        assert!(!current.contains(CommandId::Unknown(0x12)));
    }
}
