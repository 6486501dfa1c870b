//! The one mechanism: every property is a function of its input, registered once
//! with the domain `cargo test` checks (exhausted or sampled with proptest); the Kani
//! harnesses in `harnesses.rs` call the same functions on symbolic inputs.
//!
//! The registry (registry.rs, [`PROPERTIES`]) is one table; the properties and the
//! samplers of their twins are a file per family: the codecs and the data link
//! (codecs.rs), the slave along sequences of events (sequences.rs), the invariant's
//! inductive step (induction.rs), the field memory and the data field commands blind
//! to its contents (field_memory.rs). Here the mechanism: [`Property`], [`exhaust`],
//! [`sample`].

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

mod codecs;
mod field_memory;
mod induction;
mod registry;
mod sequences;

pub use codecs::{
    command_byte_round_trips, datalink_frames, decoders_are_total, request_decoder_is_total, request_round_trips,
    MAX_REQUEST, STORE_DATA_ROW,
};
pub use field_memory::contents_blind_sampled;
pub use induction::{inductive_sampled, inductive_sampled_shaped, parts_strategy};
pub use registry::PROPERTIES;
pub use sequences::{invariant_holds_along, memory_is_conserved, slave_step_is_total, stack_invariants, SequenceEvent};

/// A registered property.
pub struct Property {
    pub name: &'static str,
    /// What it proves, with the clause.
    pub claim: &'static str,
    /// The domain `cargo test` checks.
    pub domain: &'static str,
    pub exhaustive: bool,
    /// The Kani harness that proves the same property (`harnesses.rs`), where one does.
    pub harness: Option<&'static str>,
    /// Cases checked, or a counterexample.
    pub run: fn() -> Result<u64, String>,
}

/// Check `prop` for every value of `domain`.
pub fn exhaust<T: std::fmt::Debug>(domain: impl Iterator<Item = T>, prop: impl Fn(&T) -> bool) -> Result<u64, String> {
    let mut n = 0;
    for v in domain {
        let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| prop(&v))).unwrap_or(false);
        if !ok {
            return Err(format!("counterexample: {v:?}"));
        }
        n += 1;
    }
    Ok(n)
}

/// Check `prop` on `cases` values sampled from `strategy` (proptest, with shrinking).
pub fn sample<S: Strategy>(strategy: S, cases: u32, prop: impl Fn(&S::Value) -> bool) -> Result<u64, String>
where
    S::Value: std::fmt::Debug,
{
    let mut runner = TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
    runner
        .run(&strategy, |v| {
            let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| prop(&v))).unwrap_or(false);
            prop_assert!(ok);
            Ok(())
        })
        .map(|()| cases as u64)
        .map_err(|e| e.to_string())
}
