//! The decode bench's path once, for counting instructions: a wire log read, framed,
//! told apart and graded by `listen_to`, nothing printed but the count. `--write N
//! FILE` writes the bench's log of N exchanges (Read Type Label, Read Encoder Status,
//! Read Position, one every 40 ms) first. The figures in
//! docs/src/watching-a-live-bus.md come from
//!
//!     cargo build --release -p hiperface-conformance --example decode_count
//!     target/release/examples/decode_count --write 20000 /tmp/w20k.log
//!     valgrind --tool=callgrind target/release/examples/decode_count /tmp/w20k.log
//!
//! (instructions are repeatable whatever else the machine does; time is the bench's).

use hiperface_conformance::capture::{Format, ReadOptions};
use hiperface_conformance::listen::{listen_to, Options};
use hiperface_model::{profiles, UartSettings};

const CYCLE: [(&str, &str); 3] =
    [("40 52 12", "40 52 E4 22 80 00 54"), ("40 50 10", "40 50 00 10"), ("40 42 02", "40 42 00 00 00 00 02")];

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = || {
        eprintln!("usage: decode_count WIRELOG | decode_count --write EXCHANGES FILE");
        std::process::ExitCode::from(2)
    };
    let path = match args.as_slice() {
        [write, n, file] if write == "--write" => {
            let Ok(exchanges) = n.parse::<usize>() else { return usage() };
            let mut text = String::with_capacity(exchanges * 70);
            for i in 0..exchanges {
                let (req, reply) = CYCLE[i % CYCLE.len()];
                let t = 10.0 + 40.0 * i as f64;
                text += &format!("{t:12.3} ms  M> {req}\n{:12.3} ms  S< {reply}\n", t + 7.73);
            }
            if let Err(e) = std::fs::write(file, text) {
                eprintln!("{file}: {e}");
                return std::process::ExitCode::FAILURE;
            }
            return std::process::ExitCode::SUCCESS;
        }
        [path] => path,
        _ => return usage(),
    };
    let text = match std::fs::read(path) {
        Ok(text) => text,
        Err(e) => {
            eprintln!("{path}: {e}");
            return std::process::ExitCode::FAILURE;
        }
    };
    let options = Options {
        profile: profiles::srs50(),
        settings: UartSettings::DEFAULT,
        tolerance_us: 100,
        master_channel: None,
        polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
    };
    let read = ReadOptions { baud: 9600, samplerate_hz: None };
    match listen_to(&text, Some(Format::Wirelog), read, options) {
        // Every exchange of the clean log passes, or the count means nothing.
        Ok(s) if s.exchanges > 0 && s.count(hiperface_conformance::verdict::CaseVerdict::Pass) == s.exchanges => {
            println!("{} exchanges, every one PASS", s.exchanges);
            std::process::ExitCode::SUCCESS
        }
        Ok(s) => {
            eprintln!("{} exchanges heard, not every one PASS", s.exchanges);
            std::process::ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("{e}");
            std::process::ExitCode::FAILURE
        }
    }
}
