//! The world a simulated encoder lives in: its physical inputs, the faults it finds
//! at start-up and the faults of its position measurement. The simulator serves a
//! model in it, and the model the harness grades against is put in the same one
//! (`certify slave --port sim`, the encoder of `certify master`, an encoder certified
//! in-process with its world given).

use hiperface_model::Slave;

/// The device's physical inputs, the faults it found at start-up and the faults of its
/// position measurement.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct World {
    pub inputs: Option<hiperface_model::slave::inputs::PhysicalInputs>,
    pub init_faults: Vec<hiperface_model::slave::inputs::InitFault>,
    /// Reported on position commands while present (000:T39, T57, T61-T68).
    pub position_faults: Vec<hiperface_model::slave::inputs::PositionFault>,
    /// The internal I2C bus is down: the commands that need it answer 05h (000:T43).
    pub i2c_fault: bool,
}

impl World {
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
