//! The timing diagrams in the reference: their two pages (power-up, exchanges), their
//! SVG files, and a command's own diagram in its chapter.

use super::{md, GENERATED, POWER_UP, TIMING};
use crate::timing_diagrams::Diagram;
use hiperface_model::CommandId;
use std::fmt::Write as _;

/// The timing diagrams' pages and their SVG files (`svg/<id>.svg`): the power-up
/// sequences on a page of their own, the exchanges on another.
pub(super) fn timing_pages(diagrams: &[Diagram]) -> Vec<(String, String)> {
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
pub(super) fn image(d: &Diagram) -> String {
    format!("[![{}](svg/{}.svg)](svg/{}.svg)", md(&d.title), d.id, d.id)
}

/// A command's own timing diagram (`exchange-42h`, `encoder-reset-53h`), shown in its
/// chapter too.
pub(super) fn timing_of(id: CommandId, diagrams: &[Diagram]) -> String {
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
