//! `hiperface decode` throughput: a generated wire log of the reference encoder (Read
//! Type Label, Read Encoder Status, Read Position, an exchange every 40 ms) read,
//! framed, told apart and graded by the listener, without printing. Target (issue
//! 13): >= 1 M frames/s (a request and its reply are two frames); issue 55 asks 3 M on
//! one core (`taskset -c 1`: 1.65–2.16 M measured 2026-11-28, the figures and the
//! profile in docs/src/watching-a-live-bus.md). Memory does not grow with the capture.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use hiperface_conformance::capture::{Format, ReadOptions};
use hiperface_conformance::listen::{listen_to, Options};
use hiperface_model::{profiles, UartSettings};

const CYCLE: [(&str, &str); 3] =
    [("40 52 12", "40 52 E4 22 80 00 54"), ("40 50 10", "40 50 00 10"), ("40 42 02", "40 42 00 00 00 00 02")];

fn wirelog(exchanges: usize) -> String {
    let mut s = String::with_capacity(exchanges * 70);
    for i in 0..exchanges {
        let (req, reply) = CYCLE[i % CYCLE.len()];
        let t = 10.0 + 40.0 * i as f64;
        s += &format!("{t:12.3} ms  M> {req}\n{:12.3} ms  S< {reply}\n", t + 7.73);
    }
    s
}

fn decode(c: &mut Criterion) {
    const EXCHANGES: usize = 100_000;
    let text = wirelog(EXCHANGES);
    let options = Options {
        profile: profiles::srs50(),
        settings: UartSettings::DEFAULT,
        tolerance_us: 100,
        master_channel: None,
        polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
    };
    let read = ReadOptions { baud: 9600, samplerate_hz: None };
    // The session is clean: every exchange must pass, or the figure means nothing.
    let summary = listen_to(text.as_bytes(), Some(Format::Wirelog), read, options.clone()).unwrap();
    assert_eq!(summary.exchanges, EXCHANGES as u64);
    assert_eq!(summary.count(hiperface_conformance::verdict::CaseVerdict::Pass), EXCHANGES as u64);
    let mut g = c.benchmark_group("decode");
    g.sample_size(10);
    g.throughput(Throughput::Elements(2 * EXCHANGES as u64));
    g.bench_function("wirelog_frames", |b| {
        b.iter(|| listen_to(text.as_bytes(), Some(Format::Wirelog), read, options.clone()).map(|s| s.exchanges))
    });
    g.finish();
}

criterion_group!(benches, decode);
criterion_main!(benches);
