//! A stable `cargo test` replays the fuzz corpus: seeds from the golden vectors, any
//! local corpus under fuzz/corpus, and the recorded regressions under fuzz/regressions.

use arbitrary::{Arbitrary, Unstructured};
use hiperface_proofs::targets::{self, MasterEvent, SlaveInput, TimedChar};
use hiperface_suite::capture::Format;
use hiperface_suite::{listen, vectors};
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

/// The files of `dir`, or none where it does not exist (fuzz/regressions/<target> exists
/// only once a finding was recorded).
fn files(dir: &Path) -> Vec<std::path::PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    entries.flatten().map(|e| e.path()).filter(|p| p.is_file()).collect()
}

#[test]
fn the_kept_corpus_and_the_regressions_replay() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz");
    let mut replayed = Vec::new();
    for target in ["request", "response", "datalink", "slave", "observer"] {
        let corpus = files(&root.join("corpus").join(target));
        let regressions = files(&root.join("regressions").join(target));
        for path in corpus.iter().chain(&regressions) {
            run_all(&std::fs::read(path).unwrap());
        }
        replayed.push((target, corpus.len(), regressions.len()));
    }
    // The capture readers and the listener: every file through every format.
    for target in ["capture_wirelog", "capture_csv", "capture_sigrok"] {
        let corpus = files(&root.join("corpus").join(target));
        let regressions = files(&root.join("regressions").join(target));
        for path in corpus.iter().chain(&regressions) {
            let bytes = std::fs::read(path).unwrap();
            for format in [Format::Wirelog, Format::Csv, Format::Sigrok] {
                listen::fuzz_capture(format, &bytes);
            }
        }
        replayed.push((target, corpus.len(), regressions.len()));
    }
    // The report and record reader (`decode` of a report): each file, and each cut
    // short at a few places (a report truncated in transit).
    let corpus = files(&root.join("corpus").join("report"));
    let regressions = files(&root.join("regressions").join("report"));
    for path in corpus.iter().chain(&regressions) {
        let bytes = std::fs::read(path).unwrap();
        hiperface_conformance::report::recorded::fuzz_report(&bytes);
        for cut in [bytes.len() / 3, bytes.len() / 2, bytes.len().saturating_sub(2)] {
            hiperface_conformance::report::recorded::fuzz_report(&bytes[..cut]);
        }
    }
    replayed.push(("report", corpus.len(), regressions.len()));
    eprintln!("replayed (target, corpus files, regressions): {replayed:?}");
    // The minimised corpus of every target is kept in the repository (fuzz/corpus/):
    // a replay of none is no replay. Each holds dozens of files at least.
    for (target, corpus, _) in &replayed {
        assert!(*corpus >= 50, "fuzz/corpus/{target} holds {corpus} files: the kept corpus is missing");
    }
    let total: usize = replayed.iter().map(|(_, c, r)| c + r).sum();
    assert!(total >= 7000, "{total} files replayed");
}
