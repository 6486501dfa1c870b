//! The simulated sin/cos source the master-side interpolation is tested with: its
//! values at known angles, its offsets, its noise, and the phase shift a Set Position
//! leaves between the signals and the absolute position (000:T13).

mod common;
use common::*;
use hiperface_model::master::signal::{phase_shift, SignalSource};
use hiperface_model::profiles;

const QUARTER: u32 = 1 << 30;

#[test]
fn a_clean_source_is_sin_and_cos_of_the_period_fraction() {
    let mut s = SignalSource::new(1000);
    assert_eq!(s.sample(0), (0, 1000));
    assert_eq!(s.sample(QUARTER), (1000, 0));
    assert_eq!(s.sample(2 * QUARTER), (0, -1000));
    assert_eq!(s.sample(3 * QUARTER), (-1000, 0));
    // 45°: 1000 / sqrt 2 = 707.1 -> 707; 135°: cos -707; 225°: both -707.
    assert_eq!(s.sample(QUARTER / 2), (707, 707));
    assert_eq!(s.sample(QUARTER + QUARTER / 2), (707, -707));
    assert_eq!(s.sample(2 * QUARTER + QUARTER / 2), (-707, -707));
    // 30°: sin 0.5 -> 500 (rounded half up: 499.99... or 500.0...), cos 866.
    let thirty = (u64::from(u32::MAX) + 1) / 12;
    assert_eq!(s.sample(thirty as u32), (500, 866));
    // Rounding to nearest, away from zero on both sides: 20 000 * sin(1/8 turn) = 14142.1.
    let mut big = SignalSource::new(20_000);
    assert_eq!(big.sample(QUARTER / 2), (14142, 14142));
    assert_eq!(big.sample(5 * (QUARTER / 2)), (-14142, -14142));
    // sin² + cos² = A² within rounding, all around the period.
    let mut a = SignalSource::new(32767);
    for k in 0..64u32 {
        let (x, y) = a.sample(k.wrapping_mul(1 << 26));
        let r2 = i64::from(x).pow(2) + i64::from(y).pow(2);
        assert!((r2 - 32767i64.pow(2)).abs() < 2 * 32767, "{k}: {x}, {y}");
    }
}

#[test]
fn offsets_are_added_and_noise_stays_within_its_bound() {
    let mut s = SignalSource::new(1000).with_noise(0, 12, -7);
    assert_eq!(s.sample(0), (12, 993));
    let mut n = SignalSource::new(1000).with_noise(5, 0, 0);
    let mut m = SignalSource::new(1000).with_noise(5, 0, 0);
    let samples: Vec<(i32, i32)> = (0..200).map(|_| n.sample(0)).collect();
    assert!(samples.iter().all(|(x, y)| x.abs() <= 5 && (y - 1000).abs() <= 5), "{samples:?}");
    let distinct: std::collections::BTreeSet<i32> = samples.iter().flat_map(|(x, y)| [*x, *y - 1000]).collect();
    assert_eq!(distinct.len(), 11, "every value in -5..=5 occurs: {distinct:?}");
    assert_eq!(samples, (0..200).map(|_| m.sample(0)).collect::<Vec<_>>(), "deterministic");
    assert!(samples.windows(2).any(|w| w[0].0 != w[1].0 && w[0].1 != w[1].1), "sin and cos noise differ");
}

#[test]
fn the_phase_shift_is_the_offset_modulo_one_period() {
    let mut s = operational(profiles::srs50());
    assert_eq!(phase_shift(&s), 0);
    // Raw 0, Set Position to 37: offset 37, 5 steps into a period of 32.
    ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 37, 0x55]).unwrap();
    assert_eq!(phase_shift(&s), 5);
    ask_sealed(&mut s, &[0x40, 0x43, 0, 0, 0, 64, 0x55]).unwrap();
    assert_eq!(phase_shift(&s), 0);
}
