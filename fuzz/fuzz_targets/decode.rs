//! Request and response decoding (`hiperface_proofs::targets::decode`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| hiperface_proofs::targets::decode(data));
