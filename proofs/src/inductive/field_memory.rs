//! The field memory's operations on their own: what the stubs of the whole-step
//! harnesses of the data field commands answer (proofs/src/harnesses.rs), that the
//! real operations answer the same and never panic, and what `write` and `free` do to
//! the contents.

use hiperface_model::frame::MAX_FIELD_BYTES;
use hiperface_model::slave::fields::{FieldMemory, BLOCK, ERASED, MAX_FIELD_BLOCKS, MAX_MEMORY};

/// Whether `len` bytes from `start` all lie in the field memory: what
/// [`FieldMemory::write`] answers. The whole-step harnesses of the data field commands
/// take the field memory's operations as stubs (proofs/src/harnesses.rs;
/// docs/src/verification.md, "The contents of the field memory"), which answer from
/// this; [`field_memory_writes_as_stubbed`] and its siblings prove the real ones answer
/// the same.
pub fn memory_holds(start: usize, len: usize) -> bool {
    start.checked_add(len).is_some_and(|end| end <= MAX_MEMORY)
}

/// What [`FieldMemory::read`] answers on erased memory (as [`Parts`](super::Parts) build it) for up
/// to [`MAX_FIELD_BYTES`] bytes, the most `DataFields::read` asks for: FFh for each
/// byte that lies in the memory.
pub fn erased_read_answer(start: usize, count: usize) -> Option<&'static [u8]> {
    static ERASED_FIELD: [u8; MAX_FIELD_BYTES] = [ERASED; MAX_FIELD_BYTES];
    if memory_holds(start, count) {
        ERASED_FIELD.get(..count)
    } else {
        None
    }
}

/// The field memory's operations on their own, what the stubs of the whole-step
/// harnesses rely on: each answers as its stub does and never panics. Nothing else of
/// the slave can change through them: they take only `&FieldMemory` or `&mut
/// FieldMemory`. (What `write` and `free` do to the contents, which no stub relies on,
/// is [`field_memory_contents`], sampled: with it in a Kani harness the 4 080-byte
/// memory ran out of 8 GB, docs/src/verification.md.)
///
/// `read`: on erased memory, `count` bytes (at most [`MAX_FIELD_BYTES`], the most
/// `DataFields::read` asks for) at `start` are what [`erased_read_answer`] answers, in
/// length and at byte `probe` (for a symbolic `probe`, at every byte).
pub fn field_memory_reads_as_stubbed(start: usize, count: usize, probe: usize) -> bool {
    let memory = FieldMemory::erased();
    let (real, stub) = (memory.read(start, count), erased_read_answer(start, count));
    // `scripts/kani.sh --false-assertion field_memory_read`: a claim a read inside the
    // memory breaks.
    #[cfg(false_assertion)]
    assert!(real.is_none(), "false assertion: no read lies in the memory");
    count > MAX_FIELD_BYTES
        || (real.map(<[u8]>::len) == stub.map(<[u8]>::len)
            && real.and_then(|r| r.get(probe)) == stub.and_then(|s| s.get(probe)))
}

/// `write` of `data` at `start` answers [`memory_holds`] (what `write_answers_only`
/// answers) and does not panic.
pub fn field_memory_writes_as_stubbed(start: usize, data: &[u8]) -> bool {
    let mut memory = FieldMemory::erased();
    let written = memory.write(start, data);
    // `scripts/kani.sh --false-assertion field_memory_write`: a claim a write inside
    // the memory breaks.
    #[cfg(false_assertion)]
    assert!(!written, "false assertion: no write lies in the memory");
    written == memory_holds(start, data.len())
}

/// `free` from `from` to `to` does not panic (`free_changes_nothing` answers nothing
/// either): true once it returns.
pub fn field_memory_frees_without_panic(from: usize, to: usize) -> bool {
    let mut memory = FieldMemory::erased();
    memory.free(from, to);
    // `scripts/kani.sh --false-assertion field_memory_free`: a claim any range to free
    // breaks, reached after `free` returns.
    #[cfg(false_assertion)]
    assert!(from >= to, "false assertion: nothing is ever freed");
    true
}

/// What `write` and `free` do to the contents: from erased memory, a byte `write`
/// wrote (at `start`) reads what it wrote and is known, any other byte `probe` is
/// still erased and unknown; then after `free` from `from` to `to`, `probe`, if within
/// the blocks it frees (from a block boundary, as the fields end on one, and below
/// `to`), reads FFh and is unknown again.
pub fn field_memory_contents(start: usize, data: &[u8], from: usize, to: usize, probe: usize) -> bool {
    let mut memory = FieldMemory::erased();
    let written = memory.write(start, data);
    let byte = |m: &FieldMemory| m.read(probe, 1).and_then(|b| b.first().copied());
    // Past the memory's end there is no byte to be erased.
    let erased = |m: &FieldMemory| probe >= MAX_MEMORY || (byte(m) == Some(ERASED) && !m.is_known(probe));
    let at = probe.checked_sub(start).filter(|i| written && *i < data.len());
    let probed = match at {
        Some(i) => byte(&memory) == data.get(i).copied() && memory.is_known(probe),
        None => erased(&memory),
    };
    memory.free(from, to);
    let freed = from % BLOCK == 0 && from <= probe && probe - from < MAX_FIELD_BLOCKS * BLOCK && probe < to;
    written == memory_holds(start, data.len()) && probed && (!freed || erased(&memory))
}
