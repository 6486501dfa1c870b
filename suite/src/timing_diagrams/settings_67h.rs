//! The fifth diagram: Temporarily Set Serial Interface (67h), its reply in the old
//! settings and a Read Position in the new ones (000:T33).

use super::caption::{bit_time, hex, hex_plain, ms, Caption};
use super::run::{read_position, request, send, Char, Phase};
use super::svg::{
    bit_trace, char_boxes, lane_name, listening_text, marker, Axis, Font, Svg, BLUE, BLUE_FILL, GREEN, GREEN_FILL,
    GREY, INK, ORANGE, PLOT_LEFT, PLOT_RIGHT, PURPLE, WIDTH,
};
use super::{Diagram, Surprise};
use hiperface_model::clause;
use hiperface_model::request::Request;
use hiperface_model::settings::{Baud, UartSettings};
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{profiles, Slave};

/// 67h to 38400 Bd: the request and its reply in the old settings, the new settings
/// as the model applies them, and a Read Position in the new ones. // 000:T33
pub(super) fn settings_67h() -> Result<Diagram, Surprise> {
    // The SRS50 lacks the optional 67h; the reference device has every command.
    let profile = profiles::reference();
    let edition = profile.edition;
    let mut slave = Slave::operational(profile);
    let old = slave.listening_settings(0).ok_or(Surprise("the operational slave does not listen"))?;
    let new = UartSettings { baud: Baud::B38400, ..old };
    let frame = request(&profile, Request::TemporarilySetSerialInterface { settings: new.byte() });
    let first = send(&mut slave, &frame, 0, old);
    let step = first.step()?;
    let (t1, reply1) = first.reply()?;
    if t1.then_settings != Some(new) {
        return Err(Surprise("67h did not announce the new settings"));
    }
    let processed = step.received.complete_us;
    let now_listening = slave.listening_settings(processed);
    let reply1_end = reply1.last().map_or(t1.earliest_start_us, |c| c.end_us);
    let pause1 = t1.settings.pause_us(edition);
    // The next request after the reply's closing pause, in what the slave listens with.
    let start2 = reply1_end + pause1;
    let heard = slave.listening_settings(start2).ok_or(Surprise("the slave does not listen after 67h"))?;
    let second = send(&mut slave, &read_position(&profile), start2, heard);
    let step2 = second.step()?;
    let (t2, reply2) = second.reply()?;
    let reply2_end = reply2.last().map_or(t2.earliest_start_us, |c| c.end_us);
    let pause2 = t2.settings.pause_us(edition);
    let end = reply2_end + pause2 + 1000;
    let limit = profile.response_limit(hiperface_model::CommandId::TemporarilySetSerialInterface);

    let title = format!("Temporarily Set Serial Interface (67h) from {:02X}h to {new}", old.byte());
    let mut svg = Svg::new(WIDTH, 716.0);
    svg.text(20.0, 30.0, &title, Font::TITLE);
    svg.text(20.0, 62.0, &format!("Two exchanges with the {} profile on one time axis", profile.name), Font::HEADING);
    let axis = Axis::new(0, end, PLOT_LEFT, PLOT_RIGHT);
    let (master_y, slave_y, listen_y) = (118.0, 228.0, 300.0);
    lane_name(&mut svg, master_y + 16.0, "master → slave", "");
    lane_name(&mut svg, slave_y + 16.0, "slave → master", "");
    lane_name(&mut svg, listen_y + 16.0, "slave listens", "listening_settings");
    char_boxes(&mut svg, &axis, &first.chars, master_y, (BLUE_FILL, BLUE));
    char_boxes(&mut svg, &axis, &second.chars, master_y, (BLUE_FILL, BLUE));
    char_boxes(&mut svg, &axis, &reply1, slave_y, (GREEN_FILL, GREEN));
    char_boxes(&mut svg, &axis, &reply2, slave_y, (GREEN_FILL, GREEN));
    let label_over = |svg: &mut Svg, chars: &[Char], y: f64, text: &str| {
        if let Some(a) = chars.first() {
            svg.text(axis.x(a.start_us), y, text, Font::SMALL.colour(INK));
        }
    };
    label_over(
        &mut svg,
        &first.chars,
        master_y - 6.0,
        &format!("67h request {} in {:02X}h", hex_plain(&frame), old.byte()),
    );
    label_over(
        &mut svg,
        &second.chars,
        master_y - 6.0,
        &format!("42h {} in {:02X}h", hex_plain(&read_position(&profile)), heard.byte()),
    );
    let listening = [
        Phase { from_us: 0, to_us: processed, state: CommState::OperationalUser, listening: Some(old) },
        Phase { from_us: processed, to_us: end, state: CommState::OperationalUser, listening: now_listening },
    ];
    for p in &listening {
        let (x1, x2) = (axis.x(p.from_us), axis.x(p.to_us));
        svg.labelled_box(x1, x2, listen_y, 24.0, ("#f1f1f1", "#8a8a8a"), &listening_text(p.listening));
    }
    marker(
        &mut svg,
        axis.x(processed),
        (master_y - 30.0, listen_y + 30.0),
        &format!("processed at {}", ms(processed)),
        ORANGE,
    );
    let c2 = step2.received.complete_us;
    let last1 = first.last_end_us();
    let last2 = second.last_end_us();
    svg.span(
        axis.x(last1),
        axis.x(processed),
        master_y + 50.0,
        &format!("timeout {}", ms(processed - last1)),
        clause::TIMEOUT.id(),
        ORANGE,
    );
    svg.span(
        axis.x(last2),
        axis.x(c2),
        master_y + 50.0,
        &format!("timeout {}", ms(c2 - last2)),
        clause::TIMEOUT.id(),
        ORANGE,
    );
    svg.span(
        axis.x(processed),
        axis.x(t1.latest_start_us),
        master_y + 36.0,
        &format!("response window {} (67h)", ms(limit.max_ms as u64 * 1000)),
        clause::COMMANDS.id(),
        PURPLE,
    );
    svg.span(
        axis.x(t1.earliest_start_us),
        axis.x(reply1_end),
        slave_y + 42.0,
        &format!("reply {} in {:02X}h", hex_plain(t1.frame.as_bytes()), t1.settings.byte()),
        clause::TEMP_SERIAL.id(),
        GREEN,
    );
    svg.span(
        axis.x(t2.earliest_start_us),
        axis.x(reply2_end),
        slave_y + 42.0,
        &format!("reply {} in {:02X}h", hex_plain(t2.frame.as_bytes()), t2.settings.byte()),
        clause::READ_POSITION.id(),
        GREEN,
    );
    svg.span(
        axis.x(reply1_end),
        axis.x(reply1_end + pause1),
        slave_y - 26.0,
        &format!("pause {}", ms(pause1)),
        clause::REPLY_END.id(),
        GREY,
    );
    svg.span(
        axis.x(reply2_end),
        axis.x(reply2_end + pause2),
        slave_y - 26.0,
        &format!("pause {}", ms(pause2)),
        clause::REPLY_END.id(),
        GREY,
    );
    axis.draw(&mut svg, listen_y + 44.0, &axis.every(2000));

    // Panel B: one character in each setting, at one scale.
    let top = listen_y + 104.0;
    svg.text(20.0, top, "The first character of each request, at one scale", Font::HEADING);
    let span_us = old.char_time_us() + 60;
    for (i, (sent, s)) in [(&first, old), (&second, heard)].into_iter().enumerate() {
        let Some(c) = sent.chars.first() else { continue };
        let y = top + 62.0 + i as f64 * 136.0;
        let row = Axis::new(c.start_us, c.start_us + span_us, PLOT_LEFT, PLOT_RIGHT);
        lane_name(&mut svg, y + 20.0, &format!("{} Bd", s.baud.bits_per_second()), &format!("bit {}", bit_time(s)));
        bit_trace(
            &mut svg,
            &row,
            &[*c],
            s,
            y,
            &[&format!("· character {} · {}", ms(s.char_time_us()), clause::UART_SETTINGS.id())],
        );
        row.draw(&mut svg, y + 60.0, &[c.start_us, c.end_us]);
    }

    let mut caption = Caption::new(&[
        format!(
            "Temporarily Set Serial Interface (67h) to {new}, sent in {old} to the built-in {} profile (the \
             SRS50 does not implement the optional 67h), then a Read Position in the new settings. The model \
             answers 67h in the previous settings and names the new ones as the settings to listen with \
             after the reply (Transmission::then_settings); its own listening settings are the new ones from \
             the moment it processed the request.",
            profile.name
        ),
        format!(
            "The next request starts after the pause that ends the reply ({}); its characters take {} \
             instead of {}, and the timeout after it is {} instead of {}.",
            ms(pause1),
            ms(heard.char_time_us()),
            ms(old.char_time_us()),
            ms(c2 - last2),
            ms(processed - last1)
        ),
    ]);
    caption.figure(
        "67h request",
        &format!("{} in {old}", hex(&frame)),
        &[clause::TEMP_SERIAL.clause(), clause::SETTINGS_BYTE.clause()],
    );
    for s in [old, heard] {
        caption.figure(
            &format!("bit and character time at {} Bd", s.baud.bits_per_second()),
            &format!("{}, {} (11 bits, rounded up to whole µs)", bit_time(s), ms(s.char_time_us())),
            &[clause::UART_SETTINGS.clause()],
        );
    }
    caption.figure(
        "67h request timeout",
        &format!("{}, processed at {}", ms(processed - last1), ms(processed)),
        &[clause::TIMEOUT.clause(), clause::FRAME_TIMING.clause()],
    );
    caption.figure(
        "response window (67h)",
        &format!("{}, to {}", ms(limit.max_ms as u64 * 1000), ms(t1.latest_start_us)),
        &[clause::COMMANDS.clause(), clause::COMMAND_DEFINITION.clause()],
    );
    caption.figure(
        "67h reply",
        &format!("{} in {}, then {}", hex(t1.frame.as_bytes()), t1.settings, listening_text(t1.then_settings)),
        &[clause::TEMP_SERIAL.clause()],
    );
    caption.figure(
        "listening settings",
        &format!("{} until {}, {} from then", old, ms(processed), listening_text(now_listening)),
        &[clause::TEMP_SERIAL.clause()],
    );
    caption.figure("pause after the 67h reply", &format!("at least {}", ms(pause1)), &[clause::REPLY_END.clause()]);
    caption.figure(
        "Read Position in the new settings",
        &format!("sent at {}, timeout {}, processed at {}", ms(start2), ms(c2 - last2), ms(c2)),
        &[clause::TIMEOUT.clause(), clause::FRAME_TIMING.clause()],
    );
    caption.figure(
        "its reply",
        &format!("{} in {}, {}", hex(t2.frame.as_bytes()), t2.settings, ms(reply2_end - t2.earliest_start_us)),
        &[clause::READ_POSITION.clause()],
    );
    caption.figure("pause after it", &format!("at least {}", ms(pause2)), &[clause::REPLY_END.clause()]);
    Ok(Diagram { id: "settings-67h", svg: svg.finish(&title), caption: caption.finish(), title })
}
