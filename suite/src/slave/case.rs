//! A case of the slave catalogue, and why one stops early.

use super::{Ctx, Needs};
use crate::line::LineError;
use crate::verdict::CaseResult;
use hiperface_model::clause::Clause;
use hiperface_model::Profile;

/// A case of the catalogue.
pub struct Case {
    pub id: &'static str,
    pub title: &'static str,
    pub clauses: &'static [Clause],
    pub needs: Needs,
    /// `Some(reason)` when the profile excludes the case.
    pub applies: fn(&Profile) -> Option<&'static str>,
    pub run: fn(&mut Ctx<'_>) -> Result<(), CaseError>,
}

/// Why a case stopped early.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error("{0}")]
    Line(#[from] LineError),
    /// The case cannot go on (e.g. a precondition failed); already recorded.
    #[error("{0}")]
    Abort(String),
    #[error("EEPROM write budget of {0} exhausted")]
    Budget(u32),
    #[error("the device has not answered any request: check the port, power, address and data rate")]
    Silent,
    #[error("interrupted")]
    Interrupted,
}

impl Case {
    /// A result for this case, before it runs.
    pub fn result(&self) -> CaseResult {
        CaseResult::named(self.id, self.title, self.clauses)
    }
}
