//! The second and third diagrams: the power-up sequence of each edition (000:T9,
//! 002:57h), and a request in the default settings' window keeping them.

use super::caption::{hex, hex_plain, ids, ms, Caption};
use super::power_states::{boundary_markers, phase_figure, state_clauses};
use super::run::{joined, phases, read_position, send, with_stored_settings};
use super::svg::{lane_name, listening_text, phase_boxes, Axis, Font, Svg, BLUE, PLOT_LEFT, PLOT_RIGHT, WIDTH};
use super::{Diagram, Surprise};
use hiperface_model::clause;
use hiperface_model::profiles;
use hiperface_model::settings::{Baud, Edition, UartSettings};
use hiperface_model::slave::powerup::CommState;

/// The power-up sequence of `edition` (000:T9, 002:57h): no UART, the default
/// settings' window, the change of settings, the stored settings; and the other
/// branch, a request in the default window keeping the default settings.
pub(super) fn power_up(edition: Edition) -> Result<Diagram, Surprise> {
    let (profile, id, source) = match edition {
        Edition::Current => (profiles::srs50(), "power-up-current", "000 Table 9"),
        Edition::Legacy => (profiles::legacy_srs(), "power-up-legacy", "002 on Set Serial Interface 57h"),
    };
    let stored = UartSettings { baud: Baud::B19200, ..UartSettings::DEFAULT };
    let slave = with_stored_settings(profile, stored)?;
    let end = (profile.user_settings_ms as u64 + 400) * 1000;
    let quiet = phases(&slave, 0, end);

    // The other branch: a Read Position in the default window, sent as the slave
    // listens then.
    let request_at = 300_000;
    let mut talked = slave.clone();
    let heard = talked.listening_settings(request_at).ok_or(Surprise("the slave does not listen at 300 ms"))?;
    let sent = send(&mut talked, &read_position(&profile), request_at, heard);
    let step = sent.step()?;
    let (t, _) = sent.reply()?;
    let processed = step.received.complete_us;
    let kept = joined(phases(&slave, 0, processed), phases(&talked, processed, end));

    let title = format!("Power-up of the {} profile ({} edition, {source})", profile.name, edition_name(edition));
    let mut svg = Svg::new(WIDTH, 380.0);
    svg.text(20.0, 30.0, &title, Font::TITLE);
    let axis = Axis::new(0, end, PLOT_LEFT, PLOT_RIGHT);
    let (lane_a, lane_b, axis_y) = (96.0, 196.0, 268.0);
    lane_name(&mut svg, lane_a + 18.0, "no request", "in the default window");
    lane_name(&mut svg, lane_b + 18.0, "Read Position", &format!("at {}", ms(request_at)));
    boundary_markers(&mut svg, &axis, &quiet, edition, (lane_a - 12.0, lane_a + 42.0), true);
    boundary_markers(&mut svg, &axis, &quiet, edition, (lane_b, axis_y), false);
    phase_boxes(&mut svg, &axis, &quiet, lane_a);
    phase_boxes(&mut svg, &axis, &kept, lane_b);
    let x = axis.x(request_at);
    svg.line((x, lane_b - 14.0), (x, lane_b + 42.0), BLUE, false);
    svg.text(
        x + 5.0,
        lane_b - 6.0,
        &format!(
            "Read Position {}–{}, processed at {}, answered {}; default settings kept · {}",
            ms(request_at),
            ms(sent.last_end_us()),
            ms(processed),
            hex_plain(t.frame.as_bytes()),
            ids(&state_clauses(CommState::OperationalDefault, edition))
        ),
        Font::SMALL.colour(BLUE),
    );
    axis.draw(&mut svg, axis_y, &axis.every(100_000));
    svg.text(
        PLOT_LEFT,
        axis_y + 48.0,
        &format!(
            "Stored settings {stored}, written with Set Serial Interface (57h) before this power-on · {}",
            clause::SET_SERIAL.id()
        ),
        Font::LABEL,
    );
    svg.text(
        PLOT_LEFT,
        axis_y + 68.0,
        &format!(
            "Boundaries from the model's PowerUp::next_change: initialization {}, default window {}, stored settings from {}",
            ms(profile.init_ms as u64 * 1000),
            ms(profile.default_window_ms as u64 * 1000),
            ms(profile.user_settings_ms as u64 * 1000)
        ),
        Font::LABEL,
    );
    if edition == Edition::Legacy {
        svg.text(
            PLOT_LEFT,
            axis_y + 88.0,
            "002 gives no initialization time and no silent change of settings; the legacy profile keeps 000's 100 ms.",
            Font::SMALL,
        );
    }

    let mut caption = Caption::new(&[
        format!(
            "The power-up of the built-in {} profile ({} edition) as the model runs it: the states and the \
             settings the slave listens with in each, with their boundaries from the model's power-up state \
             machine. The slave stored {stored} with Set Serial Interface (57h) before it was powered on at 0 ms, \
             so the default and the stored settings differ.",
            profile.name,
            edition_name(edition)
        ),
        format!(
            "Upper lane: no request until the default window ends, so the slave changes to the stored \
             settings. Lower lane: a Read Position sent at {} in the default settings is answered, and the \
             slave keeps the default settings until the next reset.{}",
            ms(request_at),
            if edition == Edition::Legacy {
                " 002 gives no initialization time; the legacy profile keeps the 100 ms of 000 Table 9, and \
                 switches from the default to the stored settings at once (no silent change of settings)."
            } else {
                ""
            }
        ),
    ]);
    for (i, p) in quiet.iter().enumerate() {
        phase_figure(&mut caption, p, i + 1 == quiet.len(), edition);
    }
    caption.figure(
        "Read Position in the default window",
        &format!(
            "sent at {}, processed at {}, answered {}; from then {}, listening with {}",
            ms(request_at),
            ms(processed),
            hex(t.frame.as_bytes()),
            talked.state(processed).name(),
            listening_text(talked.listening_settings(end))
        ),
        &state_clauses(CommState::OperationalDefault, edition),
    );
    Ok(Diagram { id, svg: svg.finish(&title), caption: caption.finish(), title })
}

pub(super) fn edition_name(edition: Edition) -> &'static str {
    match edition {
        Edition::Current => "current",
        Edition::Legacy => "legacy",
    }
}
