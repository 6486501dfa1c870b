//! Analog values on every channel of the profile. // 000:T14, 000:T15

use super::{always, case};
use crate::slave::Case;
use hiperface_model::Request;

pub const CHANNELS: Case = case!(
    "analog.channels",
    "Read Analog Value on every channel of the profile",
    [READ_ANALOG, ANALOG_SOURCES],
    Nothing,
    always,
    |c| {
        let profile = c.profile();
        for ch in profile.analog.iter().flatten() {
            c.request(Request::ReadAnalogValue { channel: ch.selector })?;
        }
        Ok(())
    }
);
