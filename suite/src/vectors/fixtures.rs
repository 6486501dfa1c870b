//! Fixtures written once: "a valid request of command X" and "provoke error code Y
//! from command X", used by the vector generator and the tests.

use super::{hex, Inputs, Setup};
use crate::frame::sealed;
use hiperface_model::command::AccessCodeRule;
use hiperface_model::{CommandId, FaultCode, Profile};

/// Create data field 0: 32 bytes, Code0 enabled, writable.
pub const FIELD_0: &[u8] = &[0x40, 0x4D, 0, 0xC9, 0x55];

/// Codes a command's row of 000 Table 10 lists that no request can draw, with the reason.
pub const UNPRODUCIBLE: &[(CommandId, FaultCode, &str)] = &[
    (CommandId::ReadPosition, FaultCode::WrongArgument, "42h has no argument bytes"),
    (CommandId::ReadSyncOffset, FaultCode::WrongArgument, "6Ch has no argument bytes"),
    (CommandId::TemporarilySetSerialInterface, FaultCode::WrongAccessCode, "67h carries no access code"),
];

/// A valid request body for a command, on a slave with field 0 (see `FIELD_0`).
pub fn valid_request(p: &Profile, id: CommandId) -> Vec<u8> {
    let channel = p.analog.iter().flatten().next().map_or(0, |c| c.selector);
    let option = p.adjustment.iter().flatten().next().map_or(0, |o| o.option);
    let data: Vec<u8> = match id {
        CommandId::SetPosition | CommandId::SetPositionWithSync | CommandId::SetPositionInternalSync => {
            vec![0, 0, 0, 5, 0x55]
        }
        CommandId::ReadAnalogValue => vec![channel],
        CommandId::ResetCounter => vec![0x55],
        CommandId::ReadData => vec![0, 0, 16, 0x55],
        CommandId::StoreData => vec![0, 0, 2, 0x55, 1, 2],
        CommandId::DataFieldStatus => vec![0],
        CommandId::CreateDataField => vec![1, 0xC0, 0x55],
        CommandId::SetAccessCode => vec![1, 0x55, 0x56],
        CommandId::SetEncoderAddress => vec![0x41, 0x55],
        CommandId::SetSerialInterface => vec![0xE5, 0x55],
        CommandId::TemporarilySetSerialInterface => vec![0xE5],
        CommandId::SensorAdjustment => vec![option, 0x55],
        _ => vec![],
    };
    let mut v = vec![0x40, id.byte()];
    v.extend(data);
    v
}

/// The starting state of the command vectors: field 0 exists.
pub fn with_field_0() -> Setup {
    Setup { requests: vec![hex(&sealed(FIELD_0))], ..Setup::default() }
}

/// How to draw an error code from a command: the starting state and the frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Provocation {
    pub setup: Setup,
    /// The whole frame, checksum included (wrong on purpose for 0Ah).
    pub frame: Vec<u8>,
    /// A character of the frame arrives with a UART fault (09h).
    pub uart_fault: bool,
}

/// Setup and request that draw `code` for a command; `None` where no request can
/// (see [`UNPRODUCIBLE`]) or the code is not one the command's row lists.
pub fn provoke(p: &Profile, id: CommandId, code: FaultCode) -> Option<Provocation> {
    use FaultCode::*;
    let mut setup = with_field_0();
    let mut body = valid_request(p, id);
    let mut uart_fault = false;
    let mut raw: Option<Vec<u8>> = None;
    match code {
        Parity => uart_fault = true,
        Checksum => {
            let mut f = sealed(&body);
            let n = f.len() - 1;
            f[n] ^= 0x01;
            raw = Some(f);
        }
        WrongLength => body.push(0x00),
        WrongArgument => match id {
            CommandId::SetPosition | CommandId::SetPositionWithSync | CommandId::SetPositionInternalSync => {
                let r = u32::try_from(p.range()).ok()?;
                body[2..6].copy_from_slice(&r.to_be_bytes());
            }
            CommandId::ReadAnalogValue => body[2] = 0x00,
            CommandId::SetAccessCode => body[2] = 4,
            CommandId::SetEncoderAddress => body[2] = 0x60,
            CommandId::SetSerialInterface | CommandId::TemporarilySetSerialInterface => body[2] = 0xE7,
            CommandId::SensorAdjustment => body[2] = 0x77,
            _ => return None,
        },
        WrongAccessCode => match id {
            CommandId::SetAccessCode => body[3] = 0x00,
            CommandId::ReadData | CommandId::StoreData => body[5] = 0x00,
            CommandId::CreateDataField => body[4] = 0x00,
            _ if id.spec().is_some_and(|s| s.access == AccessCodeRule::Code0) => {
                let n = body.len() - 1;
                body[n] = 0x00;
            }
            _ => return None,
        },
        AngularOffset => setup.init_faults = vec!["angular-offset".into()],
        PartitionTable => setup.init_faults = vec!["partition-table".into()],
        InternalChecksum => setup.init_faults = vec!["type-code".into()],
        I2cBus => setup.i2c_fault = true,
        CounterOverflow => setup.counter = Some(0xFF_FFFF),
        ReadOnlyField if id == CommandId::StoreData => {
            setup.requests.push(hex(&sealed(&[0x40, 0x4D, 1, 0x80, 0x55])));
            body[2] = 1;
        }
        OutOfMemory if id == CommandId::CreateDataField => body[3] = 0xC7 | 0x80, // a new field of 128 bytes
        WrongOffset => match id {
            CommandId::ReadData => body[3] = 17,
            CommandId::StoreData => body[3] = 31,
            _ => return None,
        },
        WrongFieldNumber => body[2] = 5,
        LedCurrent => setup.inputs = Some(Inputs { led_current_ma: Some(1000), ..Inputs::default() }),
        Speed => setup.inputs = Some(Inputs { speed: Some(20_000), ..Inputs::default() }),
        Singleturn => setup.position_faults = vec!["singleturn".into()],
        MultiturnAmplitude => setup.position_faults = vec!["multiturn-amplitude".into()],
        MultiturnSync => setup.position_faults = vec!["multiturn-sync".into()],
        MultiturnVectorLength => setup.position_faults = vec!["multiturn-vector-length".into()],
        _ => return None,
    }
    if code == OutOfMemory {
        // Fill the memory first: 128-byte fields while they fit.
        let mut blocks = p.user_memory_blocks as u32 - 2;
        let mut n = 1u8;
        while blocks >= 8 {
            setup.requests.push(hex(&sealed(&[0x40, 0x4D, n, 0xC7, 0x55])));
            blocks -= 8;
            n += 1;
        }
        body[2] = n;
    }
    let frame = raw.unwrap_or_else(|| sealed(&body));
    Some(Provocation { setup, frame, uart_fault })
}
