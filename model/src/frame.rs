//! A fixed-capacity frame buffer (no allocation). // 000:2.3 frame composition

use crate::checksum;
use core::fmt;

/// Longest frame: Store Data request, 1 address + 1 command + 132 data + 1 checksum.
pub const MAX_FRAME: usize = 135;

/// Up to 128 data bytes (Read Data reply, Store Data request). // 000:T21, 000:T22
pub const MAX_FIELD_BYTES: usize = 128;

/// Up to `N` bytes held inline (no allocation).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Bytes<const N: usize> {
    buf: [u8; N],
    len: u8,
}

/// A frame: address, command, data and checksum.
pub type Frame = Bytes<MAX_FRAME>;

/// 1..=128 data bytes of a data field access.
pub type FieldBytes = Bytes<MAX_FIELD_BYTES>;

/// More bytes than the buffer holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameFull;

impl<const N: usize> Bytes<N> {
    pub const fn new() -> Bytes<N> {
        Bytes { buf: [0; N], len: 0 }
    }

    /// Copy bytes in; `Err` when there are more than `N`.
    pub fn from_bytes(bytes: &[u8]) -> Result<Bytes<N>, FrameFull> {
        let mut f = Bytes::new();
        f.extend(bytes)?;
        Ok(f)
    }

    pub fn push(&mut self, byte: u8) -> Result<(), FrameFull> {
        let slot = self.buf.get_mut(self.len as usize).ok_or(FrameFull)?;
        *slot = byte;
        self.len += 1;
        Ok(())
    }

    pub fn extend(&mut self, bytes: &[u8]) -> Result<(), FrameFull> {
        let start = self.len as usize;
        let end = start + bytes.len();
        self.buf.get_mut(start..end).ok_or(FrameFull)?.copy_from_slice(bytes);
        self.len = end as u8;
        Ok(())
    }

    pub fn as_bytes(&self) -> &[u8] {
        &self.buf[..self.len as usize]
    }

    pub fn len(&self) -> usize {
        self.len as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl Frame {
    /// Append the XOR checksum of the bytes so far. // 000:2.3.3
    pub fn seal(&mut self) -> Result<(), FrameFull> {
        self.push(checksum::xor(self.as_bytes()))
    }
}

impl<const N: usize> Default for Bytes<N> {
    fn default() -> Self {
        Bytes::new()
    }
}

impl<const N: usize> AsRef<[u8]> for Bytes<N> {
    fn as_ref(&self) -> &[u8] {
        self.as_bytes()
    }
}

impl<const N: usize> fmt::Debug for Bytes<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}]", Hex(self.as_bytes()))
    }
}

/// Bytes shown as `40 42 02`.
pub struct Hex<'a>(pub &'a [u8]);

impl fmt::Display for Hex<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, b) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(" ")?;
            }
            write!(f, "{b:02X}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capacity_is_enforced_without_panicking() {
        let mut f = Frame::new();
        for i in 0..MAX_FRAME {
            f.push(i as u8).unwrap();
        }
        assert_eq!(f.push(0), Err(FrameFull));
        assert_eq!(f.extend(&[1]), Err(FrameFull));
        assert!(Frame::from_bytes(&[0; MAX_FRAME + 1]).is_err());
        let mut g = Frame::from_bytes(&[0x40, 0x42]).unwrap();
        g.seal().unwrap();
        assert_eq!(g.as_bytes(), &[0x40, 0x42, 0x02]);
        assert!(FieldBytes::from_bytes(&[0; 129]).is_err());
        assert_eq!(FieldBytes::from_bytes(&[1, 2]).unwrap().as_bytes(), &[1, 2]);
    }
}
