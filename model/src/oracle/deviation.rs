//! How a device's answer differs from the model's preferred one: each deviation the
//! oracle knows, with the words a report uses for it.

use crate::fault::FaultCode;
use crate::response::{Response, ResponseError, ResponseFrame};
use core::fmt;

/// How an answer differs from the preferred one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Deviation {
    /// The model stays silent; the device answered.
    UnexpectedReply,
    /// The model answers; the device did not.
    NoReply,
    Malformed(ResponseError),
    WrongAddress {
        expected: u8,
        found: u8,
    },
    WarningBitMissing,
    WarningBitUnexpected,
    /// Another error whose condition also holds.
    OtherApplicableError {
        preferred: FaultCode,
        found: FaultCode,
    },
    WrongError {
        expected: FaultCode,
        found: FaultCode,
    },
    ErrorInsteadOfReply {
        found: FaultCode,
    },
    ReplyInsteadOfError {
        expected: FaultCode,
    },
    WrongReply {
        expected: ResponseFrame,
        found: ResponseFrame,
    },
    /// Read Type Label reported the active rather than the stored settings.
    ActiveSettingsInTypeLabel {
        stored: u8,
        active: u8,
    },
    /// A legacy device's Read Version shorter than 37 bytes.
    ShortVersion {
        data_len: usize,
    },
    /// A value the model cannot know is outside its possible range.
    ImpossibleValue {
        response: Response,
    },
    /// Read Analog Value answered with another channel than the one asked for.
    WrongChannel {
        asked: u8,
        named: u8,
    },
    /// A temperature outside the device's limits, and no warning with it.
    ImplausibleTemperature {
        celsius: i32,
        min: i16,
        max: i16,
    },
    /// The device reports an operational fault the model cannot see.
    UnseenFault {
        code: FaultCode,
    },
    /// Read Encoder Status says nothing is active but sets the warning bit.
    WarningWithoutCode,
    /// A Read Version value the profile pins differs.
    VersionDiffers {
        field: &'static str,
    },
    /// A Read Version value breaks the form the documents give it.
    VersionForm {
        field: &'static str,
        problem: &'static str,
    },
    /// Bytes of a data field created in this run and never written differ from the
    /// erased value the model assumes.
    UnwrittenContents,
}

impl fmt::Display for Deviation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Deviation::UnexpectedReply => f.write_str("the device answered where the slave must stay silent"),
            Deviation::NoReply => f.write_str("no reply where the slave must answer"),
            Deviation::Malformed(e) => write!(f, "malformed reply: {e}"),
            Deviation::WrongAddress { expected, found } => {
                write!(f, "reply from address {found:02X}h, expected {expected:02X}h")
            }
            Deviation::WarningBitMissing => {
                f.write_str("warning bit clear while the error stack holds an unread entry")
            }
            Deviation::WarningBitUnexpected => f.write_str("warning bit set while the model's error stack is empty"),
            Deviation::OtherApplicableError { preferred, found } => {
                write!(f, "answered {found}; its condition holds too, but the check order prefers {preferred}")
            }
            Deviation::WrongError { expected, found } => {
                write!(f, "answered {found}, expected {expected}")
            }
            Deviation::ErrorInsteadOfReply { found } => {
                write!(f, "answered error {found} to a valid request")
            }
            Deviation::ReplyInsteadOfError { expected } => {
                write!(f, "executed a request that must draw {expected}")
            }
            Deviation::WrongReply { expected, found } => {
                write!(f, "replied {found}, expected {expected}")
            }
            Deviation::ActiveSettingsInTypeLabel { stored, active } => {
                write!(f, "type label reports the active settings {active:02X}h, not the stored {stored:02X}h")
            }
            Deviation::ShortVersion { data_len } => {
                write!(f, "Read Version with {data_len} data bytes (legacy: up to 20 firmware characters)")
            }
            Deviation::ImpossibleValue { response: Response::Position(v) } => {
                write!(f, "position {v:08X}h is outside the measuring range")
            }
            Deviation::ImpossibleValue { response: Response::SyncOffset(v) } => {
                write!(f, "synchronization offset {v} is outside 0...31")
            }
            Deviation::ImpossibleValue { response: Response::PositionWithSyncSet(v) } => {
                write!(f, "the preset used, {v:08X}h, is not within 16 steps of the preset sent")
            }
            Deviation::ImpossibleValue { response } => {
                write!(f, "value out of range: {response:?}")
            }
            Deviation::WrongChannel { asked, named } => {
                write!(f, "the reply names channel {named:02X}h; the request asked for {asked:02X}h")
            }
            Deviation::ImplausibleTemperature { celsius, min, max } => write!(
                f,
                "a temperature of {celsius} degC, outside the device's limits ({min}...{max} degC), \
                 without the warning bit its out-of-range fault (1Eh) would set"
            ),
            Deviation::UnseenFault { code } => {
                write!(f, "the device reports {code}, a fault of its world the model cannot see")
            }
            Deviation::WarningWithoutCode => f.write_str(
                "Read Encoder Status reports no active warning or error (00h) but the reply sets the warning bit",
            ),
            Deviation::VersionDiffers { field } => write!(f, "the {field} differs from the one the profile pins"),
            Deviation::VersionForm { field, problem } => write!(f, "the {field} {problem}"),
            Deviation::UnwrittenContents => {
                f.write_str("a new data field's unwritten bytes are not FFh (erased EEPROM, the project's assumption)")
            }
        }
    }
}
