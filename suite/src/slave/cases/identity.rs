//! Identity: type label, version, status. // 000:T29, 000:T33, 000:T27

use super::{always, case};
use crate::slave::Case;
use hiperface_model::Request;

pub const TYPE_LABEL: Case = case!("identity.type-label", "Read Type Label", [READ_TYPE_LABEL], Nothing, always, |c| {
    c.request(Request::ReadTypeLabel).map(drop)
});

pub const VERSION: Case = case!(
    "identity.version",
    "Read Version: 37 bytes of serial, firmware, date",
    [READ_VERSION, LEGACY_VERSION],
    Nothing,
    always,
    |c| c.request(Request::ReadVersion).map(drop)
);

pub const STATUS: Case = case!(
    "identity.status",
    "Read Encoder Status until the stack is empty (or five times)",
    [READ_ENCODER_STATUS, WARNING_BIT, FAULT_GROUPS],
    Nothing,
    always,
    |c| {
        // Up to five reads (the stack holds four): the oracle grades each against the
        // model's stack; a persisting condition is stacked again after a read.
        for _ in 0..5 {
            if c.request(Request::ReadEncoderStatus)?.reply.as_ref().and_then(|r| r.get(2)) == Some(&0) {
                break;
            }
        }
        Ok(())
    }
);
