//! Certify a slave: the catalogue, its runner and its report are the suite's core
//! (`hiperface_suite::slave`); the harness adds the command line ([`cli`]): the port,
//! the options, Ctrl-C, progress and files.

pub mod cli;
