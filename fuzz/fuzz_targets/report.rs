//! Any bytes as a report `decode` reads: the report and record reader, the record's
//! playback and the comparison with what the report states must not panic, hang or
//! grow without bound (see `hiperface_conformance::report::recorded::fuzz_report`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    hiperface_conformance::report::recorded::fuzz_report(data);
});
