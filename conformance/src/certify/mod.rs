//! Certify a slave: run the case catalogue against a device under test, with the
//! model's oracle in lockstep grading every answer and its timing.
//!
//! - [`cases`]: the catalogue;
//! - [`ctx`]: what a case sees (the master, the model in lockstep, findings, guards);
//! - [`case`]: a case of the catalogue (verdicts and findings are `crate::verdict`'s);
//! - [`timing`]: reply timing against the windows the line can vouch for;
//! - [`identity`]: what the device says of itself, for the certificate;
//! - [`safety`]: whether the run left the device as it found it;
//! - [`run`]: the runner and the report.

mod case;
pub mod cases;
pub mod ctx;
pub mod identity;
pub mod run;
pub mod safety;
pub mod timing;

pub use crate::verdict::{CaseResult, CaseVerdict, Finding, Outcome, WireEntry};
pub use case::{Case, CaseError};
pub use ctx::{Ctx, Graded, Guard};
pub use identity::Identity;
pub use run::{run, select, Report, TimingStats};
pub use safety::Safety;

use hiperface_model::{Grading, Slave};
use serde::Serialize;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// What a case may do to the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Needs {
    /// Reads only.
    Nothing,
    /// EEPROM writes, all restored by the case.
    Writes,
    /// Changes the counter, which cannot be restored (000:T17, T18).
    CounterChange,
}

/// Options of a run.
#[derive(Debug, Clone)]
pub struct Options {
    pub allow_writes: bool,
    pub allow_counter_change: bool,
    /// At most this many EEPROM writes (counted by the model in lockstep).
    pub write_budget: u32,
    /// Only cases whose id matches this glob (`*` and `?`).
    pub cases: Option<String>,
    pub grading: Grading,
    /// Set (e.g. by Ctrl-C) to stop the run: pending restores still run.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// What the lockstep model knows of the device's world (a simulator's inputs and
    /// start-up faults); empty for real devices.
    pub world: World,
    /// How reply timing is graded.
    pub timing: TimingMode,
}

/// How reply timing is graded (`--timing`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum TimingMode {
    /// A reply outside its window FAILs.
    Strict,
    /// A reply outside its window is NON-STRICT, with the measured figure: for lines
    /// whose latency the harness cannot bound (e.g. an adapter's latency timer).
    Lenient,
    /// Timing is measured and reported, not graded.
    Off,
}

/// The device's physical inputs and the faults it found at start-up.
#[derive(Debug, Clone, Default)]
pub struct World {
    pub inputs: Option<hiperface_model::slave::inputs::PhysicalInputs>,
    pub init_faults: Vec<hiperface_model::slave::inputs::InitFault>,
}

impl World {
    /// As [`World::apply`] for a model just powered on at t = 0 whose power-up is
    /// timed (a master is certified from power-on): the start-up faults are found, the
    /// windows still to come.
    pub fn apply_at_power_on(&self, model: &mut Slave) {
        if let Some(inputs) = self.inputs {
            model.set_inputs(inputs);
        }
        model.power_up_with(self.init_faults.iter().copied(), false);
    }

    /// Bring a model into this world: inputs set, start-up faults found.
    pub fn apply(&self, model: &mut Slave) {
        if let Some(inputs) = self.inputs {
            model.set_inputs(inputs);
        }
        if !self.init_faults.is_empty() {
            model.power_up_with(self.init_faults.iter().copied(), true);
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            allow_writes: false,
            allow_counter_change: false,
            write_budget: 200,
            cases: None,
            grading: Grading::Exact,
            interrupt: None,
            world: World::default(),
            timing: TimingMode::Strict,
        }
    }
}

/// `*` and `?` glob matching for `--cases`.
pub fn glob_match(pattern: &str, text: &str) -> bool {
    fn go(p: &[u8], t: &[u8]) -> bool {
        match (p.first(), t.first()) {
            (None, None) => true,
            (Some(b'*'), _) => go(&p[1..], t) || (!t.is_empty() && go(p, &t[1..])),
            (Some(b'?'), Some(_)) => go(&p[1..], &t[1..]),
            (Some(a), Some(b)) if a == b => go(&p[1..], &t[1..]),
            _ => false,
        }
    }
    pattern.split(',').any(|p| go(p.trim().as_bytes(), text.as_bytes()))
}
