//! Protocol errors: checksum, unknown command, length, argument. // 000:2.4.2, 000:T47-T50

use super::{always, case, errors_not_stacked};
use crate::slave::Case;
use crate::verdict::Finding;
use hiperface_model::{CommandId, Request};

pub const CHECKSUM: Case = case!(
    "protocol.checksum",
    "A bad checksum draws 0Ah, also under an unknown command",
    [CHECKSUM_ERROR, CHECKSUM, COMMON_ERRORS, FAULT_GROUPS],
    Nothing,
    always,
    |c| {
        let a = c.address();
        c.send_frame(&[a, 0x42, 0x00])?;
        c.send_frame(&[a, 0x4E, 0x0F])?;
        // An unknown command with a bad checksum: "the message will not be parsed
        // further" (000:T48), so 0Ah, not 0Bh.
        c.send_frame(&[a, 0x45, 0x00])?;
        errors_not_stacked(c)
    }
);

pub const PARITY: Case = case!(
    "protocol.parity",
    "A request with a parity error draws 09h",
    [PARITY_ERROR, COMMON_ERRORS, FAULT_GROUPS],
    Nothing,
    always,
    |c| {
        let a = c.address();
        if let Err(why) = c.line_carries_parity() {
            c.push(Finding::not_applicable(why.to_string()));
            return Ok(());
        }
        let now = c.now_us();
        if c.model.listening_settings(now).and_then(|s| s.with_wrong_parity()).is_none() {
            c.push(Finding::not_applicable("the device listens without parity: no parity error can be made"));
            return Ok(());
        }
        // Read Position: a request every device answers, so that only the fault decides.
        c.send_with_wrong_parity(&crate::exchange::sealed(&[a, 0x42]))?;
        errors_not_stacked(c)
    }
);

pub const UNKNOWN_COMMAND: Case = case!(
    "protocol.unknown-command",
    "Unknown commands draw 0Bh",
    [UNKNOWN_COMMAND, COMMON_ERRORS, LEGACY_ERROR_CODES, FAULT_GROUPS],
    Nothing,
    always,
    |c| {
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
        errors_not_stacked(c)
    }
);

pub const LENGTH: Case = case!(
    "protocol.length",
    "Frames of the wrong length draw 0Ch: too short, and every command one byte too long",
    [WRONG_LENGTH, CHECK_ORDER, COMMON_ERRORS, FAULT_GROUPS],
    Nothing,
    always,
    |c| {
        let a = c.address();
        c.send_frame(&[a, 0x42])?;
        c.ask(&[a, 0x42, 0x00])?;
        c.ask(&[a, 0x4E, 0x00, 0x00])?;
        c.ask(&[a, 0x4C])?;
        // Each command of the profile with one data byte too many: its own error path.
        // One that writes only where writes are allowed (a conformant device refuses
        // the frame before any effect; one that does not might write).
        let profile = c.profile();
        let writes = c.allow_writes();
        for spec in hiperface_model::COMMAND_TABLE {
            let hiperface_model::command::DataLength::Fixed(n) = spec.master_data else { continue };
            if !profile.commands.contains(spec.id) || (spec.writes_eeprom() && !writes) {
                continue;
            }
            let mut body = vec![a, spec.id.byte()];
            body.extend(std::iter::repeat_n(0u8, n as usize + 1));
            c.ask(&body)?;
        }
        errors_not_stacked(c)
    }
);

pub const ARGUMENT: Case = case!(
    "protocol.argument",
    "A channel the device lacks draws 0Dh",
    [READ_ANALOG, WRONG_ARGUMENT, FAULT_GROUPS],
    Nothing,
    always,
    |c| {
        let profile = c.profile();
        let missing = (0u8..=0xFF).find(|s| profile.analog_channel(*s).is_none()).unwrap_or(0);
        c.request(Request::ReadAnalogValue { channel: missing })?;
        errors_not_stacked(c)
    }
);
