//! A chapter per command: its row of the command table and its clause, its packed
//! bytes bit by bit, the documents' examples, then the generated ones that add an
//! outcome the chapter has not shown yet.

use super::example::example;
use super::timing::timing_of;
use super::{bits, md, slug, GENERATED};
use crate::timing_diagrams::Diagram;
use crate::vectors::{parse_hex, Vector, VectorFile};
use hiperface_model::clause;
use hiperface_model::command::{AccessCodeRule, CommandSet, CommandSpec, DataLength, Editions, COMMAND_TABLE};
use hiperface_model::{CommandId, Edition};
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// A chapter: a command's page.
pub(super) struct Chapter {
    pub(super) spec: &'static CommandSpec,
    pub(super) legacy: bool,
    pub(super) file: String,
    pub(super) text: String,
    /// The documents' examples and the generated ones shown.
    pub(super) documents: usize,
    pub(super) generated: usize,
}

/// A vector with the name of its file.
pub(super) type Named<'a> = (&'a str, &'a Vector);

pub(super) fn chapters(files: &[(String, VectorFile)], diagrams: &[Diagram]) -> Vec<Chapter> {
    let all: Vec<Named> = files.iter().flat_map(|(n, f)| f.vectors.iter().map(move |v| (n.as_str(), v))).collect();
    let current = CommandSet::all_for(false);
    let mut out = Vec::new();
    for spec in COMMAND_TABLE.iter().filter(|s| current.contains(s.id)) {
        out.push(chapter(spec, false, &all, diagrams));
    }
    for spec in COMMAND_TABLE.iter().filter(|s| s.editions == Editions::LegacyOnly) {
        let c = chapter(spec, true, &all, diagrams);
        if c.documents + c.generated > 0 {
            out.push(c);
        }
    }
    out
}

/// The vector's command as the files write it ("42h").
pub(super) fn command_name(spec: &CommandSpec) -> String {
    format!("{:02X}h", spec.id.byte())
}

pub(super) fn is_legacy(v: &Vector) -> bool {
    hiperface_model::profiles::builtin(&v.profile).is_some_and(|p| p.edition == Edition::Legacy)
}

/// What a step shows: the request's command, and the reply's command byte and error
/// code (or silence), under the vector's result.
pub(super) type Outcome = (u8, Option<(u8, Option<u8>)>, u8);

pub(super) fn outcomes(v: &Vector) -> Vec<Outcome> {
    v.steps
        .iter()
        .map(|s| {
            let request = parse_hex(&s.request).unwrap_or_default();
            let reply = s.response.as_deref().and_then(|r| parse_hex(r).ok()).map(|r| {
                let command = r.get(1).copied().unwrap_or(0);
                (command, (command & 0x7F == 0x50).then(|| r.get(2).copied()).flatten())
            });
            (request.get(1).copied().unwrap_or(0), reply, v.result as u8)
        })
        .collect()
}

pub(super) fn chapter(spec: &'static CommandSpec, legacy: bool, all: &[Named], diagrams: &[Diagram]) -> Chapter {
    let name = command_name(spec);
    let ours = |v: &Vector| v.command == name && !v.steps.is_empty();
    let documents: Vec<Named> = all.iter().copied().filter(|(_, v)| ours(v) && v.source != "generated").collect();
    // The generated examples that add an outcome: one per distinct outcome, in file order.
    let mut seen: BTreeSet<Outcome> = documents.iter().flat_map(|(_, v)| outcomes(v)).collect();
    let generated: Vec<Named> = all
        .iter()
        .copied()
        .filter(|(_, v)| ours(v) && v.source == "generated" && is_legacy(v) == legacy)
        // Every outcome is taken in (no short cut): a later vector adds only what is new.
        .filter(|(_, v)| outcomes(v).into_iter().filter(|o| seen.insert(*o)).count() > 0)
        .collect();
    let title = format!("{name} {}{}", spec.name, if legacy { " (legacy edition)" } else { "" });
    let mut s = format!("# {title}\n\n{GENERATED}\n\n");
    s.push_str(&what_it_does(spec, legacy));
    s.push_str(&bit_fields(spec.id));
    s.push_str(&timing_of(spec.id, diagrams));
    let mut errata = Vec::new();
    let mut cited: Vec<String> = vec![spec.clause.id().to_string()];
    if !documents.is_empty() {
        s.push_str("\n## The documents' examples\n");
        for (file, v) in &documents {
            s.push_str(&example(file, v, &mut errata));
        }
    }
    if !generated.is_empty() {
        let first = if documents.is_empty() {
            "The documents print no example of this command. Each of these shows an outcome"
        } else {
            "Each adds an outcome the examples above do not show"
        };
        let _ = write!(
            s,
            "\n## Generated examples\n\n{first}: success, an error code the command answers and when, \
             silence, the warning bit. The model produced the replies; `hiperface vectors verify` replays them.\n",
        );
        for (file, v) in &generated {
            s.push_str(&example(file, v, &mut errata));
        }
    }
    for (_, v) in documents.iter().chain(&generated) {
        for c in &v.clauses {
            if !cited.contains(c) {
                cited.push(c.clone());
            }
        }
    }
    s.push_str("\n## Clauses\n\n");
    for id in &cited {
        match clause::lookup(id) {
            Some(c) => {
                let _ = writeln!(s, "- **{id}**: “{}”", md(c.quote()));
            }
            None => {
                let _ = writeln!(s, "- **{id}**");
            }
        }
    }
    let file = chapter_file(spec);
    Chapter { spec, legacy, file, text: s, documents: documents.len(), generated: generated.len() }
}

/// A command's chapter's file name: `42h-read-position.md`.
pub(super) fn chapter_file(spec: &CommandSpec) -> String {
    format!("{:02x}h-{}.md", spec.id.byte(), slug(spec.name))
}

/// The paragraph of what the command does: its row of the command table, its clause.
pub(super) fn what_it_does(spec: &CommandSpec, legacy: bool) -> String {
    let byte = spec.id.byte();
    let data = |d: DataLength| match d {
        DataLength::Fixed(0) => "no data".to_string(),
        DataLength::Fixed(1) => "1 data byte".to_string(),
        DataLength::Fixed(n) => format!("{n} data bytes"),
        DataLength::Range { min, max } => format!("{min} to {max} data bytes"),
        DataLength::NoFrame => "no reply".to_string(),
    };
    let reply = match (spec.slave_data, spec.max_response_ms) {
        (DataLength::NoFrame, _) => "The slave does not reply.".to_string(),
        (d, Some(ms)) => format!(
            "The reply carries {}; it must start within {ms} ms after the request's timeout (000:T10, \
             000:T8: transmission times and the timeout not included){}.",
            data(d),
            spec.strict_response_ms.map_or(String::new(), |s| format!("; {s} ms elsewhere, graded NON-STRICT"))
        ),
        (d, None) => format!("The reply carries {}; the data sheet gives its response time.", data(d)),
    };
    let access = match spec.access {
        AccessCodeRule::None => "needs no access code",
        AccessCodeRule::Code0 => "needs Code0",
        AccessCodeRule::FieldCode => "needs the access code of the data field (Code0 to Code3)",
    };
    let mut errors: Vec<String> = spec.errors.iter().map(|c| format!("{:02X}h {}", c.byte(), c.name())).collect();
    if errors.is_empty() {
        errors.push("none of its own".into());
    }
    let edition = match (legacy, spec.editions) {
        (true, _) => "a command of the legacy edition (002) only",
        (_, Editions::Both) => "a command of both editions",
        (_, _) => "a command of the current edition (000) only",
    };
    let mut s = format!(
        "**{} ({byte:02X}h)** is {edition}{}. The request carries {} after the address and the command \
         byte {byte:02X}h; it {access}. {reply}{}\n\n",
        spec.name,
        if spec.optional { ", optional (000:T10)" } else { "" },
        data(spec.master_data),
        if spec.writes_eeprom() { " It writes the encoder's non-volatile memory." } else { "" },
    );
    let _ = writeln!(s, "> **{}**: “{}”\n", spec.clause.id(), md(spec.clause.clause().quote()));
    let _ = writeln!(
        s,
        "Error codes its table lists, besides 09h, 0Ah, 0Bh and 0Ch of every command (000:2.4.2): {}.",
        errors.join(", ")
    );
    s.trim_end().to_string() + "\n"
}

/// The bytes of the command's frames that pack bits, drawn bit by bit (the layout's
/// values are the model's decoder's), and the Read Type Label's bytes.
pub(super) fn bit_fields(id: CommandId) -> String {
    use bits::Packed;
    let packed: &[Packed] = match id {
        CommandId::ReadTypeLabel | CommandId::SetSerialInterface | CommandId::TemporarilySetSerialInterface => {
            &[Packed::Settings]
        }
        CommandId::DataFieldStatus => &[Packed::FieldStatus],
        CommandId::CreateDataField => &[Packed::CreateRequest, Packed::CreateReply],
        _ => return String::new(),
    };
    let mut s = String::from("\n## Bit fields\n");
    if id == CommandId::ReadTypeLabel {
        s.push_str(
            "\nThe reply's four data bytes (000:T28): the UART settings byte as drawn below; the \
             encoder type, 00h to FEh a specific type, FFh an Extended Type Label available as data \
             field FFh (000:T19); the total memory in 16-byte blocks; the option code, 00h on new \
             devices.\n",
        );
    }
    for p in packed {
        let _ = write!(s, "\n### {} ({})\n\n{}", p.title(), p.clause(), bits::layout_html(*p));
        if matches!(p, Packed::Settings) && id != CommandId::ReadTypeLabel {
            s.push_str(
                "\nA value answered with 0Dh is one the model's settings decoder rejects; a data rate \
                 the device's data sheet does not list is answered with 0Dh too.\n",
            );
        }
    }
    s
}
