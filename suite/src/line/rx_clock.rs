//! A receiver's stamps on a line without a UART clock (a pseudo-terminal, TCP): when
//! each character would have ended on a UART.

use hiperface_model::datalink::RxChar;

/// Receive stamps. A UART stamps a character when it arrives. A pseudo-terminal or
/// TCP has no baud rate: a UART would deliver the bytes at least one character time
/// apart, so `max(arrival, previous + char time)`; a backlog of more than one frame
/// is more than any UART could have received, and such a character is an overrun at
/// its arrival.
#[derive(Debug, Clone, Copy, Default)]
pub struct RxClock {
    last_us: u64,
}

impl RxClock {
    /// When the last character stamped ended, µs (0 before the first).
    pub fn last_us(&self) -> u64 {
        self.last_us
    }

    /// Stamp a byte. `clocked_char_time_us`: `Some` on lines without a baud rate.
    pub fn stamp(&mut self, byte: u8, arrival_us: u64, clocked_char_time_us: Option<u64>) -> RxChar {
        let (at_us, overrun) = match clocked_char_time_us {
            Some(ct) => {
                let clocked = arrival_us.max(self.last_us + ct);
                if clocked - arrival_us > hiperface_model::frame::MAX_FRAME as u64 * ct {
                    (arrival_us, true)
                } else {
                    (clocked, false)
                }
            }
            None => (arrival_us, false),
        };
        self.last_us = at_us;
        RxChar { byte, at_us, fault: overrun.then_some(hiperface_model::UartFault::Overrun) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clocking_peer_stamps_a_burst_a_character_apart() {
        // A write read at once: a peer playing the UART stamps one character time apart.
        let mut clock = RxClock::default();
        let stamps: Vec<u64> = (0..4).map(|i| clock.stamp(i, 1_000, Some(500)).at_us).collect();
        assert_eq!(stamps, vec![1_000, 1_500, 2_000, 2_500]);
    }
}
