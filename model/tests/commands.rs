//! Every command's success path, and every error code each command can produce,
//! in both editions. A listed code the model cannot produce for a command is named
//! in `UNPRODUCIBLE` with the reason.

mod common;
use common::*;
use hiperface_model::command::{CommandSet, COMMAND_TABLE};
use hiperface_model::slave::inputs::{InitFault, PositionFault};
use hiperface_model::{profiles, CommandId, FaultCode, Profile, Response, ResponseFrame, Slave};
use FaultCode::*;

/// A profile with every command of its edition.
fn full(legacy: bool) -> Profile {
    let mut p = if legacy { profiles::legacy_srs() } else { profiles::ttk70() };
    p.commands = CommandSet::all_for(legacy);
    p
}

/// A valid request body (without checksum) for each command, on a slave prepared by
/// `prepared`.
fn valid_request(profile: &Profile, id: CommandId) -> Vec<u8> {
    let channel = profile.analog.iter().flatten().next().map_or(0, |c| c.selector);
    let data: &[u8] = match id {
        CommandId::SetPosition | CommandId::SetPositionWithSync | CommandId::SetPositionInternalSync => {
            &[0, 0, 0, 5, 0x55]
        }
        CommandId::ReadAnalogValue => &[channel],
        CommandId::ResetCounter => &[0x55],
        CommandId::ReadData => &[0, 0, 16, 0x55],
        CommandId::StoreData => &[0, 0, 2, 0x55, 1, 2],
        CommandId::DataFieldStatus => &[0],
        CommandId::CreateDataField => &[0, 0xC9, 0x55],
        CommandId::SetAccessCode => &[1, 0x55, 0x56],
        CommandId::SetEncoderAddress => &[0x41, 0x55],
        CommandId::SetSerialInterface => &[0xE5, 0x55],
        CommandId::TemporarilySetSerialInterface => &[0xE5],
        CommandId::SensorAdjustment => &[0x01, 0x55],
        _ => &[],
    };
    let mut v = vec![0x40, id.byte()];
    v.extend_from_slice(data);
    v
}

/// A slave with field 0 (32 bytes, Code0, code enabled, writable) and the given profile.
fn prepared(profile: Profile) -> Slave {
    let mut s = operational(profile);
    assert_eq!(ask_sealed(&mut s, &[0x40, 0x4D, 0, 0xC9, 0x55]), Some(sealed(&[0x40, 0x4D, 0, 0xC9])));
    s
}

fn response(bytes: &[u8], to: CommandId) -> Response {
    ResponseFrame::decode(bytes, to).unwrap_or_else(|e| panic!("{to}: {e}")).response
}

#[test]
fn every_command_succeeds_in_both_editions() {
    for legacy in [false, true] {
        for spec in COMMAND_TABLE.iter().filter(|s| full(legacy).commands.contains(s.id)) {
            let mut s = prepared(full(legacy));
            let reply = ask_sealed(&mut s, &valid_request(&full(legacy), spec.id));
            if spec.id == CommandId::EncoderReset {
                assert_eq!(reply, None, "000:T29: no response");
                continue;
            }
            let reply = reply.unwrap_or_else(|| panic!("{} must answer", spec.id));
            let r = response(&reply, spec.id);
            assert!(!matches!(r, Response::Error(_)), "{}: {r:?}", spec.id);
            assert_eq!(r.command(), spec.id, "{}", spec.id);
            let expected_addr = if spec.id == CommandId::SetEncoderAddress { 0x41 } else { 0x40 };
            assert_eq!(reply[0], expected_addr);
        }
    }
}

/// Codes a command's table row lists that no request can draw from this model.
const UNPRODUCIBLE: &[(CommandId, FaultCode, &str)] = &[
    (CommandId::ReadPosition, WrongArgument, "42h has no argument bytes"),
    (CommandId::ReadSyncOffset, WrongArgument, "6Ch has no argument bytes"),
    (CommandId::TemporarilySetSerialInterface, WrongAccessCode, "67h carries no access code"),
];

/// Bring a slave into a state where `request` draws `code`; returns the request body.
fn provoke(profile: Profile, id: CommandId, code: FaultCode) -> Option<(Slave, Vec<u8>, bool)> {
    let mut req = valid_request(&profile, id);
    let mut faulty = false;
    let mut s = prepared(profile);
    let power_cycle_with = |s: &mut Slave, f: InitFault| {
        s.inject_init_fault(f, true);
        s.power_cycle(0);
        s.settle();
    };
    match code {
        Parity => faulty = true,
        Checksum => {}
        UnknownCommand => {
            let mut p = profile;
            p.commands.remove(id);
            s = if id == CommandId::CreateDataField { operational(p) } else { prepared(p) };
        }
        WrongLength => req.push(0x00),
        WrongArgument => match id {
            CommandId::SetPosition | CommandId::SetPositionWithSync | CommandId::SetPositionInternalSync => {
                req[2..6].copy_from_slice(&(s.profile().range() as u32).to_be_bytes())
            }
            CommandId::ReadAnalogValue => req[2] = 0x00,
            CommandId::SetAccessCode => req[2] = 4,
            CommandId::SetEncoderAddress => req[2] = 0x60,
            CommandId::SetSerialInterface | CommandId::TemporarilySetSerialInterface => req[2] = 0xE7,
            CommandId::SensorAdjustment => req[2] = 0x77,
            _ => return None,
        },
        WrongAccessCode => match id {
            CommandId::SetAccessCode => req[3] = 0x00,
            CommandId::ReadData | CommandId::StoreData => req[5] = 0x00,
            CommandId::CreateDataField => req[4] = 0x00,
            _ if id.spec().is_some_and(|sp| sp.access == hiperface_model::command::AccessCodeRule::Code0) => {
                let last = req.len() - 1;
                req[last] = 0x00;
            }
            _ => return None,
        },
        AngularOffset => power_cycle_with(&mut s, InitFault::AngularOffset),
        PartitionTable => power_cycle_with(&mut s, InitFault::PartitionTable),
        InternalChecksum => power_cycle_with(&mut s, InitFault::TypeCode),
        I2cBus => s.inject_i2c_fault(true),
        CounterOverflow => s.set_counter(0xFF_FFFF),
        ReadOnlyField => match id {
            CommandId::StoreData => {
                // A read-only field 1 (16 bytes, Code0, code disabled).
                assert!(ask_sealed(&mut s, &[0x40, 0x4D, 1, 0x80, 0x55]).is_some());
                req[2] = 1;
            }
            _ => return None,
        },
        OutOfMemory => req[3] = 0xC7 | 0x08, // grow field 0 to 128 bytes: 8 blocks > 7 free? see below
        WrongOffset => match id {
            CommandId::ReadData => req[3] = 17,
            CommandId::StoreData => req[3] = 31,
            _ => return None,
        },
        WrongFieldNumber => req[2] = 5,
        LedCurrent => s = with_inputs(s, |i| i.led_current_ma = 1000),
        Speed => s = with_inputs(s, |i| i.speed = 20_000),
        Singleturn => s.inject_position_fault(PositionFault::Singleturn, true),
        MultiturnAmplitude => s.inject_position_fault(PositionFault::MultiturnAmplitude, true),
        MultiturnSync => s.inject_position_fault(PositionFault::MultiturnSync, true),
        MultiturnVectorLength => s.inject_position_fault(PositionFault::MultiturnVectorLength, true),
        _ => return None,
    }
    if code == OutOfMemory && id != CommandId::CreateDataField {
        return None;
    }
    Some((s, req, faulty))
}

#[test]
fn every_listed_error_code_is_produced() {
    let mut produced = 0;
    for legacy in [false, true] {
        let mut profile = full(legacy);
        // Little memory so that growing field 0 to 128 bytes does not fit (10h).
        profile.user_memory_blocks = 6;
        profile.memory_blocks = 8;
        for spec in COMMAND_TABLE.iter().filter(|s| profile.commands.contains(s.id)) {
            let codes = [Parity, Checksum, UnknownCommand, WrongLength].into_iter().chain(spec.errors.iter().copied());
            for code in codes {
                if UNPRODUCIBLE.iter().any(|(c, f, _)| *c == spec.id && *f == code) {
                    continue;
                }
                let (mut s, req, faulty) = provoke(profile, spec.id, code)
                    .unwrap_or_else(|| panic!("no provocation of {code} for {}", spec.id));
                let mut frame = sealed(&req);
                if code == Checksum {
                    *frame.last_mut().unwrap() ^= 0x01;
                }
                let outcome = if faulty { s.handle_faulty_frame(&frame, 0) } else { s.handle_frame(&frame, 0) };
                let reply = reply_bytes(&outcome).unwrap_or_else(|| panic!("{}: silent for {code}", spec.id));
                let r = ResponseFrame::decode(&reply, spec.id).unwrap();
                let legacy_overflow = legacy && code == CounterOverflow;
                if legacy_overflow {
                    // 002:47h: "any overflow is shown by the ERROR bit".
                    assert_eq!(r.response, Response::CounterIncremented);
                    assert!(r.warning);
                    assert_eq!(s.error_stack().entries().next(), Some(CounterOverflow));
                } else {
                    // An error response to 50h has the form of a status reply. // 000:2.3.4
                    let want = if spec.id == CommandId::ReadEncoderStatus {
                        Response::EncoderStatus(code)
                    } else {
                        Response::Error(code)
                    };
                    assert_eq!(
                        r.response,
                        want,
                        "{} ({}) for {code}",
                        spec.id,
                        if legacy { "legacy" } else { "current" }
                    );
                }
                produced += 1;
            }
        }
    }
    assert!(produced > 150, "{produced}");
}

#[test]
fn unproducible_codes_are_really_listed() {
    for (id, code, _why) in UNPRODUCIBLE {
        assert!(id.spec().unwrap().errors.contains(code), "{id} does not list {code}");
    }
}
