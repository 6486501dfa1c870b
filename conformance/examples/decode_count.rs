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

use hiperface_suite::capture::Format;
use hiperface_suite::listen::listen_to;

#[path = "../benches/support/decode_log.rs"]
mod decode_log;

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = || {
        eprintln!("usage: decode_count WIRELOG | decode_count --write EXCHANGES FILE");
        std::process::ExitCode::from(2)
    };
    let path = match args.as_slice() {
        [write, n, file] if write == "--write" => {
            let Ok(exchanges) = n.parse::<usize>() else { return usage() };
            let text = decode_log::wirelog(exchanges);
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
    let (read, options) = decode_log::heard_as();
    match listen_to(&text, Some(Format::Wirelog), read, options) {
        // Every exchange of the clean log passes, or the count means nothing.
        Ok(s) if s.exchanges > 0 && s.count(hiperface_suite::verdict::CaseVerdict::Pass) == s.exchanges => {
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
