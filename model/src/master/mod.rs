//! Master-side references of 000 chapter 3: quadrature counting (3.2.3), fine-angle
//! interpolation (3.2.4), position synchronisation (3.2.5), fault reaction (3.3.4),
//! the master's obligations on the line (the oracle for certifying a drive), the
//! reference master as a sans-IO state machine, and a simulated sin/cos signal source
//! to check them together with the slave.

pub mod fault_reaction;
pub mod interpolation;
pub mod obligations;
pub mod quadrature;
pub mod reference;
pub mod signal;
pub mod sync;
