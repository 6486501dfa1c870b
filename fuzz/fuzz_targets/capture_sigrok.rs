//! Any bytes as a sigrok capture: its reader and the passive listener must not panic,
//! hang or grow without bound (see `hiperface_suite::listen::fuzz_capture`).
#![no_main]

use hiperface_suite::capture::Format;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    hiperface_suite::listen::fuzz_capture(Format::Sigrok, data);
});
