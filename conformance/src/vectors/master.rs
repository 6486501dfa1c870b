//! Master-side table vectors (000 chapter 3): generated from the spec's tables and
//! evaluated against the model's master references.

use super::{TableCase, Vector, VectorFile, SCHEMA_VERSION};
use hiperface_model::fault::{FaultCode, FaultGroup, Severity, FAULT_TABLE};
use hiperface_model::master::fault_reaction;
use hiperface_model::master::interpolation;
use hiperface_model::master::quadrature::{self, Ab, Count};
use hiperface_model::master::sync::{self, Correction};

const OCTANT_TEXT: [&str; 8] = [
    "0: X=Vsin Y=Vcos phi=A",
    "1: X=Vcos Y=Vsin phi=90-A",
    "2: X=-Vcos Y=Vsin phi=90+A",
    "3: X=Vsin Y=-Vcos phi=180-A",
    "4: X=-Vsin Y=-Vcos phi=180+A",
    "5: X=-Vcos Y=-Vsin phi=270-A",
    "6: X=Vcos Y=-Vsin phi=270+A",
    "7: X=-Vsin Y=Vcos phi=360-A",
];

fn group_name(g: FaultGroup) -> &'static str {
    match g {
        FaultGroup::Initialization => "Initialization",
        FaultGroup::Protocol => "Protocol",
        FaultGroup::Data => "Data",
        FaultGroup::Position => "Position",
        FaultGroup::Others => "Others",
    }
}

fn severity_name(s: Severity) -> &'static str {
    match s {
        Severity::Minor => "Minor",
        Severity::Major => "Major",
        Severity::Critical => "Critical",
    }
}

/// Evaluate a table case against the model.
pub fn evaluate(table: &str, input: &str) -> Result<String, String> {
    let bits: Vec<bool> = input.chars().filter(|c| !c.is_whitespace()).map(|c| c == '1' || c == 'T').collect();
    match table {
        "quadrature" if bits.len() == 4 => {
            Ok(match quadrature::step(Ab { a: bits[0], b: bits[1] }, Ab { a: bits[2], b: bits[3] }) {
                Count::Up => "+1",
                Count::Down => "-1",
                Count::NoAction => "none",
                Count::Invalid => "invalid",
            }
            .into())
        }
        "sync" if bits.len() == 4 => {
            let f = (bits[0] as u8) << 1 | bits[1] as u8;
            let a = (bits[2] as u8) << 1 | bits[3] as u8;
            Ok(match sync::correction(f, a) {
                Correction::Same => "a",
                Correction::PlusOne => "a+1",
                Correction::MinusOne => "a-1",
                Correction::Invalid => "invalid",
            }
            .into())
        }
        "octant" if bits.len() == 3 => {
            // A representative sample with these signs and magnitudes.
            let (mag_s, mag_c) = if bits[2] { (3, 5) } else { (5, 3) };
            let s = if bits[0] { mag_s } else { -mag_s };
            let c = if bits[1] { mag_c } else { -mag_c };
            let o = interpolation::octant(s, c);
            Ok(OCTANT_TEXT[o as usize].into())
        }
        "fault-reaction" => {
            let mut parts = input.split_whitespace();
            let code =
                parts.next().and_then(|c| u8::from_str_radix(c.trim_end_matches('h'), 16).ok()).ok_or("bad code")?;
            let group = match parts.next() {
                Some("Initialization") => Some(FaultGroup::Initialization),
                Some("Protocol") => Some(FaultGroup::Protocol),
                Some("Data") => Some(FaultGroup::Data),
                Some("Position") => Some(FaultGroup::Position),
                Some("Others") => Some(FaultGroup::Others),
                _ => None,
            };
            let r = fault_reaction::reaction(FaultCode::decode(code), group);
            Ok(format!("{}: {}", severity_name(r.severity), r.response))
        }
        _ => Err(format!("unknown table case `{table}` / `{input}`")),
    }
}

fn case(id: String, table: &str, clause: &str, input: String, meaning: String) -> Vector {
    let output = evaluate(table, &input).unwrap_or_else(|e| format!("GENERATOR ERROR: {e}"));
    Vector {
        table_case: Some(TableCase { table: table.into(), input, output }),
        ..Vector::new(
            id,
            "000_a065519ffa299c0b.txt chapter 3".into(),
            &[clause],
            "Reference",
            format!("master: {table}"),
            meaning,
        )
    }
}

/// Every row of the master-side tables.
pub fn file() -> VectorFile {
    let mut v = Vec::new();
    for row in 0..16u8 {
        let input = format!("{}{}{}{}", row >> 3 & 1, row >> 2 & 1, row >> 1 & 1, row & 1);
        v.push(case(
            format!("master.quadrature.{input}"),
            "quadrature",
            "000:T72",
            input,
            "A/B of the previous and the current sample".into(),
        ));
    }
    for f in 0..4u8 {
        for a in 0..4u8 {
            let input = format!("{:02b} {:02b}", f, a);
            v.push(case(
                format!("master.sync.{:02b}-{:02b}", f, a),
                "sync",
                "000:3.2.5",
                input,
                "fine-angle quadrant and absolute a(4:3): the counter's period".into(),
            ));
        }
    }
    for o in 0..8u8 {
        let (s, c, smaller) = match o {
            0 => ("T", "T", "T"),
            1 => ("T", "T", "F"),
            2 => ("T", "F", "F"),
            3 => ("T", "F", "T"),
            4 => ("F", "F", "T"),
            5 => ("F", "F", "F"),
            6 => ("F", "T", "F"),
            _ => ("F", "T", "T"),
        };
        let input = format!("{s} {c} {smaller}");
        v.push(case(
            format!("master.octant.{o}"),
            "octant",
            "000:3.2.4",
            input,
            "octant, transformation and retransformation".into(),
        ));
    }
    for r in FAULT_TABLE {
        let input = format!("{:02X}h {}", r.code.byte(), group_name(r.group));
        let id = format!("master.fault-reaction.{:02x}-{}", r.code.byte(), group_name(r.group).to_lowercase());
        v.push(case(id, "fault-reaction", "000:T74", input, r.reference.into()));
    }
    v.push(case(
        "master.fault-reaction.unknown".into(),
        "fault-reaction",
        "000:T74",
        "42h".into(),
        "an unknown fault code: the worst-case reaction".into(),
    ));
    VectorFile {
        schema_version: SCHEMA_VERSION,
        description: "Master-side tables of 000 chapter 3, row by row".into(),
        vectors: v,
    }
}
