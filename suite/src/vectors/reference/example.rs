//! One example of a chapter: a vector's starting state in words, the requests that
//! set it up, an erratum's printed and corrected frames, then each step.

use super::frame::{frame_html, step_html, Role};
use super::{capitalised, md, ms};
use crate::vectors::{parse_hex, Erratum, Expected, Setup, Vector};
use hiperface_model::CommandId;
use std::fmt::Write as _;

/// One example: a vector, its starting state, the erratum once, then each step's
/// request and reply.
pub(super) fn example(file: &str, v: &Vector, errata: &mut Vec<Erratum>) -> String {
    let title = match v.source.as_str() {
        "generated" => md(&capitalised(&v.meaning)),
        source => format!("{}: {}", document(source), md(&v.meaning)),
    };
    let result = match v.result {
        Expected::Valid => "valid",
        Expected::Acceptable => "acceptable (NON-STRICT)",
        Expected::Invalid => "**invalid**: must not be produced, a master must reject it",
    };
    let mut s = format!(
        "\n### {title}\n\n`{}` in `{file}`; clauses {}; {result}.\n\n{}\n",
        v.id,
        v.clauses.join(", "),
        state(v)
    );
    if let Some(e) = &v.erratum {
        if errata.contains(e) {
            let _ = writeln!(s, "\nThe erratum above: printed `{}`, corrected `{}`.", e.printed, e.corrected);
        } else {
            errata.push(e.clone());
            s.push_str(&erratum(v, e));
        }
    }
    let many = v.steps.len() > 1;
    for (i, step) in v.steps.iter().enumerate() {
        let mut said = Vec::new();
        let after = if v.setup.power_on { " after power-on" } else { "" };
        if step.chars_at_us.is_empty() {
            if let Some(t) = step.at_us {
                said.push(format!("at t = {}{after}", ms(t)));
            }
        } else {
            let ends: Vec<String> = step.chars_at_us.iter().map(|t| ms(*t)).collect();
            let taken = step.at_us.map_or(String::new(), |t| format!(", the slave takes it at t = {}", ms(t)));
            said.push(format!("the request's characters end at t = {}{after}{taken}", ends.join(", ")));
        }
        if step.uart_fault {
            said.push(
                "a character of the request arrives with a UART fault (a parity, framing, noise or overrun \
                 fault: 000:T47 names the fault, not the character, and any character draws the same reply)"
                    .into(),
            );
        }
        if let Some(n) = &step.note {
            said.push(md(n));
        }
        match (many, said.is_empty()) {
            (true, _) => {
                let _ = write!(
                    s,
                    "\n**Step {}**{}\n",
                    i + 1,
                    if said.is_empty() { String::new() } else { format!(": {}.", said.join("; ")) }
                );
            }
            (false, false) => {
                let _ = write!(s, "\n{}.\n", capitalised(&said.join("; ")));
            }
            (false, true) => {}
        }
        s.push('\n');
        s.push_str(&step_html(step));
        s.push('\n');
    }
    s
}

/// The document a source names: `001 §5.1.4.9` from `001_9b88….txt §5.1.4.9`.
pub(super) fn document(source: &str) -> String {
    let (file, place) = source.split_once(' ').unwrap_or((source, ""));
    let doc = file.split('_').next().unwrap_or(file);
    format!("{doc} {place}").trim().to_string()
}

/// The vector's starting state in words.
pub(super) fn state(v: &Vector) -> String {
    let Setup { power_on, inputs, init_faults, position_faults, i2c_fault, counter, settings, requests } = &v.setup;
    let mut said = vec![format!("profile `{}`", v.profile)];
    if *power_on {
        said.push("from power-on, each step at its time after it".into());
    }
    if let Some(i) = inputs {
        let mut inputs = Vec::new();
        if let Some(p) = i.position {
            inputs.push(format!("raw position {p} steps"));
        }
        if let Some(sp) = i.speed {
            inputs.push(format!("speed {sp} rpm"));
        }
        if let Some(t) = i.temperature_c {
            inputs.push(format!("temperature {t} °C"));
        }
        if let Some(c) = i.led_current_ma {
            inputs.push(format!("transmitter current {c} mA"));
        }
        said.push(inputs.join(", "));
    }
    if !init_faults.is_empty() {
        said.push(format!("found at start-up: {}", init_faults.join(", ")));
    }
    if !position_faults.is_empty() {
        said.push(format!("position faults present: {}", position_faults.join(", ")));
    }
    if *i2c_fault {
        said.push("the internal I2C bus to the EEPROM is down".into());
    }
    if let Some(c) = counter {
        said.push(format!("counter {c}"));
    }
    if let Some(b) = settings {
        said.push(format!("stored settings byte {b}h"));
    }
    let mut out = format!("Starting state: {}.", said.join("; "));
    if !requests.is_empty() {
        out.push_str(&format!("\n\n{}", set_up(requests)));
    }
    out
}

/// The requests that bring the slave to a vector's starting state, labelled as set-up
/// (not part of the example) and, for the state every command vector shares, why.
pub(super) fn set_up(requests: &[String]) -> String {
    let frames: Vec<String> = requests
        .iter()
        .map(|r| format!("`{r}` ({})", CommandId::of_frame(&parse_hex(r).unwrap_or_default())))
        .collect();
    let shared = requests == crate::vectors::fixtures::with_field_0().requests.as_slice();
    let why = if shared {
        ": data field 0 exists, the starting state every generated command example shares, so that the \
         data-field commands have a field to act on"
    } else {
        ": they bring the slave to the state this example needs"
    };
    let request = if requests.len() == 1 { "request" } else { "requests" };
    format!("Set-up, before the example (replies not shown): the {request} {}{why}.", frames.join(", "))
}

/// The printed and the corrected frame side by side, with the reason.
pub(super) fn erratum(v: &Vector, e: &Erratum) -> String {
    let (printed, corrected) = (parse_hex(&e.printed).unwrap_or_default(), parse_hex(&e.corrected).unwrap_or_default());
    // A request where the corrected frame is one of the vector's requests; otherwise
    // the reply to the step's request.
    let request = v.steps.iter().find(|s| s.request == e.corrected || s.request == e.printed);
    let to = v.steps.iter().find(|s| s.response.as_deref() == Some(e.corrected.as_str()));
    let role = match (request, to) {
        (Some(_), _) => Role::Request,
        (None, Some(s)) => Role::Reply(CommandId::of_frame(&parse_hex(&s.request).unwrap_or_default())),
        (None, None) => Role::Request,
    };
    let differ: Vec<bool> = printed.iter().zip(&corrected).map(|(a, b)| a != b).collect();
    format!(
        "\n**Erratum**: {}.\n\n<div class=\"hf-erratum\">\n{}\n{}\n</div>\n",
        md(&e.reason),
        frame_html(&printed, role, "as printed", &differ),
        frame_html(&corrected, role, "corrected", &[]),
    )
}
