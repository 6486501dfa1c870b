//! The frame checksum. // 000:2.3.3

/// XOR of all bytes. A frame with its checksum appended XORs to 0.
#[inline]
pub fn xor(bytes: &[u8]) -> u8 {
    // A `fold`, not an index loop: with a symbolic length (Store Data, 1 to 128 data
    // bytes) Kani lost its verdict on the index loop (docs/src/design.md, "Kani").
    bytes.iter().fold(0, |acc, b| acc ^ b)
}

/// True when `frame` (checksum included) XORs to 0.
#[inline]
pub fn is_valid(frame: &[u8]) -> bool {
    xor(frame) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_7_examples() {
        // 000:T7
        assert_eq!(xor(&[0x40, 0x42]), 0x02);
        assert_eq!(xor(&[0x40, 0x4E, 0x70, 0x00]), 0x7E);
        assert!(is_valid(&[0x40, 0x4E, 0x70, 0x00, 0x7E]));
        assert!(!is_valid(&[0x40, 0x4E, 0x70, 0x00, 0x7F]));
    }
}
