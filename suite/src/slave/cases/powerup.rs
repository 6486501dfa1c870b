//! Power-up and Encoder Reset: the state machine's windows. // 000:T9, 000:T30

use super::{always, case, current_edition, wait_until};
use crate::slave::Case;
use hiperface_model::slave::powerup::CommState;
use hiperface_model::Request;

pub const RESET: Case = case!(
    "powerup.reset",
    "Encoder Reset: no reply, silence during initialization, then default settings",
    [ENCODER_RESET, STATE_MACHINE, DEFAULT_PARITY],
    Nothing,
    always,
    |c| {
        let x = c.request(Request::EncoderReset)?.exchange;
        let reset_at = x.complete_us();
        wait_until(c, reset_at + 30_000)?;
        c.request_in_state(Request::ReadPosition, CommState::Initialization)?; // silence
        let init = c.profile().init_ms as u64 * 1000;
        wait_until(c, reset_at + init + 50_000)?;
        c.request_in_state(Request::ReadPosition, CommState::DefaultCommunication)?;
        c.request(Request::ReadEncoderStatus).map(drop)
    }
);

pub const WINDOW: Case = case!(
    "powerup.window",
    "Without a request the default window closes: silence, then the stored settings",
    [STATE_MACHINE, ENCODER_RESET],
    Nothing,
    current_edition,
    |c| {
        let x = c.request(Request::EncoderReset)?.exchange;
        let reset_at = x.complete_us();
        let p = c.profile();
        let silent_at = (p.default_window_ms as u64 + p.user_settings_ms as u64) * 500;
        wait_until(c, reset_at + silent_at)?;
        c.request_in_state(Request::ReadPosition, CommState::ChangeOfSettings)?; // silence
        wait_until(c, reset_at + p.user_settings_ms as u64 * 1000 + 50_000)?;
        c.request_in_state(Request::ReadPosition, CommState::OperationalUser).map(drop)
    }
);
