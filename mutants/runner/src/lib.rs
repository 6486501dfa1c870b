//! What a PASS proves: the catalogue (the cases that decide a slave's certificate and
//! the scenarios that decide a master's) measured against devices with one defect
//! each, graded by the unmutated model and oracle.
//!
//! - [`device`]: the mutated model (mutants/model, one switch on) as an encoder on the
//!   virtual line;
//! - [`configs`]: the profiles and settings an encoder is certified in;
//! - [`certify`]: one device through the catalogue, compared with a conformant one;
//! - [`source`], [`wire`], [`master`]: the three families of defective devices;
//! - [`families`]: their names and a worker's certifier;
//! - [`run`]: the workers on the machine's cores;
//! - [`survivors`]: the committed list of what the catalogue lets through, and the table.

pub mod certify;
pub mod configs;
pub mod cross_check;
pub mod device;
pub mod diff;
pub mod families;
pub mod master;
pub mod run;
pub mod source;
pub mod survivors;
pub mod wire;
