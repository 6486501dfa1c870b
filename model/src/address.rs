//! The address byte. // 000:T5, 000:2.3.1

use core::fmt;

/// A valid slave address byte, 40h..=5Fh (bits 0-4 value, bit 6 = 1, bits 5 and 7 = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SlaveAddress(u8);

impl SlaveAddress {
    /// The default address 40h (address value 0).
    pub const DEFAULT: SlaveAddress = SlaveAddress(0x40);

    /// Decode a slave address byte; `None` outside 40h..=5Fh.
    pub const fn new(byte: u8) -> Option<SlaveAddress> {
        if byte & 0xE0 == 0x40 {
            Some(SlaveAddress(byte))
        } else {
            None
        }
    }

    /// The wire byte.
    pub const fn byte(self) -> u8 {
        self.0
    }

    /// The address value, 0..=31.
    pub const fn value(self) -> u8 {
        self.0 & 0x1F
    }
}

impl fmt::Display for SlaveAddress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:02X}h", self.0)
    }
}

/// What the first byte of a frame addresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AddressByte {
    Slave(SlaveAddress),
    /// FFh: every slave executes and answers with its own address. // 000:2.3.1
    Broadcast,
    Unknown(u8),
}

impl AddressByte {
    pub const BROADCAST_BYTE: u8 = 0xFF;

    pub const fn decode(byte: u8) -> AddressByte {
        if byte == Self::BROADCAST_BYTE {
            AddressByte::Broadcast
        } else {
            match SlaveAddress::new(byte) {
                Some(a) => AddressByte::Slave(a),
                None => AddressByte::Unknown(byte),
            }
        }
    }

    pub const fn byte(self) -> u8 {
        match self {
            AddressByte::Slave(a) => a.byte(),
            AddressByte::Broadcast => Self::BROADCAST_BYTE,
            AddressByte::Unknown(b) => b,
        }
    }

    /// True when a slave at `own` must act on a frame with this address byte.
    pub fn addresses(self, own: SlaveAddress) -> bool {
        match self {
            AddressByte::Slave(a) => a == own,
            AddressByte::Broadcast => true,
            AddressByte::Unknown(_) => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_byte_round_trips() {
        let mut slaves = 0;
        for b in 0..=255u8 {
            let a = AddressByte::decode(b);
            assert_eq!(a.byte(), b);
            if let AddressByte::Slave(s) = a {
                slaves += 1;
                assert!((0x40..=0x5F).contains(&s.byte()));
            }
        }
        assert_eq!(slaves, 32, "000:2.3.1: 32 address values");
        assert_eq!(AddressByte::decode(0xFF), AddressByte::Broadcast);
        assert_eq!(AddressByte::decode(0x60), AddressByte::Unknown(0x60));
    }
}
