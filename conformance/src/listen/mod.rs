//! Listening to a bus: the listener, its grades and the decoding of capture files are
//! the suite's core (`hiperface_suite::listen`); the harness adds the live tap on a
//! port ([`tap`]), `monitor` ([`monitor`]) and the command lines of `decode` and
//! `monitor` ([`cli`]).

pub mod cli;
pub mod monitor;
pub mod tap;
