//! Data fields: status, create, store, read, access codes, sizes, memory, the Extended
//! Type Label. // 000:T19-T25, 000:2.3.5

use super::{always, case, code0, errors_not_stacked, release};
use crate::slave::{Case, CaseError, Ctx, Guard};
use hiperface_model::frame::FieldBytes;
use hiperface_model::{Profile, Request};

fn with_etl(p: &Profile) -> Option<&'static str> {
    p.extended_type_label.is_none().then_some("the profile has no Extended Type Label; a profile with one runs it")
}

/// If the model holds field `n`, guard its deletion (status bits as now stored).
fn guard_field(c: &mut Ctx<'_>, n: u8) -> Option<Guard> {
    let status = c.model.nonvolatile().fields.status(n)?;
    let code = c.model.nonvolatile().codes[status.code_number()];
    let a = c.address();
    Some(c.guard(a, Request::CreateDataField { field: n, status: status.attributes(), code }))
}

fn read(field: u8, offset: u8, count: u8, code: u8) -> Request {
    Request::ReadData { field, offset, count, code }
}

fn create(field: u8, status: u8, code: u8) -> Request {
    Request::CreateDataField { field, status, code }
}

pub(super) fn store(field: u8, offset: u8, code: u8, data: &[u8]) -> Result<Request, CaseError> {
    let data = FieldBytes::from_bytes(data).map_err(|_| CaseError::Abort("more than 128 data bytes".into()))?;
    Ok(Request::StoreData { field, offset, code, data })
}

fn field_count(c: &Ctx<'_>) -> u8 {
    c.model.nonvolatile().fields.count()
}

fn free_blocks(c: &Ctx<'_>) -> u8 {
    c.model.nonvolatile().fields.free_blocks()
}

pub const STATUS: Case = case!(
    "fields.status",
    "Memory Status and Data Field Status",
    [MEMORY_STATUS, FIELD_STATUS, WRONG_FIELD_NUMBER],
    Nothing,
    always,
    |c| {
        c.request(Request::MemoryStatus)?;
        let n = field_count(c);
        for field in 0..n {
            c.request(Request::DataFieldStatus { field })?;
        }
        c.request(Request::DataFieldStatus { field: n })?;
        // Field FFh: the Extended Type Label's status where the profile has one, an
        // error where it has none.
        c.request(Request::DataFieldStatus { field: 0xFF }).map(drop)
    }
);

pub const LIFECYCLE: Case = case!(
    "fields.lifecycle",
    "Create, store, read back, part of a field at an offset, bounds on both sides, a second field, delete",
    [CREATE_FIELD, STORE_DATA, READ_DATA, WRONG_OFFSET, WRONG_LENGTH, FIELD_POLICY, DATA_FIELDS, FAULT_GROUPS],
    Writes,
    always,
    |c| {
        let code0 = code0(c);
        c.request(Request::MemoryStatus)?;
        let n = field_count(c);
        if free_blocks(c) == 0 {
            return Err(CaseError::Abort("no free memory for a test field".into()));
        }
        // 16 bytes, Code0, code disabled, writable.
        c.request(create(n, 0xC0, code0))?;
        let g = guard_field(c, n);
        c.request(Request::DataFieldStatus { field: n })?;
        c.request(read(n, 0, 16, 0x00))?;
        let data: Vec<u8> = (0..16u8).map(|i| i.wrapping_mul(37) ^ 0xA5).collect();
        c.request(store(n, 0, 0x00, &data)?)?;
        // The oracle compares the data read back with the data stored.
        c.request(read(n, 0, 16, 0x00))?;
        // Part of the field, at an offset: the bytes land where the offset says (7 and 3:
        // offset + count within the field, offset x count past it).
        c.request(store(n, 7, 0x00, &[0x11, 0x22, 0x33])?)?;
        c.request(read(n, 0, 16, 0x00))?;
        c.request(read(n, 6, 4, 0x00))?;
        // A count byte that is not the number of data bytes sent: 0Ch.
        c.ask(&[c.address(), 0x4B, n, 0x00, 0x04, 0x00, 0x01, 0x02, 0x03])?;
        // Off by one at the end of the field, storing and reading: 11h.
        c.request(store(n, 15, 0x00, &[1, 2])?)?;
        c.request(read(n, 16, 1, 0x00))?;
        c.request(read(n, 15, 2, 0x00))?;
        c.request(read(n, 15, 1, 0x00))?;
        c.request(read(n + 1, 0, 1, 0x00))?;
        errors_not_stacked(c)?;
        // A second field right after the first: each keeps its own bytes.
        if free_blocks(c) >= 1 {
            c.request(create(n + 1, 0xC0, code0))?;
            let g1 = guard_field(c, n + 1);
            let other: Vec<u8> = (0..16u8).map(|i| i.wrapping_mul(11) ^ 0x3C).collect();
            c.request(store(n + 1, 0, 0x00, &other)?)?;
            c.request(read(n, 0, 16, 0x00))?;
            c.request(read(n + 1, 0, 16, 0x00))?;
            c.request(create(n + 1, 0x40, code0))?;
            release(c, g1);
        }
        // Restore: delete it (all status bits but bit 7 as stored).
        c.request(create(n, 0x40, code0))?;
        release(c, g);
        c.request(Request::MemoryStatus).map(drop)
    }
);

pub const ACCESS_CODE: Case = case!(
    "fields.access-code",
    "A field's enabled code guards read, store and delete; read-only fields refuse stores",
    [READ_DATA, STORE_DATA, CREATE_FIELD, READ_ONLY_FIELD, WRONG_ACCESS_CODE],
    Writes,
    always,
    |c| {
        let code0 = code0(c);
        let n = field_count(c);
        if free_blocks(c) == 0 {
            return Err(CaseError::Abort("no free memory for a test field".into()));
        }
        c.request(create(n, 0xC8, !code0))?; // wrong code at creation: 0Fh
        c.request(create(n, 0xC8, code0))?;
        let g = guard_field(c, n);
        c.request(read(n, 0, 4, !code0))?;
        c.request(read(n, 0, 4, code0))?;
        c.request(store(n, 0, !code0, &[0x11])?)?;
        c.request(create(n, 0x88, code0))?; // read-only
        release(c, g);
        let g = guard_field(c, n);
        c.request(Request::DataFieldStatus { field: n })?;
        c.request(store(n, 0, code0, &[0x11])?)?;
        c.request(create(n, 0x08, !code0))?; // delete with the wrong code: 0Fh
        c.request(create(n, 0x08, code0))?;
        release(c, g);
        Ok(())
    }
);

pub const CODE_NUMBERS: Case = case!(
    "fields.code-numbers",
    "A field guarded by Code1, Code2 or Code3 takes that code and no other; codes restored",
    [SET_ACCESS_CODE, READ_DATA, CREATE_FIELD, WRONG_ACCESS_CODE, DATA_FIELDS],
    Writes,
    always,
    |c| {
        let (a, code0) = (c.address(), code0(c));
        let n = field_count(c);
        if free_blocks(c) == 0 {
            return Err(CaseError::Abort("no free memory for a test field".into()));
        }
        for k in 1..=3u8 {
            // Code k made unlike the others for a while, so that only it opens the field.
            let old = c.model.nonvolatile().codes[k as usize];
            let new = old ^ (0x11 * k) ^ 0x80;
            let set = |old, new| Request::SetAccessCode { number: k, old, new };
            c.request(set(old, new))?;
            if c.model.nonvolatile().codes[k as usize] != new {
                continue; // refused: the oracle graded it
            }
            let gk = c.guard(a, set(new, old));
            // Exists, writable, Code k, code enabled, 16 bytes.
            let status = 0xC8 | (k << 4);
            c.request(create(n, status, new))?;
            let gf = guard_field(c, n);
            c.request(read(n, 0, 4, code0))?; // Code0 is not Code k: 0Fh
            c.request(read(n, 0, 4, new))?;
            c.request(create(n, status & 0x7F, new))?;
            release(c, gf);
            c.request(set(new, old))?;
            c.release(gk);
        }
        Ok(())
    }
);

pub const RESIZE: Case = case!(
    "fields.resize",
    "Only the last field changes size or is deleted",
    [CREATE_FIELD, WRONG_FIELD_NUMBER, FIELD_POLICY],
    Writes,
    always,
    |c| {
        let code0 = code0(c);
        let n = field_count(c);
        if free_blocks(c) < 3 {
            return Err(CaseError::Abort("fewer than 3 free blocks for two test fields".into()));
        }
        c.request(create(n, 0xC0, code0))?;
        let g0 = guard_field(c, n);
        c.request(create(n + 1, 0xC0, code0))?;
        let g1 = guard_field(c, n + 1);
        c.request(create(n, 0xC1, code0))?; // resize a field that is not the last: 12h
        c.request(create(n, 0x40, code0))?; // delete a field that is not the last: 12h
        c.request(create(n + 3, 0xC0, code0))?; // a number past the next: 12h
                                                // Another attribute of a field that is not the last, its size kept: allowed.
        c.request(create(n, 0xC8, code0))?;
        c.request(Request::DataFieldStatus { field: n })?;
        c.request(create(n, 0xC0, code0))?;
        c.request(create(n + 1, 0xC1, code0))?; // grow the last to 32 bytes
        release(c, g1);
        let g1 = guard_field(c, n + 1);
        c.request(Request::MemoryStatus)?;
        c.request(read(n + 1, 16, 16, 0x00))?; // the grown part reads FFh
        c.request(create(n + 1, 0x41, code0))?;
        release(c, g1);
        c.request(create(n, 0x40, code0))?;
        release(c, g0);
        c.request(Request::MemoryStatus).map(drop)
    }
);

pub const MEMORY_EXHAUSTION: Case = case!(
    "fields.memory-exhaustion",
    "Memory is accounted in 16-byte blocks: 128-byte fields, one written whole, until one does not fit (10h); one block more than is free does not fit, created or grown",
    [OUT_OF_MEMORY, MEMORY_STATUS, FIELD_POLICY, STORE_DATA, READ_DATA],
    Writes,
    always,
    |c| {
        let code0 = code0(c);
        let start = field_count(c);
        let mut guards = Vec::new();
        // Fill with 128-byte fields while 8 blocks are free, then one more: 10h.
        while free_blocks(c) >= 8 && guards.len() < 32 {
            let n = field_count(c);
            c.request(create(n, 0xC7, code0))?;
            match guard_field(c, n) {
                Some(g) => guards.push(g),
                None => break,
            }
            if guards.len() == 1 {
                // The longest request there is: 128 data bytes, a whole frame (000:T22).
                let data: Vec<u8> = (0..128u8).map(|i| i.wrapping_mul(29) ^ 0x5A).collect();
                c.request(store(n, 0, code0, &data)?)?;
                c.request(read(n, 0, 128, code0))?;
            }
        }
        let n = field_count(c);
        c.request(create(n, 0xC7, code0))?;
        c.request(Request::MemoryStatus)?;
        // Memory full in whole 128-byte fields: the last one makes room for a 112-byte
        // one, so that one block is left for the edges below.
        let mut filler = None;
        if free_blocks(c) == 0 {
            if let Some(g) = guards.pop() {
                let n = start + guards.len() as u8;
                c.request(create(n, 0x47, code0))?;
                c.release(g);
                c.request(create(n, 0xC6, code0))?;
                filler = guard_field(c, n).map(|g| (g, n));
            }
        }
        // The rest of the memory exactly: one block more does not fit (10h); a field of
        // the free blocks does, written at its last byte (the memory's end); it cannot
        // grow by a block (10h) nor to 128 bytes (000:T54).
        let free = free_blocks(c);
        if (1..8).contains(&free) {
            let n = field_count(c);
            c.request(create(n, 0xC0 | free, code0))?;
            let status = 0xC0 | (free - 1);
            c.request(create(n, status, code0))?;
            if let Some(g) = guard_field(c, n) {
                let last = (u16::from(free) * 16 - 1) as u8;
                c.request(store(n, last, code0, &[0x5A])?)?;
                c.request(read(n, last, 1, code0))?;
                c.request(create(n, 0xC0 | free, code0))?;
                c.request(create(n, 0xC7, code0))?;
                c.request(create(n, status & 0x7F, code0))?;
                c.release(g);
            }
        }
        if let Some((g, n)) = filler {
            c.request(create(n, 0x46, code0))?;
            c.release(g);
        }
        while let Some(g) = guards.pop() {
            let n = start + guards.len() as u8;
            c.request(create(n, 0x47, code0))?;
            c.release(g);
        }
        c.request(Request::MemoryStatus).map(drop)
    }
);

pub const EXTENDED_TYPE_LABEL: Case = case!(
    "fields.extended-type-label",
    "The Extended Type Label reads as field FFh",
    [EXTENDED_TYPE_LABEL, WRONG_OFFSET, FIELD_STATUS],
    Nothing,
    with_etl,
    |c| {
        let label = c.request(read(0xFF, 0, 64, 0x00))?.reply;
        if let Some(bytes) = label.as_ref().and_then(|r| r.get(5..69)) {
            c.check(
                hiperface_model::checksum::xor(bytes) == 0,
                "the label's XOR checksum (offset 0) does not match",
                hiperface_model::clause::EXTENDED_TYPE_LABEL,
            );
        }
        c.request(read(0xFF, 60, 5, 0x00))?;
        c.request(Request::DataFieldStatus { field: 0xFF }).map(drop)
    }
);

pub const EXTENDED_TYPE_LABEL_READ_ONLY: Case = case!(
    "fields.extended-type-label-read-only",
    "The Extended Type Label refuses stores and creation",
    [READ_ONLY_FIELD, OUT_OF_MEMORY],
    Writes,
    with_etl,
    |c| {
        let code0 = code0(c);
        c.request(store(0xFF, 0, code0, &[0x00])?)?;
        c.request(create(0xFF, 0xC0, code0)).map(drop)
    }
);
