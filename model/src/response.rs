//! Typed slave responses: encode and decode. // 000:T12-T36, 000:2.3.4
//!
//! Long because: under 350 of them are code; the rest are the round-trip
//! tests kept beside the encoder and decoder they check.

use crate::checksum;
use crate::command::{CommandByte, CommandId};
use crate::fault::FaultCode;
use crate::frame::{FieldBytes, Frame, Hex};
use core::fmt;

/// Read Version fields. // 000:T31
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Version {
    pub serial: [u8; 9],
    pub firmware: [u8; 20],
    pub date: [u8; 8],
}

/// A slave response, one variant per command, plus the error response.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Response {
    Position(u32),
    PositionSet,
    AnalogValue {
        channel: u8,
        value: u16,
    },
    Counter(u32),
    CounterIncremented,
    CounterReset,
    Data {
        field: u8,
        offset: u8,
        data: FieldBytes,
    },
    DataStored {
        field: u8,
        offset: u8,
        count: u8,
    },
    FieldStatus {
        field: u8,
        status: u8,
    },
    FieldCreated {
        field: u8,
        status: u8,
    },
    MemoryStatus {
        free_blocks: u8,
        fields: u8,
    },
    AccessCodeSet {
        number: u8,
    },
    EncoderStatus(FaultCode),
    TypeLabel {
        settings: u8,
        type_code: u8,
        memory_blocks: u8,
        option: u8,
    },
    AddressSet,
    Version(Version),
    SerialInterfaceSet {
        settings: u8,
    },
    PositionInternalSyncSet,
    SerialInterfaceTemporarilySet {
        settings: u8,
    },
    PositionWithSyncSet(u32),
    SensorAdjusted {
        option: u8,
        status: u8,
    },
    SyncOffset(u8),
    /// Error response: command value 50h with the error code. // 000:2.3.4
    Error(FaultCode),
}

/// A response with its address byte and warning bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ResponseFrame {
    pub address: u8,
    /// Bit 7 of the command byte. // 000:2.3.4 warning bit
    pub warning: bool,
    pub response: Response,
}

/// Why bytes are not a well-formed response to a given request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ResponseError {
    /// A command that draws no response (53h).
    NoResponseExpected {
        to: CommandId,
    },
    TooShort {
        len: usize,
    },
    BadChecksum {
        expected: u8,
        found: u8,
    },
    /// Bit 6 of the command byte is 0.
    BadCommandByte {
        byte: u8,
    },
    /// Neither the request's command nor the error response 50h.
    WrongCommand {
        to: CommandId,
        found: u8,
    },
    WrongLength {
        to: CommandId,
        data_len: usize,
    },
    /// A Read Data reply whose count byte disagrees with its data.
    CountMismatch {
        count: u8,
        data_len: usize,
    },
}

impl fmt::Display for ResponseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ResponseError::NoResponseExpected { to } => {
                write!(f, "{to} draws no response")
            }
            ResponseError::TooShort { len } => {
                write!(f, "reply of {len} bytes is shorter than address, command and checksum")
            }
            ResponseError::BadChecksum { expected, found } => {
                write!(f, "reply checksum {found:02X}h, the XOR of the other bytes is {expected:02X}h")
            }
            ResponseError::BadCommandByte { byte } => {
                write!(f, "reply command byte {byte:02X}h has bit 6 clear")
            }
            ResponseError::WrongCommand { to, found } => {
                write!(f, "reply command {found:02X}h answers neither {to} nor 50h")
            }
            ResponseError::WrongLength { to, data_len } => {
                write!(f, "{data_len} data bytes are wrong for a reply to {to}")
            }
            ResponseError::CountMismatch { count, data_len } => {
                write!(f, "Read Data reply says {count} bytes but carries {data_len}")
            }
        }
    }
}

fn be32(d: &[u8]) -> u32 {
    d.iter().take(4).fold(0, |v, b| (v << 8) | *b as u32)
}

fn at(d: &[u8], i: usize) -> u8 {
    d.get(i).copied().unwrap_or(0)
}

fn array<const N: usize>(d: &[u8]) -> [u8; N] {
    let mut a = [0; N];
    for (dst, src) in a.iter_mut().zip(d) {
        *dst = *src;
    }
    a
}

impl Response {
    /// The command value this response carries (50h for an error response).
    pub const fn command(&self) -> CommandId {
        match self {
            Response::Position(_) => CommandId::ReadPosition,
            Response::PositionSet => CommandId::SetPosition,
            Response::AnalogValue { .. } => CommandId::ReadAnalogValue,
            Response::Counter(_) => CommandId::ReadCounter,
            Response::CounterIncremented => CommandId::IncrementCounter,
            Response::CounterReset => CommandId::ResetCounter,
            Response::Data { .. } => CommandId::ReadData,
            Response::DataStored { .. } => CommandId::StoreData,
            Response::FieldStatus { .. } => CommandId::DataFieldStatus,
            Response::FieldCreated { .. } => CommandId::CreateDataField,
            Response::MemoryStatus { .. } => CommandId::MemoryStatus,
            Response::AccessCodeSet { .. } => CommandId::SetAccessCode,
            Response::EncoderStatus(_) | Response::Error(_) => CommandId::ReadEncoderStatus,
            Response::TypeLabel { .. } => CommandId::ReadTypeLabel,
            Response::AddressSet => CommandId::SetEncoderAddress,
            Response::Version(_) => CommandId::ReadVersion,
            Response::SerialInterfaceSet { .. } => CommandId::SetSerialInterface,
            Response::PositionInternalSyncSet => CommandId::SetPositionInternalSync,
            Response::SerialInterfaceTemporarilySet { .. } => CommandId::TemporarilySetSerialInterface,
            Response::PositionWithSyncSet(_) => CommandId::SetPositionWithSync,
            Response::SensorAdjusted { .. } => CommandId::SensorAdjustment,
            Response::SyncOffset(_) => CommandId::ReadSyncOffset,
        }
    }

    fn write_data(&self, f: &mut Frame) {
        // Capacity: the longest reply (Read Data, 128 bytes) is 134 bytes < MAX_FRAME.
        let _ = match *self {
            Response::PositionSet
            | Response::CounterIncremented
            | Response::CounterReset
            | Response::AddressSet
            | Response::PositionInternalSyncSet => Ok(()),
            Response::Position(p) | Response::PositionWithSyncSet(p) => f.extend(&p.to_be_bytes()),
            Response::AnalogValue { channel, value } => {
                let [hi, lo] = value.to_be_bytes();
                f.extend(&[channel, hi, lo])
            }
            Response::Counter(c) => {
                let [_, a, b, c] = c.to_be_bytes();
                f.extend(&[a, b, c])
            }
            Response::Data { field, offset, data } => {
                let _ = f.extend(&[field, offset, data.len() as u8]);
                f.extend(data.as_bytes())
            }
            Response::DataStored { field, offset, count } => f.extend(&[field, offset, count]),
            Response::FieldStatus { field, status } | Response::FieldCreated { field, status } => {
                f.extend(&[field, status])
            }
            Response::MemoryStatus { free_blocks, fields } => f.extend(&[free_blocks, fields]),
            Response::AccessCodeSet { number } => f.push(number),
            Response::EncoderStatus(code) | Response::Error(code) => f.push(code.byte()),
            Response::TypeLabel { settings, type_code, memory_blocks, option } => {
                f.extend(&[settings, type_code, memory_blocks, option])
            }
            Response::Version(v) => {
                let _ = f.extend(&v.serial);
                let _ = f.extend(&v.firmware);
                f.extend(&v.date)
            }
            Response::SerialInterfaceSet { settings } | Response::SerialInterfaceTemporarilySet { settings } => {
                f.push(settings)
            }
            Response::SensorAdjusted { option, status } => f.extend(&[option, status]),
            Response::SyncOffset(s) => f.push(s),
        };
    }

    fn from_data(to: CommandId, d: &[u8]) -> Result<Response, ResponseError> {
        let wrong = ResponseError::WrongLength { to, data_len: d.len() };
        let spec = to.spec().ok_or(wrong)?;
        if !spec.slave_data.accepts(d.len()) {
            return Err(if matches!(spec.slave_data, crate::command::DataLength::NoFrame) {
                ResponseError::NoResponseExpected { to }
            } else {
                wrong
            });
        }
        Ok(match to {
            CommandId::ReadPosition => Response::Position(be32(d)),
            CommandId::SetPosition => Response::PositionSet,
            CommandId::ReadAnalogValue => {
                Response::AnalogValue { channel: at(d, 0), value: u16::from_be_bytes([at(d, 1), at(d, 2)]) }
            }
            CommandId::ReadCounter => Response::Counter(be32(&[0, at(d, 0), at(d, 1), at(d, 2)])),
            CommandId::IncrementCounter => Response::CounterIncremented,
            CommandId::ResetCounter => Response::CounterReset,
            CommandId::ReadData => {
                let data = d.get(3..).unwrap_or(&[]);
                if at(d, 2) as usize != data.len() {
                    return Err(ResponseError::CountMismatch { count: at(d, 2), data_len: data.len() });
                }
                Response::Data {
                    field: at(d, 0),
                    offset: at(d, 1),
                    data: FieldBytes::from_bytes(data).map_err(|_| wrong)?,
                }
            }
            CommandId::StoreData => Response::DataStored { field: at(d, 0), offset: at(d, 1), count: at(d, 2) },
            CommandId::DataFieldStatus => Response::FieldStatus { field: at(d, 0), status: at(d, 1) },
            CommandId::CreateDataField => Response::FieldCreated { field: at(d, 0), status: at(d, 1) },
            CommandId::MemoryStatus => Response::MemoryStatus { free_blocks: at(d, 0), fields: at(d, 1) },
            CommandId::SetAccessCode => Response::AccessCodeSet { number: at(d, 0) },
            CommandId::ReadEncoderStatus => Response::EncoderStatus(FaultCode::decode(at(d, 0))),
            CommandId::ReadTypeLabel => Response::TypeLabel {
                settings: at(d, 0),
                type_code: at(d, 1),
                memory_blocks: at(d, 2),
                option: at(d, 3),
            },
            CommandId::SetEncoderAddress => Response::AddressSet,
            CommandId::ReadVersion => Response::Version(Version {
                serial: array(d),
                firmware: array(d.get(9..).unwrap_or(&[])),
                date: array(d.get(29..).unwrap_or(&[])),
            }),
            CommandId::SetSerialInterface => Response::SerialInterfaceSet { settings: at(d, 0) },
            CommandId::SetPositionInternalSync => Response::PositionInternalSyncSet,
            CommandId::TemporarilySetSerialInterface => Response::SerialInterfaceTemporarilySet { settings: at(d, 0) },
            CommandId::SetPositionWithSync => Response::PositionWithSyncSet(be32(d)),
            CommandId::SensorAdjustment => Response::SensorAdjusted { option: at(d, 0), status: at(d, 1) },
            CommandId::ReadSyncOffset => Response::SyncOffset(at(d, 0)),
            CommandId::EncoderReset | CommandId::Unknown(_) => return Err(wrong),
        })
    }
}

impl ResponseFrame {
    /// Encode with checksum; the command byte carries the warning bit.
    pub fn encode(&self) -> Frame {
        let mut f = Frame::new();
        let _ = f.push(self.address);
        let _ = f.push(CommandByte { id: self.response.command(), error_bit: self.warning }.byte());
        self.response.write_data(&mut f);
        let _ = f.seal();
        f
    }

    /// Decode bytes as the reply to a request for `to`. A reply with command value
    /// 50h to any other command is an error response.
    pub fn decode(bytes: &[u8], to: CommandId) -> Result<ResponseFrame, ResponseError> {
        let [address, command, data @ .., _] = bytes else {
            return Err(ResponseError::TooShort { len: bytes.len() });
        };
        if !checksum::is_valid(bytes) {
            let body = &bytes[..bytes.len() - 1];
            return Err(ResponseError::BadChecksum { expected: checksum::xor(body), found: bytes[bytes.len() - 1] });
        }
        let cb = CommandByte::decode(*command).ok_or(ResponseError::BadCommandByte { byte: *command })?;
        let response = if cb.id == to && to == CommandId::EncoderReset {
            // A correct Encoder Reset draws no reply; only an error response may answer it.
            return Err(ResponseError::NoResponseExpected { to });
        } else if cb.id == to {
            Response::from_data(to, data)?
        } else if cb.id == CommandId::ReadEncoderStatus {
            match data {
                [code] => Response::Error(FaultCode::decode(*code)),
                _ => return Err(ResponseError::WrongLength { to: CommandId::ReadEncoderStatus, data_len: data.len() }),
            }
        } else {
            return Err(ResponseError::WrongCommand { to, found: *command });
        };
        Ok(ResponseFrame { address: *address, warning: cb.error_bit, response })
    }
}

impl fmt::Display for ResponseFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}]", Hex(self.encode().as_bytes()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rf(response: Response) -> ResponseFrame {
        ResponseFrame { address: 0x40, warning: false, response }
    }

    #[test]
    fn documents_responses() {
        // 001:5.1.4
        assert_eq!(rf(Response::Position(0)).encode().as_bytes(), &[0x40, 0x42, 0, 0, 0, 0, 0x02]);
        assert_eq!(
            rf(Response::AnalogValue { channel: 0x48, value: 0x25 }).encode().as_bytes(),
            &[0x40, 0x44, 0x48, 0x00, 0x25, 0x69]
        );
        assert_eq!(
            rf(Response::MemoryStatus { free_blocks: 0x16, fields: 0 }).encode().as_bytes(),
            &[0x40, 0x4E, 0x16, 0x00, 0x18]
        );
        assert_eq!(rf(Response::EncoderStatus(FaultCode::NoFault)).encode().as_bytes(), &[0x40, 0x50, 0x00, 0x10]);
        // The error response drawn by a bad checksum.
        assert_eq!(rf(Response::Error(FaultCode::Checksum)).encode().as_bytes(), &[0x40, 0x50, 0x0A, 0x1A]);
        let with_warning = ResponseFrame { warning: true, ..rf(Response::Error(FaultCode::Checksum)) };
        assert_eq!(with_warning.encode().as_bytes(), &[0x40, 0xD0, 0x0A, 0x9A]);
        // 001 erratum: 40 4C 00 C8 1E (C4 is right)
        assert_eq!(
            ResponseFrame::decode(&[0x40, 0x4C, 0x00, 0xC8, 0x1E], CommandId::DataFieldStatus),
            Err(ResponseError::BadChecksum { expected: 0xC4, found: 0x1E })
        );
    }

    #[test]
    fn every_response_round_trips_and_errors_decode_to_any_command() {
        let v = Version { serial: *b"123456789", firmware: *b"v1.0.8\0\0\0\0\0\0\0\0\0\0\0\0\0\0", date: *b"12072019" };
        let all = [
            Response::Position(0x0102_0304),
            Response::PositionSet,
            Response::AnalogValue { channel: 0xF0, value: 0xFFFE },
            Response::Counter(0xFF_FFFF),
            Response::CounterIncremented,
            Response::CounterReset,
            Response::Data { field: 0, offset: 0, data: FieldBytes::from_bytes(&[0xFF; 128]).unwrap() },
            Response::DataStored { field: 1, offset: 5, count: 2 },
            Response::FieldStatus { field: 0, status: 0xC8 },
            Response::FieldCreated { field: 0, status: 0xC9 },
            Response::MemoryStatus { free_blocks: 8, fields: 0 },
            Response::AccessCodeSet { number: 2 },
            Response::EncoderStatus(FaultCode::Temperature),
            Response::TypeLabel { settings: 0xE4, type_code: 0x22, memory_blocks: 0x16, option: 0 },
            Response::AddressSet,
            Response::Version(v),
            Response::SerialInterfaceSet { settings: 0xE4 },
            Response::PositionInternalSyncSet,
            Response::SerialInterfaceTemporarilySet { settings: 0xE5 },
            Response::PositionWithSyncSet(0x0005_D2C1),
            Response::SensorAdjusted { option: 1, status: 0 },
            Response::SyncOffset(31),
        ];
        for response in all {
            for warning in [false, true] {
                let frame = ResponseFrame { address: 0x41, warning, response };
                let to = response.command();
                assert_eq!(ResponseFrame::decode(frame.encode().as_bytes(), to), Ok(frame));
            }
        }
        let err = rf(Response::Error(FaultCode::WrongAccessCode)).encode();
        assert_eq!(
            ResponseFrame::decode(err.as_bytes(), CommandId::SetPosition).unwrap().response,
            Response::Error(FaultCode::WrongAccessCode)
        );
        assert_eq!(
            ResponseFrame::decode(&[0x40, 0x53, 0x13], CommandId::EncoderReset),
            Err(ResponseError::NoResponseExpected { to: CommandId::EncoderReset })
        );
        let to_reset = ResponseFrame::decode(&[0x40, 0x50, 0x0A, 0x1A], CommandId::EncoderReset);
        assert_eq!(to_reset.map(|r| r.response), Ok(Response::Error(FaultCode::Checksum)));
        assert!(matches!(
            ResponseFrame::decode(&[0x40, 0x43, 0x03], CommandId::ReadPosition),
            Err(ResponseError::WrongCommand { .. })
        ));
    }
}
