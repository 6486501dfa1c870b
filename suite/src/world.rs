//! The world a simulated encoder lives in: its physical inputs, the faults it finds
//! at start-up and the faults of its position measurement. The simulator serves a
//! model in it, and the model the harness grades against is put in the same one
//! (`certify slave --port sim`, the encoder of `certify master`, an encoder certified
//! in-process with its world given).

use hiperface_model::slave::inputs::{InitFault, PhysicalInputs, PositionFault};
use hiperface_model::Slave;

/// A fault's name that no fault of its kind has.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {kind} `{name}` (known: {known})")]
pub struct UnknownFault {
    kind: &'static str,
    name: String,
    known: String,
}

/// The device's physical inputs, the faults it found at start-up and the faults of its
/// position measurement.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct World {
    pub inputs: Option<PhysicalInputs>,
    pub init_faults: Vec<InitFault>,
    /// Reported on position commands while present (000:T39, T57, T61-T68).
    pub position_faults: Vec<PositionFault>,
    /// The internal I2C bus is down: the commands that need it answer 05h (000:T43).
    pub i2c_fault: bool,
}

impl World {
    /// A world from its inputs and its faults by name (`alignment-data`, `watchdog`,
    /// ...; `analog-signals`, `multiturn-sync`, ...: as the command line and the
    /// vectors spell them): the one way the front ends that take names (C's comma
    /// lists, Python's lists) read a world.
    pub fn from_names<'a>(
        inputs: Option<PhysicalInputs>,
        init_faults: impl IntoIterator<Item = &'a str>,
        position_faults: impl IntoIterator<Item = &'a str>,
        i2c_fault: bool,
    ) -> Result<World, UnknownFault> {
        /// Each name read by its kind's own `from_name`; the kind's names for the error.
        fn named<'a, F>(
            names: impl IntoIterator<Item = &'a str>,
            kind: &'static str,
            from_name: fn(&str) -> Option<F>,
            known: &[&str],
        ) -> Result<Vec<F>, UnknownFault> {
            names
                .into_iter()
                .map(|n| {
                    from_name(n).ok_or_else(|| UnknownFault { kind, name: n.to_string(), known: known.join(", ") })
                })
                .collect()
        }
        let init_names = InitFault::ALL.map(InitFault::name);
        let position_names = PositionFault::ALL.map(PositionFault::name);
        Ok(World {
            inputs,
            init_faults: named(init_faults, "start-up fault", InitFault::from_name, &init_names)?,
            position_faults: named(position_faults, "position fault", PositionFault::from_name, &position_names)?,
            i2c_fault,
        })
    }

    /// As [`World::apply`] for a model just powered on at t = 0 whose power-up is
    /// timed (a master is certified from power-on): the start-up faults are found, the
    /// windows still to come.
    pub fn apply_at_power_on(&self, model: &mut Slave) {
        if let Some(inputs) = self.inputs {
            model.set_inputs(inputs);
        }
        model.power_up_with(self.init_faults.iter().copied(), false);
        self.inject_position_faults(model);
    }

    /// Whether this is the default world (nothing given).
    pub fn is_default(&self) -> bool {
        *self == World::default()
    }

    fn inject_position_faults(&self, model: &mut Slave) {
        for f in &self.position_faults {
            model.inject_position_fault(*f, true);
        }
        if self.i2c_fault {
            model.inject_i2c_fault(true);
        }
    }

    /// Bring a model into this world: inputs set, start-up faults found.
    pub fn apply(&self, model: &mut Slave) {
        if let Some(inputs) = self.inputs {
            model.set_inputs(inputs);
        }
        if !self.init_faults.is_empty() {
            model.power_up_with(self.init_faults.iter().copied(), true);
        }
        self.inject_position_faults(model);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_are_read_by_their_names_and_an_unknown_one_is_named() {
        let w = World::from_names(None, ["watchdog", "counter"], ["multiturn-sync"], true).unwrap();
        assert_eq!(w.init_faults, [InitFault::Watchdog, InitFault::Counter]);
        assert_eq!(w.position_faults, [PositionFault::MultiturnSync]);
        assert!(w.i2c_fault && !w.is_default());
        let e = World::from_names(None, ["watchdog", "dog"], [], false).unwrap_err().to_string();
        assert!(e.starts_with("unknown start-up fault `dog` (known: alignment-data, "), "{e}");
        let e = World::from_names(None, [], ["watchdog"], false).unwrap_err().to_string();
        assert!(e.starts_with("unknown position fault `watchdog`"), "{e}");
        assert!(World::from_names(None, [], [], false).unwrap().is_default());
    }
}
