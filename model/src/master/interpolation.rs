//! Fine-angle interpolation: octant, transformation, T = X/Y, a table-based arctan,
//! retransformation. // 000:3.2.4
//!
//! Angles are fractions of one sin/cos period: `2^32` is 360°, an octant is `2^29`.

/// One octant (45°) in angle units.
pub const OCTANT: u32 = 1 << 29;

/// arctan(k/64) for k = 0..=64, in angle units (`2^29` = 45°), rounded.
pub const ATAN_64: [u32; 65] = [
    0, 10679838, 21354465, 32018685, 42667331, 53295284, 63897482, 74468939, 85004756, 95500135, 105950391, 116350962,
    126697423, 136985493, 147211045, 157370116, 167458907, 177473799, 187411349, 197268300, 207041579, 216728303,
    226325781, 235831508, 245243172, 254558647, 263775993, 272893455, 281909457, 290822599, 299631651, 308335554,
    316933406, 325424463, 333808132, 342083962, 350251643, 358310992, 366261957, 374104599, 381839095, 389465727,
    396984877, 404397019, 411702716, 418902610, 425997422, 432987938, 439875013, 446659557, 453342536, 459924966,
    466407904, 472792449, 479079736, 485270931, 491367227, 497369841, 503280012, 509098996, 514828063, 520468494,
    526021581, 531488619, 536870912,
];

/// Step 1: the octant, from the signs and magnitudes. // 000:3.2.4 step 1
#[inline]
pub const fn octant(sin: i32, cos: i32) -> u8 {
    octant_of(sin >= 0, cos >= 0, sin.unsigned_abs() < cos.unsigned_abs())
}

/// The octant table: `Vsin >= 0`, `Vcos >= 0`, `|Vsin| < |Vcos|`.
#[inline]
pub const fn octant_of(sin_non_negative: bool, cos_non_negative: bool, sin_smaller: bool) -> u8 {
    match (sin_non_negative, cos_non_negative, sin_smaller) {
        (true, true, true) => 0,
        (true, true, false) => 1,
        (true, false, false) => 2,
        (true, false, true) => 3,
        (false, false, true) => 4,
        (false, false, false) => 5,
        (false, true, false) => 6,
        (false, true, true) => 7,
    }
}

/// Step 2: X and Y of the octant, both >= 0 with X <= Y. // 000:3.2.4 step 2
#[inline]
pub fn transform(octant: u8, sin: i32, cos: i32) -> (i64, i64) {
    transform_with(octant, sin as i64, cos as i64)
}

/// The transformation table, for any signed number type.
#[inline]
pub fn transform_with<T: Copy + core::ops::Neg<Output = T>>(octant: u8, s: T, c: T) -> (T, T) {
    match octant & 7 {
        0 => (s, c),
        1 => (c, s),
        2 => (-c, s),
        3 => (s, -c),
        4 => (-s, -c),
        5 => (-c, -s),
        6 => (c, -s),
        _ => (-s, c),
    }
}

/// Step 5: the angle from the octant and A = arctan(T). // 000:3.2.4 step 5
#[inline]
pub const fn retransform(octant: u8, a: u32) -> u32 {
    let base = (octant as u32 & 7).wrapping_mul(OCTANT);
    if octant & 1 == 0 {
        base.wrapping_add(a)
    } else {
        // 90° - A, 180° - A, 270° - A, 360° - A: the next octant boundary minus A.
        base.wrapping_add(OCTANT).wrapping_sub(a)
    }
}

impl Default for Interpolator {
    /// 32 nodes: "typically 32 nodes are sufficient". // 000:3.2.4 step 4
    fn default() -> Self {
        Interpolator { stride: 2, nodes: 32 }
    }
}

/// Table-based arctan with a configurable number of nodes (a divisor of 64).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Interpolator {
    /// Table stride in the 64-node table: 64 / nodes.
    stride: usize,
    nodes: u32,
}

impl Interpolator {
    /// `nodes` must divide 64 (1, 2, 4, 8, 16, 32, 64); 32 is the spec's "typically sufficient".
    pub const fn new(nodes: u32) -> Option<Interpolator> {
        if nodes == 0 || nodes > 64 || 64 % nodes != 0 {
            return None;
        }
        Some(Interpolator { stride: (64 / nodes) as usize, nodes })
    }

    pub const fn nodes(&self) -> u32 {
        self.nodes
    }

    /// Step 4: A = arctan(T) for T = x / y in [0, 1], by linear interpolation between nodes.
    #[inline]
    pub fn atan(&self, x: u64, y: u64) -> u32 {
        if y == 0 {
            return 0;
        }
        // Step 3: T = X / Y in Q32 (0..=2^32), then the segment and the fraction in it.
        let t = ((x << 32) / y).min(1 << 32);
        let scaled = t * self.nodes as u64; // node index in the high 32 bits
        let i = (scaled >> 32) as usize;
        let frac = scaled & 0xFFFF_FFFF;
        let lo = ATAN_64.get(i * self.stride).copied().unwrap_or(OCTANT) as u64;
        let hi = ATAN_64.get((i + 1) * self.stride).copied().unwrap_or(OCTANT) as u64;
        (lo + (((hi - lo) * frac) >> 32)) as u32
    }

    /// The angle of an ADC sample pair (any signed integer scale, e.g. 10 to 16 bit);
    /// `None` when both are 0 (no signal).
    #[inline]
    pub fn angle(&self, sin: i32, cos: i32) -> Option<u32> {
        if sin == 0 && cos == 0 {
            return None;
        }
        let o = octant(sin, cos);
        let (x, y) = transform(o, sin, cos);
        Some(retransform(o, self.atan(x as u64, y as u64)))
    }
}

/// The same algorithm with an exact arctan in f64, as a reference: angle in degrees
/// [0, 360). Uses only core arithmetic (no libm).
pub fn reference_degrees(sin: f64, cos: f64) -> Option<f64> {
    if sin == 0.0 && cos == 0.0 {
        return None;
    }
    let o = octant_of(sin >= 0.0, cos >= 0.0, abs(sin) < abs(cos));
    let (x, y) = transform_with(o, sin, cos);
    let a = atan_unit(x / y) * 180.0 / core::f64::consts::PI;
    let base = 45.0 * o as f64;
    Some(if o % 2 == 0 { base + a } else { base + 45.0 - a })
}

fn abs(x: f64) -> f64 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

/// arctan(t) for t in [0, 1], to about 1e-16: reduce to |u| <= tan(pi/8) and sum the series.
fn atan_unit(t: f64) -> f64 {
    let (offset, u) =
        if t > 0.414_213_562_373_095 { (core::f64::consts::FRAC_PI_4, (t - 1.0) / (t + 1.0)) } else { (0.0, t) };
    let u2 = u * u;
    let mut term = u;
    let mut sum = 0.0;
    let mut n = 1.0;
    while abs(term) > 1e-18 && n < 200.0 {
        sum += term / n;
        term = -term * u2;
        n += 2.0;
    }
    offset + sum
}
