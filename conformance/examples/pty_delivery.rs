//! How late a pseudo-terminal delivers on this machine now: the delivery probe of
//! `line::delivery` run for a while, its statistics printed. For measuring a machine's
//! load (e.g. beside `scripts/verdicts-under-load.sh`), not a test.
//!
//!     cargo run --release -p hiperface-conformance --example pty_delivery -- 10 [--rt]

use hiperface_conformance::line::delivery::DeliveryProbe;
use std::time::{Duration, Instant};

fn main() {
    let seconds: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    // `--rt`: the reader at a real-time priority too, as `certify master` runs it (then
    // only the kernel's own delivery is measured, not the reader's wait for a processor).
    let reader_real_time = std::env::args().any(|a| a == "--rt");
    let epoch = Instant::now();
    let probe = match DeliveryProbe::start_with(epoch, reader_real_time) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut worst = Vec::new();
    for s in 0..seconds {
        std::thread::sleep(Duration::from_secs(1));
        let from = s * 1_000_000;
        worst.push(probe.max_delay_us(from, from + 1_000_000).unwrap_or(0));
    }
    let stats = probe.stats();
    println!(
        "writer at a real-time priority: {}; {} writes, {} delivered more than 1 ms late, the latest {:.3} ms",
        probe.writer_real_time,
        stats.samples,
        stats.over_1ms,
        stats.max_us as f64 / 1000.0
    );
    let per_second: Vec<String> = worst.iter().map(|us| format!("{:.1}", *us as f64 / 1000.0)).collect();
    println!("latest delivery in each second, ms: {}", per_second.join(" "));
}
