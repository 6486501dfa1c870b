//! The one vocabulary of verdicts and the timing grades are the suite's core
//! (`hiperface_suite::verdict`), re-exported here under the same names.

pub use hiperface_suite::verdict::*;
