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
//! Here the book, the index page and the single pieces; chapter.rs a command's
//! chapter, example.rs an example in it, frame.rs a frame's byte diagram, bits.rs the
//! packed bytes bit by bit, timing.rs the timing diagrams' pages, pages.rs the error
//! codes, the editions and the master-side tables.

mod bits;
mod chapter;
mod example;
mod frame;
mod pages;
mod timing;

use super::{parse_hex, Vector, VectorFile};
use crate::report::escape;
use chapter::{chapters, command_name, Chapter};
use example::{document, example};
use std::fmt::Write as _;
use timing::timing_pages;

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

const GENERATED: &str = "<!-- Generated by `hiperface vectors book` from the vector files: do not edit. -->";

/// The byte diagrams' look: one style sheet, written beside the pages (the book loads
/// it as additional CSS, `docs/book.toml`) and put in the head of a standalone HTML
/// piece; never into a page's text.
pub const STYLE_SHEET: &str = include_str!("frames.css");

/// The style sheet's file name among the pages.
pub const STYLE_FILE: &str = "frames.css";

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
    use super::frame::{frame_html, reply_labels, request_labels, Role};
    use super::*;
    use hiperface_model::CommandId;

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
