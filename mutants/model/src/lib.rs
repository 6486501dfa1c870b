//! The model's source with every mutant of the catalogue's measure compiled in
//! (mutants/schemata), one of them switched on at a time with [`mutant::activate`]:
//! the devices under test of `scripts/catalogue-mutants.sh`. A crate of its own, so
//! that the model the oracle and the catalogue use (hiperface-model) is never the
//! mutated one: a mutant changes the device, never its judge.
//!
//! The copy is generated (build.rs) and not meant to be read here: its items are the
//! model's, under the same paths (`hiperface_model_mutated::slave::Slave`).
#![no_std]
#![forbid(unsafe_code)]
// Generated code: the switches' parentheses, the model's items the devices do not use.
#![allow(warnings, clippy::all, clippy::pedantic, clippy::nursery)]

/// The switches.
pub mod mutant {
    use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

    /// A mutant of the copy.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct MutantInfo {
        /// Its switch; from 1.
        pub id: u32,
        /// `encoder` or `master`: which defective devices it makes.
        pub family: &'static str,
        /// cargo-mutants' genre: `FnValue`, `BinaryOperator`, `UnaryOperator`,
        /// `MatchArm`, `MatchArmGuard`.
        pub genre: &'static str,
        pub file: &'static str,
        pub line: u32,
        pub column: u32,
        pub function: &'static str,
        /// In cargo-mutants' words: `replace == with != in ErrorStack::push`.
        pub description: &'static str,
        /// Which of the same description in the same file, in source order.
        pub occurrence: u32,
    }

    /// A mutant cargo-mutants makes that the copy does not switch in.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct Skipped {
        pub place: &'static str,
        pub description: &'static str,
        pub why: &'static str,
    }

    /// Every mutant, by id (`ALL[id - 1]`).
    pub const ALL: &[MutantInfo] = &include!(concat!(env!("OUT_DIR"), "/mutants.rs"));
    /// What cargo-mutants makes and the copy does not switch in.
    pub const SKIPPED: &[Skipped] = &include!(concat!(env!("OUT_DIR"), "/skipped.rs"));

    static ACTIVE: AtomicU32 = AtomicU32::new(0);
    const NOT_REACHED: AtomicBool = AtomicBool::new(false);
    static REACHED: [AtomicBool; ALL.len() + 1] = [NOT_REACHED; ALL.len() + 1];

    /// Whether mutant `id` is switched on; its place is marked reached.
    #[inline]
    pub fn on(id: u32) -> bool {
        if let Some(r) = REACHED.get(id as usize) {
            r.store(true, Ordering::Relaxed);
        }
        ACTIVE.load(Ordering::Relaxed) == id
    }

    /// Switch mutant `id` on (0: none, the model as it is), every other off.
    pub fn activate(id: u32) {
        ACTIVE.store(id, Ordering::Relaxed);
    }

    /// The mutant switched on (0: none).
    pub fn active() -> u32 {
        ACTIVE.load(Ordering::Relaxed)
    }

    /// Whether the place of mutant `id` was run since [`forget_reached`].
    pub fn reached(id: u32) -> bool {
        REACHED.get(id as usize).is_some_and(|r| r.load(Ordering::Relaxed))
    }

    /// Forget which places were run.
    pub fn forget_reached() {
        for r in &REACHED {
            r.store(false, Ordering::Relaxed);
        }
    }

    /// The mutant with switch `id`.
    pub fn info(id: u32) -> Option<&'static MutantInfo> {
        ALL.get((id as usize).checked_sub(1)?)
    }
}

include!(concat!(env!("OUT_DIR"), "/model.rs"));
