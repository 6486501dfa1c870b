//! Power-up and Encoder Reset: the state machine's windows, and what a reset keeps.
//! // 000:T9, 000:T29

use super::{always, case, code0, current_edition, decoded, read_position, wait_until};
use crate::slave::safety::SETTLE_MARGIN_US;
use crate::slave::{Case, CaseError, Ctx};
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{clause, CommandId, Request, Response};

/// Send Encoder Reset; when the model's slave started again (000:T29: after the
/// request's timeout), µs.
fn reset(c: &mut Ctx<'_>) -> Result<u64, CaseError> {
    let address = c.address();
    reset_at(c, address)
}

/// [`reset`] sent to `address` (FFh: a broadcast).
fn reset_at(c: &mut Ctx<'_>, address: u8) -> Result<u64, CaseError> {
    let x = c.request_at(address, Request::EncoderReset)?.exchange;
    Ok(c.model.power_up().since_us.unwrap_or(x.complete_us()))
}

/// "Even in these cases the duration shall not exceed 200 ms after power-on/reset"
/// (000:T9, of the initialization).
const INIT_AT_MOST_MS: u16 = 200;

/// `ms` after the reset at `since`, µs.
fn after(since: u64, ms: u16) -> u64 {
    since + u64::from(ms) * 1000
}

pub const RESET: Case = case!(
    "powerup.reset",
    "Encoder Reset: no reply, silence during initialization, then an answer as soon as it is over, in the default settings",
    [ENCODER_RESET, STATE_MACHINE, DEFAULT_PARITY],
    Nothing,
    always,
    |c| {
        let since = reset(c)?;
        wait_until(c, since + 30_000)?;
        c.request_in_state(Request::ReadPosition, CommState::Initialization)?; // silence
        // "The Slave shall respond to new requests after initialization time plus
        // timeout" (000:T29): asked right after it, a slave still initializing is silent.
        let init = c.profile().init_ms;
        wait_until(c, after(since, init) + SETTLE_MARGIN_US)?;
        let answered = c.request_in_state(Request::ReadPosition, CommState::DefaultCommunication)?.reply.is_some();
        let msg = format!(
            "silent {} ms after the reset: past its initialization of {init} ms",
            u64::from(init) + SETTLE_MARGIN_US / 1000
        );
        c.check(answered, msg, clause::ENCODER_RESET);
        c.request(Request::ReadEncoderStatus)?;
        // A broadcast Encoder Reset draws no reply either: "A correct 'Encoder Reset'
        // request will not be followed by a Slave response message" (000:T29); a slave
        // that acknowledges every broadcast (HX-4's d10) answers this one.
        let since = reset_at(c, 0xFF)?;
        wait_until(c, after(since, init) + SETTLE_MARGIN_US)?;
        c.request_in_state(Request::ReadPosition, CommState::DefaultCommunication).map(drop)
    }
);

pub const DEFAULT_WINDOW: Case = case!(
    "powerup.default-window",
    "A request late in the default window is answered, and the default settings are kept through the switch's window and past it",
    [STATE_MACHINE, ENCODER_RESET],
    Nothing,
    current_edition,
    |c| {
        let since = reset(c)?;
        let p = c.profile();
        // The window lasts until 900 ms (000:T9): a slave that closes it early is
        // silent here.
        let at = after(since, p.default_window_ms) - 2 * SETTLE_MARGIN_US;
        wait_until(c, at)?;
        let answered = c.request_in_state(Request::ReadPosition, CommState::DefaultCommunication)?.reply.is_some();
        let msg = format!("silent {} ms after the reset, in the default window", (at - since) / 1000);
        c.check(answered, msg, clause::STATE_MACHINE);
        // "Any single Master request" keeps the default settings: between 900 and
        // 1100 ms, where the switch would have been silent, a slave that goes silent
        // anyway is heard (HX-3's d16: with stored settings that are the default ones,
        // nothing past 1100 ms tells it from a conformant slave)...
        let mid = after(since, (p.default_window_ms + p.user_settings_ms) / 2);
        wait_until(c, mid)?;
        let kept = c.request_in_state(Request::ReadPosition, CommState::OperationalDefault)?.reply.is_some();
        let msg = format!("silent {} ms after the reset, after a request in the default window", (mid - since) / 1000);
        c.check(kept, msg, clause::STATE_MACHINE);
        // ... and past 1100 ms too.
        wait_until(c, after(since, p.user_settings_ms) + SETTLE_MARGIN_US)?;
        c.request_in_state(Request::ReadPosition, CommState::OperationalDefault).map(drop)
    }
);

pub const WINDOW: Case = case!(
    "powerup.window",
    "Without a request the default window closes: silence until the switch, then the stored settings",
    [STATE_MACHINE, ENCODER_RESET],
    Nothing,
    current_edition,
    |c| {
        let since = reset(c)?;
        let p = c.profile();
        // Silent until 1100 ms (000:T9), asked just before, the whole request in the
        // stored settings before it (at 600 Bd three characters take 55 ms): a slave
        // that switches early answers here.
        let request_us = 3 * c.model.boot_settings().char_time_us();
        wait_until(c, after(since, p.user_settings_ms) - SETTLE_MARGIN_US - request_us)?;
        c.request_in_state(Request::ReadPosition, CommState::ChangeOfSettings)?; // silence
        wait_until(c, after(since, p.user_settings_ms) + SETTLE_MARGIN_US)?;
        c.request_in_state(Request::ReadPosition, CommState::OperationalUser).map(drop)
    }
);

pub const RETAINS: Case = case!(
    "powerup.retains",
    "Encoder Reset keeps what is stored: the address, an access code, a read-only data field, the position offset, the counter; restored",
    [RESET_KEEPS, ENCODER_RESET, SET_ADDRESS, SET_ACCESS_CODE, DATA_FIELDS, READ_ONLY_FIELD, SET_POSITION, READ_COUNTER],
    Writes,
    always,
    |c| {
        let (a, code0) = (c.address(), code0(c));
        let keeps = clause::RESET_KEEPS;
        // Changed where the case may, each guarded: another address, Code3, a new
        // field with known bytes, a preset, the counter once more.
        let moved_to = if a == 0x5F { 0x5E } else { a + 1 };
        let set_address = |address| Request::SetEncoderAddress { address, code0 };
        c.request(set_address(moved_to))?;
        let ga = (c.address() == moved_to).then(|| c.guard(moved_to, set_address(a)));
        let old3 = c.model.nonvolatile().codes[3];
        let new3 = old3 ^ 0x5A;
        let set3 = |old, new| Request::SetAccessCode { number: 3, old, new };
        c.request(set3(old3, new3))?;
        let here = c.address();
        let gc = (c.model.nonvolatile().codes[3] == new3).then(|| c.guard(here, set3(new3, old3)));
        let field = c.model.nonvolatile().fields.count();
        // Deleted as it was last set (000:T24: every other status bit as stored).
        let delete = |status: u8| Request::CreateDataField { field, status: status & 0x7F, code: code0 };
        let mut gf = None;
        if c.model.nonvolatile().fields.free_blocks() > 0 {
            c.request(Request::CreateDataField { field, status: 0xC0, code: code0 })?;
            if c.model.nonvolatile().fields.status(field).is_some() {
                gf = Some(c.guard(here, delete(0xC0)));
                let data: Vec<u8> = (0..16u8).map(|i| i.wrapping_mul(53) ^ 0x96).collect();
                c.request(super::fields::store(field, 0, 0x00, &data)?)?;
                // Then read-only (its size kept: a change of status 000:2.4.2 allows),
                // so that its protection is held to after the reset as well.
                c.request(Request::CreateDataField { field, status: 0x80, code: code0 })?;
                if let (Some(g), Some(s)) = (gf.take(), c.model.nonvolatile().fields.status(field)) {
                    c.release(g);
                    gf = Some(c.guard(here, delete(s.0)));
                }
            }
        }
        let range = c.profile().range();
        let mut gp = None;
        if let Some(p0) = read_position(c)? {
            let preset = ((u64::from(p0) + range / 3 + 7) % range) as u32;
            c.request(Request::SetPosition { preset, code0 })?;
            let back = Request::SetPosition { preset: p0, code0 };
            gp = Some((c.guard(here, back), back));
        }
        // A counter at 0 counts once, and is reset to 0 after: as it was. One that is
        // not shows its count as it is.
        let counted = c.allow_counter_change() && c.model.nonvolatile().counter == 0;
        if counted {
            c.request(Request::IncrementCounter)?;
        }
        let before = c.model.nonvolatile().clone();

        // Asked once an initialization of any length 000:T9 allows is over, so that a
        // slow one (powerup.reset's) is not taken for a lost address.
        let since = reset(c)?;
        wait_until(c, after(since, INIT_AT_MOST_MS) + SETTLE_MARGIN_US)?;
        // Read back: the oracle grades each reply against the model, which keeps it
        // all; each loss is also named here for what it is.
        let answered = c.request(Request::ReadTypeLabel)?.reply.is_some();
        c.check(answered, format!("no answer at address {here:02X}h, set before the reset"), keeps);
        if !answered {
            return Ok(()); // the guards restore what they can
        }
        let counter = c.request(Request::ReadCounter)?.reply;
        if let Some(Response::Counter(v)) = decoded(counter.as_deref(), CommandId::ReadCounter) {
            let want = before.counter;
            c.check(v == want, format!("the counter reads {v} after the reset, {want} before it"), keeps);
        }
        if counted {
            c.request(Request::ResetCounter { code0 })?;
        }
        if let (Some(g), Some(status)) = (gf, before.fields.status(field)) {
            let reply = c.request(Request::DataFieldStatus { field })?.reply;
            // A reply that does not decode says nothing of the field (the oracle FAILs it).
            if let Some(found) = decoded(reply.as_deref(), CommandId::DataFieldStatus) {
                let kept = found == Response::FieldStatus { field, status: status.0 };
                c.check(kept, format!("data field {field}, created before the reset, is gone or changed"), keeps);
            }
            // The bytes stored: the oracle compares them.
            c.request(Request::ReadData { field, offset: 0, count: 16, code: 0x00 })?;
            // Still read-only: a store is refused with 0Eh (000:T52), the bytes kept
            // (a protection lost in the reset, not at power-on: HX-3's d12; 000:T29
            // "new and future products must observe identical behavior").
            if !status.writable() {
                c.request(super::fields::store(field, 0, 0x00, &[0x3C])?)?;
                c.request(Request::ReadData { field, offset: 0, count: 1, code: 0x00 })?;
            }
            c.request(delete(status.0))?;
            c.release(g);
        }
        if let Some((g, back)) = gp {
            let want = c.model.position();
            if let Some(p) = read_position(c)? {
                let msg = format!("Read Position after the reset gives {p:08X}h, not {want:08X}h as preset before");
                c.check(u64::from(p) == want, msg, keeps);
            }
            c.request(back)?;
            c.release(g);
        }
        if let Some(g) = gc {
            // Code3 set back with the code it was changed to: refused if it was lost.
            let reply = c.request(set3(new3, old3))?.reply;
            if let Some(found) = decoded(reply.as_deref(), CommandId::SetAccessCode) {
                let kept = matches!(found, Response::AccessCodeSet { .. });
                c.check(kept, "Code3, changed before the reset, is refused after it", keeps);
            }
            c.release(g);
        }
        if let Some(g) = ga {
            c.request(set_address(a))?;
            c.release(g);
        }
        Ok(())
    }
);
