//! Master-side table vectors (000 chapter 3). `vectors/master-tables.json` is written by
//! hand from the printed tables, row by row, in the document's own words; this module
//! asks the model the same question and says its answer in those words, so that a
//! vector compares the model with the document, never with itself.

use hiperface_model::fault::{FaultCode, FaultGroup, Severity, Variant};
use hiperface_model::master::fault_reaction;
use hiperface_model::master::interpolation::{self, OCTANT};
use hiperface_model::master::quadrature::{self, Ab, Count};
use hiperface_model::master::sync::{self, Correction};
use std::ops::Neg;

/// A row the table cannot take (an unknown table, or an input not in its words), and
/// why: each word names what the printed table has in its place.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RowError {
    #[error("unknown table row `{table}` / `{input}`")]
    UnknownRow { table: String, input: String },
    #[error("fault-reaction input `{0}`: expected `CODEh [+ CODEh | [linear]] GROUP`")]
    FaultReactionInput(String),
    /// A signal level of the quadrature table (000:T72).
    #[error("`{0}`: expected 0 or 1")]
    Bit(String),
    /// A two-bit counter value of the synchronisation table (000:3.2.5).
    #[error("`{0}`: expected two bits")]
    TwoBits(String),
    /// A comparison of the octant table (000:3.2.4).
    #[error("`{0}`: expected True or False")]
    Truth(String),
    #[error("`{0}`: expected an octant 0...7")]
    Octant(String),
    /// A fault code as the fault reaction table prints it (000:T73).
    #[error("`{0}`: expected a code like 06h")]
    HexCode(String),
    #[error("`{0}`: not a fault group of 000:T37")]
    FaultGroup(String),
}

/// Evaluate a table row's input against the model; the answer in the printed table's
/// vocabulary.
pub fn evaluate(table: &str, input: &str) -> Result<String, RowError> {
    let words: Vec<&str> = input.split_whitespace().collect();
    match (table, words.as_slice()) {
        ("quadrature", [a1, b1, a, b]) => {
            let (previous, current) = (Ab { a: bit(a1)?, b: bit(b1)? }, Ab { a: bit(a)?, b: bit(b)? });
            Ok(match quadrature::step(previous, current) {
                Count::Up => "+1",
                Count::Down => "-1",
                Count::NoAction => "No action",
                Count::Invalid => "Invalid",
            }
            .into())
        }
        ("sync", [f, a]) => Ok(match sync::correction(two_bits(f)?, two_bits(a)?) {
            Correction::Same => "a(n:5)",
            Correction::PlusOne => "a(n:5) + 1",
            Correction::MinusOne => "a(n:5) - 1",
            Correction::Invalid => "Invalid",
        }
        .into()),
        ("octant", [s, c, smaller]) => Ok(interpolation::octant_of(truth(s)?, truth(c)?, truth(smaller)?).to_string()),
        ("transformation", [o]) => {
            let (x, y) = interpolation::transform_with(octant(o)?, Signal::plain("Vsin"), Signal::plain("Vcos"));
            Ok(format!("X = {x}, Y = {y}"))
        }
        ("retransformation", [o]) => {
            // φ = base ± A: the angle at A = 0 and the direction A moves it.
            let o = octant(o)?;
            let at_zero = interpolation::retransform(o, 0);
            let rising = interpolation::retransform(o, 1) == at_zero.wrapping_add(1);
            let base = match (at_zero / OCTANT * 45, rising) {
                (0, false) => 360,
                (degrees, _) => degrees,
            };
            Ok(match (base, rising) {
                (0, true) => "φ = A".into(),
                (b, true) => format!("φ = {b}° + A"),
                (b, false) => format!("φ = {b}° - A"),
            })
        }
        ("fault-reaction", [code, rest @ ..]) => {
            let code = FaultCode::decode(hex_code(code)?);
            let (variant, group) = match rest {
                ["+", with, group] => (Variant::With(FaultCode::decode(hex_code(with)?)), *group),
                ["[linear]", group] => (Variant::Linear, *group),
                [group] => (Variant::Any, *group),
                [] => (Variant::Any, ""),
                _ => return Err(RowError::FaultReactionInput(input.to_string())),
            };
            let group = match group {
                "" => None,
                g => Some(fault_group(g)?),
            };
            let r = fault_reaction::reaction_to(code, group, variant);
            if !r.known {
                return Ok(format!(
                    "worst case ({})",
                    if r.severity == Severity::Critical { "motor stop" } else { "?" }
                ));
            }
            Ok(format!("{:?}: {}", r.severity, r.response.unwrap_or("-")))
        }
        _ => Err(RowError::UnknownRow { table: table.to_string(), input: input.to_string() }),
    }
}

/// A signal named as the printed table names it, possibly negated: lets the model's
/// generic transformation print itself.
#[derive(Clone, Copy)]
struct Signal {
    name: &'static str,
    negated: bool,
}

impl Signal {
    fn plain(name: &'static str) -> Signal {
        Signal { name, negated: false }
    }
}

impl Neg for Signal {
    type Output = Signal;
    fn neg(self) -> Signal {
        Signal { negated: !self.negated, ..self }
    }
}

impl std::fmt::Display for Signal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}{}", if self.negated { "-" } else { "" }, self.name)
    }
}

fn bit(w: &str) -> Result<bool, RowError> {
    match w {
        "0" => Ok(false),
        "1" => Ok(true),
        _ => Err(RowError::Bit(w.to_string())),
    }
}

fn two_bits(w: &str) -> Result<u8, RowError> {
    match w.as_bytes() {
        [h, l] => Ok((bit(&(*h as char).to_string())? as u8) << 1 | bit(&(*l as char).to_string())? as u8),
        _ => Err(RowError::TwoBits(w.to_string())),
    }
}

fn truth(w: &str) -> Result<bool, RowError> {
    match w {
        "True" => Ok(true),
        "False" => Ok(false),
        _ => Err(RowError::Truth(w.to_string())),
    }
}

fn octant(w: &str) -> Result<u8, RowError> {
    w.parse::<u8>().ok().filter(|o| *o < 8).ok_or_else(|| RowError::Octant(w.to_string()))
}

fn hex_code(w: &str) -> Result<u8, RowError> {
    w.strip_suffix('h').and_then(|h| u8::from_str_radix(h, 16).ok()).ok_or_else(|| RowError::HexCode(w.to_string()))
}

fn fault_group(w: &str) -> Result<FaultGroup, RowError> {
    Ok(match w {
        "Initialization" => FaultGroup::Initialization,
        "Protocol" => FaultGroup::Protocol,
        "Data" => FaultGroup::Data,
        "Position" => FaultGroup::Position,
        "Others" => FaultGroup::Others,
        _ => return Err(RowError::FaultGroup(w.to_string())),
    })
}
