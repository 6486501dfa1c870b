//! Frame timing and response times over a run of requests. // 000:2.2.2, 000:T10

use super::{always, case};
use crate::slave::Case;
use hiperface_model::Request;

pub const READ_POSITION: Case = case!(
    "timing.read-position",
    "Response times and reply framing over 20 Read Position requests",
    [FRAME_TIMING, COMMANDS, TIMEOUT, LEGACY_TIMEOUT],
    Nothing,
    always,
    |c| {
        for _ in 0..20 {
            c.request(Request::ReadPosition)?;
        }
        Ok(())
    }
);
