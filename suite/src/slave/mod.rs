//! Certify a slave: run the case catalogue against a device under test, with the
//! model's oracle in lockstep grading every answer and its timing.
//!
//! - [`cases`]: the catalogue;
//! - [`ctx`]: what a case sees (the master, the model in lockstep, findings, guards);
//! - [`case`]: a case of the catalogue (verdicts and findings are `crate::verdict`'s);
//! - [`identity`]: what the device says of itself, for the certificate;
//! - [`safety`]: whether the run left the device as it found it;
//! - [`run`]: the runner and the report.

mod case;
pub mod cases;
mod ctx;
mod identity;
pub mod record;
pub mod report;
mod run;
pub(crate) mod safety;

pub use case::{Case, CaseError};
pub use ctx::{Ctx, Graded, Guard, EVERY_EXCHANGE};
pub use identity::Identity;
pub use run::{check_selection, in_process, replay, run, select, NoCaseMatches, Report, TimingStats};
pub use safety::Safety;

use crate::verdict::timing::TimingMode;
use crate::world::World;
use hiperface_model::Grading;
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
    /// Runs a Sensor Adjustment, which may recalibrate the sensor (000:T35: what it
    /// does is the device's own).
    Adjustment,
}

/// Options of a run.
#[derive(Debug, Clone)]
pub struct Options {
    pub allow_writes: bool,
    pub allow_counter_change: bool,
    /// Allow Sensor Adjustment (6Bh) with the profile's options: it may recalibrate the
    /// sensor, and no request undoes it.
    pub allow_adjustment: bool,
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

impl Options {
    /// Every case: EEPROM writes (restored), counter changes and sensor adjustments
    /// (not restorable) allowed, as for a simulator or a test.
    pub fn all_allowed() -> Options {
        Options { allow_writes: true, allow_counter_change: true, allow_adjustment: true, ..Options::default() }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            allow_writes: false,
            allow_counter_change: false,
            allow_adjustment: false,
            write_budget: 200,
            cases: None,
            grading: Grading::Exact,
            interrupt: None,
            world: World::default(),
            timing: TimingMode::Strict,
        }
    }
}
