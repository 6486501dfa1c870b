//! The drawing primitives: a small SVG builder, the time axis, and the lanes the
//! diagrams share (bit traces, character boxes, markers, power-up phases).

use super::caption::tick;
use super::run::{Char, Phase};
use crate::report::escape;
use hiperface_model::settings::{Parity, UartSettings};
use hiperface_model::slave::powerup::CommState;

pub(super) const WIDTH: f64 = 1240.0;
/// Lane names on the left, plots from here to `PLOT_RIGHT`.
pub(super) const PLOT_LEFT: f64 = 170.0;
pub(super) const PLOT_RIGHT: f64 = 1215.0;

pub(super) const INK: &str = "#1a1a1a";
pub(super) const GREY: &str = "#666666";
pub(super) const RULE: &str = "#bbbbbb";
pub(super) const BLUE: &str = "#1f56a8";
pub(super) const BLUE_FILL: &str = "#d8e4f6";
pub(super) const GREEN: &str = "#2a7a2e";
pub(super) const GREEN_FILL: &str = "#d9eed9";
pub(super) const ORANGE: &str = "#b86500";
pub(super) const PURPLE: &str = "#7a3a9e";
pub(super) const RED: &str = "#b3261e";

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Anchor {
    Start,
    Middle,
    End,
}

/// How a text is set.
#[derive(Debug, Clone, Copy)]
pub(super) struct Font {
    pub(super) size: f64,
    pub(super) bold: bool,
    pub(super) anchor: Anchor,
    pub(super) colour: &'static str,
}

impl Font {
    pub(super) const TITLE: Font = Font { size: 17.0, bold: true, anchor: Anchor::Start, colour: INK };
    pub(super) const HEADING: Font = Font { size: 13.0, bold: true, anchor: Anchor::Start, colour: INK };
    pub(super) const LABEL: Font = Font { size: 12.0, bold: false, anchor: Anchor::Start, colour: INK };
    pub(super) const SMALL: Font = Font { size: 10.5, bold: false, anchor: Anchor::Start, colour: GREY };

    pub(super) const fn at(self, anchor: Anchor) -> Font {
        Font { anchor, ..self }
    }

    pub(super) const fn colour(self, colour: &'static str) -> Font {
        Font { colour, ..self }
    }

    pub(super) const fn bold(self) -> Font {
        Font { bold: true, ..self }
    }

    /// An estimate of the width of `text` (sans-serif, about 0.58 em a character).
    pub(super) fn width(&self, text: &str) -> f64 {
        text.chars().count() as f64 * self.size * if self.bold { 0.62 } else { 0.58 }
    }
}

/// An SVG document under construction.
pub(super) struct Svg {
    pub(super) width: f64,
    pub(super) height: f64,
    pub(super) body: String,
}

impl Svg {
    pub(super) fn new(width: f64, height: f64) -> Svg {
        Svg { width, height, body: String::new() }
    }

    pub(super) fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, fill: &str, stroke: &str) {
        self.body.push_str(&format!(
            "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{h:.1}\" fill=\"{fill}\" stroke=\"{stroke}\"/>\n",
            w.max(0.5)
        ));
    }

    pub(super) fn line(&mut self, (x1, y1): (f64, f64), (x2, y2): (f64, f64), stroke: &str, dashed: bool) {
        let dash = if dashed { " stroke-dasharray=\"4 3\"" } else { "" };
        self.body.push_str(&format!(
            "<line x1=\"{x1:.1}\" y1=\"{y1:.1}\" x2=\"{x2:.1}\" y2=\"{y2:.1}\" stroke=\"{stroke}\"{dash}/>\n"
        ));
    }

    pub(super) fn polyline(&mut self, points: &[(f64, f64)], stroke: &str, width: f64) {
        let pts: Vec<String> = points.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        self.body.push_str(&format!(
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{stroke}\" stroke-width=\"{width}\" stroke-linejoin=\"miter\"/>\n",
            pts.join(" ")
        ));
    }

    pub(super) fn text(&mut self, x: f64, y: f64, text: &str, font: Font) {
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
    pub(super) fn span(&mut self, x1: f64, x2: f64, y: f64, label: &str, note: &str, colour: &'static str) {
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
    pub(super) fn labelled_box(&mut self, x1: f64, x2: f64, y: f64, h: f64, (fill, stroke): (&str, &str), label: &str) {
        self.rect(x1, y, x2 - x1, h, fill, stroke);
        let font = Font::LABEL.at(Anchor::Middle);
        if font.width(label) + 4.0 <= x2 - x1 {
            self.text((x1 + x2) / 2.0, y + h / 2.0 + 4.0, label, font);
        }
    }

    /// The document: a white background, a `<title>`, the drawing.
    pub(super) fn finish(self, title: &str) -> String {
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
pub(super) struct Axis {
    pub(super) t0: u64,
    pub(super) t1: u64,
    pub(super) x0: f64,
    pub(super) x1: f64,
}

impl Axis {
    pub(super) fn new(t0: u64, t1: u64, x0: f64, x1: f64) -> Axis {
        Axis { t0, t1: t1.max(t0 + 1), x0, x1 }
    }

    pub(super) fn x(&self, t_us: u64) -> f64 {
        let span = (self.t1 - self.t0) as f64;
        self.x0 + (t_us as f64 - self.t0 as f64) / span * (self.x1 - self.x0)
    }

    /// The axis line at `y` with a tick and label at each of `ticks` (µs) and the
    /// unit after the last one.
    pub(super) fn draw(&self, svg: &mut Svg, y: f64, ticks: &[u64]) {
        svg.line((self.x0, y), (self.x1, y), INK, false);
        for t in ticks {
            let x = self.x(*t);
            svg.line((x, y), (x, y + 5.0), INK, false);
            svg.text(x, y + 18.0, &tick(*t), Font::SMALL.colour(INK).at(Anchor::Middle));
        }
        svg.text(self.x1 + 6.0, y + 4.0, "ms", Font::SMALL.colour(INK));
    }

    /// Ticks every `step_us` from `t0` (rounded up to a multiple of the step).
    pub(super) fn every(&self, step_us: u64) -> Vec<u64> {
        let first = self.t0.div_ceil(step_us) * step_us;
        (0..).map(|i| first + i * step_us).take_while(|t| *t <= self.t1).collect()
    }
}

/// A lane's name on the left.
pub(super) fn lane_name(svg: &mut Svg, y: f64, name: &str, sub: &str) {
    svg.text(PLOT_LEFT - 10.0, y, name, Font::LABEL.bold().at(Anchor::End));
    if !sub.is_empty() {
        svg.text(PLOT_LEFT - 10.0, y + 14.0, sub, Font::SMALL.at(Anchor::End));
    }
}

/// The bits of one character, as they leave the transmitter: start, 8 data bits LSB
/// first, parity, stop; `true` is the idle level (mark). // 000:T4, 000:2.2.1
pub(super) fn bits(byte: u8, settings: UartSettings) -> Vec<(String, bool)> {
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
pub(super) fn bit_trace(svg: &mut Svg, axis: &Axis, chars: &[Char], settings: UartSettings, top: f64, names: &[&str]) {
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
pub(super) fn char_boxes(svg: &mut Svg, axis: &Axis, chars: &[Char], y: f64, colours: (&str, &str)) {
    for c in chars {
        svg.labelled_box(axis.x(c.start_us), axis.x(c.end_us), y, 24.0, colours, &format!("{:02X}", c.byte));
    }
}

/// A vertical marker through the lanes with a label at its top.
pub(super) fn marker(svg: &mut Svg, x: f64, (y1, y2): (f64, f64), label: &str, colour: &'static str) {
    svg.line((x, y1), (x, y2), colour, true);
    if !label.is_empty() {
        svg.text(x + 4.0, y1 + 11.0, label, Font::SMALL.colour(colour));
    }
}

/// Colours of a power-up state's box. // 000:T9
pub(super) fn state_colours(state: CommState) -> (&'static str, &'static str) {
    match state {
        CommState::Initialization => ("#e2e2e2", "#8a8a8a"),
        CommState::DefaultCommunication => ("#d8e4f6", "#5a7fb8"),
        CommState::OperationalDefault => ("#c4d6f2", "#3d68aa"),
        CommState::ChangeOfSettings => ("#f8e3c6", "#b88a3e"),
        CommState::OperationalUser => ("#d9eed9", "#4f8f52"),
    }
}

/// What the slave listens with, as a lane says it.
pub(super) fn listening_text(s: Option<UartSettings>) -> String {
    s.map_or_else(|| "no UART".to_string(), |s| s.to_string())
}

/// Power-up phases as boxes on a lane: the state's name, then the listening settings.
pub(super) fn phase_boxes(svg: &mut Svg, axis: &Axis, phases: &[Phase], y: f64) {
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
