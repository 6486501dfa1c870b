//! hiperface-conformance: the harness around the model: profiles as TOML files, the
//! master on a serial line, slave certification with the model's oracle in
//! lockstep, reports, and the simulator serving the model as a virtual encoder.

/// `println!` that never panics: standard output whose reader has gone (`| head`) ends
/// nothing; a run goes on, restores what it changed and writes its files, and a
/// listing ends quietly. Every command prints through it.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

pub mod args;
pub mod clauses;
pub mod command;
pub mod demo;
pub mod interrupt;
pub mod line;
pub mod listen;
pub mod master;
pub mod port;
pub mod process;
pub mod procfs;
pub mod report;
pub mod run_delay;
pub mod sched;
pub mod simulate;
pub mod slave;
