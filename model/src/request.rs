//! Typed master requests: encode and decode. // 000:T12-T36, 002:63h
//!
//! Long because: under 360 of them are code; the rest are the round-trip
//! tests kept beside the encoder and decoder they check.

use crate::address::AddressByte;
use crate::checksum;
use crate::command::{CommandByte, CommandId};
use crate::fault::FaultCode;
use crate::frame::{FieldBytes, Frame, FrameFull, Hex};
use core::fmt;

/// A master request, one variant per command of the command table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Request {
    ReadPosition,
    SetPosition {
        preset: u32,
        code0: u8,
    },
    ReadAnalogValue {
        channel: u8,
    },
    ReadCounter,
    IncrementCounter,
    ResetCounter {
        code0: u8,
    },
    ReadData {
        field: u8,
        offset: u8,
        count: u8,
        code: u8,
    },
    /// The byte count on the wire is `data.len()`.
    StoreData {
        field: u8,
        offset: u8,
        code: u8,
        data: FieldBytes,
    },
    DataFieldStatus {
        field: u8,
    },
    CreateDataField {
        field: u8,
        status: u8,
        code: u8,
    },
    MemoryStatus,
    SetAccessCode {
        number: u8,
        old: u8,
        new: u8,
    },
    ReadEncoderStatus,
    ReadTypeLabel,
    EncoderReset,
    SetEncoderAddress {
        address: u8,
        code0: u8,
    },
    ReadVersion,
    SetSerialInterface {
        settings: u8,
        code0: u8,
    },
    SetPositionInternalSync {
        preset: u32,
        code0: u8,
    },
    TemporarilySetSerialInterface {
        settings: u8,
    },
    SetPositionWithSync {
        preset: u32,
        code0: u8,
    },
    SensorAdjustment {
        option: u8,
        code0: u8,
    },
    ReadSyncOffset,
}

/// Why bytes are not a well-formed request. Each maps to the error code a slave
/// answers (DESIGN: order of checks).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RequestError {
    /// Fewer than 3 bytes (address, command, checksum): 0Ch.
    TooShort { len: usize },
    /// The XOR of all bytes is not 0: 0Ah.
    BadChecksum { expected: u8, found: u8 },
    /// Bit 6 clear, error bit set, or an identifier not in the command table: 0Bh.
    UnknownCommand { byte: u8 },
    /// The data length does not fit the command: 0Ch.
    WrongLength { command: CommandId, data_len: usize },
}

impl RequestError {
    /// The error code a slave answers this request with, in the order of 000's
    /// checks: 0Ch too short or wrong length, 0Ah checksum, 0Bh unknown command
    /// (000:2.3.3, 000:T48-T49).
    pub const fn fault_code(&self) -> FaultCode {
        match self {
            RequestError::TooShort { .. } | RequestError::WrongLength { .. } => FaultCode::WrongLength,
            RequestError::BadChecksum { .. } => FaultCode::Checksum,
            RequestError::UnknownCommand { .. } => FaultCode::UnknownCommand,
        }
    }
}

impl fmt::Display for RequestError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RequestError::TooShort { len } => {
                write!(f, "frame of {len} bytes is shorter than address, command and checksum")
            }
            RequestError::BadChecksum { expected, found } => {
                write!(f, "checksum {found:02X}h, the XOR of the other bytes is {expected:02X}h")
            }
            RequestError::UnknownCommand { byte } => {
                write!(f, "command byte {byte:02X}h is not a request command")
            }
            RequestError::WrongLength { command, data_len } => {
                write!(f, "{data_len} data bytes are wrong for {command}")
            }
        }
    }
}

/// A request with its address byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RequestFrame {
    pub address: AddressByte,
    pub request: Request,
}

fn be32(d: &[u8]) -> u32 {
    let mut v = 0u32;
    for b in d.iter().take(4) {
        v = (v << 8) | *b as u32;
    }
    v
}

/// Byte `i` of `d`, 0 when absent (lengths are checked before this is used).
fn at(d: &[u8], i: usize) -> u8 {
    d.get(i).copied().unwrap_or(0)
}

impl Request {
    pub const fn command(&self) -> CommandId {
        match self {
            Request::ReadPosition => CommandId::ReadPosition,
            Request::SetPosition { .. } => CommandId::SetPosition,
            Request::ReadAnalogValue { .. } => CommandId::ReadAnalogValue,
            Request::ReadCounter => CommandId::ReadCounter,
            Request::IncrementCounter => CommandId::IncrementCounter,
            Request::ResetCounter { .. } => CommandId::ResetCounter,
            Request::ReadData { .. } => CommandId::ReadData,
            Request::StoreData { .. } => CommandId::StoreData,
            Request::DataFieldStatus { .. } => CommandId::DataFieldStatus,
            Request::CreateDataField { .. } => CommandId::CreateDataField,
            Request::MemoryStatus => CommandId::MemoryStatus,
            Request::SetAccessCode { .. } => CommandId::SetAccessCode,
            Request::ReadEncoderStatus => CommandId::ReadEncoderStatus,
            Request::ReadTypeLabel => CommandId::ReadTypeLabel,
            Request::EncoderReset => CommandId::EncoderReset,
            Request::SetEncoderAddress { .. } => CommandId::SetEncoderAddress,
            Request::ReadVersion => CommandId::ReadVersion,
            Request::SetSerialInterface { .. } => CommandId::SetSerialInterface,
            Request::SetPositionInternalSync { .. } => CommandId::SetPositionInternalSync,
            Request::TemporarilySetSerialInterface { .. } => CommandId::TemporarilySetSerialInterface,
            Request::SetPositionWithSync { .. } => CommandId::SetPositionWithSync,
            Request::SensorAdjustment { .. } => CommandId::SensorAdjustment,
            Request::ReadSyncOffset => CommandId::ReadSyncOffset,
        }
    }

    /// The Code0 the request presents, for the commands that Code0 guards
    /// (000:T26, "Access code: Code0" in each command's table).
    pub fn code0(&self) -> Option<u8> {
        match *self {
            Request::SetPosition { code0, .. }
            | Request::SetPositionInternalSync { code0, .. }
            | Request::SetPositionWithSync { code0, .. }
            | Request::ResetCounter { code0 }
            | Request::SetEncoderAddress { code0, .. }
            | Request::SetSerialInterface { code0, .. }
            | Request::SensorAdjustment { code0, .. } => Some(code0),
            _ => None,
        }
    }

    /// Decode the data bytes of a known command whose length the table accepts.
    pub(crate) fn from_data(command: CommandId, d: &[u8]) -> Result<Request, RequestError> {
        let wrong = RequestError::WrongLength { command, data_len: d.len() };
        let spec = command.spec().ok_or(RequestError::UnknownCommand { byte: command.byte() })?;
        if !spec.master_data.accepts(d.len()) {
            return Err(wrong);
        }
        Ok(match command {
            CommandId::ReadPosition => Request::ReadPosition,
            CommandId::SetPosition => Request::SetPosition { preset: be32(d), code0: at(d, 4) },
            CommandId::ReadAnalogValue => Request::ReadAnalogValue { channel: at(d, 0) },
            CommandId::ReadCounter => Request::ReadCounter,
            CommandId::IncrementCounter => Request::IncrementCounter,
            CommandId::ResetCounter => Request::ResetCounter { code0: at(d, 0) },
            CommandId::ReadData => {
                Request::ReadData { field: at(d, 0), offset: at(d, 1), count: at(d, 2), code: at(d, 3) }
            }
            CommandId::StoreData => {
                // The count byte must equal the number of data bytes that follow. // 000:T22
                let data = d.get(4..).ok_or(wrong)?;
                if at(d, 2) as usize != data.len() {
                    return Err(wrong);
                }
                let data = FieldBytes::from_bytes(data).map_err(|_| wrong)?;
                Request::StoreData { field: at(d, 0), offset: at(d, 1), code: at(d, 3), data }
            }
            CommandId::DataFieldStatus => Request::DataFieldStatus { field: at(d, 0) },
            CommandId::CreateDataField => {
                Request::CreateDataField { field: at(d, 0), status: at(d, 1), code: at(d, 2) }
            }
            CommandId::MemoryStatus => Request::MemoryStatus,
            CommandId::SetAccessCode => Request::SetAccessCode { number: at(d, 0), old: at(d, 1), new: at(d, 2) },
            CommandId::ReadEncoderStatus => Request::ReadEncoderStatus,
            CommandId::ReadTypeLabel => Request::ReadTypeLabel,
            CommandId::EncoderReset => Request::EncoderReset,
            CommandId::SetEncoderAddress => Request::SetEncoderAddress { address: at(d, 0), code0: at(d, 1) },
            CommandId::ReadVersion => Request::ReadVersion,
            CommandId::SetSerialInterface => Request::SetSerialInterface { settings: at(d, 0), code0: at(d, 1) },
            CommandId::SetPositionInternalSync => Request::SetPositionInternalSync { preset: be32(d), code0: at(d, 4) },
            CommandId::TemporarilySetSerialInterface => Request::TemporarilySetSerialInterface { settings: at(d, 0) },
            CommandId::SetPositionWithSync => Request::SetPositionWithSync { preset: be32(d), code0: at(d, 4) },
            CommandId::SensorAdjustment => Request::SensorAdjustment { option: at(d, 0), code0: at(d, 1) },
            CommandId::ReadSyncOffset => Request::ReadSyncOffset,
            CommandId::Unknown(byte) => return Err(RequestError::UnknownCommand { byte }),
        })
    }

    /// Append the data bytes.
    fn write_data(&self, f: &mut Frame) -> Result<(), FrameFull> {
        match *self {
            Request::ReadPosition
            | Request::ReadCounter
            | Request::IncrementCounter
            | Request::MemoryStatus
            | Request::ReadEncoderStatus
            | Request::ReadTypeLabel
            | Request::EncoderReset
            | Request::ReadVersion
            | Request::ReadSyncOffset => Ok(()),
            Request::SetPosition { preset, code0 }
            | Request::SetPositionInternalSync { preset, code0 }
            | Request::SetPositionWithSync { preset, code0 } => {
                f.extend(&preset.to_be_bytes())?;
                f.push(code0)
            }
            Request::ReadAnalogValue { channel } => f.push(channel),
            Request::ResetCounter { code0 } => f.push(code0),
            Request::ReadData { field, offset, count, code } => f.extend(&[field, offset, count, code]),
            Request::StoreData { field, offset, code, data } => {
                f.extend(&[field, offset, data.len() as u8, code])?;
                f.extend(data.as_bytes())
            }
            Request::DataFieldStatus { field } => f.push(field),
            Request::CreateDataField { field, status, code } => f.extend(&[field, status, code]),
            Request::SetAccessCode { number, old, new } => f.extend(&[number, old, new]),
            Request::SetEncoderAddress { address, code0 } => f.extend(&[address, code0]),
            Request::SetSerialInterface { settings, code0 } => f.extend(&[settings, code0]),
            Request::TemporarilySetSerialInterface { settings } => f.push(settings),
            Request::SensorAdjustment { option, code0 } => f.extend(&[option, code0]),
        }
    }
}

impl RequestFrame {
    pub const fn new(address: AddressByte, request: Request) -> RequestFrame {
        RequestFrame { address, request }
    }

    /// Encode with checksum.
    pub fn encode(&self) -> Frame {
        let mut f = Frame::new();
        // Capacity: the longest request (Store Data, 128 bytes) is MAX_FRAME exactly.
        let _ = f.push(self.address.byte());
        let _ = f.push(self.request.command().byte());
        let _ = self.request.write_data(&mut f);
        let _ = f.seal();
        f
    }

    /// Decode, checking in the order of DESIGN's check list: length >= 3, checksum,
    /// command byte, data length. The address byte is returned as it is; whether it
    /// addresses a slave is the slave's business.
    pub fn decode(bytes: &[u8]) -> Result<RequestFrame, RequestError> {
        // The checks decode the request's data once: that decoding is the request.
        let (checks, request) = RequestChecks::with_request(bytes);
        let [address, command, data @ .., _checksum] = bytes else {
            return Err(RequestError::TooShort { len: bytes.len() });
        };
        if let Some((expected, found)) = checks.bad_checksum {
            return Err(RequestError::BadChecksum { expected, found });
        }
        let Some(id) = checks.command else {
            return Err(RequestError::UnknownCommand { byte: *command });
        };
        let request = match request {
            Some(request) => request?,
            None => Request::from_data(id, data)?,
        };
        Ok(RequestFrame { address: AddressByte::decode(*address), request })
    }
}

/// The request conditions of the check order (DESIGN:order), each evaluated on its
/// own: the decoder reports the first, the slave every one that holds (the others are
/// acceptable alternatives). One place for what "too short", "bad checksum", "unknown
/// command" and "wrong length" mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RequestChecks {
    /// Fewer than 3 bytes: 0Ch.
    pub too_short: bool,
    /// (the XOR of the other bytes, the checksum found) where they differ: 0Ah.
    pub bad_checksum: Option<(u8, u8)>,
    /// The command of the table, if the command byte names one (bit 6 set, error bit
    /// clear); `None` with two bytes or more: 0Bh.
    pub command: Option<CommandId>,
    /// The data length does not fit the command (or Store Data's count does not match
    /// its data): 0Ch.
    pub wrong_length: bool,
}

impl RequestChecks {
    pub fn of(bytes: &[u8]) -> RequestChecks {
        Self::with_request(bytes).0
    }

    /// The checks, and the request's data decoded for its command where the command
    /// byte names one (what `wrong_length` is read from): decoded once for the checks
    /// and the request.
    #[inline]
    pub(crate) fn with_request(bytes: &[u8]) -> (RequestChecks, Option<Result<Request, RequestError>>) {
        let bad_checksum = match bytes {
            [body @ .., last] if bytes.len() >= 2 && !checksum::is_valid(bytes) => Some((checksum::xor(body), *last)),
            _ => None,
        };
        let command = bytes.get(1).and_then(|b| match CommandByte::decode(*b) {
            Some(CommandByte { id, error_bit: false }) if id.spec().is_some() => Some(id),
            _ => None,
        });
        let request = match (command, bytes) {
            (Some(id), [_, _, data @ .., _]) => Some(Request::from_data(id, data)),
            _ => None,
        };
        let wrong_length = request.as_ref().is_some_and(Result::is_err);
        (RequestChecks { too_short: bytes.len() < 3, bad_checksum, command, wrong_length }, request)
    }
}

impl fmt::Display for RequestFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} [{}]", self.request.command(), Hex(self.encode().as_bytes()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::address::SlaveAddress;

    const A: AddressByte = AddressByte::Slave(SlaveAddress::DEFAULT);

    /// A malformed request's code is the one the slave answers it with.
    #[test]
    fn a_decode_errors_code_is_the_slaves_answer() {
        // Too short; a wrong checksum; 7Eh sealed (no such command); Read Position
        // sealed with a data byte it does not take.
        let frames: [&[u8]; 4] = [&[0x40, 0x42], &[0x40, 0x42, 0x03], &[0x40, 0x7E, 0x3E], &[0x40, 0x42, 0x00, 0x02]];
        let codes = [FaultCode::WrongLength, FaultCode::Checksum, FaultCode::UnknownCommand, FaultCode::WrongLength];
        for (frame, code) in frames.iter().zip(codes) {
            let e = RequestFrame::decode(frame).expect_err("malformed");
            assert_eq!(e.fault_code(), code, "{frame:02X?}");
            let mut slave = crate::Slave::operational(crate::profiles::srs50());
            match slave.handle_frame(frame, 0).reply {
                crate::Reply::Frame(f) => assert_eq!(f.response, crate::Response::Error(code), "{frame:02X?}"),
                other => panic!("{frame:02X?}: {other:?}"),
            }
        }
    }

    #[test]
    fn documents_requests_decode() {
        // 001:5.1.4
        let r = RequestFrame::decode(&[0x40, 0x6A, 0x00, 0x05, 0xD2, 0xC7, 0x55, 0x6F]).unwrap();
        assert_eq!(r.request, Request::SetPositionWithSync { preset: 0x0005_D2C7, code0: 0x55 });
        let r = RequestFrame::decode(&[0x40, 0x4B, 0x00, 0x00, 0x08, 0x55, 0xFF, 0, 0xFF, 0, 0xFF, 0, 0xFF, 0, 0x56])
            .unwrap();
        assert!(matches!(r.request, Request::StoreData { field: 0, offset: 0, code: 0x55, data } if data.len() == 8));
        // 001 erratum: 40 57 E4 55 5C (A6 is right)
        assert_eq!(
            RequestFrame::decode(&[0x40, 0x57, 0xE4, 0x55, 0x5C]),
            Err(RequestError::BadChecksum { expected: 0xA6, found: 0x5C })
        );
    }

    #[test]
    fn malformed_requests_are_typed_errors() {
        assert_eq!(RequestFrame::decode(&[0x40, 0x42]), Err(RequestError::TooShort { len: 2 }));
        assert_eq!(RequestFrame::decode(&[]), Err(RequestError::TooShort { len: 0 }));
        assert_eq!(RequestFrame::decode(&[0x40, 0x45, 0x05]), Err(RequestError::UnknownCommand { byte: 0x45 }));
        assert_eq!(RequestFrame::decode(&[0x40, 0xC2, 0x82]), Err(RequestError::UnknownCommand { byte: 0xC2 }));
        assert_eq!(RequestFrame::decode(&[0x40, 0x02, 0x42]), Err(RequestError::UnknownCommand { byte: 0x02 }));
        assert_eq!(
            RequestFrame::decode(&[0x40, 0x42, 0x00, 0x02]),
            Err(RequestError::WrongLength { command: CommandId::ReadPosition, data_len: 1 })
        );
        // Store Data whose count byte disagrees with the data bytes.
        let mut f = Frame::from_bytes(&[0x40, 0x4B, 0x00, 0x00, 0x02, 0x55, 0x01]).unwrap();
        f.seal().unwrap();
        assert!(matches!(RequestFrame::decode(f.as_bytes()), Err(RequestError::WrongLength { .. })));
    }

    /// One request of each command.
    fn one_of_each() -> [Request; 23] {
        let data = FieldBytes::from_bytes(&[7; 128]).unwrap();
        [
            Request::ReadPosition,
            Request::SetPosition { preset: 0x0102_0304, code0: 0x55 },
            Request::ReadAnalogValue { channel: 0x48 },
            Request::ReadCounter,
            Request::IncrementCounter,
            Request::ResetCounter { code0: 0x55 },
            Request::ReadData { field: 1, offset: 2, count: 3, code: 4 },
            Request::StoreData { field: 1, offset: 0, code: 0x55, data },
            Request::DataFieldStatus { field: 0xFF },
            Request::CreateDataField { field: 0, status: 0xC9, code: 0x55 },
            Request::MemoryStatus,
            Request::SetAccessCode { number: 2, old: 0x55, new: 0x66 },
            Request::ReadEncoderStatus,
            Request::ReadTypeLabel,
            Request::EncoderReset,
            Request::SetEncoderAddress { address: 0x41, code0: 0x55 },
            Request::ReadVersion,
            Request::SetSerialInterface { settings: 0xE4, code0: 0x55 },
            Request::SetPositionInternalSync { preset: 5, code0: 0x55 },
            Request::TemporarilySetSerialInterface { settings: 0xE5 },
            Request::SetPositionWithSync { preset: 0x0005_D2C7, code0: 0x55 },
            Request::SensorAdjustment { option: 1, code0: 0x55 },
            Request::ReadSyncOffset,
        ]
    }

    #[test]
    fn every_request_round_trips() {
        let all = one_of_each();
        assert_eq!(all.len(), crate::command::COMMAND_TABLE.len());
        for request in all {
            let rf = RequestFrame::new(A, request);
            let bytes = rf.encode();
            assert!(checksum::is_valid(bytes.as_bytes()));
            assert_eq!(RequestFrame::decode(bytes.as_bytes()), Ok(rf), "{rf}");
        }
        assert_eq!(RequestFrame::new(A, Request::ReadPosition).encode().as_bytes(), &[0x40, 0x42, 0x02]);
    }

    /// The commands whose table says "Access code: Code0" carry it as their last data
    /// byte (000:T26 and each command's table); no other request presents Code0.
    #[test]
    fn code0_is_where_the_command_table_says() {
        use crate::command::AccessCodeRule;
        for request in one_of_each() {
            let frame = RequestFrame::new(A, request).encode();
            let bytes = frame.as_bytes();
            let last_data = bytes.len().checked_sub(2).and_then(|i| bytes.get(i)).copied();
            let guarded = request.command().spec().map(|s| s.access) == Some(AccessCodeRule::Code0);
            assert_eq!(request.code0(), last_data.filter(|_| guarded), "{request:?}");
        }
    }

    /// Each condition of the check order on its own (DESIGN:order): a command byte
    /// names a command of the table only with bit 6 set and the error bit clear, and
    /// the length is judged only for such a command.
    #[test]
    fn request_checks_judge_each_condition() {
        let sealed = |body: &[u8]| {
            let mut f = body.to_vec();
            f.push(checksum::xor(body));
            f
        };
        let ok = RequestChecks::of(&sealed(&[0x40, 0x42]));
        assert_eq!(
            ok,
            RequestChecks {
                too_short: false,
                bad_checksum: None,
                command: Some(CommandId::ReadPosition),
                wrong_length: false
            }
        );
        assert_eq!(RequestChecks::of(&sealed(&[0x40, 0x45])).command, None, "45h is no command of the table");
        assert_eq!(RequestChecks::of(&sealed(&[0x40, 0xC2])).command, None, "error bit set");
        let long = RequestChecks::of(&sealed(&[0x40, 0x42, 0x00]));
        assert!(long.wrong_length && long.command.is_some());
        let unknown = RequestChecks::of(&sealed(&[0x40, 0x45, 0x00]));
        assert!(!unknown.wrong_length, "no length to judge for an unknown command");
        let short = RequestChecks::of(&[0x40, 0x42]);
        assert!(short.too_short && short.bad_checksum == Some((0x40, 0x42)));
    }
}
