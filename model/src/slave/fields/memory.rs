//! The user memory's contents, a module of its own so that nothing but its own
//! operations reaches the bytes and the bitmap of known bytes: the slave's step sees
//! them only through `read`, `write` and `free`, whose answers depend on positions and
//! lengths alone (proofs/src/harnesses.rs, `field_memory_any_*`), and through what
//! `read` answers. The `contents_blind_*` harnesses rest on that (docs/src/verification.md,
//! "From every memory state"). // 000:2.4.2, DESIGN:fields

use super::{BLOCK, ERASED, KNOWN_BYTES, MAX_FIELD_BLOCKS, MAX_MEMORY};

/// The user memory's contents: its bytes, and which of them the model *knows*
/// (written by Store Data, or read from a real device and adopted). Positions are
/// absolute, in bytes; [`DataFields`] says where the fields lie. A type of its own so
/// that what the contents do is proved apart from the rest of the slave
/// (proofs/src/lib.rs, `field_memory_*`): the whole-step proofs of the data field
/// commands replace its operations by stubs that answer as they do (on erased memory)
/// and change nothing (docs/src/verification.md, "The contents of the field memory").
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct FieldMemory {
    bytes: [u8; MAX_MEMORY],
    /// One bit per byte of `bytes`: its contents are known.
    known: [u8; KNOWN_BYTES],
}

impl FieldMemory {
    /// Memory as a new device has it: every byte FFh, none known.
    pub const fn erased() -> FieldMemory {
        FieldMemory { bytes: [ERASED; MAX_MEMORY], known: [0; MAX_MEMORY / 8 + 1] }
    }

    /// Memory in a state given byte by byte: `bytes`, and `known` a bit per byte (byte
    /// `i` at bit `i % 8` of `known[i / 8]`), for proofs that start from any contents
    /// (proofs/src/contents.rs). The bits past the memory's end are the caller's: the
    /// operations never set them.
    pub const fn from_contents(bytes: [u8; MAX_MEMORY], known: [u8; KNOWN_BYTES]) -> FieldMemory {
        FieldMemory { bytes, known }
    }

    /// Bytes `start..start + count`; `None` past the memory's end.
    pub fn read(&self, start: usize, count: usize) -> Option<&[u8]> {
        self.bytes.get(start..start.checked_add(count)?)
    }

    /// Store `data` at `start`: the model knows those bytes from now on. `false`
    /// (nothing written) if they do not all lie in the memory; the proofs' stub of this
    /// function answers the same.
    pub fn write(&mut self, start: usize, data: &[u8]) -> bool {
        let Some(end) = start.checked_add(data.len()).filter(|end| *end <= MAX_MEMORY) else {
            return false;
        };
        // Byte by byte: for Kani one store at a position it does not know per byte,
        // where a copy of a length it does not know ran out of 8 GB on its own.
        for (at, byte) in (start..end).zip(data) {
            if let Some(dst) = self.bytes.get_mut(at) {
                *dst = *byte;
            }
            if let Some(known) = self.known.get_mut(at / 8) {
                *known |= 1u8 << (at % 8);
            }
        }
        true
    }

    /// Free the bytes from `from` up to `to`, at most one field's 8 blocks (a field
    /// shrunk or deleted: the blocks between the fields' new end and their old one):
    /// they read FFh and the model knows nothing of them. Byte by byte over at most 8 blocks, rather than
    /// a `fill` of the rest of the memory (Kani would unroll it as often as the 4 080
    /// bytes allow) or a copy of whole blocks (for Kani a copy at a position it does
    /// not know ran out of 8 GB on its own; one store per byte does not). Bytes past
    /// the memory's end are not there to free.
    pub fn free(&mut self, from: usize, to: usize) {
        for i in 0..MAX_FIELD_BLOCKS * BLOCK {
            let at = from.saturating_add(i);
            if at >= to {
                break;
            }
            if let Some(byte) = self.bytes.get_mut(at) {
                *byte = ERASED;
            }
            if let Some(known) = self.known.get_mut(at / 8) {
                *known &= !(1u8 << (at % 8));
            }
        }
    }

    /// Whether the model knows byte `i` (`false` past the memory's end).
    pub fn is_known(&self, i: usize) -> bool {
        self.known.get(i / 8).is_some_and(|b| b & (1 << (i % 8)) != 0)
    }

    /// Whether every byte from `start` on reads FFh and is unknown.
    pub fn is_free_from(&self, start: usize) -> bool {
        let erased = self.bytes.get(start..).is_some_and(|m| m.iter().all(|b| *b == ERASED));
        erased && (start..MAX_MEMORY).all(|i| !self.is_known(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The contents' operations at the memory's edges: nothing past the end is read,
    /// written or freed, and no position makes them panic (an end past `usize::MAX`
    /// included).
    #[test]
    fn the_field_memory_stays_within_its_bytes() {
        let mut m = FieldMemory::erased();
        assert!(m.write(MAX_MEMORY - 2, &[1, 2]));
        assert_eq!(m.read(MAX_MEMORY - 2, 2), Some(&[1, 2][..]));
        assert!(m.is_known(MAX_MEMORY - 1) && !m.is_known(MAX_MEMORY - 3) && !m.is_known(MAX_MEMORY));
        assert!(!m.write(MAX_MEMORY - 1, &[1, 2]), "one byte past the end");
        assert!(!m.write(usize::MAX, &[1]) && m.read(usize::MAX, 2).is_none());
        assert_eq!(m.read(MAX_MEMORY - 1, 2), None);
        let before = m.clone();
        m.free(MAX_MEMORY, usize::MAX);
        m.free(usize::MAX - 3, usize::MAX);
        assert!(m == before, "nothing past the end to free");
        m.free(MAX_MEMORY - BLOCK, MAX_MEMORY);
        assert!(m.is_free_from(0), "the written block freed: all of it free again");
        assert!(m == FieldMemory::erased());
        // Freeing part of the eight bytes one `known` byte covers leaves the rest known.
        assert!(m.write(0, &[1; 16]));
        m.free(0, 4);
        assert_eq!(m.read(3, 2), Some(&[ERASED, 1][..]));
        assert!(!m.is_known(3) && m.is_known(4) && m.is_known(7));
    }

    /// A byte written twice stays known, whatever its bit's place in the bitmap: the
    /// eighth byte of a bitmap byte (`at % 8 == 7`, the top bit) written again, as a
    /// second Store Data to the same byte does (000:T22). Marking a byte known by
    /// adding its bit instead of or-ing it overflows there (found by the Kani
    /// harnesses from any memory state, issue 60).
    #[test]
    fn a_byte_written_twice_stays_known() {
        let mut m = FieldMemory::erased();
        for at in [7, 15, MAX_MEMORY - 1] {
            assert!(m.write(at, &[1]) && m.write(at, &[2]), "{at}");
            assert_eq!(m.read(at, 1), Some(&[2][..]));
            assert!(m.is_known(at) && !m.is_known(at - 1), "{at}");
        }
        // Every bit of one bitmap byte set, then each byte of it written again.
        assert!(m.write(16, &[3; 8]) && m.write(16, &[4; 8]));
        assert_eq!(m.read(16, 8), Some(&[4; 8][..]));
        assert!((16..24).all(|i| m.is_known(i)) && !m.is_known(24) && !m.is_known(14));
    }
}
