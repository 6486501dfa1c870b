//! Serial interface settings: Set Serial Interface, Temporarily Set Serial Interface.
//! // 000:T32, 000:T33

use super::{always, case, code0, lacks, other_baud};
use crate::slave::{Case, Finding};
use hiperface_model::{CommandId, Profile, Request, UartSettings};

fn with_67(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::TemporarilySetSerialInterface, "67h is optional and the profile lacks it")
        .or_else(|| other_baud(p).is_none().then_some("the profile supports a single data rate"))
}

pub const INVALID: Case = case!(
    "settings.invalid",
    "Set Serial Interface refuses undefined settings and wrong codes",
    [SET_SERIAL, READ_TYPE_LABEL, SETTINGS_BYTE],
    Writes,
    always,
    |c| {
        let code0 = code0(c);
        let stored = c.model.nonvolatile().settings.byte();
        let set = |settings, code0| Request::SetSerialInterface { settings, code0 };
        c.request(set((stored & 0xF8) | 0x07, code0))?; // data rate 111: 0Dh
        c.request(set((stored & 0xCF) | 0x10, code0))?; // parity 01: 0Dh
        c.request(set(stored, !code0))?;
        // Rewriting the stored byte: a real write that changes nothing.
        c.request(set(stored, code0)).map(drop)
    }
);

pub const TEMPORARY: Case = case!(
    "settings.temporary",
    "Temporarily Set Serial Interface: reply in the old settings, then the new; lost on reset",
    [TEMP_SERIAL, ENCODER_RESET, UART_SETTINGS, SETTINGS_BYTE],
    Nothing,
    with_67,
    |c| {
        let a = c.address();
        let Some(other) = other_baud(&c.profile()) else { return Ok(()) };
        if !c.line_can_change_settings() {
            // The device would answer at a data rate the line cannot follow.
            let why = "the line keeps fixed UART settings (a raw TCP serial server): 67h cannot be followed";
            c.push(Finding::not_applicable(why));
            return Ok(());
        }
        let temporarily = |settings| Request::TemporarilySetSerialInterface { settings };
        c.request(temporarily(0xE7))?; // data rate 111: 0Dh
        c.request(temporarily(other.byte()))?;
        let g = c.guard(a, temporarily(UartSettings::DEFAULT.byte()));
        c.request(Request::ReadPosition)?;
        c.request(temporarily(UartSettings::DEFAULT.byte()))?;
        c.release(g);
        c.request(Request::ReadPosition).map(drop)
    }
);
