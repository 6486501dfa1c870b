//! Requests per second through the model: decode the request, step the slave, encode
//! the reply. Targets (one core): >= 10 M Read Position round trips/s, >= 2 M mixed
//! data-field requests/s.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use hiperface_model::{checksum, profiles, Reply, Slave};

fn sealed(body: &[u8]) -> Vec<u8> {
    let mut v = body.to_vec();
    v.push(checksum::xor(body));
    v
}

fn round_trip(slave: &mut Slave, request: &[u8]) -> usize {
    match slave.handle_frame(request, 0).reply {
        Reply::Frame(f) => f.encode().len(),
        Reply::Silent(_) => 0,
    }
}

fn read_position(c: &mut Criterion) {
    let mut slave = Slave::operational(profiles::srm50());
    let request = sealed(&[0x40, 0x42]);
    let mut g = c.benchmark_group("read_position");
    g.throughput(Throughput::Elements(1));
    g.bench_function("round_trip", |b| b.iter(|| round_trip(&mut slave, black_box(&request))));
    g.finish();
}

fn data_field_mix(c: &mut Criterion) {
    let mut slave = Slave::operational(profiles::srm50());
    round_trip(&mut slave, &sealed(&[0x40, 0x4D, 0, 0xCF, 0x55])); // 128 bytes, Code0
    round_trip(&mut slave, &sealed(&[0x40, 0x4D, 1, 0xC1, 0x55]));
    let mut store = vec![0x40, 0x4B, 1, 0, 16, 0x55];
    store.extend(0..16u8);
    let mix = [
        sealed(&[0x40, 0x4A, 0, 0, 16, 0x55]),
        sealed(&store),
        sealed(&[0x40, 0x4C, 1]),
        sealed(&[0x40, 0x4E]),
        sealed(&[0x40, 0x4A, 1, 8, 8, 0x55]),
        sealed(&[0x40, 0x4D, 1, 0xC1, 0x55]),
        sealed(&[0x40, 0x4A, 0, 100, 28, 0x55]),
        sealed(&[0x40, 0x4A, 5, 0, 1, 0x55]), // 12h
    ];
    let mut g = c.benchmark_group("data_field_mix");
    g.throughput(Throughput::Elements(mix.len() as u64));
    g.bench_function("eight_requests", |b| {
        b.iter(|| mix.iter().map(|r| round_trip(&mut slave, black_box(r))).sum::<usize>())
    });
    g.finish();
}

criterion_group!(benches, read_position, data_field_mix);
criterion_main!(benches);
