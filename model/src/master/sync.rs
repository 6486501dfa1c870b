//! Position synchronisation of absolute position, quadrature counter and fine angle.
//! // 000:3.2.5
//!
//! Valences: the absolute position has 5 bits per period (a4..a0); the quadrature
//! counter counts quadrants (q4 q3 are its two low bits in that valence); the fine
//! angle resolves one period, its two top bits are the quadrant.

/// The period correction of the synchronisation table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Correction {
    Same,
    PlusOne,
    MinusOne,
    /// An invalid combination: a fault of the slave or of the master's synchronisation.
    Invalid,
}

use Correction::{Invalid as X, MinusOne as M, PlusOne as P, Same as S};

/// The 16-row table of 000:3.2.5, indexed `[f(i:i-1)][a(4:3)]`: what `q(n:5)` is
/// relative to `a(n:5)`.
pub const SYNC_TABLE: [[Correction; 4]; 4] = [
    [S, S, X, P], // f = 00, a = 00 01 10 11
    [S, S, S, X], // f = 01
    [X, S, S, S], // f = 10
    [M, X, S, S], // f = 11
];

#[inline]
pub const fn correction(fine_quadrant: u8, absolute_quadrant: u8) -> Correction {
    SYNC_TABLE[(fine_quadrant & 3) as usize][(absolute_quadrant & 3) as usize]
}

/// A fine angle over one period: `bits` significant bits (0..2^bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FineAngle {
    pub value: u32,
    pub bits: u8,
}

impl FineAngle {
    /// The two most significant bits: the quadrant (f_i, f_i-1).
    pub const fn quadrant(self) -> u8 {
        if self.bits < 2 {
            return 0;
        }
        ((self.value >> (self.bits - 2)) & 3) as u8
    }
}

/// Initialise the quadrature counter (4 counts per period) from the absolute position
/// (32 steps per period) and the fine angle's quadrant: `None` for an invalid
/// combination. The ±1 period is an arithmetic carry into all higher bits.
pub fn init_counter(absolute: u64, fine: FineAngle) -> Option<i64> {
    let period = (absolute >> 5) as i64;
    let period = match correction(fine.quadrant(), ((absolute >> 3) & 3) as u8) {
        Correction::Same => period,
        Correction::PlusOne => period + 1,
        Correction::MinusOne => period - 1,
        Correction::Invalid => return None,
    };
    Some(period * 4 + fine.quadrant() as i64)
}

/// Runtime synchronisation: the full-resolution position (periods, then the fine
/// angle's bits) from the counter (4 counts per period) and the fine angle. A period
/// change is kept in the result, not in the counter.
pub fn full_position(counter: i64, fine: FineAngle) -> Option<i64> {
    let period = counter.div_euclid(4);
    let quadrant = counter.rem_euclid(4) as u8;
    // The counter's quadrant plays the absolute position's a(4:3).
    let period = match correction(fine.quadrant(), quadrant) {
        Correction::Same => period,
        Correction::PlusOne => period + 1,
        Correction::MinusOne => period - 1,
        Correction::Invalid => return None,
    };
    Some((period << fine.bits) | fine.value as i64)
}
