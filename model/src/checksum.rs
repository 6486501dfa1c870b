//! The frame checksum. // 000:2.3.3

/// XOR of all bytes. A frame with its checksum appended XORs to 0.
#[inline]
pub fn xor(bytes: &[u8]) -> u8 {
    // An index loop rather than `bytes.iter()`: Kani unrolls a slice iterator as often
    // as the object the slice points into allows (a 3-byte request in an 11-byte
    // buffer: 12 times), an index loop as often as the slice is long.
    let mut acc = 0;
    for i in 0..bytes.len() {
        acc ^= bytes.get(i).copied().unwrap_or(0);
    }
    acc
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
