//! Timing diagrams of the protocol reference as SVG, drawn from the model run in
//! virtual time (issue 41). Nothing here is a figure of its own: the characters are
//! fed to a [`Slave`](hiperface_model::Slave) at the ends of their stop bits, the
//! slave is polled at its deadlines, and every time, byte and setting a diagram
//! prints is what the model said, next to the id of the clause the model's code cites
//! for it.
//!
//! A file per diagram (exchange_42h.rs, power_up.rs, encoder_reset_53h.rs,
//! settings_67h.rs); what they share: run.rs (the model driven in virtual time),
//! svg.rs (the drawing primitives), caption.rs (figures as printed), power_states.rs
//! (the power-up states as lanes and figures).
//!
//! Pure: the diagrams are strings ([`Diagram::svg`] a standalone SVG document,
//! [`Diagram::caption`] Markdown); writing them is the caller's business.

use hiperface_model::settings::Edition;

use encoder_reset_53h::encoder_reset_53h;
use exchange_42h::exchange_42h;
use power_up::power_up;
use settings_67h::settings_67h;
use svg::{Font, Svg, RED, WIDTH};

mod caption;
mod encoder_reset_53h;
mod exchange_42h;
mod power_states;
mod power_up;
mod run;
mod settings_67h;
mod svg;

#[cfg(test)]
mod tests;

/// One timing diagram of the protocol reference.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagram {
    /// Stable id, used as file name `<id>.svg` and for export: "exchange-42h",
    /// "power-up-current", "power-up-legacy", "encoder-reset-53h", "settings-67h".
    pub id: &'static str,
    pub title: String,
    /// A standalone SVG document on a white background.
    pub svg: String,
    /// Markdown: what the diagram shows and a list of the numbers it prints, each with
    /// the clause ids it comes from.
    pub caption: String,
}

/// Every diagram, in reading order.
pub fn diagrams() -> Vec<Diagram> {
    let made: [(&'static str, Result<Diagram, Surprise>); 5] = [
        ("exchange-42h", exchange_42h()),
        ("power-up-current", power_up(Edition::Current)),
        ("power-up-legacy", power_up(Edition::Legacy)),
        ("encoder-reset-53h", encoder_reset_53h()),
        ("settings-67h", settings_67h()),
    ];
    made.into_iter().map(|(id, d)| d.unwrap_or_else(|why| not_drawn(id, why))).collect()
}

/// The model did not do what a diagram draws (a changed model): the diagram says so
/// instead of drawing figures that are not the model's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Surprise(&'static str);

/// What [`diagrams`] returns for a diagram the model could not be drawn from.
const NOT_DRAWN: &str = "Not drawn:";

fn not_drawn(id: &'static str, why: Surprise) -> Diagram {
    let title = format!("{id}: not drawn");
    let mut svg = Svg::new(WIDTH, 80.0);
    svg.text(20.0, 45.0, &format!("{NOT_DRAWN} {}", why.0), Font::LABEL.colour(RED));
    Diagram { id, svg: svg.finish(&title), caption: format!("{NOT_DRAWN} {}.\n", why.0), title }
}
