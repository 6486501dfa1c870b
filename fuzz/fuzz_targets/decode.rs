//! Request and response decoding: never panics; whatever decodes re-encodes to the
//! same bytes.
#![no_main]

use hiperface_model::{CommandId, RequestFrame, ResponseFrame};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(r) = RequestFrame::decode(data) {
        assert_eq!(r.encode().as_bytes(), data);
    }
    if let Some((to, bytes)) = data.split_first() {
        if let Ok(r) = ResponseFrame::decode(bytes, CommandId::decode(*to & 0x7F)) {
            assert_eq!(r.encode().as_bytes(), bytes);
        }
    }
});
