//! The command byte and the command table. // 000:T6, 000:T8, 000:T10, 002 command overview
//!
//! Long because: the command table is one table, a row per command, read
//! as the spec's Table 10 is (under 450 without its tests).

use crate::clause::{self, Normative};
use crate::fault::FaultCode::{self, *};
use core::fmt;

/// Declares the command table once: the `CommandId` enum, its byte mapping and decoding,
/// and `COMMAND_TABLE`, all from one row per command. Adding a command is one row.
macro_rules! command_table {
    ($(
        $(#[$doc:meta])*
        $byte:literal $id:ident $name:literal
            access $access:ident, response $resp:expr, strict $strict:expr,
            request $m:expr, reply $s:expr, errors $errors:expr,
            $memory:ident, $need:ident, $ed:ident, $clause:ident;
    )*) => {
        /// A command identifier (command byte without the error bit).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum CommandId {
            $( $(#[$doc])* $id, )*
            Unknown(u8),
        }

        impl CommandId {
            pub const fn byte(self) -> u8 {
                match self {
                    $( CommandId::$id => $byte, )*
                    CommandId::Unknown(b) => b,
                }
            }

            /// Decode a command identifier (a command byte with the error bit cleared).
            pub const fn decode(byte: u8) -> CommandId {
                match byte {
                    $( $byte => CommandId::$id, )*
                    b => CommandId::Unknown(b),
                }
            }
        }

        /// The command table: 000 Table 10 with Tables 12-36, and 002's 63h.
        pub const COMMAND_TABLE: &[CommandSpec] = &[
            $( CommandSpec {
                id: CommandId::$id,
                name: $name,
                access: AccessCodeRule::$access,
                max_response_ms: $resp,
                strict_response_ms: $strict,
                master_data: $m,
                slave_data: $s,
                errors: $errors,
                listed: FaultBits::of($errors),
                memory: Memory::$memory,
                optional: matches!(Need::$need, Need::Optional),
                editions: Editions::$ed,
                clause: clause::$clause,
            }, )*
        ];
    };
}

/// The row of each command byte 40h...7Fh in `COMMAND_TABLE` (`u8::MAX`: none), built
/// from the table at compile time so that a lookup costs one index.
const ROW_OF: [u8; 64] = {
    let mut rows = [u8::MAX; 64];
    let mut i = 0;
    while i < COMMAND_TABLE.len() {
        rows[(COMMAND_TABLE[i].id.byte() & 0x3F) as usize] = i as u8;
        i += 1;
    }
    rows
};

impl CommandId {
    /// The command a frame is about, request or reply: its second byte without the
    /// error bit (000:T6); `Unknown(0)` for a frame too short to have one.
    pub fn of_frame(frame: &[u8]) -> CommandId {
        frame.get(1).map_or(CommandId::Unknown(0), |b| CommandId::decode(b & !CommandByte::ERROR_BIT))
    }

    /// This command's row of the command table; `None` for unknown commands.
    pub fn spec(self) -> Option<&'static CommandSpec> {
        if matches!(self, CommandId::Unknown(_)) {
            return None;
        }
        let row = ROW_OF.get((self.byte() & 0x3F) as usize).copied()?;
        COMMAND_TABLE.get(row as usize)
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

/// A set of fault codes (all below 40h, 000:T11), one bit each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FaultBits(u64);

impl FaultBits {
    /// The set of `codes`; a code of 40h or above (none is defined) is left out.
    pub const fn of(codes: &[FaultCode]) -> FaultBits {
        let mut bits = 0u64;
        let mut i = 0;
        while i < codes.len() {
            let b = codes[i].byte();
            if b < 64 {
                bits |= 1 << b;
            }
            i += 1;
        }
        FaultBits(bits)
    }

    pub const fn contains(self, code: FaultCode) -> bool {
        let b = code.byte();
        b < 64 && self.0 & (1 << b) != 0
    }
}

/// Which editions define a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Editions {
    Both,
    CurrentOnly,
    LegacyOnly,
}

impl Editions {
    /// Whether the legacy edition (`legacy`) or the current one defines the command.
    pub const fn includes(self, legacy: bool) -> bool {
        match self {
            Editions::Both => true,
            Editions::CurrentOnly => !legacy,
            Editions::LegacyOnly => legacy,
        }
    }
}

/// Whether a command writes non-volatile memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Memory {
    Volatile,
    WritesEeprom,
}

/// Whether a device must implement a command (000:T10 marks the optional ones).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Need {
    Required,
    Optional,
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
    /// The same codes as a set, built at compile time, for [`CommandSpec::lists`].
    pub listed: FaultBits,
    /// Whether a successful execution writes the EEPROM.
    pub memory: Memory,
    pub optional: bool,
    pub editions: Editions,
    pub clause: Normative,
}

impl CommandSpec {
    /// Whether the command's table lists `code` among its errors: one bit test (no
    /// loop over the list, which a bounded model checker could not bound when it does
    /// not know the command).
    pub const fn lists(&self, code: FaultCode) -> bool {
        self.listed.contains(code)
    }

    /// Whether the command writes non-volatile memory (DESIGN: safety on real devices).
    pub const fn writes_eeprom(&self) -> bool {
        matches!(self.memory, Memory::WritesEeprom)
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

use DataLength::{Fixed, NoFrame, Range};

// One row per command of 000 Table 10 (and 002's 63h). Columns: byte, name, access code
// (000:T12-T36 per command), maximum response time in ms after the request's timeout
// (000:T10; `None`: no reply or the data sheet's figure), a tighter printed figure graded
// NON-STRICT, request and reply data lengths (000:T8), error codes the command's table
// lists besides the common 09h-0Ch, whether it writes non-volatile memory (DESIGN:
// safety), whether a device may leave it out, the editions, and the clause.
// Set Position lists 1Fh (000:T60: shaft motion during Set Position) although Table 13
// does not.
command_table! {
    0x42 ReadPosition "Read Position"
        access None, response Some(10), strict None, request Fixed(0), reply Fixed(4), errors POSITION_ERRORS,
        Volatile, Required, Both, READ_POSITION;
    0x43 SetPosition "Set Position"
        access Code0, response Some(40), strict None, request Fixed(5), reply Fixed(0), errors SET_POSITION_ERRORS,
        WritesEeprom, Required, Both, SET_POSITION;
    0x44 ReadAnalogValue "Read Analog Value"
        access None, response Some(5), strict None, request Fixed(1), reply Fixed(3), errors &[WrongArgument],
        Volatile, Required, Both, READ_ANALOG;
    0x46 ReadCounter "Read Counter"
        access None, response Some(5), strict None, request Fixed(0), reply Fixed(3), errors &[InternalChecksum],
        Volatile, Required, Both, READ_COUNTER;
    0x47 IncrementCounter "Increment Counter"
        access None, response Some(30), strict None, request Fixed(0), reply Fixed(0),
        errors &[I2cBus, InternalChecksum, CounterOverflow],
        WritesEeprom, Required, Both, INCREMENT_COUNTER;
    0x49 ResetCounter "Reset Counter"
        access Code0, response Some(30), strict None, request Fixed(1), reply Fixed(0),
        errors &[I2cBus, InternalChecksum, WrongAccessCode],
        WritesEeprom, Required, Both, RESET_COUNTER;
    0x4A ReadData "Read Data"
        access FieldCode, response Some(30), strict None, request Fixed(4), reply Range { min: 4, max: 131 },
        errors &[PartitionTable, I2cBus, WrongAccessCode, WrongOffset, WrongFieldNumber],
        Volatile, Required, Both, READ_DATA;
    0x4B StoreData "Store Data"
        access FieldCode, response Some(250), strict None, request Range { min: 5, max: 132 }, reply Fixed(3),
        errors &[PartitionTable, I2cBus, InternalChecksum, ReadOnlyField, WrongAccessCode, WrongOffset, WrongFieldNumber],
        WritesEeprom, Required, Both, STORE_DATA;
    0x4C DataFieldStatus "Data Field Status"
        access None, response Some(5), strict None, request Fixed(1), reply Fixed(2),
        errors &[PartitionTable, I2cBus, WrongFieldNumber],
        Volatile, Required, Both, FIELD_STATUS;
    0x4D CreateDataField "Create Data Field"
        access FieldCode, response Some(70), strict None, request Fixed(3), reply Fixed(2),
        errors &[PartitionTable, I2cBus, InternalChecksum, WrongAccessCode, OutOfMemory, WrongFieldNumber],
        WritesEeprom, Required, Both, CREATE_FIELD;
    0x4E MemoryStatus "Memory Status"
        access None, response Some(5), strict None, request Fixed(0), reply Fixed(2), errors &[InternalChecksum],
        Volatile, Required, Both, MEMORY_STATUS;
    0x4F SetAccessCode "Set Access Code"
        access None, response Some(40), strict None, request Fixed(3), reply Fixed(1),
        errors &[I2cBus, InternalChecksum, WrongArgument, WrongAccessCode],
        WritesEeprom, Required, Both, SET_ACCESS_CODE;
    0x50 ReadEncoderStatus "Read Encoder Status"
        access None, response Some(5), strict None, request Fixed(0), reply Fixed(1), errors &[],
        Volatile, Required, Both, READ_ENCODER_STATUS;
    0x52 ReadTypeLabel "Read Type Label"
        access None, response Some(5), strict None, request Fixed(0), reply Fixed(4), errors &[I2cBus],
        Volatile, Required, Both, READ_TYPE_LABEL;
    0x53 EncoderReset "Encoder Reset"
        access None, response None, strict None, request Fixed(0), reply NoFrame, errors &[],
        Volatile, Required, Both, ENCODER_RESET;
    0x55 SetEncoderAddress "Set Encoder Address"
        access Code0, response Some(40), strict None, request Fixed(2), reply Fixed(0),
        errors &[I2cBus, InternalChecksum, WrongArgument, WrongAccessCode],
        WritesEeprom, Required, Both, SET_ADDRESS;
    0x56 ReadVersion "Read Version"
        access None, response Some(5), strict None, request Fixed(0), reply Fixed(37), errors &[I2cBus],
        Volatile, Required, Both, READ_VERSION;
    0x57 SetSerialInterface "Set Serial Interface"
        access Code0, response Some(40), strict None, request Fixed(2), reply Fixed(1),
        errors &[I2cBus, InternalChecksum, WrongArgument, WrongAccessCode],
        WritesEeprom, Required, Both, SET_SERIAL;
    /// 63h, legacy edition only. // 002:63h
    0x63 SetPositionInternalSync "Set Position with Internal Track Synchronisation"
        access Code0, response Some(40), strict None, request Fixed(5), reply Fixed(0), errors SET_POSITION_ERRORS,
        WritesEeprom, Optional, LegacyOnly, LEGACY_SET_POSITION_SYNC;
    0x67 TemporarilySetSerialInterface "Temporarily Set Serial Interface"
        access None, response Some(5), strict None, request Fixed(1), reply Fixed(1),
        errors &[WrongArgument, WrongAccessCode],
        Volatile, Optional, CurrentOnly, TEMP_SERIAL;
    0x6A SetPositionWithSync "Set Position with Synchronization"
        access Code0, response Some(40), strict None, request Fixed(5), reply Fixed(4), errors SET_POSITION_ERRORS,
        WritesEeprom, Optional, CurrentOnly, SET_POSITION_SYNC;
    0x6B SensorAdjustment "Sensor Adjustment"
        access Code0, response None, strict None, request Fixed(2), reply Fixed(2),
        errors &[WrongArgument, WrongAccessCode],
        WritesEeprom, Optional, CurrentOnly, SENSOR_ADJUSTMENT;
    0x6C ReadSyncOffset "Read Synchronization Offset"
        access None, response Some(30), strict Some(10), request Fixed(0), reply Fixed(1), errors &[WrongArgument],
        Volatile, Optional, CurrentOnly, READ_SYNC_OFFSET;
}

/// When a reply must start, counted from the end of the request's timeout. // 000:T10
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResponseLimit {
    /// The maximum response time, ms.
    pub max_ms: u16,
    /// A tighter figure printed elsewhere (000:T36 for 6Ch), graded NON-STRICT.
    pub strict_ms: Option<u16>,
}

const DEFINED_CURRENT: CommandSet = CommandSet::defined_in(false);
const DEFINED_LEGACY: CommandSet = CommandSet::defined_in(true);

/// A set of command identifiers (40h...7Fh), e.g. the commands a profile supports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct CommandSet(u64);

impl CommandSet {
    pub const EMPTY: CommandSet = CommandSet(0);

    /// Every command the table defines for an edition: a constant, computed from the
    /// table when compiling (a proof that builds a profile then has no loop over the
    /// table to unroll; proofs/src/lib.rs).
    pub const fn all_for(legacy: bool) -> CommandSet {
        if legacy {
            DEFINED_LEGACY
        } else {
            DEFINED_CURRENT
        }
    }

    /// The commands of `COMMAND_TABLE` defined in an edition, at compile time.
    const fn defined_in(legacy: bool) -> CommandSet {
        let mut bits = 0u64;
        let mut i = 0;
        while i < COMMAND_TABLE.len() {
            let s = &COMMAND_TABLE[i];
            if let (true, Some(bit)) = (s.editions.includes(legacy), Self::bit(s.id)) {
                bits |= bit;
            }
            i += 1;
        }
        CommandSet(bits)
    }

    const fn bit(id: CommandId) -> Option<u64> {
        match id.byte() {
            b @ 0x40..=0x7F => Some(1u64 << (b - 0x40)),
            _ => None,
        }
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
    fn the_set_of_listed_errors_is_the_list() {
        for spec in COMMAND_TABLE {
            for b in 0..=255u8 {
                let code = FaultCode::decode(b);
                assert_eq!(spec.lists(code), spec.errors.contains(&code), "{} {b:02X}h", spec.name);
            }
        }
        // Not vacuous: a listed code and one that is not.
        let set_position = CommandId::SetPosition.spec().map(|s| (s.lists(I2cBus), s.lists(CounterOverflow)));
        assert_eq!(set_position, Some((true, false)));
    }

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
    fn every_row_is_found_by_its_command_and_nothing_else() {
        for b in 0..=255u8 {
            let id = CommandId::decode(b);
            assert_eq!(id.spec(), COMMAND_TABLE.iter().find(|s| s.id == id), "{b:02X}");
        }
        assert_eq!(CommandId::Unknown(0x42).spec(), None);
    }

    #[test]
    fn a_frames_command_ignores_the_error_bit() {
        assert_eq!(CommandId::of_frame(&[0x40, 0x42, 0x02]), CommandId::ReadPosition);
        assert_eq!(CommandId::of_frame(&[0x40, 0xD2, 0x00]), CommandId::ReadTypeLabel);
        assert_eq!(CommandId::of_frame(&[0x40, 0x3F]), CommandId::decode(0x3F));
        assert_eq!(CommandId::of_frame(&[0x40]), CommandId::Unknown(0));
        assert_eq!(CommandId::of_frame(&[]), CommandId::Unknown(0));
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
        // The constants are the table's rows of each edition, each row once.
        for (set, legacy_edition) in [(current, false), (legacy, true)] {
            let mut rows = CommandSet::EMPTY;
            for s in COMMAND_TABLE.iter().filter(|s| s.editions.includes(legacy_edition)) {
                rows.insert(s.id);
            }
            assert_eq!(set, rows);
        }
        assert_eq!((current.0.count_ones(), legacy.0.count_ones()), (22, 19));
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
