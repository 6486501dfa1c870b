//! The oracle: grade a device's answer against the model, knowing where the documents
//! leave latitude. PASS is the preferred answer, NON-STRICT an acceptable one (with
//! the reason), FAIL one the specification does not allow.

use crate::clause::{self, ClauseId};
use crate::command::CommandId;
use crate::fault::{FaultCode, FaultGroup};
use crate::response::{Response, ResponseError, ResponseFrame};
use crate::settings::Edition;
use crate::slave::{Outcome, Reply, Slave};
use core::fmt;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Verdict {
    Pass,
    NonStrict,
    Fail,
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Verdict::Pass => "PASS",
            Verdict::NonStrict => "NON-STRICT",
            Verdict::Fail => "FAIL",
        })
    }
}

/// What the model knows of the device's world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Knowledge {
    /// The physical inputs are the model's own (simulator, virtual time): every value
    /// is graded exactly.
    Exact,
    /// A real device: shaft position, temperature and LED current are unknown, so
    /// values derived from them are graded by their range and invariants, and a
    /// warning bit the model did not expect may be a real operational fault.
    PhysicalUnknown,
}

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
    /// An error code the model also accepts where it would have answered.
    TolerableError {
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
    /// The device reports an operational fault the model cannot see.
    UnseenFault {
        code: FaultCode,
    },
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
            Deviation::TolerableError { found } => {
                write!(f, "answered {found}, which the documents also allow here")
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
            Deviation::ImpossibleValue { response } => {
                write!(f, "value out of range: {response:?}")
            }
            Deviation::UnseenFault { code } => {
                write!(f, "the device reports {code}, a fault of its world the model cannot see")
            }
        }
    }
}

/// A verdict with its reason and the clause it rests on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grade {
    pub verdict: Verdict,
    pub deviation: Option<Deviation>,
    pub clause: ClauseId,
}

impl Grade {
    const fn pass(clause: ClauseId) -> Grade {
        Grade { verdict: Verdict::Pass, deviation: None, clause }
    }
    const fn non_strict(d: Deviation, clause: ClauseId) -> Grade {
        Grade { verdict: Verdict::NonStrict, deviation: Some(d), clause }
    }
    const fn fail(d: Deviation, clause: ClauseId) -> Grade {
        Grade { verdict: Verdict::Fail, deviation: Some(d), clause }
    }
}

impl fmt::Display for Grade {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.verdict)?;
        if let Some(d) = self.deviation {
            write!(f, ": {d}")?;
        }
        write!(f, " [{}]", self.clause)
    }
}

/// The oracle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Oracle {
    pub knowledge: Knowledge,
}

impl Oracle {
    pub const fn new(knowledge: Knowledge) -> Oracle {
        Oracle { knowledge }
    }

    /// Grade `observed` (the device's reply bytes, `None` for silence) to `request`
    /// processed at `at_us`, given the model's state `before` the request and its
    /// `expected` outcome.
    pub fn grade(
        &self,
        before: &Slave,
        request: &[u8],
        at_us: u64,
        expected: &Outcome,
        observed: Option<&[u8]>,
    ) -> Grade {
        let command = request.get(1).map(|b| CommandId::decode(b & 0x7F)).unwrap_or(CommandId::Unknown(0));
        let expected_frame = match (expected.reply, observed) {
            (Reply::Silent(_), None) => return Grade::pass(expected.clause),
            (Reply::Silent(_), Some(_)) => return Grade::fail(Deviation::UnexpectedReply, expected.clause),
            (Reply::Frame(_), None) => return Grade::fail(Deviation::NoReply, expected.clause),
            (Reply::Frame(e), Some(_)) => e,
        };
        let bytes = observed.unwrap_or(&[]);
        let found = match ResponseFrame::decode(bytes, command) {
            Ok(found) => found,
            Err(ResponseError::WrongLength { to: CommandId::ReadVersion, data_len })
                if before.profile().edition == Edition::Legacy && data_len < 37 =>
            {
                return Grade::non_strict(Deviation::ShortVersion { data_len }, clause::LEGACY_VERSION);
            }
            Err(e) => return Grade::fail(Deviation::Malformed(e), malformed_clause(e)),
        };
        if found.address != expected_frame.address {
            let c = if command == CommandId::SetEncoderAddress { clause::SET_ADDRESS } else { clause::BROADCAST };
            return Grade::fail(Deviation::WrongAddress { expected: expected_frame.address, found: found.address }, c);
        }
        // An error response to 50h has the bytes of a status reply. // 000:2.3.4
        let found = match (expected_frame.response, found.response) {
            (Response::Error(_), Response::EncoderStatus(code)) => {
                ResponseFrame { response: Response::Error(code), ..found }
            }
            _ => found,
        };
        let active = before.listening_settings(at_us).map(|s| s.byte());
        let content = self.content(before, active, expected, &expected_frame, &found);
        if content.verdict == Verdict::Fail {
            return content;
        }
        let warning = match (expected_frame.warning, found.warning) {
            (true, false) => Some(Grade::fail(Deviation::WarningBitMissing, clause::WARNING_BIT)),
            (false, true) if self.knowledge == Knowledge::Exact => {
                Some(Grade::fail(Deviation::WarningBitUnexpected, clause::WARNING_BIT))
            }
            (false, true) => Some(Grade::non_strict(Deviation::WarningBitUnexpected, clause::WARNING_BIT)),
            _ => None,
        };
        match warning {
            Some(w) if w.verdict >= content.verdict => w,
            _ => content,
        }
    }

    fn content(
        &self,
        before: &Slave,
        active: Option<u8>,
        expected: &Outcome,
        e: &ResponseFrame,
        found: &ResponseFrame,
    ) -> Grade {
        let c = expected.clause;
        match (e.response, found.response) {
            (Response::Error(pref), Response::Error(got)) if pref == got => Grade::pass(c),
            (Response::EncoderStatus(pref), Response::EncoderStatus(got)) if pref == got => Grade::pass(c),
            (Response::Error(pref), Response::Error(got)) if expected.also.contains(got) => {
                Grade::non_strict(Deviation::OtherApplicableError { preferred: pref, found: got }, clause::CHECK_ORDER)
            }
            (Response::Error(pref), Response::Error(got)) => {
                Grade::fail(Deviation::WrongError { expected: pref, found: got }, c)
            }
            (_, Response::Error(got)) if expected.also.contains(got) => {
                Grade::non_strict(Deviation::TolerableError { found: got }, c)
            }
            (_, Response::Error(got)) => Grade::fail(Deviation::ErrorInsteadOfReply { found: got }, c),
            (Response::Error(pref), _) => Grade::fail(Deviation::ReplyInsteadOfError { expected: pref }, c),
            (a, b) if a == b => Grade::pass(c),
            (
                Response::TypeLabel { settings: stored, type_code, memory_blocks, option },
                Response::TypeLabel { settings: got, type_code: t, memory_blocks: m, option: o },
            ) if (type_code, memory_blocks, option) == (t, m, o) && active == Some(got) => Grade::non_strict(
                Deviation::ActiveSettingsInTypeLabel { stored, active: got },
                clause::TYPE_LABEL_SETTINGS,
            ),
            (a, b) if self.knowledge == Knowledge::PhysicalUnknown => self.physical(before, a, b, c, e, found),
            _ => Grade::fail(Deviation::WrongReply { expected: *e, found: *found }, c),
        }
    }

    /// Values that depend on the physical world, graded by range and invariants.
    fn physical(
        &self,
        before: &Slave,
        a: Response,
        b: Response,
        c: ClauseId,
        e: &ResponseFrame,
        found: &ResponseFrame,
    ) -> Grade {
        let range = before.profile().range();
        let ok = match (a, b) {
            (Response::Position(_), Response::Position(v)) => (v as u64) < range,
            (Response::AnalogValue { channel: x, .. }, Response::AnalogValue { channel: y, .. }) => x == y,
            (Response::SyncOffset(_), Response::SyncOffset(v)) => v < 32,
            // A stacked code the model cannot see: an operational fault of the real
            // world is plausible; protocol and data errors are never stacked. // 000:T37
            (Response::EncoderStatus(_), Response::EncoderStatus(code)) => {
                let group = crate::fault::runtime_group(code);
                let plausible = !matches!(group, Some(FaultGroup::Protocol | FaultGroup::Data) | None);
                return if plausible {
                    Grade::non_strict(Deviation::UnseenFault { code }, clause::READ_ENCODER_STATUS)
                } else {
                    Grade::fail(Deviation::WrongReply { expected: *e, found: *found }, clause::FAULT_GROUPS)
                };
            }
            (Response::PositionWithSyncSet(x), Response::PositionWithSyncSet(v)) => {
                // Same phase as an unknown raw position: only "within 16 steps of the preset" is checkable.
                let (x, v) = (x as u64 % range, v as u64);
                let d = (v + range - x) % range;
                v < range && (d <= 16 || range - d <= 16)
            }
            _ => return Grade::fail(Deviation::WrongReply { expected: *e, found: *found }, c),
        };
        if ok {
            Grade::pass(c)
        } else {
            Grade::fail(Deviation::ImpossibleValue { response: b }, c)
        }
    }
}

fn malformed_clause(e: ResponseError) -> ClauseId {
    match e {
        ResponseError::BadChecksum { .. } => clause::CHECKSUM,
        ResponseError::BadCommandByte { .. } => clause::COMMAND_BYTE,
        ResponseError::NoResponseExpected { .. } => clause::ENCODER_RESET,
        ResponseError::TooShort { .. } | ResponseError::WrongCommand { .. } => clause::ERROR_RESPONSE,
        ResponseError::WrongLength { .. } | ResponseError::CountMismatch { .. } => clause::COMMAND_DEFINITION,
    }
}
