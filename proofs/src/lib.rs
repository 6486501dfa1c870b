//! Properties of the model, written once and checked twice: by Kani harnesses
//! (`cargo kani -p hiperface-proofs`, behind `cfg(kani)`) and under `cargo test` by
//! exhausting the same domain. This crate starts with the wire codecs; issue 6 adds
//! the decoders, the data link, the slave step and the stack and memory invariants.

use hiperface_model::settings::{SettingsError, UartSettings};
use hiperface_model::{checksum, AddressByte};

/// A frame with its checksum appended XORs to 0, and flipping any one bit of it
/// (checksum included) is detected. // 000:2.3.3
pub fn checksum_detects_single_bit_flips<const N: usize>(body: [u8; N], bit: usize) -> bool {
    let mut frame = [0u8; 8];
    let Some(slot) = frame.get_mut(..N) else { return false };
    slot.copy_from_slice(&body);
    frame[N] = checksum::xor(&body);
    let sealed_ok = checksum::is_valid(&frame[..=N]);
    let (byte, mask) = (bit / 8, 1u8 << (bit % 8));
    if byte > N {
        return sealed_ok;
    }
    frame[byte] ^= mask;
    sealed_ok && !checksum::is_valid(&frame[..=N])
}

/// The settings byte decodes exactly when defined, and encodes back to itself. // 000:T28
pub fn settings_codec_round_trips(byte: u8) -> bool {
    match UartSettings::decode(byte) {
        Ok(s) => s.byte() == byte,
        Err(SettingsError::UndefinedBaud) => byte & 0x07 == 0x07,
        Err(SettingsError::ReservedBitSet) => byte & 0x08 != 0,
        Err(SettingsError::UndefinedParity) => byte & 0x30 == 0x10,
    }
}

/// The address byte codec round-trips; slave addresses are exactly 40h..=5Fh. // 000:T5
pub fn address_codec_round_trips(byte: u8) -> bool {
    let a = AddressByte::decode(byte);
    let is_slave = matches!(a, AddressByte::Slave(_));
    a.byte() == byte && is_slave == (0x40..=0x5F).contains(&byte)
}

#[cfg(kani)]
mod harnesses {
    use super::*;

    /// Bounds: a 3-byte body (address, command, one data byte), any bit of 4 bytes.
    #[kani::proof]
    fn checksum() {
        let body: [u8; 3] = kani::any();
        let bit: usize = kani::any();
        kani::assume(bit < 32);
        assert!(checksum_detects_single_bit_flips(body, bit));
    }

    /// Bounds: all 256 settings bytes.
    #[kani::proof]
    fn settings_codec() {
        assert!(settings_codec_round_trips(kani::any()));
    }

    /// Bounds: all 256 address bytes.
    #[kani::proof]
    fn address_codec() {
        assert!(address_codec_round_trips(kani::any()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksum_exhaustive_over_two_byte_bodies() {
        // Domain: every 2-byte body (65 536) x every bit of the 3-byte frame (24).
        for a in 0..=255u8 {
            for b in 0..=255u8 {
                for bit in 0..24 {
                    assert!(checksum_detects_single_bit_flips([a, b], bit), "{a:02X} {b:02X} bit {bit}");
                }
            }
        }
        eprintln!("checksum_detects_single_bit_flips: 1572864 cases, exhaustive over 2-byte bodies");
    }

    #[test]
    fn codecs_exhaustive() {
        for byte in 0..=255u8 {
            assert!(settings_codec_round_trips(byte), "{byte:02X}");
            assert!(address_codec_round_trips(byte), "{byte:02X}");
        }
        eprintln!("settings and address codecs: 256 cases each, exhaustive");
    }
}
