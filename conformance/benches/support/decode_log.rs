//! The decode bench's capture and how it is heard, shared by the bench
//! (benches/decode.rs) and the program that counts its instructions
//! (examples/decode_count.rs), so that both measure the same work.

use hiperface_model::{profiles, UartSettings};
use hiperface_suite::capture::ReadOptions;
use hiperface_suite::listen::Options;

/// Read Type Label, Read Encoder Status, Read Position, over and over.
const CYCLE: [(&str, &str); 3] =
    [("40 52 12", "40 52 E4 22 80 00 54"), ("40 50 10", "40 50 00 10"), ("40 42 02", "40 42 00 00 00 00 02")];

/// A wire log of the reference encoder: `exchanges` of the cycle, one every 40 ms.
pub fn wirelog(exchanges: usize) -> String {
    let mut s = String::with_capacity(exchanges * 70);
    for i in 0..exchanges {
        let (req, reply) = CYCLE[i % CYCLE.len()];
        let t = 10.0 + 40.0 * i as f64;
        s += &format!("{t:12.3} ms  M> {req}\n{:12.3} ms  S< {reply}\n", t + 7.73);
    }
    s
}

/// How the log is read and heard: 9600 Bd, SRS50, 0.1 ms tolerance.
pub fn heard_as() -> (ReadOptions, Options) {
    let options = Options {
        profile: profiles::srs50(),
        settings: UartSettings::DEFAULT,
        tolerance_us: 100,
        master_channel: None,
        polling_period_ms: hiperface_model::master::obligations::POLLING_PERIOD_MS,
    };
    (ReadOptions { baud: 9600, samplerate_hz: None }, options)
}
