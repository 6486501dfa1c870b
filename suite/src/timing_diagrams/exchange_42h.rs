//! The first diagram: a Read Position (42h) exchange at the default settings, the
//! request bit by bit, the timeout the slave waits (000:2.2.2), the response window,
//! the reply and the pause after it.

use super::caption::{format_words, hex, ids, ms, Caption};
use super::run::{read_position, send};
use super::svg::{
    bit_trace, char_boxes, lane_name, marker, Anchor, Axis, Font, Svg, BLUE, BLUE_FILL, GREEN, GREEN_FILL, GREY,
    ORANGE, PLOT_LEFT, PLOT_RIGHT, PURPLE, WIDTH,
};
use super::{Diagram, Surprise};
use hiperface_model::clause;
use hiperface_model::{profiles, Slave};

/// A Read Position exchange with an SRS50 at the default settings: the request at
/// bit level, the timeout the slave waits, the response window, the reply, the pause.
pub(super) fn exchange_42h() -> Result<Diagram, Surprise> {
    let profile = profiles::srs50();
    let edition = profile.edition;
    let mut slave = Slave::operational(profile);
    let mut inputs = slave.inputs();
    inputs.position = 0x3039;
    slave.set_inputs(inputs);
    let settings = slave.listening_settings(0).ok_or(Surprise("the operational SRS50 does not listen"))?;
    let sent = send(&mut slave, &read_position(&profile), 0, settings);
    let step = sent.step()?;
    let (t, reply) = sent.reply()?;
    let last_end = sent.last_end_us();
    let timeout = step.received.complete_us - last_end;
    let reply_end = reply.last().map_or(t.earliest_start_us, |c| c.end_us);
    let pause = t.settings.pause_us(edition);
    let limit = profile.response_limit(hiperface_model::CommandId::ReadPosition);

    let title = format!("Read Position (42h) with an {} at {}", profile.name, settings);
    let mut svg = Svg::new(WIDTH, 590.0);
    svg.text(20.0, 30.0, &title, Font::TITLE);

    // Panel A: the request and the reply's first character, bit by bit.
    svg.text(20.0, 62.0, "The request and the reply's first character, bit by bit", Font::HEADING);
    let gap = 70.0;
    let (req_t1, rep_t0) = (last_end, t.earliest_start_us);
    let rep_t1 = reply.first().map_or(rep_t0, |c| c.end_us);
    let per_us = (PLOT_RIGHT - PLOT_LEFT - gap) / (req_t1 + rep_t1 - rep_t0) as f64;
    let split = PLOT_LEFT + req_t1 as f64 * per_us;
    let req_axis = Axis::new(0, req_t1, PLOT_LEFT, split);
    let rep_axis = Axis::new(rep_t0, rep_t1, split + gap, PLOT_RIGHT);
    let trace_top = 118.0;
    lane_name(&mut svg, trace_top, "line level", "1 = idle (mark)");
    bit_trace(&mut svg, &req_axis, &sent.chars, settings, trace_top, &["address", "command", "checksum"]);
    bit_trace(&mut svg, &rep_axis, &reply[..reply.len().min(1)], t.settings, trace_top, &["reply address"]);
    svg.text(split + gap / 2.0, trace_top + 22.0, "…", Font::HEADING.at(Anchor::Middle));
    let axis_y = trace_top + 62.0;
    let req_ticks: Vec<u64> = std::iter::once(0).chain(sent.chars.iter().map(|c| c.end_us)).collect();
    req_axis.draw(&mut svg, axis_y, &req_ticks);
    rep_axis.draw(&mut svg, axis_y, &[rep_t0, rep_t1]);
    // The bit time as it is (1/9600 s = 104.17 µs), so that a reader gets the
    // character (11 bits = 1.146 ms) and the timeout (55 bits = 5.730 ms) from it.
    let bps = settings.baud.bits_per_second();
    let bit = 1e6 / f64::from(bps.max(1));
    let ct = settings.char_time_us();
    let notes_y = axis_y + 42.0;
    svg.text(
        PLOT_LEFT,
        notes_y,
        &format!(
            "1 bit = 1/{bps} s = {bit:.2} µs, 1 character = {} bits = {} ({}) · 000:T4, 000:T28/settings",
            settings.bits_per_char(),
            ms(ct),
            format_words(settings)
        ),
        Font::LABEL,
    );
    svg.text(
        PLOT_LEFT,
        notes_y + 18.0,
        &format!(
            "Each character reaches the slave when its stop bit ends: at {} · 000:2.2.2",
            sent.chars.iter().map(|c| ms(c.end_us)).collect::<Vec<_>>().join(", ")
        ),
        Font::LABEL,
    );

    // Panel B: the exchange on one axis.
    let top = notes_y + 56.0;
    svg.text(20.0, top, "The exchange on one time axis", Font::HEADING);
    let end = (reply_end + pause).max(t.latest_start_us) + 1000;
    let axis = Axis::new(0, end, PLOT_LEFT, PLOT_RIGHT);
    let (master_y, slave_y) = (top + 52.0, top + 150.0);
    lane_name(&mut svg, master_y + 8.0, "master → slave", &format!("request {}", hex(&read_position(&profile))));
    lane_name(&mut svg, slave_y + 8.0, "slave → master", "reply");
    char_boxes(&mut svg, &axis, &sent.chars, master_y, (BLUE_FILL, BLUE));
    char_boxes(&mut svg, &axis, &reply, slave_y, (GREEN_FILL, GREEN));
    let complete = step.received.complete_us;
    marker(&mut svg, axis.x(complete), (top + 14.0, slave_y + 70.0), &format!("processed at {}", ms(complete)), ORANGE);
    svg.span(
        axis.x(last_end),
        axis.x(complete),
        master_y + 54.0,
        &format!("request timeout {}", ms(timeout)),
        clause::TIMEOUT.id(),
        ORANGE,
    );
    svg.span(
        axis.x(complete),
        axis.x(t.latest_start_us),
        master_y + 12.0,
        &format!("response window {} (42h)", ms(limit.max_ms as u64 * 1000)),
        &ids(&[clause::COMMANDS.clause(), clause::COMMAND_DEFINITION.clause()]),
        PURPLE,
    );
    svg.span(
        axis.x(t.earliest_start_us),
        axis.x(reply_end),
        slave_y + 42.0,
        &format!(
            "reply {}: {} characters, {}",
            hex(t.frame.as_bytes()),
            reply.len(),
            ms(reply_end - t.earliest_start_us)
        ),
        clause::READ_POSITION.id(),
        GREEN,
    );
    svg.span(
        axis.x(reply_end),
        axis.x(reply_end + pause),
        slave_y - 26.0,
        &format!("pause ≥ {}", ms(pause)),
        clause::REPLY_END.id(),
        GREY,
    );
    axis.draw(&mut svg, slave_y + 84.0, &axis.every(2000));
    svg.text(
        PLOT_LEFT,
        slave_y + 134.0,
        "The reply is drawn at the earliest start the model allows; a device may start it anywhere in the window.",
        Font::SMALL,
    );

    let mut caption = Caption::new(&[
        format!(
            "A Read Position (42h) exchange with the built-in {} profile (current edition) at {}, run in \
             the model in virtual time: each request character is handed to the slave when its stop bit \
             ends, and the slave is polled at its deadline. The request's characters are drawn bit by bit \
             ({}), then the timeout the slave waits after the last one, the command's response window, \
             the reply the model produced and the pause that ends it.",
            profile.name,
            settings,
            format_words(settings)
        ),
        "The reply is drawn from the earliest start the model allows (the end of the request timeout); \
         a device may start it anywhere up to the end of the window. The position input was set to 3039h."
            .to_string(),
    ]);
    caption.figure(
        "bit time",
        &format!("{bit:.2} µs (1/{bps} s); a time of several bits is computed from it and rounded up to whole µs once"),
        &[clause::UART_SETTINGS.clause()],
    );
    caption.figure(
        "character time",
        &format!("{} bits, {}", settings.bits_per_char(), ms(ct)),
        &[clause::UART_SETTINGS.clause(), clause::SETTINGS_BYTE.clause()],
    );
    caption.figure(
        "request",
        &hex(&read_position(&profile)),
        &[clause::ADDRESS.clause(), clause::COMMAND_BYTE.clause(), clause::CHECKSUM.clause()],
    );
    caption.figure(
        "request characters received (stop bit ends)",
        &sent.chars.iter().map(|c| ms(c.end_us)).collect::<Vec<_>>().join(", "),
        &[clause::FRAME_TIMING.clause()],
    );
    caption.figure(
        "request timeout",
        &format!("{}, {} bit times", ms(timeout), settings.timeout_bits(edition)),
        &[clause::TIMEOUT.clause(), clause::FRAME_TIMING.clause()],
    );
    caption.figure("request processed", &format!("at {}", ms(complete)), &[clause::FRAME_TIMING.clause()]);
    caption.figure(
        "response window (42h)",
        &format!("{}, from {} to {}", ms(limit.max_ms as u64 * 1000), ms(t.earliest_start_us), ms(t.latest_start_us)),
        &[clause::COMMANDS.clause(), clause::COMMAND_DEFINITION.clause()],
    );
    caption.figure(
        "reply",
        &format!("{}, {} characters, {}", hex(t.frame.as_bytes()), reply.len(), ms(reply_end - t.earliest_start_us)),
        &[clause::READ_POSITION.clause(), clause::CHECKSUM.clause()],
    );
    caption.figure("pause after the reply", &format!("at least {}", ms(pause)), &[clause::REPLY_END.clause()]);
    Ok(Diagram { id: "exchange-42h", svg: svg.finish(&title), caption: caption.finish(), title })
}
