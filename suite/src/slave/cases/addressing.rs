//! Addressing: broadcast, other addresses, Set Encoder Address. // 000:2.3.1, 000:T5, 000:T31

use super::{always, case, code0, errors_not_stacked, release};
use crate::slave::Case;
use hiperface_model::Request;

pub const BROADCAST: Case = case!(
    "address.broadcast",
    "Broadcast FFh is answered with the own address, an error response too",
    [BROADCAST, UNKNOWN_COMMAND, CHECKSUM_ERROR],
    Nothing,
    always,
    |c| {
        c.request_at(0xFF, Request::ReadPosition)?;
        c.request_at(0xFF, Request::ReadTypeLabel)?;
        // "Each Slave will acknowledge with their specific address" (000:2.3.1), with an
        // error response as with any other: one that echoes FFh (HX-4's d03) is no
        // slave's address (000:T5).
        c.ask(&[0xFF, 0x45])?; // an unknown command: 0Bh
        c.send_frame(&[0xFF, 0x42, 0x00])?; // a bad checksum: 0Ah
        errors_not_stacked(c)
    }
);

pub const OTHER: Case =
    case!("address.other", "Frames for other addresses draw silence", [ADDRESS, CHECK_ORDER], Nothing, always, |c| {
        let a = c.address();
        c.request_at(a ^ 0x01, Request::ReadPosition)?;
        c.request_at(a ^ 0x10, Request::ReadVersion)?;
        c.request_at(0x20, Request::ReadPosition)?;
        // Even a bad checksum for another address stays unanswered (check 1 first).
        c.send_frame(&[a ^ 0x01, 0x42, 0x00]).map(drop)
    });

pub const CHANGE_RESTORE: Case = case!(
    "address.change-restore",
    "Set Encoder Address answers from the new address, to a broadcast too; changed and restored",
    [SET_ADDRESS, ADDRESS, BROADCAST],
    Writes,
    always,
    |c| {
        let a = c.address();
        let code0 = code0(c);
        let new = if a == 0x5F { 0x5E } else { a + 1 };
        let set = |address, code0| Request::SetEncoderAddress { address, code0 };
        c.request(set(0x60, code0))?; // outside 40h...5Fh: 0Dh
        c.request(set(0x60, !code0))?; // both wrong: 0Dh first (DESIGN:order), 0Fh acceptable
        c.request(set(new, !code0))?; // wrong Code0: 0Fh
        c.request(set(new, code0))?;
        let g = (c.address() == new).then(|| c.guard(new, set(a, code0)));
        c.request_at(new, Request::ReadPosition)?;
        // A broadcast is answered from the new address too (000:2.3.1 "each Slave will
        // acknowledge with their specific address", 000:T30): an address kept from
        // power-on for broadcasts answers it from the old one (HX-3's d04).
        c.request_at(0xFF, Request::ReadPosition)?;
        c.request_at(a, Request::ReadPosition)?; // the old address is silent now
        c.request_at(new, set(a, code0))?;
        release(c, g);
        c.request_at(a, Request::ReadPosition).map(drop)
    }
);
