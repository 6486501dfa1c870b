//! The oracle: grade a device's answer against the model, knowing where the documents
//! leave latitude. PASS is the preferred answer, NON-STRICT an acceptable one (with
//! the reason), FAIL one the specification does not allow.
//!
//! Long because: grading walks the model's outcome and the device's reply side by side,
//! a verdict per difference, in one order; the deviations are in deviation.rs (under
//! 430 lines without its tests).

use crate::clause::{self, Clause, Normative};
use crate::command::CommandId;
use crate::fault::{FaultCode, FaultGroup};
use crate::profile::AnalogSource;
use crate::response::{Response, ResponseError, ResponseFrame, Version};
use crate::settings::Edition;
use crate::slave::fields::Contents;
use crate::slave::{Outcome, Reply, Silence, Slave};
use core::fmt;

mod before;
mod deviation;
pub use before::Before;
pub use deviation::Deviation;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Verdict {
    Pass,
    NonStrict,
    Fail,
}

impl Verdict {
    /// Every verdict, the best first.
    pub const ALL: [Verdict; 3] = [Verdict::Pass, Verdict::NonStrict, Verdict::Fail];

    /// The verdict's name, as every report, C and Python spell it.
    pub const fn name(self) -> &'static str {
        match self {
            Verdict::Pass => "PASS",
            Verdict::NonStrict => "NON-STRICT",
            Verdict::Fail => "FAIL",
        }
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How values of the device's physical world are graded: what the model knows of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Grading {
    /// The physical inputs are the model's own (simulator, virtual time): every value
    /// is graded exactly.
    Exact,
    /// A real device: shaft position, temperature and LED current are unknown, so
    /// values derived from them are graded by their range and invariants, and a
    /// warning bit the model did not expect may be a real operational fault.
    Range,
}

/// `exact` or `range`, as a command line spells them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnknownGrading;

impl fmt::Display for UnknownGrading {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("expected `exact` or `range`")
    }
}

impl core::error::Error for UnknownGrading {}

impl core::str::FromStr for Grading {
    type Err = UnknownGrading;
    fn from_str(s: &str) -> Result<Grading, UnknownGrading> {
        match s {
            "exact" => Ok(Grading::Exact),
            "range" => Ok(Grading::Range),
            _ => Err(UnknownGrading),
        }
    }
}

/// A verdict with its reason and the clause it rests on. A FAIL always rests on a
/// normative clause that binds the device's edition: the constructors see to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grade {
    verdict: Verdict,
    deviation: Option<Deviation>,
    clause: Clause,
}

impl Grade {
    fn pass(clause: impl Into<Clause>) -> Grade {
        Grade { verdict: Verdict::Pass, deviation: None, clause: clause.into() }
    }
    fn non_strict(d: Deviation, clause: impl Into<Clause>) -> Grade {
        Grade { verdict: Verdict::NonStrict, deviation: Some(d), clause: clause.into() }
    }
    /// FAIL where `rule` binds a device of `edition`; NON-STRICT where it does not
    /// (a rule of the other edition's document).
    fn against(d: Deviation, rule: Normative, edition: Edition) -> Grade {
        let verdict = if rule.binds(edition) { Verdict::Fail } else { Verdict::NonStrict };
        Grade { verdict, deviation: Some(d), clause: rule.clause() }
    }

    pub fn verdict(&self) -> Verdict {
        self.verdict
    }
    pub fn deviation(&self) -> Option<Deviation> {
        self.deviation
    }
    pub fn clause(&self) -> Clause {
        self.clause
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
    pub grading: Grading,
}

impl Oracle {
    pub const fn new(grading: Grading) -> Oracle {
        Oracle { grading }
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
        self.grade_from(&Before::of(before, request, at_us), request, expected, observed)
    }

    /// [`Oracle::grade`] from what it reads of the state before the request, taken
    /// with [`Before::of`] (the request's instant is in it).
    pub fn grade_from(&self, before: &Before, request: &[u8], expected: &Outcome, observed: Option<&[u8]>) -> Grade {
        let command = CommandId::of_frame(request);
        self.grade_decoded(before, request, expected, observed.map(|bytes| ResponseFrame::decode(bytes, command)))
    }

    /// [`Oracle::grade_from`] where the reply heard was decoded already, for the
    /// request's command, by [`ResponseFrame::decode`] (a listener decodes each reply
    /// once, for the master's rules and for this).
    pub fn grade_decoded(
        &self,
        before: &Before,
        request: &[u8],
        expected: &Outcome,
        observed: Option<Result<ResponseFrame, ResponseError>>,
    ) -> Grade {
        let edition = before.profile().edition;
        let command = CommandId::of_frame(request);
        let (expected_frame, decoded) = match (expected.reply, observed) {
            (Reply::Silent(_), None) => return Grade::pass(expected.clause),
            (Reply::Silent(silence), Some(_)) => {
                // An answer while initializing: the state machine's rule (000:T9) binds
                // current devices; a legacy device's initialization is 000:T29's, the
                // one it shares ("respond to new requests after initialization time
                // (100 ms) plus timeout"; 002: a reset "runs through the same
                // initialisation process as ... when the supply voltage is switched
                // on"), as for a silent reply below (HX-4's d13).
                let c = if silence == Silence::NotListening && edition == Edition::Legacy {
                    clause::ENCODER_RESET
                } else {
                    expected.clause
                };
                return Grade::against(Deviation::UnexpectedReply, c, edition);
            }
            (Reply::Frame(_), None) => {
                // A silent broadcast breaks 2.3.1 whatever the command. // 000:2.3.1
                // Silent within the power-up windows where the slave answers: the state
                // machine's rule (000:T9; 000:T29's "respond to new requests after
                // initialization time" in the legacy edition) rather than the command's.
                let c = if request.first() == Some(&0xFF) {
                    clause::BROADCAST
                } else if before.within_power_up() {
                    if edition == Edition::Current {
                        clause::STATE_MACHINE
                    } else {
                        clause::ENCODER_RESET
                    }
                } else {
                    expected.clause
                };
                return Grade::against(Deviation::NoReply, c, edition);
            }
            (Reply::Frame(e), Some(decoded)) => (e, decoded),
        };
        let found = match decoded {
            Ok(found) => found,
            Err(ResponseError::WrongLength { to: CommandId::ReadVersion, data_len })
                if edition == Edition::Legacy && data_len < 37 =>
            {
                return Grade::non_strict(Deviation::ShortVersion { data_len }, clause::LEGACY_VERSION);
            }
            Err(e) => return Grade::against(Deviation::Malformed(e), malformed_clause(e), edition),
        };
        if found.address != expected_frame.address {
            let c = if command == CommandId::SetEncoderAddress { clause::SET_ADDRESS } else { clause::BROADCAST };
            let d = Deviation::WrongAddress { expected: expected_frame.address, found: found.address };
            return Grade::against(d, c, edition);
        }
        // An error response to 50h has the bytes of a status reply. // 000:2.3.4
        let found = match (expected_frame.response, found.response) {
            (Response::Error(_), Response::EncoderStatus(code)) => {
                ResponseFrame { response: Response::Error(code), ..found }
            }
            _ => found,
        };
        // "Nothing active" with the warning bit contradicts itself, whatever the world. // 000:T27
        if found.response == Response::EncoderStatus(FaultCode::NoFault) && found.warning {
            return Grade::against(Deviation::WarningWithoutCode, clause::WARNING_BIT, edition);
        }
        let content = self.content(before, expected, &expected_frame, &found);
        if content.verdict == Verdict::Fail {
            return content;
        }
        let warning = match (expected_frame.warning, found.warning) {
            (true, false) => Some(Grade::against(Deviation::WarningBitMissing, clause::WARNING_BIT, edition)),
            (false, true) if self.grading == Grading::Exact => {
                Some(Grade::against(Deviation::WarningBitUnexpected, clause::WARNING_BIT, edition))
            }
            (false, true) => Some(Grade::non_strict(Deviation::WarningBitUnexpected, clause::WARNING_BIT)),
            _ => None,
        };
        // Content that failed returned above: a warning deviation (NON-STRICT at least)
        // is never milder than what is left.
        warning.unwrap_or(content)
    }

    fn content(&self, before: &Before, expected: &Outcome, e: &ResponseFrame, found: &ResponseFrame) -> Grade {
        let c = expected.clause;
        let edition = before.profile().edition;
        let active = before.active_settings();
        let wrong = |d| Grade::against(d, c, edition);
        match (e.response, found.response) {
            (Response::Error(pref), Response::Error(got)) if pref == got => Grade::pass(c),
            (Response::Error(pref), Response::Error(got)) if expected.also.contains(got) => {
                Grade::non_strict(Deviation::OtherApplicableError { preferred: pref, found: got }, clause::CHECK_ORDER)
            }
            // 002 names no codes of its own: "The actual available errors vary
            // according to MFB type and are always given on the data sheet." An
            // error reply is what it asks for; another code than 000's is NON-STRICT.
            (Response::Error(pref), Response::Error(got)) if edition == Edition::Legacy => {
                Grade::non_strict(Deviation::WrongError { expected: pref, found: got }, clause::LEGACY_ERROR_CODES)
            }
            (Response::Error(pref), Response::Error(got)) => {
                wrong(Deviation::WrongError { expected: pref, found: got })
            }
            (_, Response::Error(got)) => wrong(Deviation::ErrorInsteadOfReply { found: got }),
            (Response::Error(pref), _) => wrong(Deviation::ReplyInsteadOfError { expected: pref }),
            (a, b) if a == b => Grade::pass(c),
            (
                Response::TypeLabel { settings: stored, type_code, memory_blocks, option },
                Response::TypeLabel { settings: got, type_code: t, memory_blocks: m, option: o },
            ) if (type_code, memory_blocks, option) == (t, m, o) && active == Some(got) => Grade::non_strict(
                Deviation::ActiveSettingsInTypeLabel { stored, active: got },
                clause::TYPE_LABEL_SETTINGS,
            ),
            (Response::Data { field, offset, data: want }, Response::Data { field: f, offset: o, data: got })
                if (field, offset, want.len()) == (f, o, got.len()) =>
            {
                unwritten_contents(before, field, offset, want.as_bytes(), got.as_bytes())
                    .unwrap_or_else(|| wrong(Deviation::WrongReply { expected: *e, found: *found }))
            }
            (Response::Version(want), Response::Version(got)) if self.grading == Grading::Range => {
                version(before, &want, &got)
            }
            (a, b) if self.grading == Grading::Range => self.physical(before, a, b, c, e, found),
            _ => wrong(Deviation::WrongReply { expected: *e, found: *found }),
        }
    }

    /// Values that depend on the physical world, graded by range and invariants.
    fn physical(
        &self,
        before: &Before,
        a: Response,
        b: Response,
        c: Normative,
        e: &ResponseFrame,
        found: &ResponseFrame,
    ) -> Grade {
        let edition = before.profile().edition;
        let range = before.profile().range();
        let ok = match (a, b) {
            (Response::Position(_), Response::Position(v)) => (v as u64) < range,
            (Response::AnalogValue { channel: asked, .. }, Response::AnalogValue { channel: named, value }) => {
                if asked != named {
                    return Grade::against(Deviation::WrongChannel { asked, named }, c, edition);
                }
                // The harness does not know the temperature: one outside the device's
                // limits without a warning is doubtful, never a FAIL. // 000:T14
                let profile = before.profile();
                let temperature = profile.analog_channel(named).filter(|ch| ch.source == AnalogSource::Temperature);
                if let Some(celsius) = temperature.map(|ch| ch.encoding.decode(value)) {
                    let (min, max) = (profile.temperature_min_c, profile.temperature_max_c);
                    if !found.warning && !(i32::from(min)..=i32::from(max)).contains(&celsius) {
                        let d = Deviation::ImplausibleTemperature { celsius, min, max };
                        return Grade::non_strict(d, clause::ANALOG_SOURCES);
                    }
                }
                true
            }
            (Response::SyncOffset(_), Response::SyncOffset(v)) => v < 32,
            // A stacked code the model cannot see: an operational fault of the real
            // world is plausible; protocol and data errors are never stacked. // 000:T37
            (Response::EncoderStatus(_), Response::EncoderStatus(code)) => {
                let group = crate::fault::runtime_group(code);
                let plausible = !matches!(group, Some(FaultGroup::Protocol | FaultGroup::Data) | None);
                return if plausible {
                    Grade::non_strict(Deviation::UnseenFault { code }, clause::READ_ENCODER_STATUS)
                } else {
                    Grade::against(Deviation::WrongReply { expected: *e, found: *found }, clause::FAULT_GROUPS, edition)
                };
            }
            (Response::PositionWithSyncSet(x), Response::PositionWithSyncSet(v)) => {
                // Same phase as an unknown raw position: only "within 16 steps of the preset" is checkable.
                let (x, v) = (x as u64 % range, v as u64);
                let d = (v + range - x) % range;
                v < range && (d <= 16 || range - d <= 16)
            }
            _ => return Grade::against(Deviation::WrongReply { expected: *e, found: *found }, c, edition),
        };
        if ok {
            Grade::pass(c)
        } else {
            Grade::against(Deviation::ImpossibleValue { response: b }, c, edition)
        }
    }
}

/// A Read Data reply that differs from the model only in bytes the model does not
/// know: PASS in a field the device had before the run (its contents are its own),
/// NON-STRICT in a field created in the run and never written (the model assumes
/// erased EEPROM, FFh: a decision, not a rule of 000). `None` if a known byte differs.
fn unwritten_contents(before: &Before, field: u8, offset: u8, want: &[u8], got: &[u8]) -> Option<Grade> {
    let mut erased_differs = false;
    for (i, (w, g)) in want.iter().zip(got).enumerate() {
        match before.read_contents(field, offset, i) {
            _ if w == g => {}
            Some(Contents::Unknown) => {}
            Some(Contents::Erased) => erased_differs = true,
            Some(Contents::Known) | None => return None,
        }
    }
    Some(if erased_differs {
        Grade::non_strict(Deviation::UnwrittenContents, clause::FIELD_POLICY)
    } else {
        Grade::pass(clause::READ_DATA)
    })
}

/// Read Version of a real device: exact where the profile pins a value, otherwise by
/// the form of 000:T31 (ASCII; the firmware padded with 00h; the date as DD.MM.YY)
/// or 002 (the same, with up to 20 firmware characters).
fn version(before: &Before, want: &Version, got: &Version) -> Grade {
    let profile = before.profile();
    let rule = match profile.edition {
        Edition::Current => clause::READ_VERSION,
        Edition::Legacy => clause::LEGACY_VERSION,
    };
    let pins = profile.version_pins;
    for (pinned, field, equal) in [
        (pins.serial, "serial number", want.serial == got.serial),
        (pins.firmware, "firmware version", want.firmware == got.firmware),
        (pins.date, "firmware date", want.date == got.date),
    ] {
        if pinned && !equal {
            return Grade::against(Deviation::VersionDiffers { field }, rule, profile.edition);
        }
    }
    let form = |field, problem| Grade::non_strict(Deviation::VersionForm { field, problem }, rule);
    let ascii = |b: &[u8]| b.iter().all(|c| c.is_ascii() && (*c == 0 || !c.is_ascii_control()));
    if !ascii(&got.serial) {
        return form("serial number", "is not ASCII text");
    }
    if !ascii(&got.firmware) {
        return form("firmware version", "is not ASCII text");
    }
    let text_end = got.firmware.iter().position(|c| *c == 0).unwrap_or(got.firmware.len());
    if got.firmware.get(text_end..).is_some_and(|pad| pad.iter().any(|c| *c != 0)) {
        return form("firmware version", "has text after its trailing 00h characters");
    }
    let d = &got.date;
    let date_form = d.iter().enumerate().all(|(i, c)| if i == 2 || i == 5 { *c == b'.' } else { c.is_ascii_digit() });
    if !date_form {
        return form("firmware date", "is not in the DD.MM.YY format");
    }
    Grade::pass(rule)
}

/// The clauses the oracle checks on the form of every reply it grades (what
/// `malformed_clause` cites).
pub const REPLY_FORM: [Normative; 5] =
    [clause::CHECKSUM, clause::COMMAND_BYTE, clause::ENCODER_RESET, clause::ERROR_RESPONSE, clause::COMMAND_DEFINITION];

fn malformed_clause(e: ResponseError) -> Normative {
    match e {
        ResponseError::BadChecksum { .. } => clause::CHECKSUM,
        ResponseError::BadCommandByte { .. } => clause::COMMAND_BYTE,
        ResponseError::NoResponseExpected { .. } => clause::ENCODER_RESET,
        ResponseError::TooShort { .. } | ResponseError::WrongCommand { .. } => clause::ERROR_RESPONSE,
        // A reply of the wrong length breaks the command's own definition (000:T31's
        // 37 bytes of Read Version, say).
        ResponseError::WrongLength { to, .. } => to.spec().map_or(clause::COMMAND_DEFINITION, |s| s.clause),
        ResponseError::CountMismatch { .. } => clause::COMMAND_DEFINITION,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::CommandId;

    #[test]
    fn verdicts_are_named_as_the_reports_write_them_the_best_first() {
        assert_eq!(Verdict::ALL.map(Verdict::name), ["PASS", "NON-STRICT", "FAIL"]);
        assert!(Verdict::ALL.windows(2).all(|w| w[0] < w[1]));
        extern crate std;
        assert_eq!(std::format!("{}", Verdict::NonStrict), "NON-STRICT");
    }

    #[test]
    fn reply_form_lists_every_clause_a_malformed_reply_cites() {
        let to = CommandId::ReadPosition;
        let every = [
            ResponseError::NoResponseExpected { to },
            ResponseError::TooShort { len: 1 },
            ResponseError::BadChecksum { expected: 0, found: 1 },
            ResponseError::BadCommandByte { byte: 0 },
            ResponseError::WrongCommand { to, found: 0 },
            ResponseError::WrongLength { to, data_len: 0 },
            ResponseError::CountMismatch { count: 1, data_len: 0 },
        ];
        for e in every {
            let own = match e {
                ResponseError::WrongLength { to, .. } => to.spec().map(|s| s.clause),
                _ => None,
            };
            assert!(REPLY_FORM.contains(&malformed_clause(e)) || own == Some(malformed_clause(e)), "{e:?}");
        }
        let short = ResponseError::WrongLength { to: CommandId::ReadVersion, data_len: 30 };
        assert_eq!(malformed_clause(short), clause::READ_VERSION);
        for c in REPLY_FORM {
            assert!(every.iter().any(|e| malformed_clause(*e) == c), "{c} is cited by no error");
        }
    }
}
