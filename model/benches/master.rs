//! Master-side throughput: fine-angle interpolations per second (fixed point, 32
//! nodes; target >= 100 M/s on one core) and quadrature steps per second (target
//! >= 500 M/s).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use hiperface_model::master::interpolation::Interpolator;
use hiperface_model::master::quadrature::{Ab, Counter};

fn interpolation(c: &mut Criterion) {
    let ip = Interpolator::new(32).unwrap();
    // 4096 samples around the circle, 16-bit amplitude.
    let samples: Vec<(i32, i32)> = (0..4096)
        .map(|k| {
            let phi = k as f64 / 4096.0 * std::f64::consts::TAU;
            ((phi.sin() * 32000.0) as i32, (phi.cos() * 32000.0) as i32)
        })
        .collect();
    let mut g = c.benchmark_group("interpolation");
    g.throughput(Throughput::Elements(samples.len() as u64));
    g.bench_function("fixed_point_32_nodes", |b| {
        b.iter(|| {
            let mut acc = 0u32;
            for &(s, c) in black_box(&samples) {
                acc = acc.wrapping_add(ip.angle(s, c).unwrap_or(0));
            }
            acc
        })
    });
    g.finish();
}

fn quadrature(c: &mut Criterion) {
    // A forward-and-back pattern of A/B levels.
    let cycle = [(false, false), (false, true), (true, true), (true, false)];
    let samples: Vec<Ab> = (0..4096)
        .map(|i| {
            let k = if (i / 64) % 2 == 0 { i % 4 } else { 3 - i % 4 };
            Ab { a: cycle[k].0, b: cycle[k].1 }
        })
        .collect();
    let mut g = c.benchmark_group("quadrature");
    g.throughput(Throughput::Elements(samples.len() as u64));
    g.bench_function("steps", |b| {
        b.iter(|| {
            let mut counter = Counter::new(0, Ab::default());
            for &s in black_box(&samples) {
                counter.sample(s);
            }
            counter.value
        })
    });
    g.finish();
}

criterion_group!(benches, interpolation, quadrature);
criterion_main!(benches);
