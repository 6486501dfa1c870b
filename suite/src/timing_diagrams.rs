//! Timing diagrams of the protocol reference as SVG, drawn from the model run in
//! virtual time (issue 41). Nothing here is a figure of its own: the characters are
//! fed to a [`Slave`] at the ends of their stop bits, the slave is polled at its
//! deadlines, and every time, byte and setting a diagram prints is what the model
//! said, next to the id of the clause the model's code cites for it.
//!
//! Pure: the diagrams are strings ([`Diagram::svg`] a standalone SVG document,
//! [`Diagram::caption`] Markdown); writing them is the caller's business.

use hiperface_model::clause::{self, Clause};
use hiperface_model::datalink::RxChar;
use hiperface_model::profiles;
use hiperface_model::request::{Request, RequestFrame};
use hiperface_model::response::Response;
use hiperface_model::settings::{Baud, Edition, Parity, UartSettings};
use hiperface_model::slave::powerup::CommState;
use hiperface_model::{AddressByte, Profile, Reply, Slave, Step, Transmission};

use crate::report::escape;

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

// ---------------------------------------------------------------------------------
// Running the model
// ---------------------------------------------------------------------------------

/// One character on the line: from its start bit's leading edge to its stop bit's end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Char {
    byte: u8,
    start_us: u64,
    end_us: u64,
}

/// `bytes` sent back to back from `start_us` in `settings`. // 000:T4
fn characters(bytes: &[u8], start_us: u64, settings: UartSettings) -> Vec<Char> {
    let ct = settings.char_time_us();
    (0u64..)
        .zip(bytes)
        .map(|(i, b)| Char { byte: *b, start_us: start_us + i * ct, end_us: start_us + (i + 1) * ct })
        .collect()
}

/// A request as sent and what the slave made of it.
struct Sent {
    chars: Vec<Char>,
    step: Option<Step>,
}

impl Sent {
    fn last_end_us(&self) -> u64 {
        self.chars.last().map_or(0, |c| c.end_us)
    }

    fn step(&self) -> Result<Step, Surprise> {
        self.step.ok_or(Surprise("the slave did not process the request"))
    }

    /// The reply the model sends and its characters, drawn from the earliest start it
    /// allows (a device may start anywhere up to the latest).
    fn reply(&self) -> Result<(Transmission, Vec<Char>), Surprise> {
        let t = self.step()?.transmission.ok_or(Surprise("the slave did not reply"))?;
        Ok((t, characters(t.frame.as_bytes(), t.earliest_start_us, t.settings)))
    }
}

/// Send `bytes` as a master does: each character reaches the slave when its stop bit
/// ends, the UART's receive interrupt (000:2.2.2); then time advances to the slave's
/// deadlines until it has processed the frame (its timeout after the last character).
fn send(slave: &mut Slave, bytes: &[u8], start_us: u64, settings: UartSettings) -> Sent {
    let chars = characters(bytes, start_us, settings);
    let mut step = None;
    for c in &chars {
        step = step.or(slave.receive(RxChar::ok(c.byte, c.end_us)));
    }
    let mut now = chars.last().map_or(start_us, |c| c.end_us);
    // Deadlines are the frame's timeout and the power-up state changes: a handful.
    for _ in 0..8 {
        if step.is_some() {
            break;
        }
        let Some(deadline) = slave.next_deadline(now) else { break };
        step = slave.poll(deadline);
        now = now.max(deadline);
    }
    Sent { chars, step }
}

fn request(profile: &Profile, request: Request) -> Vec<u8> {
    RequestFrame::new(AddressByte::Slave(profile.address), request).encode().as_bytes().to_vec()
}

fn read_position(profile: &Profile) -> Vec<u8> {
    request(profile, Request::ReadPosition)
}

/// A slave of `profile` that stored `settings` with Set Serial Interface (57h, with
/// the factory Code0) and was then powered on again at t = 0: the stored settings
/// hold from the next power-on (000:T32).
fn with_stored_settings(profile: Profile, settings: UartSettings) -> Result<Slave, Surprise> {
    let mut slave = Slave::operational(profile);
    let code0 = slave.nonvolatile().codes[0];
    let frame = request(&profile, Request::SetSerialInterface { settings: settings.byte(), code0 });
    let outcome = slave.handle_frame(&frame, 0);
    match outcome.reply {
        Reply::Frame(r) if !matches!(r.response, Response::Error(_)) => {}
        _ => return Err(Surprise("the slave refused Set Serial Interface (57h)")),
    }
    if slave.nonvolatile().settings != settings {
        return Err(Surprise("Set Serial Interface (57h) did not store the settings"));
    }
    slave.power_cycle(0);
    Ok(slave)
}

/// A stretch of time in one power-up state with the settings the slave listens with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Phase {
    from_us: u64,
    to_us: u64,
    state: CommState,
    listening: Option<UartSettings>,
}

/// The slave's states from `from_us` to `to_us` as it stands (no frame in progress):
/// its state and listening settings at each change its deadlines announce (000:T9).
fn phases(slave: &Slave, from_us: u64, to_us: u64) -> Vec<Phase> {
    let mut out: Vec<Phase> = Vec::new();
    let mut t = from_us;
    while t < to_us {
        let next = slave.next_deadline(t).filter(|n| *n > t).map_or(to_us, |n| n.min(to_us));
        let (state, listening) = (slave.state(t), slave.listening_settings(t));
        match out.last_mut() {
            Some(last) if last.state == state && last.listening == listening => last.to_us = next,
            _ => out.push(Phase { from_us: t, to_us: next, state, listening }),
        }
        t = next;
    }
    out
}

/// `a` then `b`, a phase continued across the seam merged into one.
fn joined(a: Vec<Phase>, b: Vec<Phase>) -> Vec<Phase> {
    let mut out = a;
    for p in b {
        match out.last_mut() {
            Some(last) if last.state == p.state && last.listening == p.listening && last.to_us == p.from_us => {
                last.to_us = p.to_us
            }
            _ => out.push(p),
        }
    }
    out
}

// ---------------------------------------------------------------------------------
// Figures and captions
// ---------------------------------------------------------------------------------

/// `us` in ms with µs precision: "5.730 ms", "100 ms".
/// One bit's time as it is (1/9600 s = "104.17 µs"), not rounded to whole µs: a reader
/// multiplies it by 11 or 55 and gets the character and the timeout printed beside it.
fn bit_time(s: UartSettings) -> String {
    format!("{:.2} µs", 1e6 / f64::from(s.baud.bits_per_second().max(1)))
}

fn ms(us: u64) -> String {
    if us % 1000 == 0 {
        format!("{} ms", us / 1000)
    } else {
        format!("{}.{:03} ms", us / 1000, us % 1000)
    }
}

/// A tick label: ms without the unit and without trailing zeros ("1.146", "0.5", "4").
fn tick(us: u64) -> String {
    let s = format!("{}.{:03}", us / 1000, us % 1000);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02X}h")).collect::<Vec<_>>().join(" ")
}

fn ids(clauses: &[Clause]) -> String {
    clauses.iter().map(|c| c.id()).collect::<Vec<_>>().join(", ")
}

/// A caption: paragraphs, then the list of figures with their clauses.
struct Caption {
    text: String,
    figures: String,
}

impl Caption {
    fn new(paragraphs: &[String]) -> Caption {
        Caption { text: paragraphs.join("\n\n"), figures: String::new() }
    }

    fn figure(&mut self, name: &str, value: &str, clauses: &[Clause]) {
        self.figures.push_str(&format!("- {name}: {value} ({})\n", ids(clauses)));
    }

    fn finish(self) -> String {
        format!("{}\n\n{}", self.text, self.figures)
    }
}

// ---------------------------------------------------------------------------------
// A small SVG builder
// ---------------------------------------------------------------------------------

const WIDTH: f64 = 1240.0;
/// Lane names on the left, plots from here to `PLOT_RIGHT`.
const PLOT_LEFT: f64 = 170.0;
const PLOT_RIGHT: f64 = 1215.0;

const INK: &str = "#1a1a1a";
const GREY: &str = "#666666";
const RULE: &str = "#bbbbbb";
const BLUE: &str = "#1f56a8";
const BLUE_FILL: &str = "#d8e4f6";
const GREEN: &str = "#2a7a2e";
const GREEN_FILL: &str = "#d9eed9";
const ORANGE: &str = "#b86500";
const PURPLE: &str = "#7a3a9e";
const RED: &str = "#b3261e";

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Anchor {
    Start,
    Middle,
    End,
}

/// How a text is set.
#[derive(Debug, Clone, Copy)]
struct Font {
    size: f64,
    bold: bool,
    anchor: Anchor,
    colour: &'static str,
}

impl Font {
    const TITLE: Font = Font { size: 17.0, bold: true, anchor: Anchor::Start, colour: INK };
    const HEADING: Font = Font { size: 13.0, bold: true, anchor: Anchor::Start, colour: INK };
    const LABEL: Font = Font { size: 12.0, bold: false, anchor: Anchor::Start, colour: INK };
    const SMALL: Font = Font { size: 10.5, bold: false, anchor: Anchor::Start, colour: GREY };

    const fn at(self, anchor: Anchor) -> Font {
        Font { anchor, ..self }
    }

    const fn colour(self, colour: &'static str) -> Font {
        Font { colour, ..self }
    }

    const fn bold(self) -> Font {
        Font { bold: true, ..self }
    }

    /// An estimate of the width of `text` (sans-serif, about 0.58 em a character).
    fn width(&self, text: &str) -> f64 {
        text.chars().count() as f64 * self.size * if self.bold { 0.62 } else { 0.58 }
    }
}

/// An SVG document under construction.
struct Svg {
    width: f64,
    height: f64,
    body: String,
}

impl Svg {
    fn new(width: f64, height: f64) -> Svg {
        Svg { width, height, body: String::new() }
    }

    fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, fill: &str, stroke: &str) {
        self.body.push_str(&format!(
            "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{h:.1}\" fill=\"{fill}\" stroke=\"{stroke}\"/>\n",
            w.max(0.5)
        ));
    }

    fn line(&mut self, (x1, y1): (f64, f64), (x2, y2): (f64, f64), stroke: &str, dashed: bool) {
        let dash = if dashed { " stroke-dasharray=\"4 3\"" } else { "" };
        self.body.push_str(&format!(
            "<line x1=\"{x1:.1}\" y1=\"{y1:.1}\" x2=\"{x2:.1}\" y2=\"{y2:.1}\" stroke=\"{stroke}\"{dash}/>\n"
        ));
    }

    fn polyline(&mut self, points: &[(f64, f64)], stroke: &str, width: f64) {
        let pts: Vec<String> = points.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        self.body.push_str(&format!(
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{stroke}\" stroke-width=\"{width}\" stroke-linejoin=\"miter\"/>\n",
            pts.join(" ")
        ));
    }

    fn text(&mut self, x: f64, y: f64, text: &str, font: Font) {
        let anchor = match font.anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let weight = if font.bold { " font-weight=\"bold\"" } else { "" };
        self.body.push_str(&format!(
            "<text x=\"{x:.1}\" y=\"{y:.1}\" font-size=\"{}\" text-anchor=\"{anchor}\" fill=\"{}\"{weight}>{}</text>\n",
            font.size,
            font.colour,
            escape(text)
        ));
    }

    /// A dimension line from `x1` to `x2` with end ticks, `label` above it and the
    /// clause ids (`note`) below, both centred and kept inside the plot.
    fn span(&mut self, x1: f64, x2: f64, y: f64, label: &str, note: &str, colour: &'static str) {
        self.line((x1, y), (x2, y), colour, false);
        self.line((x1, y - 5.0), (x1, y + 5.0), colour, false);
        self.line((x2, y - 5.0), (x2, y + 5.0), colour, false);
        let font = Font::LABEL.colour(colour);
        for (text, font, dy) in [(label, font, -5.0), (note, Font::SMALL, 14.0)] {
            if text.is_empty() {
                continue;
            }
            let w = font.width(text);
            let x = ((x1 + x2) / 2.0).clamp(8.0 + w / 2.0, self.width - 8.0 - w / 2.0);
            self.text(x, y + dy, text, font.at(Anchor::Middle));
        }
    }

    /// A box with `label` centred in it when it fits.
    fn labelled_box(&mut self, x1: f64, x2: f64, y: f64, h: f64, (fill, stroke): (&str, &str), label: &str) {
        self.rect(x1, y, x2 - x1, h, fill, stroke);
        let font = Font::LABEL.at(Anchor::Middle);
        if font.width(label) + 4.0 <= x2 - x1 {
            self.text((x1 + x2) / 2.0, y + h / 2.0 + 4.0, label, font);
        }
    }

    /// The document: a white background, a `<title>`, the drawing.
    fn finish(self, title: &str) -> String {
        let (w, h) = (self.width, self.height);
        format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
             <svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" \
             font-family=\"Helvetica, Arial, sans-serif\">\n<title>{}</title>\n\
             <rect x=\"0\" y=\"0\" width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>\n{}</svg>\n",
            escape(title),
            self.body
        )
    }
}

/// Maps time (µs) onto x over `t0..t1`.
#[derive(Debug, Clone, Copy)]
struct Axis {
    t0: u64,
    t1: u64,
    x0: f64,
    x1: f64,
}

impl Axis {
    fn new(t0: u64, t1: u64, x0: f64, x1: f64) -> Axis {
        Axis { t0, t1: t1.max(t0 + 1), x0, x1 }
    }

    fn x(&self, t_us: u64) -> f64 {
        let span = (self.t1 - self.t0) as f64;
        self.x0 + (t_us as f64 - self.t0 as f64) / span * (self.x1 - self.x0)
    }

    /// The axis line at `y` with a tick and label at each of `ticks` (µs) and the
    /// unit after the last one.
    fn draw(&self, svg: &mut Svg, y: f64, ticks: &[u64]) {
        svg.line((self.x0, y), (self.x1, y), INK, false);
        for t in ticks {
            let x = self.x(*t);
            svg.line((x, y), (x, y + 5.0), INK, false);
            svg.text(x, y + 18.0, &tick(*t), Font::SMALL.colour(INK).at(Anchor::Middle));
        }
        svg.text(self.x1 + 6.0, y + 4.0, "ms", Font::SMALL.colour(INK));
    }

    /// Ticks every `step_us` from `t0` (rounded up to a multiple of the step).
    fn every(&self, step_us: u64) -> Vec<u64> {
        let first = self.t0.div_ceil(step_us) * step_us;
        (0..).map(|i| first + i * step_us).take_while(|t| *t <= self.t1).collect()
    }
}

/// A lane's name on the left.
fn lane_name(svg: &mut Svg, y: f64, name: &str, sub: &str) {
    svg.text(PLOT_LEFT - 10.0, y, name, Font::LABEL.bold().at(Anchor::End));
    if !sub.is_empty() {
        svg.text(PLOT_LEFT - 10.0, y + 14.0, sub, Font::SMALL.at(Anchor::End));
    }
}

/// The bits of one character, as they leave the transmitter: start, 8 data bits LSB
/// first, parity, stop; `true` is the idle level (mark). // 000:T4, 000:2.2.1
fn bits(byte: u8, settings: UartSettings) -> Vec<(String, bool)> {
    let mut out = vec![("St".to_string(), false)];
    out.extend((0..8).map(|i| (format!("D{i}"), byte >> i & 1 == 1)));
    let odd_ones = byte.count_ones() % 2 == 1;
    match settings.parity {
        // Even: the parity bit makes the number of ones even.
        Parity::Even => out.push(("P".to_string(), odd_ones)),
        Parity::Odd => out.push(("P".to_string(), !odd_ones)),
        Parity::None => {}
    }
    out.push(("Sp".to_string(), true));
    out
}

/// Draw characters as a line level trace, one cell per bit with its name and value,
/// the byte above. `top` is the level trace's high line.
fn bit_trace(svg: &mut Svg, axis: &Axis, chars: &[Char], settings: UartSettings, top: f64, names: &[&str]) {
    let (hi, lo) = (top, top + 34.0);
    let level = |one: bool| if one { hi } else { lo };
    let first_x = chars.first().map_or(axis.x0, |c| axis.x(c.start_us));
    let mut points = vec![(first_x - 8.0, hi), (first_x, hi)];
    for (n, c) in chars.iter().enumerate() {
        let bs = bits(c.byte, settings);
        for (i, (name, one)) in (0u32..).zip(&bs) {
            let (x1, x2) = (axis.x(c.start_us + settings.bits_us(i)), axis.x(c.start_us + settings.bits_us(i + 1)));
            points.push((x1, level(*one)));
            points.push((x2, level(*one)));
            svg.line((x1, hi - 22.0), (x1, lo + 6.0), RULE, true);
            let mid = (x1 + x2) / 2.0;
            svg.text(mid, hi - 8.0, name, Font::SMALL.colour(INK).at(Anchor::Middle));
            svg.text(mid, lo + 18.0, if *one { "1" } else { "0" }, Font::SMALL.at(Anchor::Middle));
        }
        let (x1, x2) = (axis.x(c.start_us), axis.x(c.end_us));
        svg.line((x2, hi - 22.0), (x2, lo + 6.0), RULE, true);
        let name = names.get(n).copied().unwrap_or("");
        svg.text((x1 + x2) / 2.0, hi - 30.0, &format!("{:02X}h {name}", c.byte), Font::LABEL.bold().at(Anchor::Middle));
    }
    let last_x = chars.last().map_or(axis.x1, |c| axis.x(c.end_us));
    points.push((last_x.max(axis.x1) + 8.0, hi));
    svg.polyline(&points, BLUE, 2.0);
}

/// Characters as boxes on a lane, the byte in each when it fits.
fn char_boxes(svg: &mut Svg, axis: &Axis, chars: &[Char], y: f64, colours: (&str, &str)) {
    for c in chars {
        svg.labelled_box(axis.x(c.start_us), axis.x(c.end_us), y, 24.0, colours, &format!("{:02X}", c.byte));
    }
}

/// A vertical marker through the lanes with a label at its top.
fn marker(svg: &mut Svg, x: f64, (y1, y2): (f64, f64), label: &str, colour: &'static str) {
    svg.line((x, y1), (x, y2), colour, true);
    if !label.is_empty() {
        svg.text(x + 4.0, y1 + 11.0, label, Font::SMALL.colour(colour));
    }
}

/// Colours of a power-up state's box. // 000:T9
fn state_colours(state: CommState) -> (&'static str, &'static str) {
    match state {
        CommState::Initialization => ("#e2e2e2", "#8a8a8a"),
        CommState::DefaultCommunication => ("#d8e4f6", "#5a7fb8"),
        CommState::OperationalDefault => ("#c4d6f2", "#3d68aa"),
        CommState::ChangeOfSettings => ("#f8e3c6", "#b88a3e"),
        CommState::OperationalUser => ("#d9eed9", "#4f8f52"),
    }
}

/// What the slave listens with, as a lane says it.
fn listening_text(s: Option<UartSettings>) -> String {
    s.map_or_else(|| "no UART".to_string(), |s| s.to_string())
}

/// Power-up phases as boxes on a lane: the state's name, then the listening settings.
fn phase_boxes(svg: &mut Svg, axis: &Axis, phases: &[Phase], y: f64) {
    let h = 42.0;
    for p in phases {
        let (x1, x2) = (axis.x(p.from_us), axis.x(p.to_us));
        svg.rect(x1, y, x2 - x1, h, state_colours(p.state).0, state_colours(p.state).1);
        let room = x2 - x1 - 6.0;
        let names = p.state.names();
        let fonts = [Font::LABEL, Font::SMALL.colour(INK)];
        let fits = fonts.iter().flat_map(|f| names.iter().map(move |n| (*f, *n))).find(|(f, n)| f.width(n) <= room);
        if let Some((font, name)) = fits {
            svg.text((x1 + x2) / 2.0, y + 17.0, name, font.at(Anchor::Middle));
        }
        let full = listening_text(p.listening);
        let brief = p.listening.map_or_else(|| "no UART".to_string(), |s| format!("{:02X}h", s.byte()));
        let small = Font::SMALL.colour(INK).at(Anchor::Middle);
        if let Some(s) = [full, brief].into_iter().find(|s| small.width(s) <= room) {
            svg.text((x1 + x2) / 2.0, y + 33.0, &s, small);
        }
    }
}

/// The character format of `s` in words. // 000:T4
fn format_words(s: UartSettings) -> String {
    let parity = match s.parity {
        Parity::Even => "even parity, ",
        Parity::Odd => "odd parity, ",
        Parity::None => "",
    };
    format!("start bit, 8 data bits LSB first, {parity}stop bit")
}

// ---------------------------------------------------------------------------------
// 1. Read Position exchange
// ---------------------------------------------------------------------------------

/// A Read Position exchange with an SRS50 at the default settings: the request at
/// bit level, the timeout the slave waits, the response window, the reply, the pause.
fn exchange_42h() -> Result<Diagram, Surprise> {
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

/// Bytes as the lanes print them: "40 42 02".
fn hex_plain(bytes: &[u8]) -> String {
    hiperface_model::Hex(bytes).to_string()
}

// ---------------------------------------------------------------------------------
// 2. Power-up
// ---------------------------------------------------------------------------------

/// The clauses a power-up state comes from in `edition`: 000 Table 9, or 002's
/// "about 1 second" of default settings (002 gives no initialization time; the legacy
/// profile keeps 000's).
fn state_clauses(state: CommState, edition: Edition) -> Vec<Clause> {
    let source = state_source(state, edition);
    match state {
        CommState::DefaultCommunication => vec![source, clause::SETTINGS_BYTE.clause()],
        CommState::OperationalDefault => vec![source, clause::POWER_UP_POLICY],
        CommState::OperationalUser => vec![source, clause::SET_SERIAL.clause()],
        CommState::Initialization | CommState::ChangeOfSettings => vec![source],
    }
}

/// The clause a power-up state and its duration come from.
fn state_source(state: CommState, edition: Edition) -> Clause {
    match (state, edition) {
        (CommState::Initialization, _) | (_, Edition::Current) => clause::STATE_MACHINE.clause(),
        (_, Edition::Legacy) => clause::LEGACY_DEFAULT_WINDOW.clause(),
    }
}

/// A phase as a caption's figure: "from 100 ms to 900 ms, listening with E4h (...)".
fn phase_figure(caption: &mut Caption, p: &Phase, last: bool, edition: Edition) {
    let when = if last { format!("from {}", ms(p.from_us)) } else { format!("{} to {}", ms(p.from_us), ms(p.to_us)) };
    let listening = p.listening.map_or_else(|| "no UART communication".to_string(), |s| format!("listening with {s}"));
    caption.figure(p.state.name(), &format!("{when}, {listening}"), &state_clauses(p.state, edition));
}

/// Dashed lines at the state boundaries of `phases` from `y1` to `y2`; if `labelled`,
/// the time above and the clause it comes from: the end of the state
/// before (000:T9, 002:57h) or, into Initialization, the reset (000:T29).
fn boundary_markers(
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

/// The power-up sequence of `edition` (000:T9, 002:57h): no UART, the default
/// settings' window, the change of settings, the stored settings; and the other
/// branch, a request in the default window keeping the default settings.
fn power_up(edition: Edition) -> Result<Diagram, Surprise> {
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

fn edition_name(edition: Edition) -> &'static str {
    match edition {
        Edition::Current => "current",
        Edition::Legacy => "legacy",
    }
}

// ---------------------------------------------------------------------------------
// 3. Encoder Reset
// ---------------------------------------------------------------------------------

/// An Encoder Reset (53h): the request, what the model answers (silence), and the
/// power-up sequence from the reset on. // 000:T29
fn encoder_reset_53h() -> Result<Diagram, Surprise> {
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

// ---------------------------------------------------------------------------------
// 4. Temporarily Set Serial Interface
// ---------------------------------------------------------------------------------

/// 67h to 38400 Bd: the request and its reply in the old settings, the new settings
/// as the model applies them, and a Read Position in the new ones. // 000:T33
fn settings_67h() -> Result<Diagram, Surprise> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The clause ids a caption cites: tokens that look like `DOC:PLACE`.
    fn cited(caption: &str) -> Vec<String> {
        caption
            .split(|c: char| c.is_whitespace() || matches!(c, '(' | ')' | ',' | ';'))
            .map(|w| w.trim_end_matches(['.', ':']))
            .filter(|w| ["000:", "001:", "002:", "DESIGN:"].iter().any(|d| w.starts_with(d)))
            .map(str::to_string)
            .collect()
    }

    #[test]
    fn every_diagram_is_drawn_with_a_unique_id() {
        let all = diagrams();
        let ids: Vec<&str> = all.iter().map(|d| d.id).collect();
        assert_eq!(ids, ["exchange-42h", "power-up-current", "power-up-legacy", "encoder-reset-53h", "settings-67h"]);
        for d in &all {
            assert!(!d.caption.starts_with(NOT_DRAWN), "{}: {}", d.id, d.caption);
            assert!(!d.title.is_empty());
            assert!(ids.iter().filter(|i| **i == d.id).count() == 1, "{}", d.id);
        }
    }

    #[test]
    fn every_svg_is_a_standalone_well_formed_document() {
        for d in diagrams() {
            let doc = roxmltree::Document::parse(&d.svg).unwrap_or_else(|e| panic!("{}: {e}", d.id));
            let root = doc.root_element();
            assert_eq!(root.tag_name().name(), "svg", "{}", d.id);
            assert_eq!(root.tag_name().namespace(), Some("http://www.w3.org/2000/svg"), "{}", d.id);
            for a in ["width", "height", "viewBox"] {
                assert!(root.attribute(a).is_some(), "{}: {a}", d.id);
            }
            let title = root.children().find(|n| n.has_tag_name("title")).and_then(|n| n.text());
            assert_eq!(title, Some(d.title.as_str()), "{}", d.id);
            // A white background first, so that the diagram reads on a dark page.
            let first = root.children().find(|n| n.has_tag_name("rect")).expect("background");
            assert_eq!(first.attribute("fill"), Some("#ffffff"), "{}", d.id);
            // Everything drawn lies inside the view box.
            let width: f64 = root.attribute("width").and_then(|w| w.parse().ok()).expect("width");
            let height: f64 = root.attribute("height").and_then(|h| h.parse().ok()).expect("height");
            for n in root.descendants().filter(|n| n.has_tag_name("text")) {
                let x: f64 = n.attribute("x").and_then(|v| v.parse().ok()).expect("x");
                let y: f64 = n.attribute("y").and_then(|v| v.parse().ok()).expect("y");
                assert!((0.0..=width).contains(&x) && (0.0..=height).contains(&y), "{}: {:?}", d.id, n.text());
            }
        }
    }

    #[test]
    fn every_caption_cites_clauses_that_exist() {
        for d in diagrams() {
            assert!(!d.caption.trim().is_empty(), "{}", d.id);
            let figures: Vec<&str> = d.caption.lines().filter(|l| l.starts_with("- ")).collect();
            assert!(!figures.is_empty(), "{}: no list of figures", d.id);
            for f in figures {
                assert!(f.ends_with(')') && !cited(f).is_empty(), "{}: a figure without its clause: {f}", d.id);
            }
            let doc = roxmltree::Document::parse(&d.svg).expect("well-formed");
            let drawn: Vec<String> = doc.descendants().filter_map(|n| n.text()).flat_map(cited).collect();
            assert!(!drawn.is_empty(), "{}: the drawing cites no clause", d.id);
            for id in cited(&d.caption).iter().chain(&drawn) {
                assert!(clause::lookup(id).is_some(), "{}: {id} is no clause", d.id);
            }
        }
    }

    fn svg_of(id: &str) -> String {
        diagrams().into_iter().find(|d| d.id == id).map(|d| d.svg).expect(id)
    }

    /// The figures on the exchange are the model's, run here again by hand.
    #[test]
    fn the_exchange_prints_the_models_figures() {
        let svg = svg_of("exchange-42h");
        let s = UartSettings::DEFAULT;
        let timeout = s.timeout_us(Edition::Current);
        assert_eq!(timeout, 5730);
        assert!(svg.contains(&format!("request timeout {}", ms(timeout))), "5.730 ms");
        // 11 × 104.17 µs = 1.146 ms and 55 × 104.17 µs = 5.730 ms, as printed.
        assert!(svg.contains("1 bit = 1/9600 s = 104.17 µs"), "104.17 µs");
        assert!(svg.contains(&format!("= {}", ms(s.char_time_us()))), "1.146 ms");
        assert!(svg.contains(&format!("pause ≥ {}", ms(s.pause_us(Edition::Current)))));
        // The request's characters reach the slave at the ends of their stop bits, and
        // the model processes the frame one timeout after the last.
        let mut slave = Slave::operational(profiles::srs50());
        let mut inputs = slave.inputs();
        inputs.position = 0x3039;
        slave.set_inputs(inputs);
        let ct = s.char_time_us();
        for (i, b) in [0x40, 0x42, 0x02].into_iter().enumerate() {
            assert!(slave.receive(RxChar::ok(b, (i as u64 + 1) * ct)).is_none());
        }
        let deadline = slave.next_deadline(3 * ct).expect("a frame in progress");
        assert_eq!(deadline, 3 * ct + timeout);
        let t = slave.poll(deadline).and_then(|s| s.transmission).expect("a reply");
        assert!(svg.contains(&format!("processed at {}", ms(deadline))));
        assert!(svg.contains(&format!("reply {}", hex(t.frame.as_bytes()))));
        assert_eq!(t.frame.as_bytes(), &[0x40, 0x42, 0x00, 0x00, 0x30, 0x39, 0x0B]);
        let limit = profiles::srs50().response_limit(hiperface_model::CommandId::ReadPosition).max_ms;
        assert!(svg.contains(&format!("response window {} (42h)", ms(limit as u64 * 1000))));
        assert_eq!(t.latest_start_us - t.earliest_start_us, limit as u64 * 1000);
        // Each bit of the request is drawn with its name: start, D0...D7, parity, stop.
        for name in [">St<", ">D0<", ">D7<", ">P<", ">Sp<", ">40h address<", ">42h command<", ">02h checksum<"] {
            assert!(svg.contains(name), "{name}");
        }
    }

    #[test]
    fn the_power_up_boundaries_are_the_models() {
        let p = profiles::srs50();
        let up = hiperface_model::slave::powerup::PowerUp::at(0);
        let svg = svg_of("power-up-current");
        let mut t = 0;
        while let Some(next) = up.next_change(&p, t) {
            assert!(svg.contains(&format!(">{}<", ms(next))), "{}", ms(next));
            t = next;
        }
        assert_eq!(t, 1_100_000);
        // The legacy window ends at about 1 s, with no change of settings between.
        let legacy = svg_of("power-up-legacy");
        assert!(legacy.contains(">1000 ms<") && !legacy.contains("Change of"));
        // The other branch keeps the default settings.
        for svg in [svg, legacy] {
            assert!(svg.contains("Operational (default communication)"));
            assert!(
                svg.contains("E5h (19200 Bd 8E1, long timeout)") && svg.contains("E4h (9600 Bd 8E1, long timeout)")
            );
        }
    }

    #[test]
    fn the_reset_is_silent_and_the_slave_listens_again_after_the_initialization() {
        let d = diagrams().into_iter().find(|d| d.id == "encoder-reset-53h").expect("drawn");
        let reset_at = 3 * UartSettings::DEFAULT.char_time_us() + 5730;
        assert!(d.svg.contains(&format!("reset at {}: no reply (Reset)", ms(reset_at))));
        assert!(d.caption.contains(&format!("sent at {}", ms(reset_at + 100_000))));
    }

    #[test]
    fn the_new_settings_shorten_the_characters() {
        let svg = svg_of("settings-67h");
        let fast = UartSettings { baud: Baud::B38400, ..UartSettings::DEFAULT };
        assert!(svg.contains(&format!("character {}", ms(fast.char_time_us()))), "0.287 ms");
        assert!(svg.contains(&format!("timeout {}", ms(fast.timeout_us(Edition::Current)))));
        assert!(svg.contains("42h 40 42 02 in E6h"));
    }

    #[test]
    fn text_is_escaped_and_bits_are_lsb_first_with_even_parity() {
        assert_eq!(escape("a < b & \"c\" > d"), "a &lt; b &amp; \"c\" &gt; d");
        let b = bits(0x42, UartSettings::DEFAULT);
        let levels: Vec<bool> = b.iter().map(|(_, l)| *l).collect();
        // 42h = 0100 0010: D1 and D6 set; two ones, so even parity 0.
        assert_eq!(levels, [false, false, true, false, false, false, false, true, false, false, true]);
        assert_eq!(b.len() as u32, UartSettings::DEFAULT.bits_per_char());
        assert_eq!(
            (ms(5730), ms(100_000), ms(287), tick(500), tick(1146)),
            (
                "5.730 ms".to_string(),
                "100 ms".to_string(),
                "0.287 ms".to_string(),
                "0.5".to_string(),
                "1.146".to_string()
            )
        );
    }
}
