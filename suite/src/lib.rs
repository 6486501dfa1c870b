//! hiperface-suite: the conformance suite without I/O. What a certification reads and
//! writes as data (profiles as TOML, the golden vectors), the vocabulary of verdicts
//! and the simulated world of a case, on top of the model, with no
//! operating system, terminal or process in its tree: the harness
//! (`hiperface-conformance`) adds the lines, the processes and the command line, and
//! the C and Python libraries link this alone.

#![forbid(unsafe_code)]
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
#![cfg_attr(test, allow(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod capture;
pub mod exchange;
pub mod frame;
pub mod line;
pub mod listen;
pub mod master;
pub mod profile_file;
pub mod report;
pub mod serve;
pub mod slave;
pub mod time;
pub(crate) mod timing_diagrams;
pub mod vectors;
pub mod verdict;
pub mod world;
