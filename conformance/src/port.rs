//! What `--port` names, and opening it as a line: the reference model in virtual
//! time or on a pseudo-terminal, a serial port, or a serial device server over TCP.

use crate::line::adapter::STRICT_LIMIT_US;
use crate::line::serial::SerialLine;
use crate::line::tcp::TcpLine;
use crate::simulate::PtySimulator;
use hiperface_model::{Profile, UartSettings};
use hiperface_suite::line::virtual_line::VirtualLine;
use hiperface_suite::line::{Line, LineError};
use hiperface_suite::verdict::timing::TimingMode;
use hiperface_suite::world::World;
use std::fmt;
use std::str::FromStr;

/// A `--port` argument.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PortSpec {
    /// The reference model served on an in-process pseudo-terminal, real time.
    Sim,
    /// The reference model in-process, virtual time.
    Virtual,
    /// A new pseudo-terminal pair; the path of the other end is printed.
    Pty,
    /// Raw TCP to a serial device server, `host:port`.
    Tcp(String),
    /// A serial device server that takes UART settings through RFC 2217, `host:port`.
    Rfc2217(String),
    /// A serial port or pseudo-terminal by path.
    Path(String),
}

/// A `--port` argument that names nothing.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{given}` is not a port: {why} (expected sim, virtual, pty, tcp://HOST:PORT, rfc2217://HOST:PORT or a device path)")]
pub struct BadPort {
    pub given: String,
    pub why: &'static str,
}

impl FromStr for PortSpec {
    type Err = BadPort;

    fn from_str(s: &str) -> Result<PortSpec, BadPort> {
        let bad = |why| BadPort { given: s.to_string(), why };
        match s {
            "sim" => Ok(PortSpec::Sim),
            "virtual" => Ok(PortSpec::Virtual),
            "pty" => Ok(PortSpec::Pty),
            "" => Err(bad("it is empty")),
            _ => {
                let server = |address: &str| -> Result<String, BadPort> {
                    let (host, port) = address.rsplit_once(':').ok_or_else(|| bad("no :PORT after the host"))?;
                    if host.is_empty() {
                        return Err(bad("no host"));
                    }
                    port.parse::<u16>().map_err(|_| bad("the TCP port is not a number from 0 to 65535"))?;
                    Ok(address.to_string())
                };
                match (s.strip_prefix("tcp://"), s.strip_prefix("rfc2217://")) {
                    (Some(address), _) => server(address).map(PortSpec::Tcp),
                    (_, Some(address)) => server(address).map(PortSpec::Rfc2217),
                    _ if s.contains("://") => Err(bad("only tcp:// and rfc2217:// are spoken")),
                    _ => Ok(PortSpec::Path(s.to_string())),
                }
            }
        }
    }
}

impl fmt::Display for PortSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PortSpec::Sim => f.write_str("sim"),
            PortSpec::Virtual => f.write_str("virtual"),
            PortSpec::Pty => f.write_str("pty"),
            PortSpec::Tcp(a) => write!(f, "tcp://{a}"),
            PortSpec::Rfc2217(a) => write!(f, "rfc2217://{a}"),
            PortSpec::Path(p) => f.write_str(p),
        }
    }
}

impl PortSpec {
    /// The reference model is the device: its world is known exactly.
    pub fn is_model(&self) -> bool {
        matches!(self, PortSpec::Sim | PortSpec::Virtual)
    }
}

/// An open line, and the simulator serving it (kept alive as long as the line).
pub struct Opened {
    pub line: Box<dyn Line>,
    pub simulator: Option<PtySimulator>,
    /// The timing mode the line supports when the user did not choose one, and why.
    pub default_timing: (TimingMode, Option<String>),
}

/// How the line is to be taken, beyond what its kind says: from the command line.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LineOptions {
    /// Overrides the line's default jitter tolerance on every real-time line, µs.
    pub tolerance_us: Option<u64>,
    /// The line may deliver received characters this late (`--latency-ms`), µs.
    pub latency_us: Option<u64>,
}

impl LineOptions {
    pub fn tolerance(tolerance_us: u64) -> LineOptions {
        LineOptions { tolerance_us: Some(tolerance_us), ..LineOptions::default() }
    }
}

/// Open `spec` for certifying a slave of `profile`, the line taken as `options` say.
pub fn open_for_slave(
    spec: &PortSpec,
    profile: Profile,
    world: &World,
    options: LineOptions,
) -> Result<Opened, LineError> {
    let LineOptions { tolerance_us, latency_us } = options;
    let strict = (TimingMode::Strict, None);
    let (line, simulator, default_timing): (Box<dyn Line>, _, _) = match spec {
        PortSpec::Virtual => {
            let mut device = hiperface_model::Slave::operational(profile);
            world.apply(&mut device);
            (Box::new(VirtualLine::new(device)), None, strict)
        }
        PortSpec::Sim => {
            let (sim, port) = PtySimulator::start_in(profile, world.clone())
                .map_err(|reason| LineError::Open { port: "sim".into(), reason })?;
            let name = format!("{} to the built-in reference encoder", sim.path);
            let mut line = SerialLine::from_port(port, name, profile.settings, true)
                .with_peer_lateness(sim.lateness(), sim.heard());
            if let Some(t) = tolerance_us {
                line = line.with_tolerance(t);
            }
            (Box::new(line), Some(sim), strict)
        }
        PortSpec::Pty => {
            return Err(LineError::Open {
                port: "pty".into(),
                reason: "a slave is certified on its own port: give its path (a pseudo-terminal path works)".into(),
            })
        }
        PortSpec::Tcp(address) | PortSpec::Rfc2217(address) => {
            let connect =
                if matches!(spec, PortSpec::Rfc2217(_)) { TcpLine::connect_rfc2217 } else { TcpLine::connect };
            let mut line = connect(address, UartSettings::DEFAULT)?;
            if let Some(t) = tolerance_us {
                line = line.with_tolerance(t);
            }
            (Box::new(line), None, strict)
        }
        PortSpec::Path(path) => {
            let mut line = SerialLine::open(path, UartSettings::DEFAULT)?;
            if let Some(t) = tolerance_us {
                line = line.with_tolerance(t);
            }
            if let Some(l) = latency_us {
                line = line.with_declared_latency(l);
            }
            let timing = match line.input_latency_us() {
                latency if latency > STRICT_LIMIT_US => (
                    TimingMode::Lenient,
                    Some(format!(
                        "timing graded leniently: the line may hold replies back up to {:.1} ms \
                         (lower the adapter's latency timer, or choose --timing strict)",
                        latency as f64 / 1000.0
                    )),
                ),
                _ => strict,
            };
            (Box::new(line), None, timing)
        }
    };
    Ok(Opened { line, simulator, default_timing })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_specs() {
        assert_eq!("sim".parse(), Ok(PortSpec::Sim));
        assert_eq!("virtual".parse(), Ok(PortSpec::Virtual));
        assert_eq!("pty".parse(), Ok(PortSpec::Pty));
        assert_eq!("tcp://127.0.0.1:2000".parse(), Ok(PortSpec::Tcp("127.0.0.1:2000".into())));
        assert_eq!("tcp://[::1]:2000".parse(), Ok(PortSpec::Tcp("[::1]:2000".into())));
        assert_eq!("rfc2217://10.0.0.5:4001".parse(), Ok(PortSpec::Rfc2217("10.0.0.5:4001".into())));
        assert!("rfc2217://nohost".parse::<PortSpec>().is_err());
        assert_eq!("/dev/ttyUSB0".parse(), Ok(PortSpec::Path("/dev/ttyUSB0".into())));
        assert_eq!("COM3".parse(), Ok(PortSpec::Path("COM3".into())));
        for bad in ["", "tcp://host", "tcp://:2000", "tcp://h:99999", "ftp://h:1", "rfc2217://h"] {
            let e = bad.parse::<PortSpec>().unwrap_err();
            assert!(e.to_string().contains("is not a port"), "{bad}: {e}");
        }
        for s in ["sim", "virtual", "pty", "tcp://h:1", "rfc2217://h:1", "/dev/pts/3"] {
            assert_eq!(s.parse::<PortSpec>().unwrap().to_string(), s);
        }
    }

    #[test]
    fn the_tolerance_reaches_every_real_time_line() {
        let profile = hiperface_model::profiles::srs50();
        let opened = open_for_slave(&PortSpec::Sim, profile, &World::default(), LineOptions::tolerance(7_000)).unwrap();
        assert_eq!(opened.line.tolerance_us(), 7_000);
        // A pseudo-terminal by path: the other end stays open, its own handle is closed.
        use serialport::SerialPort as _;
        let (_keep, other) = serialport::TTYPort::pair().unwrap();
        let path = other.name().unwrap();
        drop(other);
        let opened =
            open_for_slave(&PortSpec::Path(path), profile, &World::default(), LineOptions::tolerance(9_000)).unwrap();
        assert_eq!(opened.line.tolerance_us(), 9_000);
        let server = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let spec = PortSpec::Tcp(server.local_addr().unwrap().to_string());
        let opened = open_for_slave(&spec, profile, &World::default(), LineOptions::tolerance(11_000)).unwrap();
        assert_eq!(opened.line.tolerance_us(), 11_000);
        assert!(open_for_slave(&PortSpec::Pty, profile, &World::default(), LineOptions::default()).is_err());
    }
}
