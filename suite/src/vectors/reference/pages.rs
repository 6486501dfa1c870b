//! The reference's table pages: the error codes (000 chapter 2.4.3 and Table 74, with the
//! commands whose tables list each), the two editions side by side (each row the model's
//! own figure or the model's reply), and the master-side tables as the vectors hold them
//! with the model's answer beside each row.

use super::chapter::chapter_file;
use super::{md, GENERATED};
use crate::report::escape;
use crate::vectors::{tables, VectorFile};
use hiperface_model::clause;
use hiperface_model::command::{CommandSpec, Editions, COMMAND_TABLE};
use hiperface_model::fault::{self, FaultCode, FaultGroup, Indication, Severity, Variant};
use hiperface_model::profiles;
use hiperface_model::slave::powerup::PowerUp;
use hiperface_model::{Profile, UartSettings};
use std::fmt::Write as _;

pub const ERROR_CODES: &str = "error-codes.md";
pub const EDITIONS: &str = "editions.md";
pub const MASTER_TABLES: &str = "master-side-tables.md";

/// A clause quoted as a block, its id first.
fn quote(id: &str) -> String {
    match clause::lookup(id) {
        Some(c) => format!("> **{id}**: “{}”\n", md(c.quote())),
        None => format!("> **{id}**\n"),
    }
}

/// The commands' chapters that list `code` among their errors, linked.
fn listing(code: FaultCode) -> String {
    // 000:2.4.2: every command can answer 09h to 0Ch.
    if matches!(code, FaultCode::Parity | FaultCode::Checksum | FaultCode::UnknownCommand | FaultCode::WrongLength) {
        return "every command (000:2.4.2)".into();
    }
    let commands: Vec<String> = COMMAND_TABLE
        .iter()
        .filter(|c| c.lists(code))
        .map(|c: &CommandSpec| format!("[{:02X}h]({})", c.id.byte(), chapter_file(c)))
        .collect();
    if commands.is_empty() {
        "none: stacked, read with 50h".into()
    } else {
        commands.join(" ")
    }
}

fn group(g: FaultGroup) -> &'static str {
    match g {
        FaultGroup::Initialization => "initialization",
        FaultGroup::Protocol => "protocol",
        FaultGroup::Data => "data",
        FaultGroup::Position => "position",
        FaultGroup::Others => "others",
    }
}

fn severity(s: Severity) -> &'static str {
    match s {
        Severity::Minor => "minor",
        Severity::Major => "major",
        Severity::Critical => "critical",
    }
}

/// The page of the error codes: how an error reaches the master, then a row per code.
pub fn error_codes() -> String {
    let mut s = format!("# Error codes, the warning bit and the error stack\n\n{GENERATED}\n\n");
    s.push_str(
        "A slave tells the master of a fault in one of two ways (000:2.3.4): it answers the request \
         with an **error response**, the command byte 50h and the error code instead of the reply \
         (D0h with the warning bit), or it answers normally with the **warning bit**, bit 7 of the \
         reply's command byte, set, and keeps the code on its **error stack** for the master to read \
         with Read Encoder Status (50h). Which way a fault takes depends on its group (000:T37).\n\n",
    );
    for id in ["000:2.3.4", "000:T37", "000:T27"] {
        s.push_str(&quote(id));
        s.push('\n');
    }
    s.push_str(
        "Each row below is the model's fault table (000 chapter 2.4.3 merged with Table 74, \
         `hiperface_model::fault::FAULT_TABLE`): the groups a code occurs in, how it is indicated, its \
         severity, and the commands whose table (000 Tables 12 to 36) lists it. The chapter of each \
         command shows the codes it answers with an example where the model can produce one.\n\n\
         | code | name | groups | indication | severity | listed by |\n|---|---|---|---|---|---|\n",
    );
    for code in FaultCode::ALL.iter().copied().filter(|c| *c != FaultCode::NoFault) {
        let rows: Vec<&fault::FaultRow> = fault::rows(code).filter(|r| r.variant != Variant::Linear).collect();
        let mut groups: Vec<&str> = rows.iter().map(|r| group(r.group)).collect();
        groups.dedup();
        let indication = if rows.iter().any(|r| r.indication == Indication::WarningBit) {
            "warning bit, stacked"
        } else {
            "error response"
        };
        let severities: Vec<&str> = {
            let mut v: Vec<Severity> = rows.iter().map(|r| r.severity).collect();
            v.sort();
            v.dedup();
            v.into_iter().map(severity).collect()
        };
        let _ = writeln!(
            s,
            "| {:02X}h | {} | {} | {indication} | {} | {} |",
            code.byte(),
            md(code.name()),
            groups.join(", "),
            severities.join(", "),
            listing(code)
        );
    }
    s.push_str(
        "\nThe legacy edition (002) names no error codes of its own: \"The actual available errors vary \
         according to MFB type and are always given on the data sheet\" (002:50h). A legacy profile's \
         codes are the same table's, as its data sheet lists them; see [the two editions](editions.md).\n",
    );
    s
}

/// A vector's reply to its first step, with the vector's id: "`40 50 08 18`
/// (`current.47h.increment-counter.error-08`)".
fn vector_reply(files: &[(String, VectorFile)], id: &str) -> String {
    let found = files.iter().flat_map(|(_, f)| &f.vectors).find(|v| v.id == id);
    match found.and_then(|v| v.steps.first()) {
        Some(step) => match &step.response {
            Some(r) => format!("`{r}` (`{id}`)"),
            None => format!("none (`{id}`)"),
        },
        None => format!("no vector `{id}`"),
    }
}

/// The two editions side by side, every figure the model's.
pub fn editions(files: &[(String, VectorFile)]) -> String {
    let (current, legacy) = (profiles::srs50(), profiles::legacy_srs());
    let mut s = format!("# The current and the legacy edition\n\n{GENERATED}\n\n");
    s.push_str(
        "000 is the current HIPERFACE specification; 002, the older SICK-STEGMANN description, is the \
         legacy edition a legacy profile (`Legacy-SRS`) follows. Each figure below is the model's, \
         asked of a current profile (SRS50) and a legacy one (Legacy-SRS); the power-up sequence of \
         each is drawn in [Timing](timing.md).\n\n| | current (000) | legacy (002) | clause |\n|---|---|---|---|\n",
    );
    let both = |s: &mut String, what: &str, f: &dyn Fn(&Profile) -> String, clause: &str| {
        let _ = writeln!(s, "| {what} | {} | {} | {clause} |", f(&current), f(&legacy));
    };
    let window = |p: &Profile, at_ms: u16| PowerUp::at(0).state(p, u64::from(at_ms) * 1000).name().to_string();
    both(&mut s, "initialization, no UART", &|p| format!("{} ms", p.init_ms), "000:T9, 002:57h");
    both(&mut s, "default settings until", &|p| format!("{} ms", p.default_window_ms), "000:T9, 002:57h");
    both(&mut s, "stored settings from", &|p| format!("{} ms", p.user_settings_ms), "000:T9, 002:57h");
    both(&mut s, "state 1000 ms after power-on", &|p| window(p, 1000), "000:T9, 002:57h");
    for (name, settings) in [("long", UartSettings::DEFAULT), ("short", short())] {
        both(
            &mut s,
            &format!("timeout, {name} ({:02X}h), character end to character end", settings.byte()),
            &|p| format!("{} bit times", settings.timeout_bits(p.edition)),
            "000:2.2.2, DESIGN:legacy-timeout",
        );
        both(
            &mut s,
            &format!("shortest pause after a reply, {name}, stop bit to start bit"),
            &|p| format!("{} bit times", settings.pause_bits(p.edition)),
            "000:2.2.2, 002:timing",
        );
    }
    let only = |e: Editions| -> String {
        let v: Vec<String> = COMMAND_TABLE
            .iter()
            .filter(|c| c.editions == e)
            .map(|c| format!("{:02X}h {}", c.id.byte(), c.name))
            .collect();
        if v.is_empty() {
            "none".into()
        } else {
            v.join(", ")
        }
    };
    let _ = writeln!(
        s,
        "| commands of this edition only | {} | {} | 000:T10, 002:63h |",
        only(Editions::CurrentOnly),
        only(Editions::LegacyOnly)
    );
    // Increment Counter at the top of the counter, as the generated vectors have it.
    let _ = writeln!(
        s,
        "| 47h Increment Counter at FFFFFFh: the reply | {} | {} | 000:T46, 002:47h |",
        vector_reply(files, "current.47h.increment-counter.error-08"),
        vector_reply(files, "legacy.47h.increment-counter.shows-08")
    );
    s.push_str(
        "| error codes | 000 chapter 2.4.3, [the table](error-codes.md) | the data sheet's (002:50h) | 000:2.4.3, 002:50h |\n",
    );
    s.push_str("\nThe clauses:\n\n");
    for id in ["000:T9", "002:57h", "000:2.2.2", "002:timing", "DESIGN:legacy-timeout", "000:T46", "002:47h", "002:50h"]
    {
        s.push_str(&quote(id));
        s.push('\n');
    }
    s
}

/// The short timeout with the default's other bits (64h).
fn short() -> UartSettings {
    UartSettings { timeout: hiperface_model::settings::TimeoutSelect::Short, ..UartSettings::DEFAULT }
}

/// The master-side tables of 000 chapter 3, each row as the vector file holds it (the
/// printed table, transcribed by hand) with the model's answer beside it.
pub fn master_tables(files: &[(String, VectorFile)]) -> String {
    let mut s = format!("# Master-side tables\n\n{GENERATED}\n\n");
    s.push_str(
        "The tables of 000 chapter 3 that a master computes by: each row as the vector file holds it \
         (`master-tables.json`, transcribed by hand from the printed table, row by row) and the model's \
         answer to the same input (`hiperface_model::master`). A row where the two differ would be \
         marked; `hiperface vectors verify` fails on it.\n",
    );
    const TABLES: &[(&str, &str, &str, &str)] = &[
        ("quadrature", "Quadrature counting (000 Table 72)", "A(n-1) B(n-1) A(n) B(n)", "counter"),
        ("sync", "Synchronization of the counter (000 3.2.5)", "f(i:i-1) a(4:3)", "q(n:5)"),
        ("octant", "The octant (000 3.2.4, step 1)", "Vsin ≥ 0, Vcos ≥ 0, |Vsin| < |Vcos|", "octant"),
        ("transformation", "The octant's transformation (000 3.2.4, step 2)", "octant", "X, Y"),
        ("retransformation", "The retransformation to the angle (000 3.2.4, step 5)", "octant", "φ"),
        ("fault-reaction", "The master's reaction to a fault (000 Table 74)", "code, group", "severity: response"),
    ];
    let vectors: Vec<&crate::vectors::Vector> = files.iter().flat_map(|(_, f)| &f.vectors).collect();
    for (table, title, input, output) in TABLES {
        let rows: Vec<(&str, &crate::vectors::TableCase)> = vectors
            .iter()
            .filter_map(|v| v.table_case.as_ref().filter(|t| t.table == *table).map(|t| (v.id.as_str(), t)))
            .collect();
        if rows.is_empty() {
            continue;
        }
        let clauses: Vec<&str> = vectors
            .iter()
            .filter(|v| v.table_case.as_ref().is_some_and(|t| t.table == *table))
            .flat_map(|v| v.clauses.iter().map(String::as_str))
            .fold(Vec::new(), |mut acc, c| {
                if !acc.contains(&c) {
                    acc.push(c);
                }
                acc
            });
        let _ = write!(
            s,
            "\n## {title}\n\n{} rows; clause {}.\n\n| {} | {} (as printed) | the model | vector |\n|---|---|---|---|\n",
            rows.len(),
            clauses.join(", "),
            escape(input),
            escape(output)
        );
        for (id, t) in rows {
            let model = match tables::evaluate(table, &t.input) {
                Ok(a) if a == t.output => "the same".to_string(),
                Ok(a) => format!("**differs**: {}", md(&a)),
                Err(e) => format!("**cannot evaluate**: {}", md(&e.to_string())),
            };
            let _ = writeln!(s, "| {} | {} | {model} | `{id}` |", md(&t.input), md(&t.output));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_named_code_has_a_row_and_the_common_ones_say_so() {
        let page = error_codes();
        for code in FaultCode::ALL.iter().filter(|c| **c != FaultCode::NoFault) {
            assert!(page.contains(&format!("| {:02X}h | ", code.byte())), "{code:?}");
        }
        assert!(
            page.contains("| 0Ah | Checksum error | protocol | error response | major | every command (000:2.4.2) |")
        );
        assert!(page.contains("| 1Eh | Encoder temperature critical | others | warning bit, stacked |"), "{page}");
        // 0Dh: listed by commands with arguments, linked to their chapters.
        assert!(page.contains("[57h](57h-set-serial-interface.md)"), "{page}");
    }

    #[test]
    fn the_editions_differ_where_the_model_says() {
        let page = editions(&super::super::tests::files());
        assert!(page.contains("| initialization, no UART | 100 ms | 100 ms |"), "{page}");
        assert!(page.contains("| default settings until | 900 ms | 1000 ms |"), "{page}");
        assert!(page
            .contains("| shortest pause after a reply, long, stop bit to start bit | 55 bit times | 44 bit times |"));
        // 000:T46 answers 08h; 002 stacks it behind the warning bit.
        let row = page.lines().find(|l| l.starts_with("| 47h")).unwrap();
        assert!(row.contains("`40 50 08 18` (`current.47h.increment-counter.error-08`)"), "{row}");
        assert!(row.contains("`40 C7 87` (`legacy.47h.increment-counter.shows-08`)"), "{row}");
        assert!(!editions(&[]).contains("`40 C7 87`"), "the replies are the vectors'");
    }
}
