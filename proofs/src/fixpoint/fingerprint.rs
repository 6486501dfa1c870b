//! The fingerprint of a state, all the searches to a fixpoint keep of one (this
//! module's and the reference master's, proofs/src/master_fixpoint/).

use std::hash::{Hash, Hasher};

/// A 128-bit fingerprint of a world: the search keeps fingerprints of the states it
/// has seen, not the states (about 5 KB each, most of it the data field memory), and
/// hashes each once (hash compaction; docs/src/verification.md says what it costs).
/// Two lanes of multiply-rotate over 8-byte words, each finished by MurmurHash3's
/// mixer: fast in a debug build, where SipHash takes 50 µs per state.
#[derive(Default)]
pub(crate) struct Fingerprint {
    a: u64,
    b: u64,
    len: u64,
}

impl Fingerprint {
    pub(crate) fn of(w: &impl Hash) -> u128 {
        let mut f = Fingerprint { a: 0x243F_6A88_85A3_08D3, b: 0x1319_8A2E_0370_7344, len: 0 };
        w.hash(&mut f);
        let fmix = |mut k: u64| {
            k ^= k >> 33;
            k = k.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
            k ^= k >> 33;
            k = k.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
            k ^ (k >> 33)
        };
        let (a, b) = (fmix(f.a ^ f.len), fmix(f.b.wrapping_add(f.len)));
        ((a as u128) << 64) | b as u128
    }

    fn words(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            self.word(u64::from_le_bytes(w));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut w = [0u8; 8];
            w[..rest.len()].copy_from_slice(rest);
            self.word(u64::from_le_bytes(w) ^ ((rest.len() as u64) << 56));
        }
    }

    fn word(&mut self, w: u64) {
        self.a = (self.a ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(31);
        self.b = (self.b.rotate_left(27) ^ w).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
        self.len += 1;
    }
}

impl Hasher for Fingerprint {
    fn write(&mut self, bytes: &[u8]) {
        // Blocks of 64 bytes that are all FFh (erased memory) or all 00h (memory no
        // one knows, unused status slots) are one tag each: most of a state, found by
        // a comparison (memcmp) rather than a debug build's loop over its words. The
        // encoding stays one-to-one: a tag, or another tag and the block's words.
        const ERASED: [u8; 64] = [0xFF; 64];
        const ZERO: [u8; 64] = [0; 64];
        let mut blocks = bytes.chunks_exact(64);
        for block in &mut blocks {
            if block == ERASED {
                self.word(0xE5E5_E5E5_0000_00FF);
            } else if block == ZERO {
                self.word(0xE5E5_E5E5_0000_0000);
            } else {
                self.word(0xE5E5_E5E5_0000_0B0C);
                self.words(block);
            }
        }
        self.words(blocks.remainder());
    }

    fn write_u8(&mut self, i: u8) {
        self.word(i as u64 | 0x100);
    }

    fn write_u64(&mut self, i: u64) {
        self.word(i);
    }

    fn finish(&self) -> u64 {
        self.a ^ self.b
    }
}
