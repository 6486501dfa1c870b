//! A unit's wire log as a certificate shows it: a line per frame, long frames wrapped
//! at 16 bytes so that nothing hides past the right edge, the frame a finding is about
//! marked with the finding ("<-- FAIL 000:2.3.3"), and in a marked frame the byte that
//! carries the fault pointed at ("^^") and, in HTML, highlighted as the book does.
//!
//! The marked frame is the one the device under test sent: a slave's reply (its
//! request where none was heard: a reply missing, or the request the slave must have
//! ignored), a master's request.

use crate::report::escape;
use crate::verdict::{CaseResult, CaseVerdict, WireEntry};
use hiperface_model::checksum;

/// Who is under test, so whose frame carries a fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnderTest {
    Slave,
    Master,
}

/// Bytes per line of a wrapped frame.
const PER_LINE: usize = 16;

/// The width of "   12345.678 ms  M>  " (12, " ms  ", 2, "  "): where a frame's first byte starts.
const BYTES_AT: usize = 21;

/// A byte the reader must look at: its index in the frame and why.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Pointed {
    index: usize,
    why: String,
}

/// The wire log as text (Markdown code blocks, JUnit, the console).
pub fn text(c: &CaseResult, under: UnderTest) -> String {
    render(c, under, &str::to_string, &|b| b.to_string())
}

/// The wire log as the inside of an HTML `<pre>`: escaped, the faulty byte in `<mark>`.
pub fn html(c: &CaseResult, under: UnderTest) -> String {
    render(c, under, &escape, &|b| format!("<mark class=\"bad\">{b}</mark>"))
}

fn render(c: &CaseResult, under: UnderTest, words: &dyn Fn(&str) -> String, bad: &dyn Fn(&str) -> String) -> String {
    let marks = marks(c, under);
    let mut s = String::new();
    for (w, mark) in c.wire.iter().zip(marks) {
        let head = format!("{:>12.3} ms  {:<2}  ", w.t_us as f64 / 1000.0, w.direction);
        let mark = if mark.is_empty() { String::new() } else { format!("  <-- {mark}") };
        let Some(bytes) = frame_bytes(w) else {
            s += &format!("{}{}{}\n", words(&head), words(&w.bytes), words(&mark));
            continue;
        };
        let pointed = if mark.is_empty() { None } else { faulty_byte(&bytes) };
        let hex: Vec<String> = bytes.iter().map(|b| format!("{b:02X}")).collect();
        for (row, chunk) in hex.chunks(PER_LINE).enumerate() {
            let lead = if row == 0 { head.clone() } else { " ".repeat(BYTES_AT) };
            let cells: Vec<String> = chunk
                .iter()
                .enumerate()
                .map(|(i, h)| match &pointed {
                    Some(p) if p.index == row * PER_LINE + i => bad(h),
                    _ => h.clone(),
                })
                .collect();
            let tail = if row == 0 { words(&mark) } else { String::new() };
            s += &format!("{}{}{tail}\n", words(&lead), cells.join(" "));
            if let Some(p) = pointed.as_ref().filter(|p| p.index / PER_LINE == row) {
                let at = BYTES_AT + 3 * (p.index % PER_LINE);
                s += &words(&format!("{}^^ {}\n", " ".repeat(at), p.why));
            }
        }
    }
    s
}

/// For each wire entry, the verdicts of the findings about the frame it is ("FAIL
/// 000:T10"), for the marks in a wire log; "" for an entry no finding is about. The
/// frame is the one the device under test sent in the exchange: a slave's reply, or
/// its request where none was heard; a master's request.
fn marks(c: &CaseResult, under: UnderTest) -> Vec<String> {
    let mut marks: Vec<Vec<String>> = vec![Vec::new(); c.wire.len()];
    for f in c.findings.iter().filter(|f| !matches!(f.verdict(), CaseVerdict::Pass | CaseVerdict::NotApplicable)) {
        let frame = f.at_us().and_then(|t| request_index(c, t)).map(|i| match under {
            UnderTest::Slave => reply_index(c, i).unwrap_or(i),
            UnderTest::Master => i,
        });
        let Some(entry) = frame.and_then(|i| marks.get_mut(i)) else {
            continue;
        };
        let m = match f.clause_id() {
            "" => f.verdict().label().to_string(),
            id => format!("{} {id}", f.verdict().label()),
        };
        if !entry.contains(&m) {
            entry.push(m);
        }
    }
    marks.into_iter().map(|m| m.join(", ")).collect()
}

/// The wire entry of the reply to the request at `request` (before the next request).
pub(super) fn reply_index(u: &CaseResult, request: usize) -> Option<usize> {
    u.wire
        .iter()
        .enumerate()
        .skip(request + 1)
        .take_while(|(_, w)| w.direction != WireEntry::REQUEST)
        .find(|(_, w)| w.direction == WireEntry::REPLY)
        .map(|(i, _)| i)
}

/// The wire entry of the request a finding at `at_us` is about. A slave's finding is
/// placed at its request's end, that request's time in the wire log; a master's broken
/// rule at the start of the frame that broke it, whose entry (stamped at its end) is
/// the next one. So: the first request at or after `at_us` with no reply before it,
/// else the last one sent by then (a reaction missing after a reply with a fault).
pub(super) fn request_index(u: &CaseResult, at_us: u64) -> Option<usize> {
    let frame = |w: &WireEntry| w.direction == WireEntry::REQUEST || w.direction == WireEntry::REPLY;
    match u.wire.iter().position(|w| w.t_us >= at_us && frame(w)) {
        Some(i) if u.wire.get(i).is_some_and(|w| w.direction == WireEntry::REQUEST) => Some(i),
        _ => u.wire.iter().rposition(|w| w.direction == WireEntry::REQUEST && w.t_us <= at_us),
    }
}

/// A frame's bytes, where the entry is a frame (a request, a reply, an injected one);
/// `None` for the entries in words (a broken rule, the harness's notes).
fn frame_bytes(w: &WireEntry) -> Option<Vec<u8>> {
    if ![WireEntry::REQUEST, WireEntry::REPLY, WireEntry::INJECTED].contains(&w.direction) {
        return None;
    }
    let bytes: Vec<u8> = w
        .bytes
        .split_whitespace()
        .map(|b| if b.len() == 2 { u8::from_str_radix(b, 16).ok() } else { None })
        .collect::<Option<_>>()?;
    (!bytes.is_empty()).then_some(bytes)
}

/// The byte of a frame that is wrong in itself: a checksum that is not the XOR of the
/// bytes before it (000:2.3.3). A frame too short to carry one (an address and a
/// command at least) points at nothing.
fn faulty_byte(frame: &[u8]) -> Option<Pointed> {
    let (last, body) = frame.split_last()?;
    (body.len() >= 2 && !checksum::is_valid(frame)).then(|| Pointed {
        index: body.len(),
        why: format!("checksum {last:02X}h, the XOR of the bytes before it {:02X}h (000:2.3.3)", checksum::xor(body)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verdict::Finding;
    use hiperface_model::{clause, Edition};

    fn unit(wire: &[(u64, &'static str, &str)]) -> CaseResult {
        let mut c = CaseResult::named("identity.version", "Read Version", &[]);
        for &(t_us, direction, bytes) in wire {
            c.wire.push(WireEntry { t_us, direction, bytes: bytes.to_string() });
        }
        c
    }

    const VERSION: &str = "40 56 48 58 31 30 30 30 30 34 32 68 78 31 20 66 77 20 32 2E 37 00 00 00 00 00 00 00 00 00 00 30 33 2E 31 30 2E 32 36 76";

    #[test]
    fn a_slaves_bad_checksum_is_marked_on_its_reply_and_the_byte_pointed_at() {
        let mut c = unit(&[(74_201, WireEntry::REQUEST, "40 56 16"), (79_226, WireEntry::REPLY, VERSION)]);
        c.push(Finding::fail("malformed reply", clause::CHECKSUM, Edition::Current).at(74_201));
        let t = text(&c, UnderTest::Slave);
        let lines: Vec<&str> = t.lines().collect();
        assert!(!lines[0].contains("<--"), "the request is not where the fault is:\n{t}");
        assert!(lines[1].contains("S<  40 56 48") && lines[1].ends_with("<-- FAIL 000:2.3.3"), "{t}");
        // 40 bytes: three lines of at most 16, the marker on the first.
        assert_eq!(lines.len(), 5, "{t}");
        assert!(lines[..4].iter().all(|l| l.chars().count() <= BYTES_AT + 3 * PER_LINE + 20), "{t}");
        let caret = lines[4];
        let checksum_at = lines[3].rfind("76").unwrap();
        assert_eq!(caret.find("^^"), Some(checksum_at), "under the checksum byte:\n{t}");
        assert!(caret.contains("checksum 76h, the XOR of the bytes before it 2Ch"), "{t}");
        let h = html(&c, UnderTest::Slave);
        assert!(h.contains("<mark class=\"bad\">76</mark>") && h.contains("&lt;-- FAIL"), "{h}");
        assert_eq!(h.matches("<mark").count(), 1, "{h}");
    }

    #[test]
    fn a_missing_reply_is_marked_on_its_request_and_a_masters_fault_on_its_request() {
        let mut c = unit(&[
            (1_000, WireEntry::REQUEST, "40 42 02"),
            (9_000, WireEntry::REQUEST, "40 42 03"),
            (9_500, WireEntry::REPLY, "40 42 00 00 00 01 03"),
        ]);
        c.push(Finding::fail("no reply", clause::COMMANDS, Edition::Current).at(1_000));
        let t = text(&c, UnderTest::Slave);
        assert!(t.lines().next().unwrap().ends_with("<-- FAIL 000:T10"), "{t}");
        assert_eq!(t.matches("<--").count(), 1, "{t}");
        assert!(!t.contains("^^"), "a valid request has no faulty byte: {t}");
        let mut m = unit(&[(9_000, WireEntry::REQUEST, "40 42 03"), (9_500, WireEntry::REPLY, "40 42 00 00 00 01 03")]);
        m.push(Finding::fail("bad checksum", clause::MASTER_FRAME, Edition::Current).at(8_000));
        let t = text(&m, UnderTest::Master);
        let lines: Vec<&str> = t.lines().collect();
        assert!(lines[0].contains("M>  40 42 03") && lines[0].contains("<-- FAIL"), "{t}");
        assert!(lines[1].trim_start().starts_with("^^ checksum 03h, the XOR of the bytes before it 02h"), "{t}");
        assert_eq!(lines[1].find("^^"), lines[0].find("03"), "{t}");
        assert!(!lines[2].contains("<--"), "the encoder's reply is not the master's fault: {t}");
    }

    #[test]
    fn entries_in_words_are_written_as_they_are() {
        let c = unit(&[(5, WireEntry::BROKEN, "a frame that is no request"), (6, WireEntry::REQUEST, "40 4")]);
        let t = text(&c, UnderTest::Master);
        assert!(t.contains("×   a frame that is no request") && t.contains("M>  40 4\n"), "{t}");
    }
}
