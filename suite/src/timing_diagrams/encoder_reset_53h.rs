//! The fourth diagram: an Encoder Reset (53h), the silence that answers it, and the
//! power-up sequence from the reset on (000:T29).

use super::caption::{hex, hex_plain, ids, ms, Caption};
use super::power_states::{boundary_markers, phase_figure};
use super::run::{joined, phases, read_position, request, send, Phase};
use super::svg::{
    char_boxes, lane_name, marker, phase_boxes, Axis, Font, Svg, BLUE, BLUE_FILL, GREEN, GREEN_FILL, ORANGE, PLOT_LEFT,
    PLOT_RIGHT, RED, WIDTH,
};
use super::{Diagram, Surprise};
use hiperface_model::clause;
use hiperface_model::request::Request;
use hiperface_model::{profiles, Reply, Slave};

/// An Encoder Reset (53h): the request, what the model answers (silence), and the
/// power-up sequence from the reset on. // 000:T29
pub(super) fn encoder_reset_53h() -> Result<Diagram, Surprise> {
    let profile = profiles::srs50();
    let mut slave = Slave::operational(profile);
    let settings = slave.listening_settings(0).ok_or(Surprise("the operational SRS50 does not listen"))?;
    let before = slave.clone();
    let frame = request(&profile, Request::EncoderReset);
    let sent = send(&mut slave, &frame, 0, settings);
    let step = sent.step()?;
    let reply = sent.reply().ok();
    let silence = match step.outcome.reply {
        Reply::Silent(why) => format!("no reply ({why:?})"),
        Reply::Frame(_) => "a reply".to_string(),
    };
    let (last_end, reset_at) = (sent.last_end_us(), step.received.complete_us);
    let timeout = reset_at - last_end;
    let end = reset_at + (profile.user_settings_ms as u64 + 300) * 1000;
    let all = joined(phases(&before, 0, reset_at), phases(&slave, reset_at, end));
    // The first time the slave listens again, and a Read Position sent then.
    let resume = all.iter().find(|p| p.from_us >= reset_at && p.listening.is_some()).map(|p| p.from_us);
    let resume = resume.ok_or(Surprise("the slave does not listen again after Encoder Reset"))?;
    let mut probe = slave.clone();
    let heard = probe.listening_settings(resume).ok_or(Surprise("the slave does not listen after the reset"))?;
    let probe_sent = send(&mut probe, &read_position(&profile), resume, heard);
    let (probe_t, _) = probe_sent.reply()?;

    let title = format!("Encoder Reset (53h) with an {} at {}", profile.name, settings);
    let mut svg = Svg::new(WIDTH, 516.0);
    svg.text(20.0, 30.0, &title, Font::TITLE);

    // Panel A: the request and the reset, in ms.
    svg.text(20.0, 62.0, "The request and the reset", Font::HEADING);
    let zoom = Axis::new(0, reset_at + 3000, PLOT_LEFT, PLOT_RIGHT);
    let (master_y, state_y) = (92.0, 172.0);
    lane_name(&mut svg, master_y + 16.0, "master → slave", &format!("request {}", hex_plain(&frame)));
    lane_name(&mut svg, state_y + 16.0, "slave state", "");
    char_boxes(&mut svg, &zoom, &sent.chars, master_y, (BLUE_FILL, BLUE));
    if let Some((_, chars)) = &reply {
        char_boxes(&mut svg, &zoom, chars, master_y + 34.0, (GREEN_FILL, GREEN));
    }
    let zoomed: Vec<Phase> =
        all.iter().filter(|p| p.from_us < zoom.t1).map(|p| Phase { to_us: p.to_us.min(zoom.t1), ..*p }).collect();
    phase_boxes(&mut svg, &zoom, &zoomed, state_y);
    svg.span(
        zoom.x(last_end),
        zoom.x(reset_at),
        master_y + 44.0,
        &format!("request timeout {}", ms(timeout)),
        clause::TIMEOUT.id(),
        ORANGE,
    );
    marker(
        &mut svg,
        zoom.x(reset_at),
        (master_y - 16.0, state_y + 42.0),
        &format!("reset at {}: {silence} · {}", ms(reset_at), clause::ENCODER_RESET.id()),
        RED,
    );
    zoom.draw(&mut svg, state_y + 56.0, &zoom.every(1000));

    // Panel B: the power-up from the reset.
    let top = state_y + 116.0;
    svg.text(20.0, top, "The power-up sequence from the reset", Font::HEADING);
    let axis = Axis::new(0, end, PLOT_LEFT, PLOT_RIGHT);
    let (lane_y, probe_y, axis_y) = (top + 60.0, top + 134.0, top + 176.0);
    lane_name(&mut svg, lane_y + 18.0, "slave state", "no further request");
    lane_name(&mut svg, probe_y + 4.0, "master", "");
    phase_boxes(&mut svg, &axis, &all, lane_y);
    boundary_markers(&mut svg, &axis, &all, profile.edition, (lane_y - 12.0, axis_y), true);
    let x = axis.x(resume);
    svg.line((x, probe_y - 12.0), (x, probe_y + 8.0), BLUE, false);
    svg.text(
        x + 5.0,
        probe_y + 4.0,
        &format!(
            "Read Position sent at {} = reset + {} initialization: answered {} · {}",
            ms(resume),
            ms(resume - reset_at),
            hex_plain(probe_t.frame.as_bytes()),
            ids(&[clause::ENCODER_RESET.clause(), clause::MASTER_RESET_WAIT.clause()])
        ),
        Font::SMALL.colour(BLUE),
    );
    axis.draw(&mut svg, axis_y, &axis.every(100_000));

    let mut caption = Caption::new(&[
        format!(
            "An Encoder Reset (53h) sent to an operational {} at {} and what the model does with it: \
             {silence}. The reset takes effect when the request's timeout has elapsed, and the power-up \
             sequence of 000 Table 9 starts again from there (the settings of 67h are dropped and the \
             stored ones apply again after the default window).",
            profile.name, settings
        ),
        format!(
            "A master waits the request's timeout plus the initialization time before it talks again: a \
             Read Position sent at {} is answered.",
            ms(resume)
        ),
    ]);
    caption.figure("request", &hex(&frame), &[clause::ENCODER_RESET.clause(), clause::CHECKSUM.clause()]);
    caption.figure(
        "request timeout",
        &format!("{} after the last character, which ended at {}", ms(timeout), ms(last_end)),
        &[clause::TIMEOUT.clause(), clause::FRAME_TIMING.clause()],
    );
    caption.figure("reset executed", &format!("at {}, {silence}", ms(reset_at)), &[clause::ENCODER_RESET.clause()]);
    let after: Vec<&Phase> = all.iter().filter(|p| p.from_us >= reset_at).collect();
    for (i, p) in after.iter().enumerate() {
        phase_figure(&mut caption, p, i + 1 == after.len(), profile.edition);
    }
    caption.figure(
        "first request heard",
        &format!(
            "sent at {} (the timeout plus {} of initialization after the request), answered {}",
            ms(resume),
            ms(resume - reset_at),
            hex(probe_t.frame.as_bytes())
        ),
        &[clause::ENCODER_RESET.clause(), clause::MASTER_RESET_WAIT.clause()],
    );
    Ok(Diagram { id: "encoder-reset-53h", svg: svg.finish(&title), caption: caption.finish(), title })
}
