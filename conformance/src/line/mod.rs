//! The harness's lines: the core's [`Line`] (`hiperface_suite::line`, re-exported here
//! under the same names, with the virtual line and the echo's handling) on real ports
//! and pseudo-terminals ([`serial::SerialLine`]) and serial device servers
//! ([`tcp::TcpLine`], [`rfc2217`]), in real time (see [`clock`]): the clock, sleeping,
//! receive stamps, and what a pseudo-terminal delays ([`delivery`]).

pub mod adapter;
pub mod clock;
pub mod delivery;
pub mod rfc2217;
pub mod rs485;
pub mod serial;
pub mod tcp;

pub use clock::{read_until, RealTime, RxClock};
pub use hiperface_suite::line::{echo, reply_echo, virtual_line, Line, LineError, LineKind, Sent, Window};
