//! The field memory from any memory state (issue 60). The whole-step proofs build
//! erased memory and take the field memory's operations as stubs (proofs/src/harnesses.rs);
//! what that rests on is proved here from any contents and any bitmap of known bytes:
//!
//! - the operations themselves ([`memory_ops_from_any`]): `read`, `write` and `free`,
//!   one or two in a row, never panic, answer what the stubs answer (`read` with the
//!   memory's own bytes), and leave every byte as a byte-by-byte reference says (a byte
//!   written holds its value and is known, a byte freed reads FFh and is unknown, every
//!   other byte and bit as it was);
//! - no control flow of a command depends on a content byte or on the bitmap but
//!   through `read`'s answer ([`step_blind_to_contents`]): one step on two memories
//!   that differ in contents and bitmap leaves the same state but the contents and
//!   gives the same reply, Read Data's data bytes excepted.
//!
//! docs/src/verification.md, "The contents of the field memory".

use crate::inductive::{erased_read_answer, memory_holds};
use hiperface_model::frame::MAX_FIELD_BYTES;
use hiperface_model::response::Response;
use hiperface_model::slave::fields::{FieldMemory, BLOCK, ERASED, KNOWN_BYTES, MAX_FIELD_BLOCKS, MAX_MEMORY};
use hiperface_model::{Outcome, Reply, Slave};

/// A field memory's state as plain values: any contents and any bitmap of known bytes
/// (byte `i`'s bit at `i % 8` of `known[i / 8]`).
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(kani, derive(kani::Arbitrary))]
pub struct MemoryState {
    pub bytes: [u8; MAX_MEMORY],
    pub known: [u8; KNOWN_BYTES],
}

impl MemoryState {
    /// The memory these values make. The bitmap's bits past the memory's end are
    /// cleared: no byte lies there to be known; erased memory has them clear and no
    /// operation sets them (a byte probed past the end is checked unknown after each).
    pub fn memory(&self) -> FieldMemory {
        let mut known = self.known;
        // The bits from MAX_MEMORY on are those of the last bitmap byte from bit
        // MAX_MEMORY % 8 on (KNOWN_BYTES is MAX_MEMORY / 8 + 1): no loop, for Kani.
        if let Some(bits) = known.get_mut(MAX_MEMORY / 8) {
            *bits &= (1u8 << (MAX_MEMORY % 8)) - 1;
        }
        FieldMemory::from_contents(self.bytes, known)
    }

    /// Byte `probe` as these values have it: its contents (none past the end) and
    /// whether it is known.
    pub fn at(&self, probe: usize) -> (Option<u8>, bool) {
        let known = probe < MAX_MEMORY && self.known.get(probe / 8).is_some_and(|bits| bits & (1 << (probe % 8)) != 0);
        (self.bytes.get(probe).copied(), known)
    }
}

/// Where `field_memory_any_free_block` frees from: the second block, where a field
/// after a first one of one block starts (fields start on a block boundary).
pub const FREE_BLOCK: usize = BLOCK;

/// [`MemoryOp::kind`] modulo 3: a read, a write or a free.
pub const READ: u8 = 0;
pub const WRITE: u8 = 1;

/// One operation on the field memory as plain values: `kind` modulo 3 is [`READ`]
/// (`extent` bytes at `at`), [`WRITE`] (the first `len` of `data`, at most 8, at `at`)
/// or a free (from `at` to `extent`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(kani, derive(kani::Arbitrary))]
pub struct MemoryOp {
    pub kind: u8,
    pub at: usize,
    pub extent: usize,
    pub data: [u8; 8],
    pub len: usize,
}

/// The field memory's operations from any state: `ops` in a row from the memory
/// `state` makes, each answering what the stubs of the whole-step harnesses answer and
/// none panicking, and byte `probe` (any position, past the end included) after each
/// as a byte-by-byte reference has it:
///
/// - `read` of `count` bytes at `start` answers something exactly when they all lie in
///   the memory ([`memory_holds`]), `count` bytes, the memory's own (at `probe`, where
///   it lies among them); for up to 128 bytes, the most `DataFields::read` asks for, of
///   the stub's length ([`erased_read_answer`], whose bytes are FFh: the contents the
///   whole-step harnesses build); it changes nothing;
/// - `write` answers [`memory_holds`] (the stub's answer); a byte it wrote holds its
///   value and is known;
/// - `free` from `from` to `to` forgets the bytes from `from` below `to`, at most one
///   field's 8 blocks (`DataFields::free_up_to` frees no more): they read FFh and are
///   unknown;
/// - every other byte keeps its value and its bit; past the end there is no byte and
///   none is known. // DESIGN:fields, 000:T21, 000:T22
pub fn memory_ops_from_any(state: &MemoryState, ops: &[MemoryOp], probe: usize, read_back: bool) -> bool {
    let mut memory = state.memory();
    let (mut byte, mut known) = state.at(probe);
    let mut holds = true;
    for op in ops {
        match op.kind % 3 {
            READ => {
                let (real, count) = (memory.read(op.at, op.extent), op.extent);
                let stub_length = count > MAX_FIELD_BYTES
                    || real.map(<[u8]>::len) == erased_read_answer(op.at, count).map(<[u8]>::len);
                let probed = probe
                    .checked_sub(op.at)
                    .filter(|i| *i < count)
                    .is_none_or(|i| real.is_none_or(|r| r.get(i).copied() == byte));
                holds &= real.is_some() == memory_holds(op.at, count)
                    && real.is_none_or(|r| r.len() == count)
                    && stub_length
                    && (!read_back || probed);
            }
            WRITE => {
                let data = op.data.get(..op.len).unwrap_or(&op.data);
                let written = memory.write(op.at, data);
                holds &= written == memory_holds(op.at, data.len());
                if let Some(i) = probe.checked_sub(op.at).filter(|i| written && *i < data.len()) {
                    byte = data.get(i).copied();
                    known = true;
                }
            }
            _ => {
                memory.free(op.at, op.extent);
                if op.at <= probe && probe < op.extent && probe - op.at < MAX_FIELD_BLOCKS * BLOCK {
                    known = false;
                    byte = byte.map(|_| ERASED);
                }
            }
        }
        if read_back {
            holds &= memory.read(probe, 1).and_then(|b| b.first().copied()) == byte && memory.is_known(probe) == known;
        }
    }
    // `scripts/kani.sh --false-assertion field_memory_any_*`: a claim that holds on
    // erased memory and that any state breaks, reached after the operations.
    #[cfg(false_assertion)]
    assert!(byte == Some(ERASED) || !known, "false assertion: the byte probed is erased or unknown");
    holds
}

/// One step from `state` on two memories, `first` and `second` (any contents, any
/// bitmaps, in place of `state`'s): the same state afterwards but the contents, and
/// the same outcome but Read Data's data bytes (its address, warning bit, field,
/// offset and count the same). So no control flow of the step depends on a content
/// byte or on the bitmap but through `read`'s answer, which only Read Data's reply
/// copies: what holds of the step on erased memory holds on any. // DESIGN:fields
pub fn step_blind_to_contents(
    state: &Slave,
    first: FieldMemory,
    second: FieldMemory,
    frame: &[u8],
    now_us: u64,
    uart_fault: bool,
) -> bool {
    let (mut a, mut b) = (state.clone(), state.clone());
    a.replace_field_memory(first);
    b.replace_field_memory(second);
    let (first_outcome, second_outcome) = (a.handle(frame, uart_fault, now_us), b.handle(frame, uart_fault, now_us));
    // `scripts/kani.sh --false-assertion contents_blind_*`: a claim two memories in any
    // states break (their first field's first byte alike), reached after the step.
    #[cfg(false_assertion)]
    assert!(
        a.nonvolatile().fields.read(0, 0, 1) == b.nonvolatile().fields.read(0, 0, 1),
        "false assertion: field 0's first byte is alike in both memories"
    );
    a.replace_field_memory(FieldMemory::erased());
    b.replace_field_memory(FieldMemory::erased());
    a == b && same_but_data(&first_outcome, &second_outcome)
}

/// One step from `state` twice, the field memory's `read` answering any bytes each
/// time (the harness's stub): the same state afterwards and the same outcome but Read
/// Data's data bytes. With the memory reached only through its operations, whose
/// answers depend on positions and lengths alone but for what `read` answers, that is
/// [`step_blind_to_contents`] for every pair of memories (`contents_blind_*`
/// harnesses, docs/src/verification.md). // DESIGN:fields
pub fn step_blind_to_reads(state: &Slave, frame: &[u8], now_us: u64, uart_fault: bool) -> bool {
    let (mut a, mut b) = (state.clone(), state.clone());
    let (first, second) = (a.handle(frame, uart_fault, now_us), b.handle(frame, uart_fault, now_us));
    // `scripts/kani.sh --false-assertion contents_blind_read_data`: a claim two reads
    // break, that Read Data's first data byte is alike in both steps.
    #[cfg(false_assertion)]
    {
        let first_byte = |o: &Outcome| match o.reply {
            Reply::Frame(r) => match r.response {
                Response::Data { data, .. } => data.as_bytes().first().copied(),
                _ => None,
            },
            _ => None,
        };
        assert!(
            first_byte(&first) == first_byte(&second),
            "false assertion: Read Data's first data byte is alike in both steps"
        );
    }
    a.same_but_contents(&b) && same_but_data(&first, &second)
}

/// Two outcomes alike but for the data bytes of Read Data's reply. The clauses by
/// their ids, which the registry holds unique (`clause::ids_are_unique_and_well_formed`):
/// compared whole, a clause's quotation is a string of up to hundreds of bytes, a loop
/// past a harness's unwind bound.
fn same_but_data(a: &Outcome, b: &Outcome) -> bool {
    let replies = match (a.reply, b.reply) {
        (Reply::Frame(ra), Reply::Frame(rb)) => match (ra.response, rb.response) {
            (Response::Data { field, offset, data }, Response::Data { field: f, offset: o, data: d }) => {
                (ra.address, ra.warning, field, offset, data.len()) == (rb.address, rb.warning, f, o, d.len())
            }
            _ => ra == rb,
        },
        (ra, rb) => ra == rb,
    };
    replies
        && a.clause.clause().id() == b.clause.clause().id()
        && (a.also, a.then_settings) == (b.also, b.then_settings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_model::profiles;

    fn sealed<const N: usize>(mut frame: [u8; N]) -> [u8; N] {
        frame[N - 1] = hiperface_model::checksum::xor(&frame[..N - 1]);
        frame
    }

    fn erased_state() -> MemoryState {
        MemoryState { bytes: [ERASED; MAX_MEMORY], known: [0; KNOWN_BYTES] }
    }

    /// The reference agrees with the memory on the examples of fields.rs, and fails a
    /// wrong expectation: a byte that should be known and is not.
    #[test]
    fn the_reference_follows_the_memory() {
        let mut state = erased_state();
        state.known[0] = 0x80; // byte 7 known
        state.bytes[7] = 3;
        let write = MemoryOp { kind: WRITE, at: 7, extent: 0, data: [9; 8], len: 1 };
        let free = MemoryOp { kind: 2, at: 0, extent: 4, data: [0; 8], len: 0 };
        let read = MemoryOp { kind: READ, at: 5, extent: 4, data: [0; 8], len: 0 };
        for probe in [0, 3, 4, 6, 7, 8, MAX_MEMORY - 1, MAX_MEMORY, usize::MAX] {
            assert!(memory_ops_from_any(&state, &[write, write], probe, true), "{probe}");
            assert!(memory_ops_from_any(&state, &[free, read], probe, true), "{probe}");
        }
        // The bits past the end are cleared whatever the values say.
        state.known[KNOWN_BYTES - 1] = 0xFF;
        assert!(!state.memory().is_known(MAX_MEMORY) && memory_ops_from_any(&state, &[read], MAX_MEMORY, true));
        assert_eq!(state.at(7), (Some(3), true));
        assert_eq!(state.at(MAX_MEMORY), (None, false));
    }

    /// Two memories that differ: Read Data's reply differs in its data only, Store
    /// Data's not at all; the state afterwards differs in nothing but the contents.
    #[test]
    fn read_data_tells_the_contents_apart_and_nothing_else_does() {
        let mut slave = Slave::operational(profiles::sek37());
        // Create Data Field 0, one block (000:T24), then Read Data of its first byte
        // (000:T21), each with Code0 and its checksum.
        let frame = sealed([0x40, 0x4D, 0x00, 0xC0, 0x55, 0]);
        let created = slave.handle_frame(&frame, 0).reply;
        assert!(
            matches!(created, Reply::Frame(rf) if matches!(rf.response, Response::FieldCreated { .. })),
            "{created:?}"
        );
        let mut other = erased_state();
        other.bytes[0] = 1;
        other.known[0] = 1;
        let frame = sealed([0x40, 0x4A, 0x00, 0x00, 0x01, 0x55, 0]);
        let mut a = slave.clone();
        a.replace_field_memory(other.memory());
        let (ra, rb) = (a.handle_frame(&frame, 0), slave.clone().handle_frame(&frame, 0));
        assert_ne!(ra, rb, "Read Data answers the contents");
        assert!(same_but_data(&ra, &rb));
        assert!(step_blind_to_contents(&slave, other.memory(), FieldMemory::erased(), &frame, 0, false));
    }
}
