//! A stable `cargo test` replays the fuzz corpus: seeds from the golden vectors, any
//! local corpus under fuzz/corpus, and the recorded regressions under fuzz/regressions.

use arbitrary::{Arbitrary, Unstructured};
use hiperface_conformance::capture::Format;
use hiperface_conformance::{listen, vectors};
use hiperface_proofs::targets::{self, MasterEvent, SlaveInput, TimedChar};
use std::path::Path;

fn run_all(bytes: &[u8]) {
    targets::decode(bytes);
    if let Ok((t, chars)) = <(u16, Vec<TimedChar>)>::arbitrary_take_rest(Unstructured::new(bytes)) {
        targets::datalink(t, &chars);
    }
    if let Ok(input) = SlaveInput::arbitrary_take_rest(Unstructured::new(bytes)) {
        targets::slave(&input);
    }
    if let Ok(events) = Vec::<MasterEvent>::arbitrary_take_rest(Unstructured::new(bytes)) {
        targets::observer(&events);
    }
}

#[test]
fn seeds_from_the_vectors_replay() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut n = 0;
    for path in vectors::files(&root.join("vectors")).unwrap() {
        for v in vectors::load(&path).unwrap().vectors {
            for s in &v.steps {
                run_all(&vectors::parse_hex(&s.request).unwrap());
                n += 1;
            }
        }
    }
    assert!(n > 300, "{n}");
}

#[test]
fn local_corpus_and_regressions_replay() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz");
    let mut n = 0;
    for dir in ["corpus", "regressions"] {
        for target in ["request", "response", "datalink", "slave", "observer"] {
            let Ok(entries) = std::fs::read_dir(root.join(dir).join(target)) else { continue };
            for e in entries.flatten() {
                if let Ok(bytes) = std::fs::read(e.path()) {
                    run_all(&bytes);
                    n += 1;
                }
            }
        }
        // The capture readers and the listener: every file through every format.
        for target in ["capture_wirelog", "capture_csv", "capture_sigrok"] {
            let Ok(entries) = std::fs::read_dir(root.join(dir).join(target)) else { continue };
            for e in entries.flatten() {
                if let Ok(bytes) = std::fs::read(e.path()) {
                    for format in [Format::Wirelog, Format::Csv, Format::Sigrok] {
                        listen::fuzz_capture(format, &bytes);
                    }
                    n += 1;
                }
            }
        }
    }
    eprintln!("replayed {n} corpus and regression files");
}
