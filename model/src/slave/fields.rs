//! Data fields in user memory. // 000:2.4.2 data field specification, 000:T21-T25, DESIGN:fields
//!
//! Long because: the field table and its accounting in blocks are one invariant (back
//! to back, only the last field changes size, 000:2.4.2); under 400 lines without its
//! tests. The contents are `memory` ([`FieldMemory`]), a module of their own.
//!
//! Fields are stored back to back in the order of their numbers, so only the last one
//! can grow, shrink or be deleted, and memory is accounted in 16-byte blocks.

use crate::frame::MAX_FIELD_BYTES;

pub mod memory;
pub use memory::FieldMemory;

pub const BLOCK: usize = 16;
/// The memory size byte counts blocks: at most 255 blocks.
pub const MAX_MEMORY: usize = 255 * BLOCK;
/// The most blocks one field has (size bits 111: 8 blocks of 16 bytes). // 000:T23
pub const MAX_FIELD_BLOCKS: usize = 8;
/// The number of fields is bounded by the number of blocks.
pub const MAX_FIELDS: usize = 255;
/// Erased EEPROM reads FFh (001 §5.1.4 reads 16 x FFh from a new field).
pub const ERASED: u8 = 0xFF;
/// The bytes of [`FieldMemory`]'s bitmap of known bytes: a bit per byte of the memory,
/// and a last byte whose bits lie past its end (no byte there to know).
pub const KNOWN_BYTES: usize = MAX_MEMORY / 8 + 1;

/// A data field status byte. // 000:T23
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FieldStatus(pub u8);

impl FieldStatus {
    pub const EXISTS: u8 = 0x80;
    pub const WRITABLE: u8 = 0x40;
    pub const CODE_ENABLED: u8 = 0x08;

    pub const fn blocks(self) -> u8 {
        (self.0 & 0x07) + 1
    }
    pub const fn size_bytes(self) -> usize {
        self.blocks() as usize * BLOCK
    }
    pub const fn code_enabled(self) -> bool {
        self.0 & Self::CODE_ENABLED != 0
    }
    /// Code0...Code3.
    pub const fn code_number(self) -> usize {
        ((self.0 >> 4) & 0x03) as usize
    }
    pub const fn writable(self) -> bool {
        self.0 & Self::WRITABLE != 0
    }
    pub const fn exists(self) -> bool {
        self.0 & Self::EXISTS != 0
    }
    /// The status without the exists/create bit.
    pub const fn attributes(self) -> u8 {
        self.0 & !Self::EXISTS
    }
}

/// The data field table: the fields' statuses in number order and the user memory's
/// size, which together say where each field lies and how much memory is free
/// (000:2.4.2, 000:T23-T25). The accounting on its own, without the contents: its
/// part of the slave's invariant is proved on this type alone
/// (proofs/src/inductive/, `inductive_data_fields`), and [`DataFields`] changes it
/// only through [`FieldTable::create`], [`FieldTable::modify`] and
/// [`FieldTable::delete_last`].
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct FieldTable {
    statuses: [u8; MAX_FIELDS],
    count: u8,
    capacity_blocks: u8,
}

impl core::fmt::Debug for FieldTable {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.debug_as("FieldTable", f)
    }
}

impl FieldTable {
    pub const fn new(capacity_blocks: u8) -> FieldTable {
        FieldTable { statuses: [0; MAX_FIELDS], count: 0, capacity_blocks }
    }

    /// A table as stored, for proofs that start from any table satisfying an invariant
    /// the caller checks (proofs/src/inductive/): the first `count` of `statuses` as
    /// the fields (each with its exists bit set; as many as there are and the table
    /// holds), no check that they fit. It has no path that refuses: a bounded model
    /// checker would merge the refusing path's table with the built one, and the count
    /// (a constant on every path that builds) would be symbolic after the merge.
    pub fn from_table(capacity_blocks: u8, statuses: &[u8], count: usize) -> FieldTable {
        let mut t = FieldTable::new(capacity_blocks);
        let count = count.min(statuses.len()).min(MAX_FIELDS);
        // Slot by slot over all of `statuses`, not `0..count`: a bounded model checker
        // that does not know `count` unrolls a loop to it as often as its bound allows,
        // one over a slice of known length as often as the slice is long.
        for i in 0..statuses.len().min(MAX_FIELDS) {
            if let (Some(slot), Some(s)) = (t.statuses.get_mut(i), statuses.get(i)) {
                if i < count {
                    *slot = s | FieldStatus::EXISTS;
                }
            }
        }
        t.count = count as u8;
        t
    }

    /// The statuses of the fields, in number order.
    pub fn statuses(&self) -> &[u8] {
        self.statuses.get(..self.count as usize).unwrap_or(&[])
    }

    /// The debug form of the table and of [`DataFields`], which shows it: the statuses
    /// and the free memory (the contents are not shown).
    fn debug_as(&self, name: &str, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct(name).field("statuses", &self.statuses()).field("free_blocks", &self.free_blocks()).finish()
    }

    pub const fn count(&self) -> u8 {
        self.count
    }

    pub const fn capacity_blocks(&self) -> u8 {
        self.capacity_blocks
    }

    pub fn status(&self, number: u8) -> Option<FieldStatus> {
        (number < self.count).then(|| FieldStatus(self.statuses[number as usize]))
    }

    pub fn used_blocks(&self) -> u32 {
        self.blocks_before(self.count)
    }

    /// Blocks of the fields below `number`. Every field in use is visited (those at or
    /// above `number` count 0): the loop's length is the number of fields, whatever
    /// `number` is, so that a bounded model checker that knows the table but not
    /// `number` (a field number from a request) runs it once per field, not once per
    /// slot of the table. An index loop, not an iterator over `statuses()`: Kani unrolls
    /// a slice iterator as often as the 255-entry table allows, an index loop once per
    /// field.
    fn blocks_before(&self, number: u8) -> u32 {
        let mut blocks = 0;
        for i in 0..self.count {
            if i < number {
                blocks += self.statuses.get(i as usize).map_or(0, |s| FieldStatus(*s).blocks() as u32);
            }
        }
        blocks
    }

    pub fn free_blocks(&self) -> u8 {
        (self.capacity_blocks as u32).saturating_sub(self.used_blocks()) as u8
    }

    /// Where field `number` starts in memory, in bytes.
    pub fn start(&self, number: u8) -> usize {
        self.blocks_before(number) as usize * BLOCK
    }

    /// Where the fields end in memory, in bytes: free memory from here on.
    pub fn end(&self) -> usize {
        self.start(self.count)
    }

    /// Whether `blocks` more blocks fit.
    pub fn fits(&self, extra_blocks: u32) -> bool {
        self.used_blocks() + extra_blocks <= self.capacity_blocks as u32
    }

    /// Append a field; `false` (nothing changed) if it does not fit.
    pub fn create(&mut self, status: FieldStatus) -> bool {
        if self.count as usize >= MAX_FIELDS || !self.fits(status.blocks() as u32) {
            return false;
        }
        self.statuses[self.count as usize] = status.0 | FieldStatus::EXISTS;
        self.count += 1;
        true
    }

    /// Change a field's status; `false` (nothing changed) for no such field, a size
    /// change of a field other than the last, or growth that does not fit.
    pub fn modify(&mut self, number: u8, status: FieldStatus) -> bool {
        let Some(old) = self.status(number) else {
            return false;
        };
        if old.blocks() != status.blocks() {
            if number + 1 != self.count {
                return false;
            }
            let grow = status.blocks().saturating_sub(old.blocks()) as u32;
            if !self.fits(grow) {
                return false;
            }
        }
        self.statuses[number as usize] = status.0 | FieldStatus::EXISTS;
        true
    }

    /// Delete the last field; `false` if there is none.
    pub fn delete_last(&mut self) -> bool {
        let Some(last) = self.count.checked_sub(1) else {
            return false;
        };
        self.statuses[last as usize] = 0;
        self.count = last;
        true
    }
}

/// The data field table and user memory: the table says where each field lies, the
/// memory holds the contents.
///
/// Which bytes the model knows it records in [`FieldMemory`]. The rest is its
/// assumption: a new field reads FFh (DESIGN:fields), a real device's existing field
/// holds what it holds.
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct DataFields {
    table: FieldTable,
    memory: FieldMemory,
    /// Fields `0..adopted` were found on a real device: their contents are its own.
    adopted: u8,
}

/// What the model knows of a byte of a data field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contents {
    /// Written in lockstep or read back from the device.
    Known,
    /// Never written since the field was created: erased EEPROM by the model's decision.
    Erased,
    /// In a field the device had before the run: whatever it holds.
    Unknown,
}

impl core::fmt::Debug for DataFields {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.table.debug_as("DataFields", f)
    }
}

impl DataFields {
    pub fn new(capacity_blocks: u8) -> DataFields {
        DataFields::with_table(FieldTable::new(capacity_blocks))
    }

    /// A table with its fields in free memory: they read FFh, the model knows none of
    /// their bytes, and all of them are the device's own (adopted).
    fn with_table(table: FieldTable) -> DataFields {
        let adopted = table.count();
        DataFields { table, memory: FieldMemory::erased(), adopted }
    }

    /// A table as a device reports it: capacity and the statuses of its fields (the
    /// contents are unknown). `None` if the statuses do not fit.
    pub fn from_statuses(capacity_blocks: u8, statuses: &[u8]) -> Option<DataFields> {
        let mut table = FieldTable::new(capacity_blocks);
        for s in statuses {
            if !table.create(FieldStatus(*s)) {
                return None;
            }
        }
        Some(DataFields::with_table(table))
    }

    /// A table as stored ([`FieldTable::from_table`]: no check that the fields fit),
    /// its fields in free memory, for proofs that start from any state satisfying an
    /// invariant the caller checks.
    pub fn from_table(capacity_blocks: u8, statuses: &[u8], count: usize) -> DataFields {
        DataFields::with_table(FieldTable::from_table(capacity_blocks, statuses, count))
    }

    /// The table: statuses and memory accounting.
    pub const fn table(&self) -> &FieldTable {
        &self.table
    }

    /// The statuses of the fields, in number order.
    pub fn statuses(&self) -> &[u8] {
        self.table.statuses()
    }

    /// The same table (count, capacity, the fields' statuses) and the same fields adopted,
    /// whatever the contents: see [`crate::slave::Slave::same_but_contents`].
    pub fn same_but_contents(&self, other: &DataFields) -> bool {
        let (t, o) = (&self.table, &other.table);
        (t.count, t.capacity_blocks, self.adopted) == (o.count, o.capacity_blocks, other.adopted)
            && t.statuses() == o.statuses()
    }

    /// Memory past the last field is free: it reads FFh and the model knows nothing of
    /// it, so a new field and the grown blocks of the last one read FFh (DESIGN:fields)
    /// with nothing more to do. Nothing writes past the fields' end, so after a change
    /// of where they end only the blocks between the new end and `old_end` (a field
    /// shrunk or deleted: at most one field's 8 blocks) need freeing.
    fn free_up_to(&mut self, old_end: usize) {
        self.memory.free(self.table.end(), old_end);
    }

    /// The contents replaced by `memory` (the table as it is), the old ones returned:
    /// for proofs that step a slave from any contents and compare what is left
    /// (proofs/src/contents.rs).
    pub fn replace_memory(&mut self, memory: FieldMemory) -> FieldMemory {
        core::mem::replace(&mut self.memory, memory)
    }

    /// Whether the memory past the last field reads FFh and is unknown, as
    /// [`DataFields::free_up_to`] relies on.
    pub fn rest_is_free(&self) -> bool {
        self.memory.is_free_from(self.table.end())
    }

    /// What the model knows of byte `offset` of field `number` (`None` outside it).
    pub fn contents(&self, number: u8, offset: usize) -> Option<Contents> {
        let size = self.status(number)?.size_bytes();
        if offset >= size {
            return None;
        }
        let known = self.memory.is_known(self.table.start(number) + offset);
        Some(match (known, number < self.adopted) {
            (true, _) => Contents::Known,
            (false, true) => Contents::Unknown,
            (false, false) => Contents::Erased,
        })
    }

    pub const fn count(&self) -> u8 {
        self.table.count()
    }

    pub const fn capacity_blocks(&self) -> u8 {
        self.table.capacity_blocks()
    }

    pub fn status(&self, number: u8) -> Option<FieldStatus> {
        self.table.status(number)
    }

    pub fn used_blocks(&self) -> u32 {
        self.table.used_blocks()
    }

    pub fn free_blocks(&self) -> u8 {
        self.table.free_blocks()
    }

    /// Bytes `offset..offset+count` of a field; `None` if out of bounds.
    pub fn read(&self, number: u8, offset: u8, count: u8) -> Option<&[u8]> {
        let size = self.status(number)?.size_bytes();
        let (offset, count) = (offset as usize, count as usize);
        if count == 0 || count > MAX_FIELD_BYTES || offset + count > size {
            return None;
        }
        self.memory.read(self.table.start(number) + offset, count)
    }

    /// Store bytes; `false` (nothing written) if out of bounds.
    pub fn write(&mut self, number: u8, offset: u8, data: &[u8]) -> bool {
        let Some(status) = self.status(number) else {
            return false;
        };
        let offset = offset as usize;
        if data.is_empty() || offset + data.len() > status.size_bytes() {
            return false;
        }
        self.memory.write(self.table.start(number) + offset, data)
    }

    /// Whether `blocks` more blocks fit.
    pub fn fits(&self, extra_blocks: u32) -> bool {
        self.table.fits(extra_blocks)
    }

    /// Append a field (the caller checked number == count and that it fits). Its
    /// contents read FFh: they were free memory.
    pub fn create(&mut self, status: FieldStatus) -> bool {
        self.table.create(status)
    }

    /// Change a field's status. A size change is only possible for the last field;
    /// grown blocks read FFh, blocks given up become free memory.
    pub fn modify(&mut self, number: u8, status: FieldStatus) -> bool {
        let old_end = self.table.end();
        if !self.table.modify(number, status) {
            return false;
        }
        self.free_up_to(old_end);
        true
    }

    /// Delete the last field; its blocks become free and read FFh again.
    pub fn delete_last(&mut self) -> bool {
        let old_end = self.table.end();
        if !self.table.delete_last() {
            return false;
        }
        self.adopted = self.adopted.min(self.table.count());
        self.free_up_to(old_end);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_is_conserved_and_new_fields_read_ff() {
        let mut f = DataFields::new(8);
        assert!(f.create(FieldStatus(0xC9)));
        assert_eq!((f.free_blocks(), f.count()), (6, 1));
        assert!(f.write(0, 30, &[1, 2]));
        assert!(!f.write(0, 31, &[1, 2]), "offset + count beyond the field");
        assert_eq!(f.read(0, 29, 3), Some(&[0xFF, 1, 2][..]));
        assert!(f.create(FieldStatus(0xE0)));
        assert!(!f.modify(0, FieldStatus(0xCA)), "only the last field changes size");
        assert!(f.modify(1, FieldStatus(0xE3)));
        assert_eq!(f.free_blocks(), 2);
        assert!(!f.modify(1, FieldStatus(0xE6)), "does not fit");
        assert!(f.delete_last() && f.delete_last() && !f.delete_last());
        assert_eq!(f.free_blocks(), 8);
        assert!(f.create(FieldStatus(0xC9)));
        assert_eq!(f.read(0, 29, 3), Some(&[0xFF; 3][..]), "re-created field starts at FFh");
        assert!(f.rest_is_free());
        assert_eq!(f.read(0, 0, 0), None);
        assert_eq!(f.read(1, 0, 1), None);
    }

    /// Shrinking, deleting, growing again after writes: the memory past the fields
    /// stays erased and unknown, so that growing needs no freeing.
    #[test]
    fn the_memory_past_the_fields_stays_free() {
        // `free_up_to` frees at most one field's blocks.
        assert_eq!(FieldStatus(0xFF).blocks() as usize, MAX_FIELD_BLOCKS);
        let mut f = DataFields::new(8);
        assert!(f.rest_is_free());
        assert!(f.create(FieldStatus(0xC3)) && f.create(FieldStatus(0xC3)));
        assert!(f.write(0, 0, &[1; 64]) && f.write(1, 0, &[2; 64]));
        assert!(f.rest_is_free());
        assert!(f.modify(1, FieldStatus(0xC0)), "shrink the last field to one block");
        assert!(f.rest_is_free());
        assert!(f.modify(1, FieldStatus(0xC3)), "grow it again");
        assert_eq!(f.read(1, 0, 32), Some(&[[2; 16], [0xFF; 16]].concat()[..]));
        assert_eq!((f.contents(1, 15), f.contents(1, 16)), (Some(Contents::Known), Some(Contents::Erased)));
        assert!(f.delete_last() && f.rest_is_free());
        assert!(f.create(FieldStatus(0xC3)));
        assert_eq!(f.read(1, 0, 64), Some(&[0xFF; 64][..]), "the deleted field's bytes were freed");
        assert!(f.delete_last() && f.delete_last() && f.rest_is_free());
        // The largest field given up whole, after its bytes were written.
        assert!(f.create(FieldStatus(0xC7)) && f.write(0, 112, &[3; 16]));
        assert!(f.delete_last() && f.rest_is_free());
    }

    /// The check itself: a byte past the fields' end that is not FFh, or one the model
    /// knows, is memory that is not free.
    #[test]
    fn memory_past_the_fields_that_is_written_or_known_is_not_free() {
        let mut f = DataFields::from_table(8, &[0xC0], 1);
        assert!(f.rest_is_free());
        let mut bytes = [ERASED; MAX_MEMORY];
        bytes[BLOCK] = 0;
        f.replace_memory(FieldMemory::from_contents(bytes, [0; KNOWN_BYTES]));
        assert!(!f.rest_is_free(), "a byte past the end that is not FFh");
        f.replace_memory(FieldMemory::erased());
        // FFh written: the byte reads as free memory does, but the model knows it.
        assert!(f.memory.write(MAX_MEMORY - 1, &[ERASED]));
        assert!(!f.rest_is_free(), "a byte past the end that the model knows");
        // Inside the field, neither counts.
        let mut g = DataFields::from_table(8, &[0xC0], 1);
        assert!(g.memory.write(0, &[0]));
        assert!(g.rest_is_free());
    }

    #[test]
    fn a_table_as_stored_is_the_table_created_field_by_field() {
        for statuses in [&[][..], &[0xC9], &[0x41, 0xE0, 0x80]] {
            assert_eq!(
                Some(DataFields::from_table(8, statuses, statuses.len())),
                DataFields::from_statuses(8, statuses)
            );
        }
        // The first `count` only.
        assert_eq!(
            DataFields::from_table(8, &[0x41, 0xE0, 0x80], 2),
            DataFields::from_statuses(8, &[0x41, 0xE0]).unwrap()
        );
        assert_eq!(FieldTable::from_table(8, &[0x41], 5).statuses(), &[0xC1]);
        // Fields that do not fit are taken as stored (the caller's invariant refuses them).
        let f = DataFields::from_table(8, &[0xC7, 0xC0], 2);
        assert_eq!((f.count(), f.used_blocks(), DataFields::from_statuses(8, &[0xC7, 0xC0])), (2, 9, None));
        assert_eq!(DataFields::from_table(255, &[0x80; 256], 256).count(), 255, "as many as the table holds");
    }

    #[test]
    fn the_model_knows_what_it_wrote_and_what_it_adopted() {
        let mut f = DataFields::from_statuses(8, &[0xC0]).unwrap();
        assert_eq!(f.contents(0, 0), Some(Contents::Unknown), "a real device's field");
        assert!(f.create(FieldStatus(0xC0)));
        assert_eq!(f.contents(1, 3), Some(Contents::Erased), "a field created in the run");
        assert!(f.write(1, 3, &[7]));
        assert_eq!((f.contents(1, 3), f.contents(1, 4)), (Some(Contents::Known), Some(Contents::Erased)));
        assert!(f.write(0, 0, &[1, 2]), "adopting a device's bytes is a store's bookkeeping");
        assert_eq!((f.contents(0, 1), f.contents(0, 2)), (Some(Contents::Known), Some(Contents::Unknown)));
        assert_eq!(f.read(0, 0, 2), Some(&[1, 2][..]));
        assert!(f.delete_last());
        assert!(f.create(FieldStatus(0xC0)));
        assert_eq!(f.contents(1, 3), Some(Contents::Erased), "re-created: erased again");
        assert_eq!(f.contents(1, 16), None);
    }
}
