//! Request decoding (`hiperface_proofs::targets::request`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| hiperface_proofs::targets::request(data));
