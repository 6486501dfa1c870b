//! The world a simulated encoder lives in: its physical inputs and the faults it
//! finds at start-up. The simulator serves a model in it, and the model the harness
//! grades against is put in the same one (`certify slave --port sim`, the encoder of
//! `certify master`).

use hiperface_model::Slave;

/// The device's physical inputs and the faults it found at start-up.
#[derive(Debug, Clone, Default)]
pub struct World {
    pub inputs: Option<hiperface_model::slave::inputs::PhysicalInputs>,
    pub init_faults: Vec<hiperface_model::slave::inputs::InitFault>,
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
    }

    /// Bring a model into this world: inputs set, start-up faults found.
    pub fn apply(&self, model: &mut Slave) {
        if let Some(inputs) = self.inputs {
            model.set_inputs(inputs);
        }
        if !self.init_faults.is_empty() {
            model.power_up_with(self.init_faults.iter().copied(), true);
        }
    }
}
