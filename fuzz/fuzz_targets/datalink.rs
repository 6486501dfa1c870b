//! The data link on any timed character sequence (`hiperface_proofs::targets::datalink`).
#![no_main]
use hiperface_proofs::targets::{datalink, TimedChar};
libfuzzer_sys::fuzz_target!(|input: (u16, Vec<TimedChar>)| datalink(input.0, &input.1));
