//! The case catalogue for slave certification. Each case names its clauses; the
//! oracle grades every exchange; cases add checks across exchanges (data read back,
//! state restored). Cases that write restore what they changed.

use super::{Case, CaseError, Ctx, Needs};
use hiperface_model::clause::*;
use hiperface_model::{CommandId, Edition, Profile, UartSettings};

type Res = Result<(), CaseError>;

fn always(_: &Profile) -> Option<&'static str> {
    None
}
fn with_etl(p: &Profile) -> Option<&'static str> {
    p.extended_type_label.is_none().then_some("the profile has no Extended Type Label")
}
fn with_6a(p: &Profile) -> Option<&'static str> {
    (!p.commands.contains(CommandId::SetPositionWithSync)).then_some("6Ah is optional and the profile lacks it")
}
fn with_6c(p: &Profile) -> Option<&'static str> {
    (!p.commands.contains(CommandId::ReadSyncOffset)).then_some("6Ch is optional and the profile lacks it")
}
fn with_67(p: &Profile) -> Option<&'static str> {
    if !p.commands.contains(CommandId::TemporarilySetSerialInterface) {
        return Some("67h is optional and the profile lacks it");
    }
    other_baud(p).is_none().then_some("the profile supports a single data rate")
}
fn with_adjustment(p: &Profile) -> Option<&'static str> {
    (!p.commands.contains(CommandId::SensorAdjustment)).then_some("6Bh is optional and the profile lacks it")
}
fn with_63(p: &Profile) -> Option<&'static str> {
    (!p.commands.contains(CommandId::SetPositionInternalSync)).then_some("63h exists in the legacy edition only")
}
fn current_edition(p: &Profile) -> Option<&'static str> {
    (p.edition != Edition::Current).then_some("the legacy edition has no silent settings-change window")
}

/// A supported data rate other than the default, for 67h.
fn other_baud(p: &Profile) -> Option<UartSettings> {
    hiperface_model::settings::Baud::ALL
        .into_iter()
        .rev()
        .find(|b| *b != UartSettings::DEFAULT.baud && p.supports_baud(*b))
        .map(|baud| UartSettings { baud, ..UartSettings::DEFAULT })
}

macro_rules! case {
    ($id:literal, $title:literal, [$($clause:ident),*], $needs:ident, $applies:expr, $run:expr) => {
        Case {
            id: $id,
            title: $title,
            clauses: const { &[$($clause.clause()),*] },
            needs: Needs::$needs,
            applies: $applies,
            run: $run,
        }
    };
}

/// Every case, in run order.
pub fn catalogue() -> Vec<Case> {
    vec![
        case!("identity.type-label", "Read Type Label", [READ_TYPE_LABEL], Nothing, always, |c| {
            let a = c.address();
            c.ask(&[a, 0x52]).map(drop)
        }),
        case!(
            "identity.version",
            "Read Version: 37 bytes of serial, firmware, date",
            [READ_VERSION, LEGACY_VERSION],
            Nothing,
            always,
            |c| {
                let a = c.address();
                c.ask(&[a, 0x56]).map(drop)
            }
        ),
        case!(
            "identity.status",
            "Read Encoder Status until the stack is empty (or five times)",
            [READ_ENCODER_STATUS, WARNING_BIT],
            Nothing,
            always,
            |c| {
                let a = c.address();
                // Up to five reads (the stack holds four): the oracle grades each against
                // the model's stack; a persisting condition is stacked again after a read.
                for _ in 0..5 {
                    if c.ask(&[a, 0x50])?.reply.as_ref().and_then(|r| r.get(2)) == Some(&0) {
                        break;
                    }
                }
                Ok(())
            }
        ),
        case!("position.read", "Read Position", [READ_POSITION], Nothing, always, |c| {
            let a = c.address();
            for _ in 0..3 {
                c.ask(&[a, 0x42])?;
            }
            Ok(())
        }),
        case!(
            "address.broadcast",
            "Broadcast FFh is answered with the own address",
            [BROADCAST],
            Nothing,
            always,
            |c| {
                c.ask(&[0xFF, 0x42])?;
                c.ask(&[0xFF, 0x52]).map(drop)
            }
        ),
        case!(
            "address.other",
            "Frames for other addresses draw silence",
            [ADDRESS, CHECK_ORDER],
            Nothing,
            always,
            |c| {
                let a = c.address();
                c.ask(&[a ^ 0x01, 0x42])?;
                c.ask(&[a ^ 0x10, 0x56])?;
                c.ask(&[0x20, 0x42])?;
                // Even a bad checksum for another address stays unanswered (check 1 first).
                c.send_frame(&[a ^ 0x01, 0x42, 0x00]).map(drop)
            }
        ),
        case!("protocol.checksum", "A bad checksum draws 0Ah", [CHECKSUM_ERROR, CHECKSUM], Nothing, always, |c| {
            let a = c.address();
            c.send_frame(&[a, 0x42, 0x00])?;
            c.send_frame(&[a, 0x4E, 0x0F]).map(drop)
        }),
        case!("protocol.unknown-command", "Unknown commands draw 0Bh", [UNKNOWN_COMMAND], Nothing, always, |c| {
            let a = c.address();
            c.ask(&[a, 0x45])?;
            c.ask(&[a, 0x7F])?;
            // Read-only commands of the table the profile lacks.
            let profile = c.profile();
            for id in [CommandId::ReadSyncOffset, CommandId::ReadAnalogValue] {
                if !profile.commands.contains(id) && id.spec().is_some_and(|s| !s.writes_eeprom()) {
                    c.ask(&[a, id.byte()])?;
                }
            }
            Ok(())
        }),
        case!(
            "protocol.length",
            "Frames of the wrong length draw 0Ch",
            [WRONG_LENGTH, CHECK_ORDER],
            Nothing,
            always,
            |c| {
                let a = c.address();
                c.send_frame(&[a, 0x42])?;
                c.ask(&[a, 0x42, 0x00])?;
                c.ask(&[a, 0x4E, 0x00, 0x00])?;
                c.ask(&[a, 0x4C]).map(drop)
            }
        ),
        case!(
            "protocol.argument",
            "A channel the device lacks draws 0Dh",
            [READ_ANALOG, WRONG_ARGUMENT],
            Nothing,
            always,
            |c| {
                let a = c.address();
                let profile = c.profile();
                let missing = (0u8..=0xFF).find(|s| profile.analog_channel(*s).is_none()).unwrap_or(0);
                c.ask(&[a, 0x44, missing]).map(drop)
            }
        ),
        case!(
            "analog.channels",
            "Read Analog Value on every channel of the profile",
            [READ_ANALOG, ANALOG_SOURCES],
            Nothing,
            always,
            |c| {
                let a = c.address();
                let profile = c.profile();
                for ch in profile.analog.iter().flatten() {
                    c.ask(&[a, 0x44, ch.selector])?;
                }
                Ok(())
            }
        ),
        case!("counter.read", "Read Counter", [READ_COUNTER], Nothing, always, |c| {
            let a = c.address();
            c.ask(&[a, 0x46]).map(drop)
        }),
        case!(
            "counter.increment",
            "Increment Counter counts; Reset Counter needs Code0",
            [INCREMENT_COUNTER, RESET_COUNTER],
            CounterChange,
            always,
            |c| {
                let a = c.address();
                c.ask(&[a, 0x46])?;
                c.ask(&[a, 0x47])?;
                c.ask(&[a, 0x46])?;
                let code0 = c.model.nonvolatile().codes[0];
                c.ask(&[a, 0x49, !code0])?;
                c.ask(&[a, 0x49, code0])?;
                c.ask(&[a, 0x46]).map(drop)
            }
        ),
        case!(
            "fields.status",
            "Memory Status and Data Field Status",
            [MEMORY_STATUS, FIELD_STATUS, WRONG_FIELD_NUMBER],
            Nothing,
            always,
            |c| {
                let a = c.address();
                c.ask(&[a, 0x4E])?;
                let n = c.model.nonvolatile().fields.count();
                for f in 0..n {
                    c.ask(&[a, 0x4C, f])?;
                }
                c.ask(&[a, 0x4C, n]).map(drop)
            }
        ),
        case!(
            "fields.lifecycle",
            "Create, store, read back, bounds, delete a data field",
            [CREATE_FIELD, STORE_DATA, READ_DATA, WRONG_OFFSET, FIELD_POLICY],
            Writes,
            always,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                c.ask(&[a, 0x4E])?;
                let n = c.model.nonvolatile().fields.count();
                if c.model.nonvolatile().fields.free_blocks() == 0 {
                    return Err(CaseError::Abort("no free memory for a test field".into()));
                }
                // 16 bytes, Code0, code disabled, writable.
                c.ask(&[a, 0x4D, n, 0xC0, code0])?;
                let g = guard_field(c, n);
                c.ask(&[a, 0x4C, n])?;
                c.ask(&[a, 0x4A, n, 0, 16, 0x00])?;
                let data: Vec<u8> = (0..16u8).map(|i| i.wrapping_mul(37) ^ 0xA5).collect();
                let mut store = vec![a, 0x4B, n, 0, 16, 0x00];
                store.extend(&data);
                c.ask(&store)?;
                // The oracle compares the data read back with the data stored.
                c.ask(&[a, 0x4A, n, 0, 16, 0x00])?;
                // Off by one at the end of the field: 11h.
                c.ask(&[a, 0x4B, n, 15, 2, 0x00, 1, 2])?;
                c.ask(&[a, 0x4A, n, 16, 1, 0x00])?;
                c.ask(&[a, 0x4A, n, 15, 1, 0x00])?;
                c.ask(&[a, 0x4A, n + 1, 0, 1, 0x00])?;
                // Restore: delete it (all status bits but bit 7 as stored).
                c.ask(&[a, 0x4D, n, 0x40, code0])?;
                release(c, g);
                c.ask(&[a, 0x4E]).map(drop)
            }
        ),
        case!(
            "fields.access-code",
            "A field's enabled code guards read, store and delete; read-only fields refuse stores",
            [READ_DATA, STORE_DATA, CREATE_FIELD, READ_ONLY_FIELD, WRONG_ACCESS_CODE],
            Writes,
            always,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let n = c.model.nonvolatile().fields.count();
                if c.model.nonvolatile().fields.free_blocks() == 0 {
                    return Err(CaseError::Abort("no free memory for a test field".into()));
                }
                c.ask(&[a, 0x4D, n, 0xC8, !code0])?; // wrong code at creation: 0Fh
                c.ask(&[a, 0x4D, n, 0xC8, code0])?;
                let g = guard_field(c, n);
                c.ask(&[a, 0x4A, n, 0, 4, !code0])?;
                c.ask(&[a, 0x4A, n, 0, 4, code0])?;
                c.ask(&[a, 0x4B, n, 0, 1, !code0, 0x11])?;
                c.ask(&[a, 0x4D, n, 0x88, code0])?; // read-only
                release(c, g);
                let g = guard_field(c, n);
                c.ask(&[a, 0x4B, n, 0, 1, code0, 0x11])?;
                c.ask(&[a, 0x4D, n, 0x08, !code0])?; // delete with the wrong code: 0Fh
                c.ask(&[a, 0x4D, n, 0x08, code0])?;
                release(c, g);
                Ok(())
            }
        ),
        case!(
            "fields.resize",
            "Only the last field changes size or is deleted",
            [CREATE_FIELD, WRONG_FIELD_NUMBER, FIELD_POLICY],
            Writes,
            always,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let n = c.model.nonvolatile().fields.count();
                if c.model.nonvolatile().fields.free_blocks() < 3 {
                    return Err(CaseError::Abort("fewer than 3 free blocks for two test fields".into()));
                }
                c.ask(&[a, 0x4D, n, 0xC0, code0])?;
                let g0 = guard_field(c, n);
                c.ask(&[a, 0x4D, n + 1, 0xC0, code0])?;
                let g1 = guard_field(c, n + 1);
                c.ask(&[a, 0x4D, n, 0xC1, code0])?; // resize a field that is not the last: 12h
                c.ask(&[a, 0x4D, n, 0x40, code0])?; // delete a field that is not the last: 12h
                c.ask(&[a, 0x4D, n + 3, 0xC0, code0])?; // a number past the next: 12h
                c.ask(&[a, 0x4D, n + 1, 0xC1, code0])?; // grow the last to 32 bytes
                release(c, g1);
                let g1 = guard_field(c, n + 1);
                c.ask(&[a, 0x4E])?;
                c.ask(&[a, 0x4A, n + 1, 16, 16, 0x00])?; // the grown part reads FFh
                c.ask(&[a, 0x4D, n + 1, 0x41, code0])?;
                release(c, g1);
                c.ask(&[a, 0x4D, n, 0x40, code0])?;
                release(c, g0);
                c.ask(&[a, 0x4E]).map(drop)
            }
        ),
        case!(
            "fields.memory-exhaustion",
            "Memory is accounted in 16-byte blocks: a field that does not fit draws 10h",
            [OUT_OF_MEMORY, MEMORY_STATUS, FIELD_POLICY],
            Writes,
            always,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let start = c.model.nonvolatile().fields.count();
                let mut guards = Vec::new();
                // Fill with 128-byte fields while 8 blocks are free, then one more: 10h.
                while c.model.nonvolatile().fields.free_blocks() >= 8 && guards.len() < 32 {
                    let n = c.model.nonvolatile().fields.count();
                    c.ask(&[a, 0x4D, n, 0xC7, code0])?;
                    match guard_field(c, n) {
                        Some(g) => guards.push(g),
                        None => break,
                    }
                }
                let n = c.model.nonvolatile().fields.count();
                c.ask(&[a, 0x4D, n, 0xC7, code0])?;
                c.ask(&[a, 0x4E])?;
                while let Some(g) = guards.pop() {
                    let n = start + guards.len() as u8;
                    c.ask(&[a, 0x4D, n, 0x47, code0])?;
                    c.release(g);
                }
                c.ask(&[a, 0x4E]).map(drop)
            }
        ),
        case!(
            "fields.extended-type-label",
            "The Extended Type Label reads as field FFh",
            [EXTENDED_TYPE_LABEL, WRONG_OFFSET, FIELD_STATUS],
            Nothing,
            with_etl,
            |c| {
                let a = c.address();
                let label = c.ask(&[a, 0x4A, 0xFF, 0, 64, 0x00])?.reply;
                if let Some(bytes) = label.as_ref().and_then(|r| r.get(5..69)) {
                    c.check(
                        hiperface_model::checksum::xor(bytes) == 0,
                        "the label's XOR checksum (offset 0) does not match",
                        EXTENDED_TYPE_LABEL,
                    );
                }
                c.ask(&[a, 0x4A, 0xFF, 60, 5, 0x00])?;
                c.ask(&[a, 0x4C, 0xFF]).map(drop)
            }
        ),
        case!(
            "fields.extended-type-label-read-only",
            "The Extended Type Label refuses stores and creation",
            [READ_ONLY_FIELD, OUT_OF_MEMORY],
            Writes,
            with_etl,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                c.ask(&[a, 0x4B, 0xFF, 0, 1, code0, 0x00])?;
                c.ask(&[a, 0x4D, 0xFF, 0xC0, code0]).map(drop)
            }
        ),
        case!(
            "codes.change-restore",
            "Set Access Code needs the old code; changed and restored",
            [SET_ACCESS_CODE, WRONG_ACCESS_CODE],
            Writes,
            always,
            |c| {
                let a = c.address();
                let old = c.model.nonvolatile().codes[3];
                let new = old.wrapping_add(1);
                c.ask(&[a, 0x4F, 4, old, new])?; // no Code4: 0Dh
                c.ask(&[a, 0x4F, 3, new, new])?; // wrong old code: 0Fh
                c.ask(&[a, 0x4F, 3, old, new])?;
                let g = (c.model.nonvolatile().codes[3] == new).then(|| c.guard(vec![a, 0x4F, 3, new, old]));
                c.ask(&[a, 0x4F, 3, old, old])?; // the old one is gone: 0Fh
                c.ask(&[a, 0x4F, 3, new, old])?;
                release(c, g);
                Ok(())
            }
        ),
        case!(
            "address.change-restore",
            "Set Encoder Address answers from the new address; changed and restored",
            [SET_ADDRESS, ADDRESS],
            Writes,
            always,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let new = if a == 0x5F { 0x5E } else { a + 1 };
                c.ask(&[a, 0x55, 0x60, code0])?; // outside 40h...5Fh: 0Dh
                c.ask(&[a, 0x55, 0x60, !code0])?; // both wrong: 0Dh first (DESIGN:order), 0Fh acceptable
                c.ask(&[a, 0x55, new, !code0])?; // wrong Code0: 0Fh
                c.ask(&[a, 0x55, new, code0])?;
                let g = (c.address() == new).then(|| c.guard(vec![new, 0x55, a, code0]));
                c.ask(&[new, 0x42])?;
                c.ask(&[a, 0x42])?; // the old address is silent now
                c.ask(&[new, 0x55, a, code0])?;
                release(c, g);
                c.ask(&[a, 0x42]).map(drop)
            }
        ),
        case!(
            "position.set",
            "Set Position at standstill, then Read Position; errors for range and code",
            [SET_POSITION, READ_POSITION, POSITION_POLICY],
            Writes,
            always,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let range = c.profile().range();
                let Some(p0) = read_position(c)? else {
                    return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
                };
                if let Ok(r) = u32::try_from(range) {
                    let r = r.to_be_bytes();
                    c.ask(&[a, 0x43, r[0], r[1], r[2], r[3], code0])?; // outside the range: 0Dh
                }
                c.ask(&[a, 0x43, p0[0], p0[1], p0[2], p0[3], !code0])?;
                // Setting the position it reads keeps the offset: a real write, nothing changed.
                c.ask(&[a, 0x43, p0[0], p0[1], p0[2], p0[3], code0])?;
                let p1 = c.ask(&[a, 0x42])?.reply;
                c.check(
                    p1.as_ref().and_then(|r| r.get(2..6)) == Some(&p0[..]),
                    "Read Position after Set Position differs from the preset",
                    SET_POSITION,
                );
                Ok(())
            }
        ),
        case!(
            "position.sync",
            "Set Position with Synchronization keeps the phase; restored",
            [SET_POSITION_SYNC, POSITION_POLICY],
            Writes,
            with_6a,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let Some(p0) = read_position(c)? else {
                    return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
                };
                let shifted = ((u32::from_be_bytes(p0) as u64 + 7) % c.profile().range()) as u32;
                let shifted = shifted.to_be_bytes();
                c.ask(&[a, 0x6A, shifted[0], shifted[1], shifted[2], shifted[3], code0])?;
                let g = c.guard(vec![a, 0x43, p0[0], p0[1], p0[2], p0[3], code0]);
                c.ask(&[a, 0x43, p0[0], p0[1], p0[2], p0[3], code0])?;
                c.release(g);
                Ok(())
            }
        ),
        case!(
            "adjustment.errors",
            "Sensor Adjustment refuses unknown options and wrong codes",
            [SENSOR_ADJUSTMENT],
            Writes,
            with_adjustment,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let profile = c.profile();
                let unknown = (0u8..=0xFF).find(|o| profile.adjustment_option(*o).is_none()).unwrap_or(0xFF);
                c.ask(&[a, 0x6B, unknown, code0])?;
                // Only error paths: a real adjustment may change the device's calibration.
                let known = profile.adjustment.iter().flatten().next().map_or(0, |o| o.option);
                c.ask(&[a, 0x6B, known, !code0]).map(drop)
            }
        ),
        case!(
            "legacy.set-position-sync",
            "Legacy 63h at standstill keeps the position it is given",
            [LEGACY_SET_POSITION_SYNC],
            Writes,
            with_63,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let Some(p0) = read_position(c)? else {
                    return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
                };
                c.ask(&[a, 0x63, p0[0], p0[1], p0[2], p0[3], !code0])?;
                c.ask(&[a, 0x63, p0[0], p0[1], p0[2], p0[3], code0])?;
                c.ask(&[a, 0x42]).map(drop)
            }
        ),
        case!("position.sync-offset", "Read Synchronization Offset", [READ_SYNC_OFFSET], Nothing, with_6c, |c| {
            let a = c.address();
            c.ask(&[a, 0x6C]).map(drop)
        }),
        case!(
            "settings.invalid",
            "Set Serial Interface refuses undefined settings and wrong codes",
            [SET_SERIAL, READ_TYPE_LABEL],
            Writes,
            always,
            |c| {
                let a = c.address();
                let code0 = c.model.nonvolatile().codes[0];
                let stored = c.model.nonvolatile().settings.byte();
                c.ask(&[a, 0x57, (stored & 0xF8) | 0x07, code0])?; // data rate 111: 0Dh
                c.ask(&[a, 0x57, (stored & 0xCF) | 0x10, code0])?; // parity 01: 0Dh
                c.ask(&[a, 0x57, stored, !code0])?;
                // Rewriting the stored byte: a real write that changes nothing.
                c.ask(&[a, 0x57, stored, code0]).map(drop)
            }
        ),
        case!(
            "settings.temporary",
            "Temporarily Set Serial Interface: reply in the old settings, then the new; lost on reset",
            [TEMP_SERIAL, ENCODER_RESET],
            Nothing,
            with_67,
            |c| {
                let a = c.address();
                let Some(other) = other_baud(&c.profile()) else { return Ok(()) };
                if !c.line_can_change_settings() {
                    // The device would answer at a data rate the line cannot follow.
                    let why = "the line keeps fixed UART settings (a raw TCP serial server): 67h cannot be followed";
                    c.push(super::Finding::not_applicable(why));
                    return Ok(());
                }
                c.ask(&[a, 0x67, 0xE7])?; // data rate 111: 0Dh
                c.ask(&[a, 0x67, other.byte()])?;
                let g = c.guard(vec![a, 0x67, UartSettings::DEFAULT.byte()]);
                c.ask(&[a, 0x42])?;
                c.ask(&[a, 0x67, UartSettings::DEFAULT.byte()])?;
                c.release(g);
                c.ask(&[a, 0x42]).map(drop)
            }
        ),
        case!(
            "powerup.reset",
            "Encoder Reset: no reply, silence during initialization, then default settings",
            [ENCODER_RESET, STATE_MACHINE],
            Nothing,
            always,
            |c| {
                let a = c.address();
                let x = c.ask(&[a, 0x53])?.exchange;
                let reset_at = x.complete_us();
                wait_until(c, reset_at + 30_000)?;
                c.ask(&[a, 0x42])?; // initialization: silence
                let init = c.profile().init_ms as u64 * 1000;
                wait_until(c, reset_at + init + 50_000)?;
                c.ask(&[a, 0x42])?;
                c.ask(&[a, 0x50]).map(drop)
            }
        ),
        case!(
            "powerup.window",
            "Without a request the default window closes: silence, then the stored settings",
            [STATE_MACHINE, ENCODER_RESET],
            Nothing,
            current_edition,
            |c| {
                let a = c.address();
                let x = c.ask(&[a, 0x53])?.exchange;
                let reset_at = x.complete_us();
                let p = c.profile();
                let silent_at = (p.default_window_ms as u64 + p.user_settings_ms as u64) * 500;
                wait_until(c, reset_at + silent_at)?;
                c.ask(&[a, 0x42])?; // change of settings: silence
                wait_until(c, reset_at + p.user_settings_ms as u64 * 1000 + 50_000)?;
                c.ask(&[a, 0x42]).map(drop)
            }
        ),
        case!(
            "timing.read-position",
            "Response times and reply framing over 20 Read Position requests",
            [FRAME_TIMING, COMMANDS],
            Nothing,
            always,
            |c| {
                let a = c.address();
                for _ in 0..20 {
                    c.ask(&[a, 0x42])?;
                }
                Ok(())
            }
        ),
    ]
}

/// Read Position; the four position bytes, or `None` when the reply is no position.
fn read_position(c: &mut Ctx<'_>) -> Result<Option<[u8; 4]>, CaseError> {
    let a = c.address();
    let reply = c.ask(&[a, 0x42])?.reply;
    Ok(reply.as_ref().filter(|r| r.len() == 7 && r[1] & 0x7F == 0x42).and_then(|r| r[2..6].try_into().ok()))
}

/// If the model holds field `n`, guard its deletion (status bits as now stored).
fn guard_field(c: &mut Ctx<'_>, n: u8) -> Option<super::Guard> {
    let status = c.model.nonvolatile().fields.status(n)?;
    let (a, code) = (c.address(), c.model.nonvolatile().codes[status.code_number()]);
    Some(c.guard(vec![a, 0x4D, n, status.attributes(), code]))
}

fn release(c: &mut Ctx<'_>, g: Option<super::Guard>) {
    if let Some(g) = g {
        c.release(g);
    }
}

fn wait_until(c: &mut Ctx<'_>, t_us: u64) -> Res {
    let now = c.now_us();
    if t_us > now {
        c.wait_ms((t_us - now).div_ceil(1000))?;
    }
    Ok(())
}
