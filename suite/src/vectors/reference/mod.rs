//! The protocol reference: a chapter of the user guide per command, generated from the
//! vector files (`hiperface vectors book --out docs/src/reference`). Pure: the loaded
//! files in, the pages out (a path relative to the reference's folder, and its text).
//!
//! Every frame a page shows is a request or a reply of a vector, never typed here; each
//! is drawn as a byte diagram (an HTML table, a cell per byte, the row beneath naming
//! the bytes by the model's request and reply types) with its checksum worked out. A
//! chapter gives the command's row of the command table and its clause, the documents'
//! worked examples first (errata with the printed and the corrected bytes side by side),
//! then the generated examples that add an outcome the chapter has not shown yet.
//!
//! Past 400 lines for a reason: the pages, the diagrams and the names of the bytes are
//! one generator, read together.

mod bits;
mod pages;

use super::{parse_hex, Erratum, Expected, Setup, Vector, VectorFile, VectorStep};
use crate::report::escape;
use crate::timing_diagrams::Diagram;
use hiperface_model::clause;
use hiperface_model::command::{AccessCodeRule, CommandSet, CommandSpec, DataLength, Editions, COMMAND_TABLE};
use hiperface_model::{checksum, CommandId, Edition, Request, RequestFrame, Response, ResponseFrame};
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// The command that writes the reference into the user guide.
pub const REGENERATE: &str = "hiperface vectors book --out docs/src/reference";

/// The reference's first page.
pub const INDEX: &str = "index.md";

/// The pages of the reference from the vector files (each with its file name), in the
/// order of the book: the index, then a chapter per command of the current edition in
/// byte order, then the legacy edition's own commands that vectors exist for.
pub fn book(files: &[(String, VectorFile)]) -> Vec<(String, String)> {
    // Drawn once: each run of the model is the same.
    let diagrams = crate::timing_diagrams::diagrams();
    let chapters = chapters(files, &diagrams);
    let mut pages = vec![(INDEX.to_string(), index(files, &chapters))];
    pages.extend(chapters.iter().map(|c| (c.file.clone(), c.text.clone())));
    pages.extend(timing_pages(&diagrams));
    pages.push((pages::ERROR_CODES.to_string(), pages::error_codes()));
    pages.push((pages::EDITIONS.to_string(), pages::editions(files)));
    pages.push((pages::MASTER_TABLES.to_string(), pages::master_tables(files)));
    pages.push((STYLE_FILE.to_string(), STYLE_SHEET.to_string()));
    pages
}

/// The lines of the user guide's `SUMMARY.md` that list the reference's pages, under
/// `# Protocol reference`.
pub fn summary(pages: &[(String, String)]) -> String {
    let mut s = String::new();
    for (i, (path, text)) in pages.iter().filter(|(p, _)| p.ends_with(".md")).enumerate() {
        let title = text.lines().next().and_then(|l| l.strip_prefix("# ")).unwrap_or(path);
        let indent = if i == 0 { "" } else { "    " };
        let _ = writeln!(s, "{indent}- [{title}](reference/{path})");
    }
    s
}

/// How the pages found on disk differ from the pages the generator writes: a page
/// missing, one not generated, one whose text differs (with its first differing line).
pub fn differences(expected: &[(String, String)], found: &[(String, String)]) -> Vec<String> {
    let mut out = Vec::new();
    for (path, text) in expected {
        match found.iter().find(|(p, _)| p == path) {
            None => out.push(format!("{path}: missing")),
            Some((_, on_disk)) if on_disk != text => {
                let line = text.lines().zip(on_disk.lines()).position(|(a, b)| a != b);
                let line = line.unwrap_or_else(|| text.lines().count().min(on_disk.lines().count())) + 1;
                out.push(format!("{path}: differs from line {line}"));
            }
            Some(_) => {}
        }
    }
    for (path, _) in found.iter().filter(|(p, _)| !expected.iter().any(|(e, _)| e == p)) {
        out.push(format!("{path}: not generated (a stale page?)"));
    }
    out
}

/// The timing diagrams' pages and their SVG files (`svg/<id>.svg`): the power-up
/// sequences on a page of their own, the exchanges on another.
fn timing_pages(diagrams: &[Diagram]) -> Vec<(String, String)> {
    let page = |title: &str, intro: &str, power_up: bool| {
        let mut s = format!("# {title}\n\n{GENERATED}\n\n{intro}\n");
        for d in diagrams.iter().filter(|d| d.id.starts_with("power-up") == power_up) {
            let _ = write!(
                s,
                "\n## {}\n\n{}\n\n{}\n\nOn its own: `hiperface vectors show {}` (SVG).\n",
                md(&d.title),
                image(d),
                d.caption.trim(),
                d.id
            );
        }
        s
    };
    let mut out = vec![
        (
            TIMING.to_string(),
            page(
                "Timing",
                "Each diagram is drawn from the model run in virtual time: the characters at the line's \
                 rate, the times the model takes a request, answers it and listens again; every figure \
                 on a diagram is the model's, with the clause it comes from. The power-up sequence has \
                 [a page of its own](power-up.md).",
                false,
            ),
        ),
        (
            POWER_UP.to_string(),
            page(
                "The power-up sequence",
                "What a slave does after power-on or an Encoder Reset (53h), in both editions: when it \
                 does not listen, when it listens with the default settings and when with the stored \
                 ones (000 Table 9; 002 for the legacy edition). Drawn from the model's power-up state \
                 machine; every figure is the model's. [Timing](timing.md) has the exchanges.",
                true,
            ),
        ),
    ];
    out.extend(diagrams.iter().map(|d| (format!("svg/{}.svg", d.id), d.svg.clone())));
    out
}

/// A diagram on a page, a link to its SVG for the full size.
fn image(d: &Diagram) -> String {
    format!("[![{}](svg/{}.svg)](svg/{}.svg)", md(&d.title), d.id, d.id)
}

/// A command's own timing diagram (`exchange-42h`, `encoder-reset-53h`), shown in its
/// chapter too.
fn timing_of(id: CommandId, diagrams: &[Diagram]) -> String {
    let suffix = format!("-{:02x}h", id.byte());
    let Some(d) = diagrams.iter().find(|d| d.id.ends_with(&suffix)) else {
        return String::new();
    };
    format!(
        "\n## Timing\n\n{}\n\nDrawn from the model in virtual time; the figures and their clauses are on the \
         [timing](timing.md) page. On its own: `hiperface vectors show {}` (SVG).\n",
        image(d),
        d.id
    )
}

pub const TIMING: &str = "timing.md";
pub const POWER_UP: &str = "power-up.md";

/// How a piece of the reference is written out on its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PieceFormat {
    /// Markdown with the byte diagrams as HTML tables and their style (what the book's
    /// pages hold).
    Markdown,
    /// A standalone HTML page.
    Html,
    /// A timing diagram as an SVG document.
    Svg,
}

/// One example or diagram of the reference on its own, for a writer to put into a manual
/// of their own: a vector's example by the vector's id (Markdown or HTML), a timing
/// diagram by its id (SVG by default, or Markdown or HTML around it). `None` for the
/// format: the piece's own (Markdown for an example, SVG for a diagram).
pub fn piece(files: &[(String, VectorFile)], id: &str, format: Option<PieceFormat>) -> Result<String, PieceError> {
    let found = files.iter().find_map(|(n, f)| f.vectors.iter().find(|v| v.id == id).map(|v| (n.as_str(), v)));
    if let Some((file, v)) = found {
        if v.steps.is_empty() {
            return Err(PieceError::NoFrames(id.to_string()));
        }
        let text = example(file, v, &mut Vec::new());
        return match format.unwrap_or(PieceFormat::Markdown) {
            PieceFormat::Markdown => Ok(text),
            PieceFormat::Html => Ok(standalone(id, &text)),
            PieceFormat::Svg => Err(PieceError::ExampleAsSvg(id.to_string())),
        };
    }
    let diagrams = crate::timing_diagrams::diagrams();
    if let Some(d) = diagrams.iter().find(|d| d.id == id) {
        let text = format!("## {}\n\n{}\n\n{}\n", md(&d.title), d.svg.trim(), d.caption.trim());
        return Ok(match format.unwrap_or(PieceFormat::Svg) {
            PieceFormat::Svg => d.svg.clone(),
            PieceFormat::Markdown => text,
            PieceFormat::Html => standalone(id, &text),
        });
    }
    let known: Vec<&str> = diagrams.iter().map(|d| d.id).collect();
    Err(PieceError::Unknown { id: id.to_string(), diagrams: known.join(", ") })
}

/// Every id [`piece`] takes, one line each: the vectors' (id, command, what it shows,
/// its file) and the diagrams' (id, title), for `hiperface vectors list`.
pub fn list(files: &[(String, VectorFile)]) -> String {
    let mut out = String::new();
    for (name, file) in files {
        for v in &file.vectors {
            out.push_str(&format!("{}\t{}\t{} ({name})\n", v.id, v.command, v.meaning));
        }
    }
    for d in crate::timing_diagrams::diagrams() {
        out.push_str(&format!("{}\tdiagram\t{}\n", d.id, d.title));
    }
    out
}

/// Why [`piece`] has nothing to give.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PieceError {
    #[error("vector {0} has no frames to draw (a table row or a checksum example)")]
    NoFrames(String),
    #[error(
        "vector {0} is an example, drawn as byte diagrams in Markdown or HTML (--format markdown or html); \
         SVG is for the timing diagrams"
    )]
    ExampleAsSvg(String),
    #[error(
        "no vector or diagram has the id {id:?}; `hiperface vectors list` lists every id; the diagrams \
         are {diagrams}"
    )]
    Unknown { id: String, diagrams: String },
}

/// A standalone HTML page around Markdown (with HTML blocks in it).
fn standalone(title: &str, markdown: &str) -> String {
    let mut body = String::new();
    pulldown_cmark::html::push_html(
        &mut body,
        pulldown_cmark::Parser::new_ext(markdown, pulldown_cmark::Options::ENABLE_TABLES),
    );
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n\
         <style>body {{ font-family: sans-serif; max-width: 60em; margin: 1em auto; padding: 0 1em; }}\n{STYLE_SHEET}</style>\n\
         </head>\n<body>\n{body}</body>\n</html>\n",
        escape(title)
    )
}

/// A chapter: a command's page.
struct Chapter {
    spec: &'static CommandSpec,
    legacy: bool,
    file: String,
    text: String,
    /// The documents' examples and the generated ones shown.
    documents: usize,
    generated: usize,
}

/// A vector with the name of its file.
type Named<'a> = (&'a str, &'a Vector);

fn chapters(files: &[(String, VectorFile)], diagrams: &[Diagram]) -> Vec<Chapter> {
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
fn command_name(spec: &CommandSpec) -> String {
    format!("{:02X}h", spec.id.byte())
}

fn is_legacy(v: &Vector) -> bool {
    hiperface_model::profiles::builtin(&v.profile).is_some_and(|p| p.edition == Edition::Legacy)
}

/// What a step shows: the request's command, and the reply's command byte and error
/// code (or silence), under the vector's result.
type Outcome = (u8, Option<(u8, Option<u8>)>, u8);

fn outcomes(v: &Vector) -> Vec<Outcome> {
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

fn chapter(spec: &'static CommandSpec, legacy: bool, all: &[Named], diagrams: &[Diagram]) -> Chapter {
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
fn chapter_file(spec: &CommandSpec) -> String {
    format!("{:02x}h-{}.md", spec.id.byte(), slug(spec.name))
}

const GENERATED: &str = "<!-- Generated by `hiperface vectors book` from the vector files: do not edit. -->";

/// The byte diagrams' look: one style sheet, written beside the pages (the book loads
/// it as additional CSS, `docs/book.toml`) and put in the head of a standalone HTML
/// piece; never into a page's text.
pub const STYLE_SHEET: &str = include_str!("frames.css");

/// The style sheet's file name among the pages.
pub const STYLE_FILE: &str = "frames.css";

/// The paragraph of what the command does: its row of the command table, its clause.
fn what_it_does(spec: &CommandSpec, legacy: bool) -> String {
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
fn bit_fields(id: CommandId) -> String {
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

/// One example: a vector, its starting state, the erratum once, then each step's
/// request and reply.
fn example(file: &str, v: &Vector, errata: &mut Vec<Erratum>) -> String {
    let title = match v.source.as_str() {
        "generated" => md(&capitalised(&v.meaning)),
        source => format!("{}: {}", document(source), md(&v.meaning)),
    };
    let result = match v.result {
        Expected::Valid => "valid",
        Expected::Acceptable => "acceptable (NON-STRICT)",
        Expected::Invalid => "**invalid**: must not be produced, a master must reject it",
    };
    let mut s = format!(
        "\n### {title}\n\n`{}` in `{file}`; clauses {}; {result}.\n\n{}\n",
        v.id,
        v.clauses.join(", "),
        state(v)
    );
    if let Some(e) = &v.erratum {
        if errata.contains(e) {
            let _ = writeln!(s, "\nThe erratum above: printed `{}`, corrected `{}`.", e.printed, e.corrected);
        } else {
            errata.push(e.clone());
            s.push_str(&erratum(v, e));
        }
    }
    let many = v.steps.len() > 1;
    for (i, step) in v.steps.iter().enumerate() {
        let mut said = Vec::new();
        let after = if v.setup.power_on { " after power-on" } else { "" };
        if step.chars_at_us.is_empty() {
            if let Some(t) = step.at_us {
                said.push(format!("at t = {}{after}", ms(t)));
            }
        } else {
            let ends: Vec<String> = step.chars_at_us.iter().map(|t| ms(*t)).collect();
            let taken = step.at_us.map_or(String::new(), |t| format!(", the slave takes it at t = {}", ms(t)));
            said.push(format!("the request's characters end at t = {}{after}{taken}", ends.join(", ")));
        }
        if step.uart_fault {
            said.push(
                "a character of the request arrives with a UART fault (a parity, framing, noise or overrun \
                 fault: 000:T47 names the fault, not the character, and any character draws the same reply)"
                    .into(),
            );
        }
        if let Some(n) = &step.note {
            said.push(md(n));
        }
        match (many, said.is_empty()) {
            (true, _) => {
                let _ = write!(
                    s,
                    "\n**Step {}**{}\n",
                    i + 1,
                    if said.is_empty() { String::new() } else { format!(": {}.", said.join("; ")) }
                );
            }
            (false, false) => {
                let _ = write!(s, "\n{}.\n", capitalised(&said.join("; ")));
            }
            (false, true) => {}
        }
        s.push('\n');
        s.push_str(&step_html(step));
        s.push('\n');
    }
    s
}

/// The document a source names: `001 §5.1.4.9` from `001_9b88….txt §5.1.4.9`.
fn document(source: &str) -> String {
    let (file, place) = source.split_once(' ').unwrap_or((source, ""));
    let doc = file.split('_').next().unwrap_or(file);
    format!("{doc} {place}").trim().to_string()
}

/// The vector's starting state in words.
fn state(v: &Vector) -> String {
    let Setup { power_on, inputs, init_faults, position_faults, i2c_fault, counter, settings, requests } = &v.setup;
    let mut said = vec![format!("profile `{}`", v.profile)];
    if *power_on {
        said.push("from power-on, each step at its time after it".into());
    }
    if let Some(i) = inputs {
        let mut inputs = Vec::new();
        if let Some(p) = i.position {
            inputs.push(format!("raw position {p} steps"));
        }
        if let Some(sp) = i.speed {
            inputs.push(format!("speed {sp} rpm"));
        }
        if let Some(t) = i.temperature_c {
            inputs.push(format!("temperature {t} °C"));
        }
        if let Some(c) = i.led_current_ma {
            inputs.push(format!("transmitter current {c} mA"));
        }
        said.push(inputs.join(", "));
    }
    if !init_faults.is_empty() {
        said.push(format!("found at start-up: {}", init_faults.join(", ")));
    }
    if !position_faults.is_empty() {
        said.push(format!("position faults present: {}", position_faults.join(", ")));
    }
    if *i2c_fault {
        said.push("the internal I2C bus to the EEPROM is down".into());
    }
    if let Some(c) = counter {
        said.push(format!("counter {c}"));
    }
    if let Some(b) = settings {
        said.push(format!("stored settings byte {b}h"));
    }
    let mut out = format!("Starting state: {}.", said.join("; "));
    if !requests.is_empty() {
        out.push_str(&format!("\n\n{}", set_up(requests)));
    }
    out
}

/// The requests that bring the slave to a vector's starting state, labelled as set-up
/// (not part of the example) and, for the state every command vector shares, why.
fn set_up(requests: &[String]) -> String {
    let frames: Vec<String> = requests
        .iter()
        .map(|r| format!("`{r}` ({})", CommandId::of_frame(&parse_hex(r).unwrap_or_default())))
        .collect();
    let shared = requests == crate::vectors::fixtures::with_field_0().requests.as_slice();
    let why = if shared {
        ": data field 0 exists, the starting state every generated command example shares, so that the \
         data-field commands have a field to act on"
    } else {
        ": they bring the slave to the state this example needs"
    };
    let request = if requests.len() == 1 { "request" } else { "requests" };
    format!("Set-up, before the example (replies not shown): the {request} {}{why}.", frames.join(", "))
}

/// The printed and the corrected frame side by side, with the reason.
fn erratum(v: &Vector, e: &Erratum) -> String {
    let (printed, corrected) = (parse_hex(&e.printed).unwrap_or_default(), parse_hex(&e.corrected).unwrap_or_default());
    // A request where the corrected frame is one of the vector's requests; otherwise
    // the reply to the step's request.
    let request = v.steps.iter().find(|s| s.request == e.corrected || s.request == e.printed);
    let to = v.steps.iter().find(|s| s.response.as_deref() == Some(e.corrected.as_str()));
    let role = match (request, to) {
        (Some(_), _) => Role::Request,
        (None, Some(s)) => Role::Reply(CommandId::of_frame(&parse_hex(&s.request).unwrap_or_default())),
        (None, None) => Role::Request,
    };
    let differ: Vec<bool> = printed.iter().zip(&corrected).map(|(a, b)| a != b).collect();
    format!(
        "\n**Erratum**: {}.\n\n<div class=\"hf-erratum\">\n{}\n{}\n</div>\n",
        md(&e.reason),
        frame_html(&printed, role, "as printed", &differ),
        frame_html(&corrected, role, "corrected", &[]),
    )
}

#[derive(Clone, Copy)]
enum Role {
    Request,
    /// A reply to a request of this command.
    Reply(CommandId),
}

fn step_html(step: &VectorStep) -> String {
    let request = parse_hex(&step.request).unwrap_or_default();
    let to = CommandId::of_frame(&request);
    let reply = match step.response.as_deref().map(parse_hex) {
        Some(Ok(r)) => frame_html(&r, Role::Reply(to), "reply", &[]),
        _ => "<div class=\"hf-f\"><p class=\"hf-none\"><b>reply</b>: none, the slave stays silent</p></div>".into(),
    };
    format!("<div class=\"hf-step\">\n{}\n{reply}\n</div>\n", frame_html(&request, Role::Request, "request", &[]))
}

/// A frame as a byte diagram, its checksum worked out and, in a reply, the warning bit
/// spelled out. `marked`: the bytes to mark as wrong (an erratum's printed bytes).
fn frame_html(bytes: &[u8], role: Role, caption: &str, marked: &[bool]) -> String {
    let labels = match role {
        Role::Request => request_labels(bytes),
        Role::Reply(to) => reply_labels(bytes, to),
    };
    let n = bytes.len();
    let sum_ok = n >= 3 && checksum::xor(&bytes[..n - 1]) == bytes[n - 1];
    let mut s = String::from("<div class=\"hf-f\">");
    // Sixteen bytes to a table, each row of bytes with its row of names; the frame's
    // caption on the first.
    for start in (0..n).step_by(16) {
        let end = (start + 16).min(n);
        s.push_str("<table class=\"hf-frame\">");
        if start == 0 {
            let _ = write!(s, "<caption>{caption}</caption>");
        }
        s.push_str("\n<tr>");
        for (i, byte) in bytes.iter().enumerate().take(end).skip(start) {
            let kind = match i {
                0 => "hf-addr",
                1 => "hf-cmd",
                i if i + 1 == n && n >= 3 => "hf-sum",
                _ => "hf-data",
            };
            let bad = marked.get(i).copied().unwrap_or(false) || (i + 1 == n && n >= 3 && !sum_ok);
            let class = if bad { format!("{kind} hf-bad") } else { kind.to_string() };
            let _ = write!(s, "<td class=\"hf-b {class}\">{byte:02X}</td>");
        }
        s.push_str("</tr>\n<tr>");
        let mut i = start;
        while i < end {
            let span = labels[i..end].iter().take_while(|l| **l == labels[i]).count();
            let colspan = if span > 1 { format!(" colspan=\"{span}\"") } else { String::new() };
            let _ = write!(s, "<td class=\"hf-l\"{colspan}>{}</td>", escape(&labels[i]));
            i += span;
        }
        s.push_str("</tr>\n</table>\n");
    }
    if n >= 3 {
        let body: Vec<String> = bytes[..n - 1].iter().map(|b| format!("{b:02X}h")).collect();
        let xor = checksum::xor(&bytes[..n - 1]);
        let carried =
            if sum_ok { String::new() } else { format!("; the frame carries <b>{:02X}h</b>: wrong", bytes[n - 1]) };
        let _ =
            writeln!(s, "<p class=\"hf-xor\">checksum: <code>{} = {xor:02X}h</code>{carried}</p>", body.join(" XOR "));
    } else {
        let bytes = if n == 1 { "1 byte" } else { "2 bytes" };
        let _ =
            writeln!(s, "<p class=\"hf-xor\">{bytes}: too short for a checksum after the address and the command</p>");
    }
    for line in meanings(bytes, role, &labels) {
        let _ = writeln!(s, "<p class=\"hf-bits-said\">{}</p>", escape(&line));
    }
    if let (Role::Reply(_), Some(&command)) = (role, bytes.get(1)) {
        if command & 0x80 != 0 {
            let id = CommandId::decode(command & 0x7F);
            let what = if id == CommandId::ReadEncoderStatus && n == 4 {
                "50h, the error response (000:2.3.4/error)".to_string()
            } else {
                id.to_string()
            };
            let _ = writeln!(
                s,
                "<p class=\"hf-warn\">command byte {command:02X}h = 80h + {what}: bit 7 is the <b>warning bit</b> \
                 (000:2.3.4), set until the master reads the error stack with 50h or resets the slave with 53h</p>"
            );
        }
    }
    s.push_str("</div>");
    s
}

/// What the bytes of a frame that pack bits or count blocks say, by the model's
/// decoders (000:T23-T25, T28, T32, T33).
fn meanings(bytes: &[u8], role: Role, labels: &[String]) -> Vec<String> {
    use bits::Packed;
    let command = CommandId::of_frame(bytes);
    let mut out = Vec::new();
    for (byte, label) in bytes.iter().zip(labels) {
        let packed = match (label.as_str(), role) {
            ("settings", _) => Some(Packed::Settings),
            ("status", Role::Request) if command == CommandId::CreateDataField => Some(Packed::CreateRequest),
            ("status", Role::Reply(CommandId::CreateDataField)) => Some(Packed::CreateReply),
            ("status", Role::Reply(CommandId::DataFieldStatus)) => Some(Packed::FieldStatus),
            _ => None,
        };
        let said = match (packed, label.as_str()) {
            (Some(p), _) => format!("{label} {}", bits::spelled(p, *byte)),
            (None, "free 16-byte blocks") => {
                format!(
                    "free user memory {byte:02X}h = {byte} blocks of 16 bytes = {} bytes (000:T25)",
                    *byte as usize * 16
                )
            }
            (None, "memory, 16-byte blocks") => {
                format!(
                    "total memory {byte:02X}h = {byte} blocks of 16 bytes = {} bytes (000:T28)",
                    *byte as usize * 16
                )
            }
            (None, "data fields") => format!("{byte} data fields exist (000:T25)"),
            (None, "encoder type") if *byte == 0xFF => {
                "encoder type FFh: an Extended Type Label is available, read it as data field FFh (000:T28, 000:T19)"
                    .to_string()
            }
            (None, "encoder type") => format!("encoder type {byte:02X}h: a specific encoder type (000:T28)"),
            _ => continue,
        };
        out.push(said);
    }
    out
}

/// The address, the command and the checksum, and the data bytes between them.
fn frame_labels(bytes: &[u8], command: &str, data: Option<Vec<String>>) -> Vec<String> {
    let n = bytes.len();
    let mut out = Vec::with_capacity(n);
    if let Some(&a) = bytes.first() {
        out.push(if a == 0xFF { "broadcast address".to_string() } else { "address".to_string() });
    }
    if n >= 2 {
        out.push(command.to_string());
    }
    if n >= 3 {
        let len = n - 3;
        match data.filter(|d| d.len() == len) {
            Some(d) => out.extend(d),
            None => out.extend((1..=len).map(|i| format!("data {i}"))),
        }
        out.push("checksum".into());
    }
    out
}

/// `bytes` with the checksum it should carry: the layout of the data does not depend on
/// it, so a frame with a wrong checksum is named as the right one would be.
fn sealed(bytes: &[u8]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    if let Some((last, body)) = b.split_last_mut() {
        *last = checksum::xor(body);
    }
    b
}

fn request_labels(bytes: &[u8]) -> Vec<String> {
    let data = RequestFrame::decode(&sealed(bytes))
        .ok()
        .map(|f| request_fields(&f.request).into_iter().map(str::to_string).collect());
    let command = match CommandId::of_frame(bytes) {
        CommandId::Unknown(_) => "command (unknown)",
        _ => "command",
    };
    frame_labels(bytes, command, data)
}

fn reply_labels(bytes: &[u8], to: CommandId) -> Vec<String> {
    let decoded = if bytes.len() >= 3 { ResponseFrame::decode(&sealed(bytes), to).ok() } else { None };
    let warning = bytes.get(1).is_some_and(|c| c & 0x80 != 0);
    let error = matches!(decoded, Some(ResponseFrame { response: Response::Error(_), .. }));
    let command = match (error, warning) {
        (true, true) => "error response + warning bit",
        (true, false) => "error response",
        (false, true) => "command + warning bit",
        (false, false) => "command",
    };
    frame_labels(bytes, command, decoded.map(|f| response_fields(&f.response)))
}

const PRESET: &str = "preset, MSB first";

/// The names of a request's data bytes, in the order the model writes them.
fn request_fields(r: &Request) -> Vec<&'static str> {
    use Request::*;
    match r {
        ReadPosition | ReadCounter | IncrementCounter | MemoryStatus | ReadEncoderStatus | ReadTypeLabel
        | EncoderReset | ReadVersion | ReadSyncOffset => vec![],
        SetPosition { .. } | SetPositionInternalSync { .. } | SetPositionWithSync { .. } => {
            vec![PRESET, PRESET, PRESET, PRESET, "Code0"]
        }
        ReadAnalogValue { .. } => vec!["channel"],
        ResetCounter { .. } => vec!["Code0"],
        ReadData { .. } => vec!["field", "offset", "count", "access code"],
        StoreData { data, .. } => {
            let mut v = vec!["field", "offset", "count", "access code"];
            v.extend(std::iter::repeat_n("data", data.len()));
            v
        }
        DataFieldStatus { .. } => vec!["field"],
        CreateDataField { .. } => vec!["field", "status", "access code"],
        SetAccessCode { .. } => vec!["code number", "old code", "new code"],
        SetEncoderAddress { .. } => vec!["new address", "Code0"],
        SetSerialInterface { .. } => vec!["settings", "Code0"],
        TemporarilySetSerialInterface { .. } => vec!["settings"],
        SensorAdjustment { .. } => vec!["option", "Code0"],
    }
}

/// The names of a reply's data bytes, in the order the model writes them; an error
/// code with its name.
fn response_fields(r: &Response) -> Vec<String> {
    use Response::*;
    const POSITION: &str = "position, MSB first";
    let names: Vec<&str> = match r {
        PositionSet | CounterIncremented | CounterReset | AddressSet | PositionInternalSyncSet => vec![],
        Position(_) => vec![POSITION; 4],
        PositionWithSyncSet(_) => vec!["preset used, MSB first"; 4],
        AnalogValue { .. } => vec!["channel", "value, MSB first", "value, MSB first"],
        Counter(_) => vec!["counter, MSB first"; 3],
        Data { data, .. } => {
            let mut v = vec!["field", "offset", "count"];
            v.extend(std::iter::repeat_n("data", data.len()));
            v
        }
        DataStored { .. } => vec!["field", "offset", "count"],
        FieldStatus { .. } | FieldCreated { .. } => vec!["field", "status"],
        MemoryStatus { .. } => vec!["free 16-byte blocks", "data fields"],
        AccessCodeSet { .. } => vec!["code number"],
        EncoderStatus(code) | Error(code) => return vec![format!("error code: {}", code.name())],
        TypeLabel { .. } => vec!["settings", "encoder type", "memory, 16-byte blocks", "option"],
        Version(_) => {
            let mut v = vec!["serial number"; 9];
            v.extend(["firmware version"; 20]);
            v.extend(["firmware date"; 8]);
            v
        }
        SerialInterfaceSet { .. } | SerialInterfaceTemporarilySet { .. } => vec!["settings"],
        SensorAdjusted { .. } => vec!["option", "status"],
        SyncOffset(_) => vec!["sync offset"],
    };
    names.into_iter().map(str::to_string).collect()
}

/// The reference's first page: what it is, where it comes from, how to read it.
fn index(files: &[(String, VectorFile)], chapters: &[Chapter]) -> String {
    let used: Vec<String> = files
        .iter()
        .filter(|(_, f)| f.vectors.iter().any(|v| !v.steps.is_empty() || v.checksum_example.is_some()))
        .map(|(n, _)| format!("`{n}`"))
        .collect();
    let mut s = format!(
        "# The protocol reference\n\n{GENERATED}\n\n\
         A chapter per command of the current edition (000 Table 10), in byte order, and one for \
         the legacy edition's own command 63h (002). Every frame shown is a request or a reply of a \
         [golden vector](../golden-vectors.md), drawn as a byte diagram, with its checksum worked out; \
         none is typed by hand.\n\n\
         These pages are generated from the vector files {} (in `vectors/`) by\n\n\
         ```sh\n{REGENERATE}\n```\n\n\
         (`--dir DIR` reads the vector files from another folder). Do not edit them: a test \
         (`conformance/tests/vectors.rs`) fails when they differ from what the command writes, and \
         checks that every frame shown is a frame of a vector that `hiperface vectors verify` \
         replays through the model, and that every checksum worked out is right.\n",
        used.join(", ")
    );
    s.push_str(
        "\n## How to read a chapter\n\n\
         A chapter begins with the command's row of the command table and its clause, quoted. Then \
         come the documents' worked examples, as the documents print them; where a document prints \
         a frame wrongly, its **erratum** shows the printed and the corrected bytes side by side, the \
         wrong bytes marked, with the reason. Then the generated examples that add something: each \
         error code the command answers and when, silence, the warning bit.\n\n\
         A byte diagram is a frame, a cell per byte in hex: the address byte, the command byte, the \
         data bytes named as the model's request and reply types name them, and the checksum, the \
         XOR of all the bytes before it (000:2.3.3). A reply's command byte with bit 7 set carries \
         the **warning bit** (000:2.3.4); an error response carries 50h with the error code \
         (D0h with the warning bit).\n\n\
         The command byte of a reply (000:2.3.4):\n\n\
         <table class=\"hf-bits\">\n<tr><th>bit</th><th>7</th><th>6</th><th>5</th><th>4</th><th>3</th>\
         <th>2</th><th>1</th><th>0</th></tr>\n<tr><th>field</th><td><b>warning bit</b></td>\
         <td colspan=\"7\"><b>command</b></td></tr>\n<tr><th>values</th><td><code>0</code> no \
         warning<br><code>1</code> a warning or an error is on the stack</td><td colspan=\"7\">the \
         request's command byte, 40h to 6Ch; 50h in an error response</td></tr>\n</table>\n",
    );
    let examples: Vec<&Vector> = files.iter().flat_map(|(_, f)| &f.vectors).collect();
    let sums: Vec<&Vector> = examples.iter().copied().filter(|v| v.checksum_example.is_some()).collect();
    if !sums.is_empty() {
        s.push_str("\n## The checksum\n\n");
        for v in sums {
            if let Some(c) = &v.checksum_example {
                let bytes = parse_hex(&c.frame).unwrap_or_default();
                let body: Vec<String> = bytes.iter().map(|b| format!("{b:02X}h")).collect();
                let _ = writeln!(s, "- {}: {} = {}h (`{}`)", document(&v.source), body.join(" XOR "), c.checksum, v.id);
            }
        }
    }
    s.push_str(
        "\n## The chapters\n\n| command | name | the documents' examples | generated examples |\n|---|---|---|---|\n",
    );
    for c in chapters {
        let _ = writeln!(
            s,
            "| [{}]({}) | {}{} | {} | {} |",
            command_name(c.spec),
            c.file,
            c.spec.name,
            if c.legacy { " (legacy edition)" } else { "" },
            c.documents,
            c.generated
        );
    }
    s.push_str(
        "\n## Beyond the commands\n\n\
         - [Timing](timing.md): a request's bits on the wire, the timeout, the response window and the \
         pause, the power-up sequence of both editions, Encoder Reset, a change of settings; drawn from \
         the model in virtual time.\n\
         - [Error codes](error-codes.md): every code, its group and severity, how it reaches the master \
         and which commands list it.\n\
         - [The two editions](editions.md): where the legacy edition (002) differs, figure by figure.\n\
         - [Master-side tables](master-side-tables.md): quadrature counting, synchronization, octants and \
         the fault reaction, each row beside the model's answer.\n\n\
         One example or diagram on its own, for a manual of your own: `hiperface vectors show ID` \
         (a vector's id, such as `doc.001.4a-read-data`, or a diagram's, such as `exchange-42h`; \
         `--format html` for a page with the diagrams' style, `--format svg` for a diagram).\n",
    );
    s
}

/// A time after power-on, in ms.
fn ms(us: u64) -> String {
    match us % 1000 {
        0 => format!("{} ms", us / 1000),
        frac => format!("{}.{frac:03} ms", us / 1000),
    }
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
}

fn slug(name: &str) -> String {
    let words: Vec<String> = name
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(|w| w.to_ascii_lowercase())
        .collect();
    words.join("-")
}

/// Text for Markdown prose: no HTML, no emphasis by accident.
fn md(s: &str) -> String {
    escape(s).replace('*', "\\*").replace('_', "\\_")
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn files() -> Vec<(String, VectorFile)> {
        super::super::load_named(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../vectors")).unwrap()
    }

    #[test]
    fn a_chapter_per_command_of_the_current_edition_and_63h() {
        let pages = book(&files());
        assert_eq!(pages[0].0, INDEX);
        let names: Vec<&str> = pages.iter().map(|(p, _)| p.as_str()).collect();
        let md = names.iter().filter(|n| n.ends_with(".md")).count();
        // The index, 22 commands, 63h, timing, power-up, error codes, editions, master tables.
        assert_eq!(md, 1 + 22 + 1 + 5, "{names:?}");
        // The diagrams, and the one style sheet the pages share (in no page's text).
        let others: Vec<&&str> = names.iter().filter(|n| !n.ends_with(".md") && **n != STYLE_FILE).collect();
        assert!(others.iter().all(|n| n.starts_with("svg/") && n.ends_with(".svg")), "{others:?}");
        assert_eq!(names.iter().filter(|n| **n == STYLE_FILE).count(), 1);
        assert!(pages.iter().all(|(_, text)| !text.contains("<style>")), "no page carries its own style");
        assert_eq!(names[1], "42h-read-position.md");
        assert_eq!(names[23], "63h-set-position-with-internal-track-synchronisation.md");
        // Deterministic.
        assert_eq!(pages, book(&files()));
    }

    #[test]
    fn the_bytes_are_named_by_the_models_types() {
        assert_eq!(
            request_labels(&[0x40, 0x4A, 0x00, 0x00, 0x10, 0x55, 0x4F]),
            ["address", "command", "field", "offset", "count", "access code", "checksum"]
        );
        // A wrong checksum does not change the layout.
        assert_eq!(request_labels(&[0x40, 0x57, 0xE4, 0x55, 0x5C])[2..4], ["settings", "Code0"]);
        assert_eq!(reply_labels(&[0x40, 0x42, 0, 0, 0, 0, 0x02], CommandId::ReadPosition)[2], "position, MSB first");
        assert_eq!(
            reply_labels(&[0x40, 0xD0, 0x02, 0x92], CommandId::ReadPosition),
            ["address", "error response + warning bit", "error code: Incorrect internal angular offset", "checksum"]
        );
        // Unknown layouts are numbered.
        assert_eq!(request_labels(&[0x40, 0x42, 0x00, 0x02]), ["address", "command", "data 1", "checksum"]);
        assert_eq!(request_labels(&[0x40, 0x42]), ["address", "command"]);
    }

    #[test]
    fn the_checksum_is_worked_out_and_a_wrong_one_marked() {
        let good = frame_html(&[0x40, 0x42, 0x02], Role::Request, "request", &[]);
        assert!(good.contains("<code>40h XOR 42h = 02h</code></p>"), "{good}");
        let bad = frame_html(&[0x40, 0x4C, 0x00, 0xC8, 0x1E], Role::Reply(CommandId::DataFieldStatus), "x", &[]);
        assert!(bad.contains("40h XOR 4Ch XOR 00h XOR C8h = C4h</code>; the frame carries <b>1Eh</b>: wrong"), "{bad}");
        assert!(bad.contains("hf-sum hf-bad\">1E<"), "{bad}");
        let warning = frame_html(&[0x40, 0xCE, 0x70, 0x00, 0xFE], Role::Reply(CommandId::MemoryStatus), "x", &[]);
        assert!(warning.contains("CEh = 80h + 4Eh Memory Status: bit 7 is the <b>warning bit</b>"), "{warning}");
    }

    #[test]
    fn stale_pages_are_named() {
        let pages = vec![("a.md".to_string(), "x\ny\n".to_string()), ("b.md".to_string(), "z\n".to_string())];
        let found = vec![("a.md".to_string(), "x\nY\n".to_string()), ("c.md".to_string(), String::new())];
        assert_eq!(
            differences(&pages, &found),
            ["a.md: differs from line 2", "b.md: missing", "c.md: not generated (a stale page?)"]
        );
        assert!(differences(&pages, &pages).is_empty());
    }
}
