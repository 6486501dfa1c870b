//! What several subcommands are told, defined once so that the same idea has the same
//! flag name and unit everywhere: times are milliseconds (`--…-ms`, a decimal where a
//! fraction makes sense), a port is `--port` parsed as a [`crate::port::PortSpec`], a
//! profile is `--profile`, and the simulated encoder's world is the same group of
//! flags for `simulate` and `certify slave --port sim`.
//!
//! Flags renamed for this agreement keep their old name as a hidden alias for one
//! release (docs/src/command-line.md): `master --poll-ms` (now `--polling-period-ms`) and
//! `monitor --duration-s` (now `--duration-ms`).

use hiperface_model::slave::inputs::{InitFault, PhysicalInputs};
use hiperface_suite::world::World;

/// A duration or a tolerance in milliseconds: a finite decimal, not negative.
pub fn parse_ms(s: &str) -> Result<f64, String> {
    let ms: f64 = s.parse().map_err(|_| format!("`{s}` is not a number of milliseconds"))?;
    if !ms.is_finite() || ms < 0.0 {
        return Err(format!("`{s}`: milliseconds must be a finite number, zero or more"));
    }
    // A minute is more than any delay or uncertainty of a HIPERFACE line; far larger
    // figures would overflow as microseconds.
    if ms > 60_000.0 {
        return Err(format!("`{s}`: at most 60000 milliseconds"));
    }
    Ok(ms)
}

/// The simulated encoder's physical inputs and start-up faults.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct WorldArgs {
    /// Encoder temperature in °C (outside the profile's limits raises warning 1Eh).
    #[arg(long, allow_hyphen_values = true)]
    pub temperature: Option<i16>,
    /// Raw shaft position in steps.
    #[arg(long)]
    pub position: Option<u64>,
    /// A fault found at start-up (repeatable): alignment-data, angular-offset,
    /// partition-table, analog-limits, type-code, watchdog, counter, extended-type-label,
    /// multiturn-parameters.
    #[arg(long = "init-fault", value_parser = parse_init_fault)]
    pub init_faults: Vec<InitFault>,
}

impl WorldArgs {
    /// The world these flags describe (the default one when none is given).
    pub fn world(&self) -> World {
        let mut inputs = PhysicalInputs::default();
        let custom = self.temperature.is_some() || self.position.is_some();
        if let Some(t) = self.temperature {
            inputs.temperature_c = t;
        }
        if let Some(p) = self.position {
            inputs.position = p;
        }
        World { inputs: custom.then_some(inputs), init_faults: self.init_faults.clone(), ..World::default() }
    }
}

fn parse_init_fault(s: &str) -> Result<InitFault, String> {
    InitFault::from_name(s).ok_or_else(|| format!("unknown start-up fault `{s}`"))
}

/// A command byte as `--not-used` takes it (`hiperface_suite::master::parse_command`).
pub fn parse_command(s: &str) -> Result<hiperface_model::CommandId, hiperface_suite::master::BadCommand> {
    hiperface_suite::master::parse_command(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hiperface_suite::time::ms_to_us;

    #[test]
    fn milliseconds_are_finite_and_not_negative() {
        assert_eq!(parse_ms("2.5"), Ok(2.5));
        assert_eq!(parse_ms("0"), Ok(0.0));
        for bad in ["-1", "NaN", "inf", "two", ""] {
            assert!(parse_ms(bad).is_err(), "{bad} accepted");
        }
        assert_eq!(ms_to_us(2.5), 2500);
        assert_eq!(ms_to_us(0.0004), 0);
    }
}
