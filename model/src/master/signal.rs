//! A simulated encoder signal source: sin/cos ADC values from the raw shaft position,
//! with amplitude, offset and deterministic noise. The slave's absolute position is
//! raw + Set Position offset: a phase shift the signals do not follow.

use crate::slave::Slave;

/// Signal shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SignalSource {
    /// Peak amplitude in ADC counts (e.g. 2^15 - 1 for a 16-bit ADC, 511 for 10 bit).
    pub amplitude: i32,
    pub offset_sin: i32,
    pub offset_cos: i32,
    /// Peak noise in ADC counts (uniform, deterministic).
    pub noise: i32,
    seed: u64,
}

impl SignalSource {
    pub const fn new(amplitude: i32) -> SignalSource {
        SignalSource { amplitude, offset_sin: 0, offset_cos: 0, noise: 0, seed: 0x9E37_79B9_7F4A_7C15 }
    }

    pub const fn with_noise(mut self, noise: i32, offset_sin: i32, offset_cos: i32) -> SignalSource {
        self.noise = noise;
        self.offset_sin = offset_sin;
        self.offset_cos = offset_cos;
        self
    }

    fn next_noise(&mut self) -> i32 {
        if self.noise == 0 {
            return 0;
        }
        self.seed = self.seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.seed >> 33) as i64 % (2 * self.noise as i64 + 1)) as i32 - self.noise
    }

    /// sin/cos samples at `position_ticks`, where one period is `2^32` ticks of the
    /// fine position (32 absolute steps per period).
    pub fn sample(&mut self, period_fraction: u32) -> (i32, i32) {
        // The fraction as a signed one is the same angle in [-pi, pi): the Taylor
        // series below needs no range reduction there.
        let rad = period_fraction as i32 as f64 / 4294967296.0 * 2.0 * core::f64::consts::PI;
        let (s, c) = sin_cos(rad);
        let a = self.amplitude as f64;
        let sin = self.noisy(round(s * a) as i32 + self.offset_sin);
        let cos = self.noisy(round(c * a) as i32 + self.offset_cos);
        (sin, cos)
    }

    /// A clean value with the next draw of noise on it.
    fn noisy(&mut self, clean: i32) -> i32 {
        clean + self.next_noise()
    }
}

/// The slave's absolute position is raw + offset: its 5 LSBs follow the signals only
/// when `offset % 32 == 0` (000:T13 "phase shift").
pub fn phase_shift(slave: &Slave) -> u8 {
    (slave.nonvolatile().offset % 32) as u8
}

fn round(x: f64) -> f64 {
    if x >= 0.0 {
        (x + 0.5) as i64 as f64
    } else {
        -((-x + 0.5) as i64 as f64)
    }
}

/// sin and cos of `r` in [-pi, pi] by Taylor series (core only; 20 terms leave an
/// error below 10^-15 there).
fn sin_cos(r: f64) -> (f64, f64) {
    let (mut s, mut c) = (0.0, 0.0);
    let (mut ts, mut tc) = (r, 1.0);
    let r2 = r * r;
    for k in 0..20 {
        s += ts;
        c += tc;
        let k = k as f64;
        ts = -ts * r2 / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
        tc = -tc * r2 / ((2.0 * k + 1.0) * (2.0 * k + 2.0));
    }
    (s, c)
}
