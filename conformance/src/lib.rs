//! hiperface-conformance: the harness around the model. So far: profiles as TOML
//! files and a demonstration of the model in virtual time; the certification harness
//! (issue 3) builds on these.

pub mod demo;
pub mod profile_file;
