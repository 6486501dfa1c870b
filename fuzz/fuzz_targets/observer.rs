//! The observer of a master's obligations on any stream of characters, replies,
//! power-ons and idle time (`hiperface_proofs::targets::observer`).
#![no_main]
use hiperface_proofs::targets::{observer, MasterEvent};
libfuzzer_sys::fuzz_target!(|events: Vec<MasterEvent>| observer(&events));
