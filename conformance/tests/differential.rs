//! A differential check of the model against HX-1, the independent slave
//! (`tests/independent/hx1_slave.py`, written from 000's tables alone): the same random
//! request sequences (valid requests, data field work, counter, malformed frames, an
//! Encoder Reset followed by a request in one of the power-up phases) go to
//! a fresh HX-1 on a pseudo-terminal and to the model, and the oracle grades HX-1's
//! every reply against the model's. They must agree: PASS, or NON-STRICT where 000
//! leaves latitude. A disagreement prints the sequence up to it. Real time, bounded
//! (a few sequences of a few dozen requests).

mod common;

use common::hx1::{profile, Hx1};
use hiperface_conformance::line::serial::SerialLine;
use hiperface_model::oracle::Verdict;
use hiperface_model::{Grading, Hex, Oracle, Reply, Slave, UartSettings};
use hiperface_suite::exchange::{sealed, BusMaster};
use proptest::prelude::*;
use std::time::Duration;

/// One request of a sequence, as bytes the master sends.
#[derive(Debug, Clone)]
enum Step {
    Valid(Vec<u8>),
    BadChecksum(Vec<u8>),
    UnknownCommand(u8),
    Truncated(Vec<u8>),
    /// Encoder Reset (53h), then the next request in the given phase of 000:T9.
    Reset(Phase),
}

/// Where the request after an Encoder Reset falls in 000:T9 (HX-1's profile:
/// initialization 100 ms, default settings until 900 ms, its own from 1100 ms). Each
/// far from the phase's ends, so that neither side's clock can move it across one.
#[derive(Debug, Clone, Copy)]
enum Phase {
    /// At once: a few milliseconds after the reset, well inside the initialization.
    Initialization,
    /// About 400 ms after the reset: the default settings' window.
    DefaultWindow,
    /// About 1500 ms after the reset: operational with its stored settings.
    Operational,
}

impl Phase {
    /// How long to wait after the reset's exchange before the next request.
    fn pause(self) -> Duration {
        Duration::from_millis(match self {
            Phase::Initialization => 0,
            Phase::DefaultWindow => 400,
            Phase::Operational => 1500,
        })
    }
}

impl Step {
    fn frame(&self) -> Vec<u8> {
        match self {
            Step::Valid(body) => sealed(body),
            Step::BadChecksum(body) => {
                let mut f = sealed(body);
                if let Some(last) = f.last_mut() {
                    *last ^= 0x01;
                }
                f
            }
            Step::UnknownCommand(c) => sealed(&[0x40, *c]),
            Step::Truncated(body) => sealed(body.get(..body.len().saturating_sub(1)).unwrap_or(body)),
            Step::Reset(_) => sealed(&[0x40, 0x53]),
        }
    }
}

/// Valid requests to HX-1's address: reads, the counter, data fields (Code0 55h).
fn valid() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        Just(vec![0x40, 0x42]),
        Just(vec![0x40, 0x50]),
        Just(vec![0x40, 0x52]),
        Just(vec![0x40, 0x46]),
        Just(vec![0x40, 0x47]),
        Just(vec![0x40, 0x4E]),
        Just(vec![0x40, 0x49, 0x55]),
        (0u8..0x50).prop_map(|ch| vec![0x40, 0x44, ch]),
        (0u8..4).prop_map(|f| vec![0x40, 0x4C, f]),
        // Create a field: number, status (80h exists, 40h writable, 16 bytes * (n + 1)),
        // Code0.
        (0u8..3, 0u8..3).prop_map(|(f, size)| vec![0x40, 0x4D, f, 0xC0 | size, 0x55]),
        // Read Data: field, offset, count, access code.
        (0u8..3, 0u8..20, 1u8..17).prop_map(|(f, off, n)| vec![0x40, 0x4A, f, off, n, 0x55]),
        // Store Data: field, offset, access code, count, data.
        (0u8..3, 0u8..16, proptest::collection::vec(any::<u8>(), 1..4)).prop_map(|(f, off, data)| {
            let mut b = vec![0x40, 0x4B, f, off, 0x55, data.len() as u8];
            b.extend(data);
            b
        }),
    ]
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        6 => valid().prop_map(Step::Valid),
        1 => valid().prop_map(Step::BadChecksum),
        1 => prop_oneof![Just(0x45u8), Just(0x51), Just(0x7F)].prop_map(Step::UnknownCommand),
        1 => valid().prop_filter("has data", |b| b.len() > 2).prop_map(Step::Truncated),
        1 => prop_oneof![
            2 => Just(Phase::Initialization),
            2 => Just(Phase::DefaultWindow),
            1 => Just(Phase::Operational),
        ]
        .prop_map(Step::Reset),
    ]
}

/// Run `steps` against a fresh HX-1 (started with `args`) and the model; the first
/// disagreement, if any. (`None` too where python3 is missing outside CI.)
fn disagreement(steps: &[Step], args: &[&str]) -> Option<String> {
    let _one = common::one_at_a_time();
    let hx1 = Hx1::start(args);
    let line = SerialLine::open(&hx1.path, UartSettings::DEFAULT).expect("HX-1's pseudo-terminal");
    let profile = profile();
    let mut master = BusMaster::new(line, profile.edition);
    let mut model = Slave::operational(profile);
    let oracle = Oracle::new(Grading::Range);
    let mut log = Vec::new();
    for s in steps {
        let frame = s.frame();
        let before = model.clone();
        // After an Encoder Reset the next request is timed by the phase; the reset
        // itself is answered by silence (000:T9), so listen for it only briefly.
        let listen_ms = if matches!(s, Step::Reset(_)) { 0 } else { 100 };
        let x = master.exchange(&frame, listen_ms).expect("the line");
        let expected = model.handle_frame(&frame, x.complete_us());
        let observed = x.reply_bytes();
        let grade = oracle.grade(&before, &frame, x.complete_us(), &expected, observed.as_deref());
        let shown = |r: Option<&[u8]>| r.map_or("silence".to_string(), |b| Hex(b).to_string());
        let wanted = match expected.reply {
            Reply::Frame(f) => Hex(f.encode().as_bytes()).to_string(),
            Reply::Silent(_) => "silence".into(),
        };
        log.push(format!("M> {}  HX-1< {}  model< {wanted}", Hex(&frame), shown(observed.as_deref())));
        if grade.verdict() == Verdict::Fail {
            let why = grade.deviation().map_or(String::new(), |d| d.to_string());
            return Some(format!("{} ({})\n{}", why, grade.clause(), log.join("\n")));
        }
        if let Step::Reset(phase) = s {
            std::thread::sleep(phase.pause());
        }
    }
    None
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, failure_persistence: None, ..ProptestConfig::default() })]
    #[test]
    #[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
    fn the_model_and_hx1_agree_on_random_sequences(steps in proptest::collection::vec(step(), 10..30)) {
        if let Some(d) = disagreement(&steps, &[]) {
            prop_assert!(false, "the model and HX-1 disagree: {d}");
        }
    }
}

#[test]
#[cfg_attr(not(has_python3), ignore = "python3 is not installed")]
fn a_defective_hx1_is_a_disagreement() {
    // The check can fail: HX-1 with a defect switch, and a sequence that reaches it.
    let cases: [(&str, Vec<Step>); 5] = [
        ("wrong-error-code", vec![Step::Valid(vec![0x40, 0x42]), Step::UnknownCommand(0x45)]),
        (
            "no-field-bounds",
            // A field of 16 bytes, then 16 bytes read from offset 10.
            vec![Step::Valid(vec![0x40, 0x4D, 0, 0xC0, 0x55]), Step::Valid(vec![0x40, 0x4A, 0, 10, 16, 0x55])],
        ),
        // The stack read empty, and the warning bit still set.
        ("warning-stuck", [0x42, 0x50, 0x50, 0x42].map(|c| Step::Valid(vec![0x40, c])).to_vec()),
        // A request at once after an Encoder Reset, inside the initialization.
        (
            "no-init-silence",
            vec![Step::Valid(vec![0x40, 0x42]), Step::Reset(Phase::Initialization), Step::Valid(vec![0x40, 0x42])],
        ),
        (
            "reset-answers",
            vec![Step::Valid(vec![0x40, 0x42]), Step::Reset(Phase::DefaultWindow), Step::Valid(vec![0x40, 0x42])],
        ),
    ];
    for (defect, steps) in cases {
        let found = disagreement(&steps, &["--defect", defect]);
        assert!(found.is_some(), "{defect}: no disagreement found");
        eprintln!("{defect}: {}", found.unwrap_or_default().lines().next().unwrap_or_default());
    }
}
