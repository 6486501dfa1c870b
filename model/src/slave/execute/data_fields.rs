//! Data field commands: access checks, Read Data, Store Data, Create Data Field.
//! // 000:T21-T25, DESIGN:fields

use super::{Checks, Slave, EXTENDED_TYPE_LABEL_FIELD};
use crate::clause;
use crate::command::CommandId;
use crate::fault::FaultCode::*;
use crate::response::Response;
use crate::slave::fields::FieldStatus;
impl Slave {
    /// Field number, access code and bounds of a data field access; the Extended Type
    /// Label is field FFh, 64 bytes, no code. Returns the field's size in bytes.
    pub(super) fn field_access(&self, c: &mut Checks, field: u8, code: u8) -> Option<usize> {
        if field == EXTENDED_TYPE_LABEL_FIELD && self.profile.extended_type_label.is_some() {
            return Some(64);
        }
        let status = self.nv.fields.status(field);
        c.check(status.is_none(), WrongFieldNumber, clause::WRONG_FIELD_NUMBER);
        let status = status?;
        let expected = self.nv.codes.get(status.code_number()).copied();
        c.check(status.code_enabled() && expected != Some(code), WrongAccessCode, clause::WRONG_ACCESS_CODE);
        Some(status.size_bytes())
    }

    pub(super) fn read_data(
        &mut self,
        c: &mut Checks,
        field: u8,
        offset: u8,
        count: u8,
        code: u8,
    ) -> Result<Response, ()> {
        c.check(self.locks.data_fields, PartitionTable, clause::INIT_FAULTS);
        self.memory_checks(c, CommandId::ReadData);
        let size = self.field_access(c, field, code);
        // DESIGN: 1..=128 and offset + count <= size, else 11h; 0Dh for count 0 is acceptable.
        let bounds_bad = |size: usize| count == 0 || offset as usize + count as usize > size;
        c.check(size.is_some_and(bounds_bad), WrongOffset, clause::WRONG_OFFSET);
        c.tolerate(count == 0, WrongArgument);
        if c.first.is_some() {
            return Err(());
        }
        let bytes = if field == EXTENDED_TYPE_LABEL_FIELD && self.profile.extended_type_label.is_some() {
            let label = self.profile.extended_type_label.as_ref();
            label.and_then(|l| l.get(offset as usize..offset as usize + count as usize))
        } else {
            self.nv.fields.read(field, offset, count)
        };
        let data = bytes.and_then(|b| crate::frame::FieldBytes::from_bytes(b).ok()).ok_or(())?;
        Ok(Response::Data { field, offset, data })
    }

    pub(super) fn store_data(
        &mut self,
        c: &mut Checks,
        field: u8,
        offset: u8,
        code: u8,
        data: &[u8],
    ) -> Result<Response, ()> {
        c.check(self.locks.data_fields, PartitionTable, clause::INIT_FAULTS);
        self.memory_checks(c, CommandId::StoreData);
        let etl = field == EXTENDED_TYPE_LABEL_FIELD && self.profile.extended_type_label.is_some();
        c.check(etl, ReadOnlyField, clause::READ_ONLY_FIELD);
        if !etl {
            let size = self.field_access(c, field, code);
            let writable = self.nv.fields.status(field).is_some_and(|s| s.writable());
            c.check(size.is_some() && !writable, ReadOnlyField, clause::READ_ONLY_FIELD);
            c.check(size.is_some_and(|size| offset as usize + data.len() > size), WrongOffset, clause::WRONG_OFFSET);
        }
        if c.first.is_some() || !self.nv.fields.write(field, offset, data) {
            return Err(());
        }
        self.count_write();
        Ok(Response::DataStored { field, offset, count: data.len() as u8 })
    }

    /// Create, modify or delete a data field. // 000:T24, DESIGN:fields
    pub(super) fn create_data_field(
        &mut self,
        c: &mut Checks,
        field: u8,
        status: u8,
        code: u8,
    ) -> Result<Response, ()> {
        let new = FieldStatus(status);
        let fields = &self.nv.fields;
        let count = fields.count();
        c.check(self.locks.data_fields, PartitionTable, clause::INIT_FAULTS);
        self.memory_checks(c, CommandId::CreateDataField);
        // 000:T54: a Create Data Field request that targets the Extended Type Label.
        if field == EXTENDED_TYPE_LABEL_FIELD {
            c.check(true, OutOfMemory, clause::OUT_OF_MEMORY);
            return Err(());
        }
        let code_of = |n: usize| self.nv.codes.get(n).copied();
        if !new.exists() {
            // Delete: only the last field, with all other status bits as stored.
            let last = count.checked_sub(1);
            c.check(last != Some(field), WrongFieldNumber, clause::WRONG_FIELD_NUMBER);
            if let Some(old) = fields.status(field) {
                c.check(code_of(old.code_number()) != Some(code), WrongAccessCode, clause::WRONG_ACCESS_CODE);
                let mismatch = old.attributes() != new.attributes();
                c.check(mismatch, WrongFieldNumber, clause::CREATE_FIELD);
                c.tolerate(mismatch, WrongArgument);
            }
            if c.first.is_some() || !self.nv.fields.delete_last() {
                return Err(());
            }
        } else if field == count {
            // Create: the code byte must be the code the new status names, even if disabled.
            c.check(code_of(new.code_number()) != Some(code), WrongAccessCode, clause::WRONG_ACCESS_CODE);
            c.check(!fields.fits(new.blocks() as u32), OutOfMemory, clause::OUT_OF_MEMORY);
            if c.first.is_some() || !self.nv.fields.create(new) {
                return Err(());
            }
        } else if let Some(old) = fields.status(field) {
            // Modify: the code byte must be the field's current code.
            c.check(code_of(old.code_number()) != Some(code), WrongAccessCode, clause::WRONG_ACCESS_CODE);
            let resize = old.blocks() != new.blocks();
            c.check(resize && field + 1 != count, WrongFieldNumber, clause::WRONG_FIELD_NUMBER);
            let grow = new.blocks().saturating_sub(old.blocks()) as u32;
            c.check(resize && field + 1 == count && !fields.fits(grow), OutOfMemory, clause::OUT_OF_MEMORY);
            if c.first.is_some() || !self.nv.fields.modify(field, new) {
                return Err(());
            }
        } else {
            c.check(true, WrongFieldNumber, clause::WRONG_FIELD_NUMBER);
            return Err(());
        }
        self.count_write();
        Ok(Response::FieldCreated { field, status })
    }
}
