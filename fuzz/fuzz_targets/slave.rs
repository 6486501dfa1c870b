//! The slave driven by timed characters, frames and physical inputs, with the
//! invariants checked after every step (`hiperface_proofs::targets::slave`).
#![no_main]
use hiperface_proofs::targets::{slave, SlaveInput};
libfuzzer_sys::fuzz_target!(|input: SlaveInput| slave(&input));
