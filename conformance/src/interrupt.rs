//! Ctrl-C (SIGINT), SIGTERM and SIGHUP end a long-running command the same way: the
//! first sets a flag that the run looks at (it stops what it started, restores what it
//! can, writes its partial report and says what was cut short); a second ends the
//! harness at once, after stopping any master under test still running.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Exit code of a run ended at once by a second interrupt (128 + SIGINT, as a shell
/// reports a process ended by Ctrl-C).
pub const EXIT_SECOND_INTERRUPT: i32 = 130;

/// A flag set by the first interrupt, which prints `message`.
pub fn flag(message: &'static str) -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    let f = flag.clone();
    let handled = ctrlc::set_handler(move || {
        if f.swap(true, Ordering::Relaxed) {
            eprintln!("\ninterrupted again: ending now");
            crate::process::stop_all();
            std::process::exit(EXIT_SECOND_INTERRUPT);
        }
        eprintln!("{message}");
    });
    if let Err(e) = handled {
        eprintln!("warning: Ctrl-C is not handled: {e}");
    }
    flag
}
