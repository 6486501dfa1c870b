//! Data fields: status, create, store, read, access codes, sizes, memory, the Extended
//! Type Label. // 000:T19-T25, 000:2.3.5

use super::{always, case, code0, release};
use crate::slave::{Case, CaseError, Ctx, Guard};
use hiperface_model::frame::FieldBytes;
use hiperface_model::{Profile, Request};

fn with_etl(p: &Profile) -> Option<&'static str> {
    p.extended_type_label.is_none().then_some("the profile has no Extended Type Label")
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

fn store(field: u8, offset: u8, code: u8, data: &[u8]) -> Result<Request, CaseError> {
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
        c.request(Request::DataFieldStatus { field: n }).map(drop)
    }
);

pub const LIFECYCLE: Case = case!(
    "fields.lifecycle",
    "Create, store, read back, bounds, delete a data field",
    [CREATE_FIELD, STORE_DATA, READ_DATA, WRONG_OFFSET, FIELD_POLICY, DATA_FIELDS],
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
        // Off by one at the end of the field: 11h.
        c.request(store(n, 15, 0x00, &[1, 2])?)?;
        c.request(read(n, 16, 1, 0x00))?;
        c.request(read(n, 15, 1, 0x00))?;
        c.request(read(n + 1, 0, 1, 0x00))?;
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
        c.request(store(n, 0, code0, &[0x11])?)?;
        c.request(create(n, 0x08, !code0))?; // delete with the wrong code: 0Fh
        c.request(create(n, 0x08, code0))?;
        release(c, g);
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
    "Memory is accounted in 16-byte blocks: a field that does not fit draws 10h",
    [OUT_OF_MEMORY, MEMORY_STATUS, FIELD_POLICY],
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
        }
        let n = field_count(c);
        c.request(create(n, 0xC7, code0))?;
        c.request(Request::MemoryStatus)?;
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
