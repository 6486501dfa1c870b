//! Serial interface settings: Set Serial Interface, Temporarily Set Serial Interface.
//! // 000:T32, 000:T33

use super::{always, case, code0, decoded, lacks, other_baud, wait_until};
use crate::slave::Case;
use crate::verdict::Finding;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{CommandId, FaultCode, Profile, Request, Response, UartSettings};

fn with_67(p: &Profile) -> Option<&'static str> {
    lacks(
        p,
        CommandId::TemporarilySetSerialInterface,
        "67h is optional and the profile lacks it; a profile with 67h runs it",
    )
    .or_else(|| {
        other_baud(p).is_none().then_some("the profile supports a single data rate; a profile with two runs it")
    })
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
                                                        // A data rate the profile does not offer: 0Dh (000:T32, "the actually available
                                                        // data rates are specified in the product data sheet").
        let profile = c.profile();
        if let Some(missing) = hiperface_model::settings::Baud::ALL.into_iter().find(|b| !profile.supports_baud(*b)) {
            let byte = UartSettings { baud: missing, ..c.model.nonvolatile().settings }.byte();
            c.request(set(byte, code0))?;
        }
        c.request(set(stored, !code0))?;
        // Rewriting the stored byte: a real write that changes nothing.
        c.request(set(stored, code0)).map(drop)
    }
);

fn with_other_rate(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::SetSerialInterface, "the profile lacks 57h; a profile with 57h runs it").or_else(|| {
        other_baud(p).is_none().then_some("the profile supports a single data rate; a profile with two runs it")
    })
}

/// On a line without a data rate, what the case cannot see said as such: the replies
/// are graded, but that the device listens and answers at the other rate (000:T4) is
/// not observed, and a device that never changed its rate would be heard the same.
fn unobserved_rate(c: &mut crate::slave::Ctx<'_>) {
    if let Err(why) = c.line_carries_data_rate() {
        c.push(Finding::not_applicable(format!(
            "{why}: that the device listens and answers at the other data rate (000:T4) is not observed here, only \
             its replies; a serial port or the virtual line (--port virtual) observes it"
        )));
    }
}

pub const STORED: Case = case!(
    "settings.stored",
    "Set Serial Interface: the old settings until Encoder Reset, the new ones after it; restored",
    [SET_SERIAL, ENCODER_RESET, STATE_MACHINE, UART_SETTINGS],
    Writes,
    with_other_rate,
    |c| {
        let (a, code0) = (c.address(), code0(c));
        let stored = c.model.nonvolatile().settings;
        let Some(other) = other_baud(&c.profile()).map(|o| UartSettings { baud: o.baud, ..stored }) else {
            return Ok(());
        };
        if !c.line_can_change_settings() {
            let why =
                "the line keeps fixed UART settings (a raw TCP serial server): another data rate cannot be followed";
            c.push(Finding::not_applicable(why));
            return Ok(());
        }
        unobserved_rate(c);
        // The fastest rate the profile offers and the slowest below the default: a
        // timeout kept at another rate's length (HX-4's d08, a timer that saturates
        // at 9600 Bd) is early at the slower one, whatever the line (000:2.2.2).
        let slower = slowest_below_default(&c.profile()).map(|baud| UartSettings { baud, ..stored });
        for other in std::iter::once(other).chain(slower.filter(|s| *s != other && s.baud != stored.baud)) {
            stored_then_restored(c, a, code0, stored, other)?;
        }
        Ok(())
    }
);

/// The slowest data rate the profile offers below the default one.
fn slowest_below_default(p: &Profile) -> Option<hiperface_model::settings::Baud> {
    hiperface_model::settings::Baud::ALL
        .into_iter()
        .find(|b| b.bits_per_second() < UartSettings::DEFAULT.baud.bits_per_second() && p.supports_baud(*b))
}

/// `settings.stored` at `other`: the old settings until a reset, `other` after it,
/// then `stored` again after the next.
fn stored_then_restored(
    c: &mut crate::slave::Ctx<'_>,
    a: u8,
    code0: u8,
    stored: UartSettings,
    other: UartSettings,
) -> Result<(), crate::slave::CaseError> {
    let set = |s: UartSettings| Request::SetSerialInterface { settings: s.byte(), code0 };
    c.request(set(other))?;
    // The guard talks as the model says the device listens: in the old settings
    // until a reset, in the new ones after it (or at power-on, in the default
    // window, whatever was stored: 000:T9).
    let g = c.guard(a, set(stored));
    // Still the old settings until a reset (000:T32): a device that took the new
    // ones at once hears this request garbled (or not at all).
    // (A reply that does not decode is the oracle's to FAIL, not this rule's.)
    let reply = c.request(Request::ReadPosition)?.reply;
    let decodes = decoded(reply.as_deref(), CommandId::ReadPosition);
    let heard = match reply {
        None => false,
        Some(_) => !matches!(decodes, Some(Response::Error(FaultCode::Parity))),
    };
    let msg = "after Set Serial Interface, a request in the old settings is not heard: the new settings are in \
               use before an Encoder Reset";
    c.check(heard, msg, hiperface_model::clause::SET_SERIAL);
    // Read Type Label reports the stored settings, the new ones already (000:T28;
    // the active ones are NON-STRICT).
    c.request(Request::ReadTypeLabel)?;
    // At the other data rate, a pause of the default rate's timeout and frame before
    // each request: a listener that does not follow the rate (a wire log is read at
    // one) still tells the frames apart.
    let apart = |c: &mut crate::slave::Ctx<'_>| c.wait_ms(20);
    for target in [other, stored] {
        if target == stored {
            apart(c)?;
            c.request(set(stored))?;
            c.release(g);
            apart(c)?;
        }
        let reset_at = c.request(Request::EncoderReset)?.exchange.complete_us();
        let p = c.profile();
        wait_until(c, reset_at + p.user_settings_ms as u64 * 1000 + 50_000)?;
        c.request_in_state(Request::ReadPosition, CommState::OperationalUser)?;
    }
    Ok(())
}

pub const TEMPORARY: Case = case!(
    "settings.temporary",
    "Temporarily Set Serial Interface: reply in the old settings, then the new; lost on reset",
    [TEMP_SERIAL, ENCODER_RESET, UART_SETTINGS, SETTINGS_BYTE, STATE_MACHINE],
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
        unobserved_rate(c);
        let temporarily = |settings| Request::TemporarilySetSerialInterface { settings };
        c.request(temporarily(0xE7))?; // data rate 111: 0Dh
        c.request(temporarily(other.byte()))?;
        let g = c.guard(a, temporarily(UartSettings::DEFAULT.byte()));
        c.request(Request::ReadPosition)?;
        // Lost on reset (000:T33 "after an encoder reset or a power cycle the settings
        // are discarded"; 000:T29, a reset as a power-on): asked once the stored
        // settings are in use. A device that keeps them answers in the temporary ones
        // (HX-3's d02): not heard on a line with a data rate, early after the stored
        // settings' timeout on one without (000:2.2.2).
        let reset_at = c.request(Request::EncoderReset)?.exchange.complete_us();
        let p = c.profile();
        wait_until(c, reset_at + p.user_settings_ms as u64 * 1000 + 50_000)?;
        c.request_in_state(Request::ReadPosition, CommState::OperationalUser)?;
        c.release(g);
        Ok(())
    }
);
