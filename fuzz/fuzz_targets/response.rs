//! Response decoding; the first byte names the request's command
//! (`hiperface_proofs::targets::response`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| hiperface_proofs::targets::response(data));
