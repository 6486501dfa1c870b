//! The kernel's `PARMRK` marking of what a UART saw, undone: the live tap on a serial
//! port and the harness's encoder on one (000:T47: a character with a parity error is
//! a UART fault the encoder answers with 09h) read their bytes through it.

use super::Mark;

/// Undo the kernel's `PARMRK` marking: `FF FF` is FFh, `FF 00 00` a break, `FF 00 c`
/// a character with a parity or framing error (the kernel does not say which; it is
/// reported as a parity error).
#[derive(Debug, Default, Clone, Copy)]
pub struct Marks {
    state: MarkState,
}

#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
enum MarkState {
    #[default]
    Data,
    Ff,
    Ff00,
}

impl Marks {
    /// Take one byte as delivered; a mark when one is complete.
    pub fn push(&mut self, b: u8, out: &mut impl FnMut(Mark)) {
        self.state = match (self.state, b) {
            (MarkState::Data, 0xFF) => MarkState::Ff,
            (MarkState::Data, b) => {
                out(Mark::Byte(b));
                MarkState::Data
            }
            (MarkState::Ff, 0xFF) => {
                out(Mark::Byte(0xFF));
                MarkState::Data
            }
            (MarkState::Ff, 0x00) => MarkState::Ff00,
            // Not a marking the kernel makes: the FFh was data after all.
            (MarkState::Ff, b) => {
                out(Mark::Byte(0xFF));
                out(Mark::Byte(b));
                MarkState::Data
            }
            (MarkState::Ff00, 0x00) => {
                out(Mark::Break);
                MarkState::Data
            }
            (MarkState::Ff00, c) => {
                out(Mark::ParityError(c));
                MarkState::Data
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unmark(bytes: &[u8]) -> Vec<Mark> {
        let mut m = Marks::default();
        let mut out = Vec::new();
        for &b in bytes {
            m.push(b, &mut |x| out.push(x));
        }
        out
    }

    #[test]
    fn the_kernels_marks_become_errors_and_breaks() {
        assert_eq!(
            unmark(&[0x40, 0xFF, 0xFF, 0xFF, 0x00, 0x42, 0xFF, 0x00, 0x00, 0x02]),
            vec![Mark::Byte(0x40), Mark::Byte(0xFF), Mark::ParityError(0x42), Mark::Break, Mark::Byte(0x02)]
        );
    }

    proptest! {
        /// Marking as the kernel does (FFh doubled) and unmarking gives the data back.
        #[test]
        fn data_survives_marking(data in proptest::collection::vec(any::<u8>(), 0..64)) {
            let marked: Vec<u8> = data.iter().flat_map(|&b| if b == 0xFF { vec![0xFF, 0xFF] } else { vec![b] }).collect();
            prop_assert_eq!(unmark(&marked), data.into_iter().map(Mark::Byte).collect::<Vec<_>>());
        }

        /// Any input: nothing is lost beyond the marking itself (at most one mark per byte).
        #[test]
        fn any_input_unmarks_without_panic(data in proptest::collection::vec(any::<u8>(), 0..64)) {
            prop_assert!(unmark(&data).len() <= data.len());
        }
    }
}
