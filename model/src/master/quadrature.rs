//! Quadrature counting. // 000:T72

/// What one sample of the A/B comparator signals does to the counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Count {
    Up,
    Down,
    NoAction,
    /// An invalid transition: a fault in the slave, the input stage, or the sampling rate.
    Invalid,
}

use Count::{Down as M, Invalid as X, NoAction as N, Up as P};

/// 000 Table 72, indexed by `(A[n-1] B[n-1] A[n] B[n])` as a 4-bit number.
pub const TABLE_72: [Count; 16] = [
    N, P, M, X, // 00 -> 00 01 10 11
    M, N, X, P, // 01 -> 00 01 10 11
    P, X, N, M, // 10 -> 00 01 10 11
    X, M, P, N, // 11 -> 00 01 10 11
];

/// A/B signal levels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Ab {
    pub a: bool,
    pub b: bool,
}

impl Ab {
    pub const fn bits(self) -> usize {
        ((self.a as usize) << 1) | self.b as usize
    }
}

/// One counting step from the previous to the current sample.
#[inline]
pub const fn step(previous: Ab, current: Ab) -> Count {
    TABLE_72[(previous.bits() << 2) | current.bits()]
}

/// A software quadrature counter (4 counts per sin/cos period).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counter {
    pub value: i64,
    pub last: Ab,
    /// Invalid transitions seen.
    pub invalid: u32,
}

impl Counter {
    pub const fn new(value: i64, state: Ab) -> Counter {
        Counter { value, last: state, invalid: 0 }
    }

    #[inline]
    pub fn sample(&mut self, now: Ab) -> Count {
        let c = step(self.last, now);
        match c {
            Count::Up => self.value += 1,
            Count::Down => self.value -= 1,
            Count::NoAction => {}
            Count::Invalid => self.invalid = self.invalid.saturating_add(1),
        }
        self.last = now;
        c
    }
}
