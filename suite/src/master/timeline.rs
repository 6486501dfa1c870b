//! One SVG timeline per scenario of a master's certificate: the encoder's
//! state-machine phases, the master's requests, the encoder's replies, the injected
//! faults and the broken rules on one time axis (hover for the bytes and the clause).

use crate::report::escape;
use crate::verdict::{CaseResult, WireEntry};
use hiperface_model::Profile;
use std::fmt::Write as _;

const WIDTH: f64 = 1000.0;
const LEFT: f64 = 80.0;
const ROW: f64 = 22.0;
/// A character at 9600 Bd, for the width of a frame, ms.
const CHAR_MS: f64 = 11.0 / 9.6;

/// One scenario's timeline.
pub fn svg(c: &CaseResult, profile: &Profile) -> String {
    let end_ms = c.wire.iter().map(|w| w.t_us as f64 / 1000.0).fold(0.0, f64::max).max(1.0) + 20.0;
    let x = |ms: f64| LEFT + ms / end_ms * WIDTH;
    // The harness's own timing has a lane of its own, grey: it is no rule broken.
    let rows = ["encoder state", "master", "encoder", "injected", "rules broken", "harness timing"];
    let height = ROW * (rows.len() as f64 + 1.0);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{height}\" font-size=\"11\">",
        LEFT + WIDTH + 10.0
    );
    for (i, name) in rows.iter().enumerate() {
        let _ = write!(s, "<text x=\"2\" y=\"{}\">{name}</text>", ROW * (i as f64 + 1.0) - 6.0);
    }
    // The state machine after power-on (000:T9): initialization, default settings,
    // change of settings, user-defined settings.
    let phases = [
        (0.0, profile.init_ms as f64, "#ccc", "initialization: no UART"),
        (profile.init_ms as f64, profile.default_window_ms as f64, "#cde", "default communication"),
        (
            profile.default_window_ms as f64,
            profile.user_settings_ms as f64,
            "#edc",
            "change of settings (unless a request came)",
        ),
        (profile.user_settings_ms as f64, end_ms, "#dec", "operational"),
    ];
    for (from, to, colour, what) in phases {
        if from >= to {
            continue;
        }
        let _ = write!(
            s,
            "<rect x=\"{:.1}\" y=\"2\" width=\"{:.1}\" height=\"{}\" fill=\"{colour}\"><title>{what}: {from:.0}-{to:.0} ms</title></rect>",
            x(from),
            x(to) - x(from),
            ROW - 6.0
        );
    }
    for w in &c.wire {
        let ms = w.t_us as f64 / 1000.0;
        let n = w.bytes.split_whitespace().count() as f64;
        let title = escape(&format!("{ms:.3} ms {} {}", w.direction, w.bytes));
        let (row, colour, start, len) = match w.direction {
            // A request is stamped at its last character, a reply at its first.
            WireEntry::REQUEST => (1.0, "#36c", ms - n * CHAR_MS, n * CHAR_MS),
            WireEntry::REPLY => (2.0, "#393", ms, n * CHAR_MS),
            WireEntry::INJECTED => (3.0, "#c80", ms, 0.0),
            WireEntry::BROKEN => (4.0, "#c00", ms, 0.0),
            _ => (5.0, "#999", ms, 0.0),
        };
        let y = ROW * row + 2.0;
        if len > 0.0 {
            let _ = write!(
                s,
                "<rect x=\"{:.1}\" y=\"{y}\" width=\"{:.1}\" height=\"{}\" fill=\"{colour}\"><title>{title}</title></rect>",
                x(start),
                (x(start + len) - x(start)).max(1.0),
                ROW - 6.0
            );
        } else {
            let _ = write!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{}\" r=\"5\" fill=\"{colour}\"><title>{title}</title></circle>",
                x(start),
                y + (ROW - 6.0) / 2.0
            );
        }
    }
    // The time axis.
    let step = [10.0, 50.0, 100.0, 250.0, 500.0, 1000.0].into_iter().find(|s| end_ms / s <= 12.0).unwrap_or(1000.0);
    let mut t = 0.0;
    while t <= end_ms {
        let _ = write!(
            s,
            "<line x1=\"{0:.1}\" x2=\"{0:.1}\" y1=\"0\" y2=\"{1}\" stroke=\"#eee\"/><text x=\"{0:.1}\" y=\"{2}\">{t:.0} ms</text>",
            x(t),
            height - ROW,
            height - 6.0
        );
        t += step;
    }
    s += "</svg>";
    s
}
