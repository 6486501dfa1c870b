//! The harness's lines: the core's `Line` (`hiperface_suite::line`, with the virtual
//! line and the echo's handling) on real ports
//! and pseudo-terminals ([`serial::SerialLine`]) and serial device servers
//! ([`tcp::TcpLine`], [`rfc2217`]), in real time (see [`clock`]): the clock, sleeping,
//! receive stamps, and what a pseudo-terminal delays ([`delivery`]).

pub mod adapter;
pub mod clock;
pub mod delivery;
pub mod device_held;
pub mod host_pauses;
pub mod rfc2217;
pub mod rs485;
pub mod serial;
pub mod tcp;

/// A pseudo-terminal pair (its controlling side, its `/dev/pts/N` side) whose
/// descriptors are close-on-exec: a master under test started by the harness
/// (`process`) inherits neither, only the path it is given. `TTYPort::pair` opens both
/// without the flag; each is replaced by a duplicate that has it (`F_DUPFD_CLOEXEC`) and
/// the original closed.
pub fn pty_pair() -> serialport::Result<(serialport::TTYPort, serialport::TTYPort)> {
    let (controller, terminal) = serialport::TTYPort::pair()?;
    Ok((controller.try_clone_native()?, terminal.try_clone_native()?))
}
