//! Access codes: Set Access Code. // 000:T26

use super::{always, case, release};
use crate::slave::Case;
use hiperface_model::Request;

pub const CHANGE_RESTORE: Case = case!(
    "codes.change-restore",
    "Set Access Code needs the old code; changed and restored",
    [SET_ACCESS_CODE, WRONG_ACCESS_CODE],
    Writes,
    always,
    |c| {
        let a = c.address();
        let old = c.model.nonvolatile().codes[3];
        let new = old.wrapping_add(1);
        let set = |number, old, new| Request::SetAccessCode { number, old, new };
        c.request(set(4, old, new))?; // no Code4: 0Dh
        c.request(set(3, new, new))?; // wrong old code: 0Fh
        c.request(set(3, old, new))?;
        let g = (c.model.nonvolatile().codes[3] == new).then(|| c.guard(a, set(3, new, old)));
        c.request(set(3, old, old))?; // the old one is gone: 0Fh
        c.request(set(3, new, old))?;
        release(c, g);
        Ok(())
    }
);
