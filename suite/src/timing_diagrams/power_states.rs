//! The power-up states (000:T9) as captions and markers: shared by the power-up,
//! Encoder Reset and settings diagrams.

use super::caption::{ms, Caption};
use super::run::Phase;
use super::svg::{Anchor, Axis, Font, Svg, GREY, INK};
use hiperface_model::clause::{self, Clause};
use hiperface_model::settings::Edition;
use hiperface_model::slave::powerup::CommState;

/// The clauses a power-up state comes from in `edition`: 000 Table 9, or 002's
/// "about 1 second" of default settings (002 gives no initialization time; the legacy
/// profile keeps 000's).
pub(super) fn state_clauses(state: CommState, edition: Edition) -> Vec<Clause> {
    let source = state_source(state, edition);
    match state {
        CommState::DefaultCommunication => vec![source, clause::SETTINGS_BYTE.clause()],
        CommState::OperationalDefault => vec![source, clause::POWER_UP_POLICY],
        CommState::OperationalUser => vec![source, clause::SET_SERIAL.clause()],
        CommState::Initialization | CommState::ChangeOfSettings => vec![source],
    }
}

/// The clause a power-up state and its duration come from.
pub(super) fn state_source(state: CommState, edition: Edition) -> Clause {
    match (state, edition) {
        (CommState::Initialization, _) | (_, Edition::Current) => clause::STATE_MACHINE.clause(),
        (_, Edition::Legacy) => clause::LEGACY_DEFAULT_WINDOW.clause(),
    }
}

/// A phase as a caption's figure: "from 100 ms to 900 ms, listening with E4h (...)".
pub(super) fn phase_figure(caption: &mut Caption, p: &Phase, last: bool, edition: Edition) {
    let when = if last { format!("from {}", ms(p.from_us)) } else { format!("{} to {}", ms(p.from_us), ms(p.to_us)) };
    let listening = p.listening.map_or_else(|| "no UART communication".to_string(), |s| format!("listening with {s}"));
    caption.figure(p.state.name(), &format!("{when}, {listening}"), &state_clauses(p.state, edition));
}

/// Dashed lines at the state boundaries of `phases` from `y1` to `y2`; if `labelled`,
/// the time above and the clause it comes from: the end of the state
/// before (000:T9, 002:57h) or, into Initialization, the reset (000:T29).
pub(super) fn boundary_markers(
    svg: &mut Svg,
    axis: &Axis,
    phases: &[Phase],
    edition: Edition,
    (y1, y2): (f64, f64),
    labelled: bool,
) {
    for pair in phases.windows(2) {
        let [before, after] = pair else { continue };
        let x = axis.x(after.from_us);
        svg.line((x, y1), (x, y2), GREY, true);
        let source = match after.state {
            CommState::Initialization => clause::ENCODER_RESET.clause(),
            _ => state_source(before.state, edition),
        };
        if labelled {
            svg.text(x, y1 - 18.0, &ms(after.from_us), Font::SMALL.colour(INK).at(Anchor::Middle));
            svg.text(x, y1 - 5.0, source.id(), Font::SMALL.at(Anchor::Middle));
        }
    }
}
