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
//! `--here WIRELOG` reads the log on the listener's thread instead of a thread of its
//! own, for comparing the two under `perf stat -e task-clock,context-switches`.

use hiperface_suite::capture::Format;
use hiperface_suite::listen::listen_to;

#[path = "../benches/support/decode_log.rs"]
mod decode_log;

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = || {
        eprintln!("usage: decode_count [--here] WIRELOG | decode_count --write EXCHANGES FILE");
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
        [path] => (path, false),
        [here, path] if here == "--here" => (path, true),
        _ => return usage(),
    };
    let (path, here) = path;
    let text = match std::fs::read(path) {
        Ok(text) => text,
        Err(e) => {
            eprintln!("{path}: {e}");
            return std::process::ExitCode::FAILURE;
        }
    };
    let (read, options) = decode_log::heard_as();
    let summary =
        if here { listen_here(&text, read, options) } else { listen_to(&text, Some(Format::Wirelog), read, options) };
    match summary {
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

/// What `listen_to` does, the capture read on this thread.
fn listen_here(
    text: &[u8],
    read: hiperface_suite::capture::ReadOptions,
    options: hiperface_suite::listen::Options,
) -> Result<hiperface_suite::listen::Summary, hiperface_suite::capture::ParseError> {
    let (_, mut capture) = hiperface_suite::capture::open(Box::new(text), Some(Format::Wirelog), read)?;
    let mut listener = hiperface_suite::listen::Listener::new(options);
    let mut last_us = 0;
    while let Some(run) = capture.next_run() {
        let run = run?;
        last_us = run.last_us();
        listener.feed_run(&run, &mut |_| {});
    }
    listener.finish(last_us, &mut |_| {});
    Ok(listener.summary)
}
