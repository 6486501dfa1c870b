//! Figures and captions: times, bytes and settings as the diagrams print them, and
//! a caption's list of figures with the clauses they come from.

use hiperface_model::clause::Clause;
use hiperface_model::settings::{Parity, UartSettings};

/// One bit's time as it is (1/9600 s = "104.17 µs"), not rounded to whole µs: a reader
/// multiplies it by 11 or 55 and gets the character and the timeout printed beside it.
pub(super) fn bit_time(s: UartSettings) -> String {
    format!("{:.2} µs", 1e6 / f64::from(s.baud.bits_per_second().max(1)))
}

/// `us` in ms with µs precision: "5.730 ms", "100 ms".
pub(super) fn ms(us: u64) -> String {
    if us % 1000 == 0 {
        format!("{} ms", us / 1000)
    } else {
        format!("{}.{:03} ms", us / 1000, us % 1000)
    }
}

/// A tick label: ms without the unit and without trailing zeros ("1.146", "0.5", "4").
pub(super) fn tick(us: u64) -> String {
    let s = format!("{}.{:03}", us / 1000, us % 1000);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

pub(super) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02X}h")).collect::<Vec<_>>().join(" ")
}

pub(super) fn ids(clauses: &[Clause]) -> String {
    clauses.iter().map(|c| c.id()).collect::<Vec<_>>().join(", ")
}

/// A caption: paragraphs, then the list of figures with their clauses.
pub(super) struct Caption {
    pub(super) text: String,
    pub(super) figures: String,
}

impl Caption {
    pub(super) fn new(paragraphs: &[String]) -> Caption {
        Caption { text: paragraphs.join("\n\n"), figures: String::new() }
    }

    pub(super) fn figure(&mut self, name: &str, value: &str, clauses: &[Clause]) {
        self.figures.push_str(&format!("- {name}: {value} ({})\n", ids(clauses)));
    }

    pub(super) fn finish(self) -> String {
        format!("{}\n\n{}", self.text, self.figures)
    }
}

/// The character format of `s` in words. // 000:T4
pub(super) fn format_words(s: UartSettings) -> String {
    let parity = match s.parity {
        Parity::Even => "even parity, ",
        Parity::Odd => "odd parity, ",
        Parity::None => "",
    };
    format!("start bit, 8 data bits LSB first, {parity}stop bit")
}

/// Bytes as the lanes print them: "40 42 02".
pub(super) fn hex_plain(bytes: &[u8]) -> String {
    hiperface_model::Hex(bytes).to_string()
}
