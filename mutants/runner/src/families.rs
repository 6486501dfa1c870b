//! The families' mutants: their names, and certifying one in a worker.

use crate::certify::Verdicts;
use crate::run::{Family, MutantName};
use crate::source;
use hiperface_model_mutated::mutant;

/// Every mutant of a family, in id order.
pub fn names(family: Family) -> Vec<MutantName> {
    match family {
        Family::Encoder | Family::Master => {
            let member = |m: &mutant::MutantInfo| match family {
                Family::Encoder => m.family == "encoder",
                _ => m.family == "master" || crate::master::SHARED.contains(&m.file),
            };
            mutant::ALL
                .iter()
                .filter(|m| member(m))
                .map(|m| MutantName {
                    family,
                    id: m.id,
                    key: hiperface_schemata::key(m.file, m.description, m.occurrence as usize),
                    function: m.function.to_string(),
                })
                .collect()
        }
        Family::Wire => crate::wire::names(),
    }
}

/// What a worker keeps between mutants of a family (the conformant device's reports).
pub enum Certifier {
    Encoder(source::Baselines),
    Wire(crate::wire::Baselines),
    Master(crate::master::Baselines),
}

impl Certifier {
    pub fn new(family: Family) -> Certifier {
        match family {
            Family::Encoder => Certifier::Encoder(source::Baselines::new()),
            Family::Wire => Certifier::Wire(crate::wire::Baselines::new()),
            Family::Master => Certifier::Master(crate::master::Baselines::new()),
        }
    }

    /// Certify mutant `id` of the family.
    pub fn certify(&mut self, id: u32) -> Verdicts {
        match self {
            Certifier::Encoder(b) => b.certify(id),
            Certifier::Wire(b) => b.certify(id),
            Certifier::Master(b) => b.certify(id),
        }
    }
}
