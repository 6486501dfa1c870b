//! The diagrams against the model they are drawn from: unique ids, standalone
//! well-formed SVG, captions citing clauses that exist, the figures the model's.

use super::caption::{hex, ms, tick};
use super::svg::bits;
use super::*;
use crate::report::escape;
use hiperface_model::clause;
use hiperface_model::datalink::RxChar;
use hiperface_model::profiles;
use hiperface_model::settings::{Baud, UartSettings};
use hiperface_model::Slave;

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
        assert!(svg.contains("E5h (19200 Bd 8E1, long timeout)") && svg.contains("E4h (9600 Bd 8E1, long timeout)"));
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
        ("5.730 ms".to_string(), "100 ms".to_string(), "0.287 ms".to_string(), "0.5".to_string(), "1.146".to_string())
    );
}
