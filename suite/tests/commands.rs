//! Every command's success path, and every error code each command's row lists, in
//! both editions: drawn by the one fixture builder (`vectors::fixtures`) and answered
//! by the model. A listed code no request can draw is in `fixtures::UNPRODUCIBLE` with
//! the reason.

use hiperface_model::command::{CommandSet, COMMAND_TABLE};
use hiperface_model::{profiles, CommandId, FaultCode, Profile, Reply, Response, ResponseFrame, Slave};
use hiperface_suite::vectors::fixtures::{self, Provocation};
use hiperface_suite::vectors::{self, Setup};

/// A profile with every command of its edition.
fn full(legacy: bool) -> Profile {
    let mut p = if legacy { profiles::legacy_srs() } else { profiles::ttk70() };
    p.commands = CommandSet::all_for(legacy);
    p
}

fn answer(slave: &mut Slave, frame: &[u8], uart_fault: bool) -> Option<Vec<u8>> {
    let outcome = if uart_fault { slave.handle_faulty_frame(frame, 0) } else { slave.handle_frame(frame, 0) };
    match outcome.reply {
        Reply::Frame(f) => Some(f.encode().as_bytes().to_vec()),
        Reply::Silent(_) => None,
    }
}

#[test]
fn every_command_succeeds_in_both_editions() {
    for legacy in [false, true] {
        let profile = full(legacy);
        for spec in COMMAND_TABLE.iter().filter(|s| profile.commands.contains(s.id)) {
            let mut s = vectors::start(profile, &fixtures::with_field_0()).unwrap();
            let request = hiperface_suite::exchange::sealed(&fixtures::valid_request(&profile, spec.id));
            let reply = answer(&mut s, &request, false);
            if spec.id == CommandId::EncoderReset {
                assert_eq!(reply, None, "000:T29: no response");
                continue;
            }
            let reply = reply.unwrap_or_else(|| panic!("{} must answer", spec.id));
            let r = ResponseFrame::decode(&reply, spec.id).unwrap_or_else(|e| panic!("{}: {e}", spec.id)).response;
            assert!(!matches!(r, Response::Error(_)), "{}: {r:?}", spec.id);
            assert_eq!(r.command(), spec.id, "{}", spec.id);
            let expected_addr = if spec.id == CommandId::SetEncoderAddress { 0x41 } else { 0x40 };
            assert_eq!(reply[0], expected_addr);
        }
    }
}

#[test]
fn every_listed_error_code_is_produced() {
    use FaultCode::*;
    let mut produced = 0;
    for legacy in [false, true] {
        let profile = full(legacy);
        for spec in COMMAND_TABLE.iter().filter(|s| profile.commands.contains(s.id)) {
            let codes = [Parity, Checksum, UnknownCommand, WrongLength].into_iter().chain(spec.errors.iter().copied());
            for code in codes {
                if fixtures::UNPRODUCIBLE.iter().any(|(c, f, _)| *c == spec.id && *f == code) {
                    continue;
                }
                let (mut s, frame, uart_fault) = if code == UnknownCommand {
                    // A device without the command: 0Bh. // 000:T49
                    let mut lacking = profile;
                    lacking.commands.remove(spec.id);
                    let request = fixtures::valid_request(&lacking, spec.id);
                    let s = vectors::start(lacking, &Setup::default()).unwrap();
                    (s, hiperface_suite::exchange::sealed(&request), false)
                } else {
                    let Provocation { setup, frame, uart_fault } = fixtures::provoke(&profile, spec.id, code)
                        .unwrap_or_else(|| panic!("no provocation of {code} for {}", spec.id));
                    (vectors::start(profile, &setup).unwrap(), frame, uart_fault)
                };
                let reply =
                    answer(&mut s, &frame, uart_fault).unwrap_or_else(|| panic!("{}: silent for {code}", spec.id));
                let r = ResponseFrame::decode(&reply, spec.id).unwrap();
                if legacy && code == CounterOverflow {
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
                    let edition = if legacy { "legacy" } else { "current" };
                    assert_eq!(r.response, want, "{} ({edition}) for {code}", spec.id);
                }
                produced += 1;
            }
        }
    }
    assert!(produced > 150, "{produced}");
}

#[test]
fn unproducible_codes_are_really_listed() {
    for (id, code, _why) in fixtures::UNPRODUCIBLE {
        assert!(id.spec().unwrap().errors.contains(code), "{id} does not list {code}");
    }
}
