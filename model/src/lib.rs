//! # hiperface-model
//!
//! The executable specification of a HIPERFACE slave (encoder) per the SICK
//! specification (seed 000, "current" edition) with the older SICK-STEGMANN
//! description (seed 002, "legacy") selectable by profile:
//!
//! - wire layer: [`address`], [`command`] (the command table), [`checksum`],
//!   [`request`] and [`response`] codecs, [`fault`] (the fault table);
//! - UART layer: [`settings`] (the settings byte and timing);
//! - data link, sans-IO: [`datalink`];
//! - slave behaviour and the power-up state machine: [`slave`];
//! - device data sheets: [`profile`], [`profiles`];
//! - the grading [`oracle`] and the [`clause`] registry.
//!
//! The model never reads a clock or a port: time is an argument in µs, characters
//! come in one by one, and the slave says what to send and when.
#![no_std]
#![forbid(unsafe_code)]
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
#![cfg_attr(test, allow(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod address;
pub mod checksum;
pub mod clause;
pub mod command;
pub mod datalink;
pub mod fault;
pub mod frame;
pub mod master;
pub mod oracle;
pub mod profile;
pub mod profiles;
pub mod request;
pub mod response;
pub mod settings;
pub mod slave;

pub use address::{AddressByte, SlaveAddress};
pub use command::{CommandId, CommandSpec, COMMAND_TABLE};
pub use datalink::{DataLink, RxChar, UartFault};
pub use fault::FaultCode;
pub use frame::{Frame, Hex};
pub use oracle::{Grade, Grading, Oracle, Verdict};
pub use profile::Profile;
pub use request::{Request, RequestFrame};
pub use response::{Response, ResponseFrame};
pub use settings::{Edition, UartSettings};
pub use slave::{Outcome, Reply, Silence, Slave, Step, Transmission};
