//! The project's own wire logs: the text of `simulate --log` and of a certificate
//! (`   171.465 ms  M> 40 42 02`), and `certify --report`'s report.json.
//!
//! Long because: the text form, its fast path for the common line and report.json's
//! record are one reader of the project's own logs; its tests are the format's edge
//! cases.
//!
//! A line holds a whole frame with one time: for a request (`M>`) the end of its last
//! character's stop bit, for a reply (`S<`) the start of its first start bit. The
//! characters between are taken as sent back to back at the bus's rate: the log does
//! not keep them apart, so a gap inside a frame is not in it.

use super::{Capture, Event, Input, Mark, ParseError, ReadOptions, Role, Run};

/// A line of the text form.
pub fn is_line(l: &str) -> bool {
    parse_line(l).is_some()
}

/// `(t_us, role, bytes)` of one text line.
fn parse_line(l: &str) -> Option<(u64, Role, Vec<u8>)> {
    let mut words = l.split_ascii_whitespace();
    let t_us = ms_as_us(words.next()?)?;
    if words.next()? != "ms" {
        return None;
    }
    let role = match words.next()? {
        "M>" => Role::Master,
        "S<" => Role::Slave,
        _ => return None,
    };
    let mut bytes = Vec::with_capacity(hiperface_model::frame::MAX_FRAME);
    for w in words {
        bytes.push(super::hex_byte(w)?);
    }
    (!bytes.is_empty()).then_some((t_us, role, bytes))
}

/// A time written in ms (`171.465`), in µs. The logs' own form (at most three
/// decimals) is read exactly; any other number is rounded to the µs.
fn ms_as_us(word: &str) -> Option<u64> {
    // A word holds no space or tab: the exact form, if it is one, is the whole word.
    if let Some((us, _)) = exact_ms_as_us(word.as_bytes()) {
        return Some(us);
    }
    let t_ms: f64 = word.parse().ok()?;
    (t_ms.is_finite() && t_ms >= 0.0).then(|| (t_ms * 1000.0).round() as u64)
}

/// The logs' own form of a time at the start of `text`, exactly in µs, and how many
/// bytes it takes: 1 to 12 digits, then optionally a point and up to 3 more, up to the
/// end of `text` or a space or a tab.
fn exact_ms_as_us(text: &[u8]) -> Option<(u64, usize)> {
    // One pass: the integer's digits and then the fraction's, as one number.
    let (mut n, mut int_digits, mut frac_digits, mut point) = (0u64, 0u32, 0u32, false);
    let mut len = text.len();
    for (i, b) in text.iter().enumerate() {
        match b {
            b'0'..=b'9' if !point && int_digits < 12 => int_digits += 1,
            b'0'..=b'9' if point && frac_digits < 3 => frac_digits += 1,
            b'.' if !point => {
                point = true;
                continue;
            }
            b' ' | b'\t' => {
                len = i;
                break;
            }
            _ => return None,
        }
        n = n * 10 + u64::from(b - b'0');
    }
    (int_digits > 0).then(|| (n * 10u64.pow(3 - frac_digits), len))
}

/// Read the common form of a line from its bytes (without its end):
/// `<digits>[.<up to 3 digits>] ms M>|S<` and two-digit hex bytes, separated by spaces
/// or tabs, printable ASCII only. What it reads, [`parse_line`] reads the same;
/// anything else (`0x40`, `1e3 ms`, a comment, a character outside ASCII) is left to
/// [`parse_line`], which checks the text is UTF-8. A capture holds millions of such
/// lines: no allocation, one pass over the words.
fn parse_common(line: &[u8], bytes: &mut Vec<u8>) -> Option<(u64, Role)> {
    read_common(line, LineEnd::TextEnd, bytes).map(|(t_us, role, _)| (t_us, role))
}

/// Where the line [`read_common`] reads ends.
#[derive(Clone, Copy, PartialEq, Eq)]
enum LineEnd {
    /// At its newline, which must be in the text (`\r\n` or `\n`).
    Newline,
    /// At the end of the text: a line without its end.
    TextEnd,
}

/// The common form of a line at the start of `text` (see [`parse_common`]), read in
/// one pass up to its end: `(t_us, role, where the line ends)` (its newline, or the
/// text's end). Read up to a newline, a log's lines need no search for their newline
/// first; a line this does not read so (no newline in `text`, more than one `\r`
/// before it) is searched for and read again without its end.
fn read_common(text: &[u8], end: LineEnd, bytes: &mut Vec<u8>) -> Option<(u64, Role, usize)> {
    let mut s = skip_blanks(text);
    // The time: 1 to 12 digits, then optionally a point and up to 3 more (as
    // [`exact_ms_as_us`] reads it, without looking past it first: a hot path).
    let (mut n, mut digits) = (0u64, 0u32);
    while let [d @ b'0'..=b'9', rest @ ..] = s {
        n = n * 10 + u64::from(d - b'0');
        digits += 1;
        s = rest;
    }
    if digits == 0 || digits > 12 {
        return None;
    }
    let mut scale = 1000;
    if let [b'.', rest @ ..] = s {
        s = rest;
        while let [d @ b'0'..=b'9', rest @ ..] = s {
            if scale == 1 {
                return None;
            }
            scale /= 10;
            n = n * 10 + u64::from(d - b'0');
            s = rest;
        }
    }
    let t_us = n * scale;
    // `ms`, then `M>` or `S<`, blanks before each.
    let after = skip_blanks(s);
    let [b'm', b's', rest @ ..] = after else { return None };
    if after.len() == s.len() {
        return None;
    }
    let after = skip_blanks(rest);
    let role = match after {
        [b'M', b'>', ..] => Role::Master,
        [b'S', b'<', ..] => Role::Slave,
        _ => return None,
    };
    if after.len() == rest.len() {
        return None;
    }
    s = after.get(2..)?;
    // The bytes: two hex digits each, blanks before each; blanks, then the newline.
    bytes.clear();
    loop {
        let after = skip_blanks(s);
        match after {
            [b'\n', ..] | [b'\r', b'\n', ..] if end == LineEnd::Newline && !bytes.is_empty() => {
                let newline = text.len() - after.len() + usize::from(after.first() == Some(&b'\r'));
                return Some((t_us, role, newline));
            }
            [] if end == LineEnd::TextEnd && !bytes.is_empty() => return Some((t_us, role, text.len())),
            [h, l, rest @ ..] if after.len() < s.len() => {
                let (h, l) = (super::HEX_DIGIT[usize::from(*h)], super::HEX_DIGIT[usize::from(*l)]);
                if (h | l) > 0x0F {
                    return None;
                }
                bytes.push(h << 4 | l);
                s = rest;
            }
            _ => return None,
        }
    }
}

/// `s` without its leading spaces and tabs.
#[inline]
fn skip_blanks(s: &[u8]) -> &[u8] {
    let blanks = s.iter().position(|b| !matches!(b, b' ' | b'\t')).unwrap_or(s.len());
    s.get(blanks..).unwrap_or_default()
}

/// One frame of the log: its time, who sent it, its bytes (a buffer kept from frame to
/// frame).
struct Logged {
    t_us: u64,
    role: Role,
    bytes: Vec<u8>,
    /// The line it was read from.
    line: u64,
}

impl Logged {
    fn new() -> Logged {
        Logged { t_us: 0, role: Role::Master, bytes: Vec::with_capacity(hiperface_model::frame::MAX_FRAME), line: 0 }
    }
}

/// The frame whose characters are being handed out: the first one's end, the step
/// between them, the next to hand out.
struct Expanding {
    first_end: u64,
    step: u64,
    next: usize,
}

pub struct Reader<'a> {
    source: Source<'a>,
    options: ReadOptions,
    last_us: u64,
    line: u64,
    /// The frame being expanded, and how.
    frame: Logged,
    expanding: Option<Expanding>,
    /// One frame of look-ahead (where the next one starts bounds this one), if read.
    ahead: Logged,
    has_ahead: bool,
    /// Replies whose characters did not fit at the bus's rate.
    compressed: u64,
    /// The run's timing tolerance, where a report states it.
    tolerance_us: Option<u64>,
}

enum Source<'a> {
    Text {
        input: Input<'a>,
        buf: Vec<u8>,
    },
    /// The frames of a report.json, case after case.
    Report(std::vec::IntoIter<(u64, Role, Vec<u8>)>),
}

#[derive(serde::Deserialize)]
struct Report {
    cases: Vec<ReportCase>,
    #[serde(default)]
    tolerance_us: Option<u64>,
}

#[derive(serde::Deserialize)]
struct ReportCase {
    wire: Vec<ReportWire>,
}

#[derive(serde::Deserialize)]
struct ReportWire {
    t_us: u64,
    direction: String,
    bytes: String,
}

impl<'a> Reader<'a> {
    pub fn new(mut input: Input<'a>, options: ReadOptions) -> Result<Reader<'a>, ParseError> {
        let first = super::peek_first_line(&mut input).map_err(|e| ParseError::at(0, e.to_string()))?;
        let mut tolerance_us = None;
        let source = if first.trim_start().starts_with('{') {
            // A report is small (the cases' wire logs); it is read whole.
            let report: Report = serde_json::from_reader(input)
                .map_err(|e| ParseError::at(e.line() as u64, format!("expected a certify report.json: {e}")))?;
            let mut frames = Vec::new();
            for w in report.cases.iter().flat_map(|c| &c.wire) {
                let role = match w.direction.as_str() {
                    "M>" => Role::Master,
                    "S<" => Role::Slave,
                    d => return Err(ParseError::at(0, format!("a wire entry's direction `{d}`: expected M> or S<"))),
                };
                let bytes: Option<Vec<u8>> = w.bytes.split_whitespace().map(super::hex_byte).collect();
                let bytes = bytes
                    .filter(|b| !b.is_empty())
                    .ok_or_else(|| ParseError::at(0, format!("a wire entry's bytes `{}`: expected hex", w.bytes)))?;
                frames.push((super::capture_time(w.t_us, 0)?, role, bytes));
            }
            tolerance_us = report.tolerance_us;
            Source::Report(frames.into_iter())
        } else {
            Source::Text { input, buf: Vec::new() }
        };
        Ok(Reader {
            source,
            options,
            last_us: 0,
            line: 0,
            frame: Logged::new(),
            expanding: None,
            ahead: Logged::new(),
            has_ahead: false,
            compressed: 0,
            tolerance_us,
        })
    }

    /// The next frame of the log into `into`; `false` at the end.
    fn next_frame(source: &mut Source, line: &mut u64, into: &mut Logged) -> Result<bool, ParseError> {
        match source {
            Source::Report(frames) => {
                *line += 1;
                let Some((t_us, role, bytes)) = frames.next() else { return Ok(false) };
                (into.t_us, into.role, into.line) = (t_us, role, *line);
                into.bytes.clear();
                into.bytes.extend_from_slice(&bytes);
                Ok(true)
            }
            Source::Text { input, buf } => loop {
                // A line of the common form wholly in the reader's buffer is read where
                // it is (most lines are): no copy. Anything else, the way below.
                let available = match input.fill_buf() {
                    Ok(available) => available,
                    Err(e) => {
                        *line += 1;
                        return Err(ParseError::at(*line, format!("cannot read: {e}")));
                    }
                };
                // Most lines are read through their newline in one pass; the others
                // after a search for it. A line must end before the bound on its length.
                let within = available.get(..super::MAX_LINE).unwrap_or(available);
                let common = match read_common(within, LineEnd::Newline, &mut into.bytes) {
                    Some((t_us, role, newline)) => Some(((t_us, role), newline)),
                    None => memchr::memchr(b'\n', within).and_then(|newline| {
                        let l = super::without_line_end(available.get(..newline)?);
                        Some((parse_common(l, &mut into.bytes)?, newline))
                    }),
                };
                if let Some(((t_us, role), newline)) = common {
                    *line += 1;
                    input.consume(newline + 1);
                    (into.t_us, into.role, into.line) = (super::capture_time(t_us, *line)?, role, *line);
                    return Ok(true);
                }
                if !super::next_line_bytes(input.as_mut(), buf, line)? {
                    return Ok(false);
                }
                let (t_us, role) = match parse_common(buf, &mut into.bytes) {
                    Some(common) => common,
                    None => {
                        let l = std::str::from_utf8(buf).map_err(|_| ParseError::at(*line, "not UTF-8 text"))?.trim();
                        if l.is_empty() || l.starts_with('#') {
                            continue;
                        }
                        let (t_us, role, bytes) = parse_line(l).ok_or_else(|| {
                            ParseError::at(*line, format!("expected `<time> ms M>|S< <hex bytes>`, found `{l}`"))
                        })?;
                        into.bytes.clear();
                        into.bytes.extend_from_slice(&bytes);
                        (t_us, role)
                    }
                };
                (into.t_us, into.role, into.line) = (super::capture_time(t_us, *line)?, role, *line);
                return Ok(true);
            },
        }
    }

    /// How the frame's characters are stamped, each at the end of its stop bit. A
    /// reply whose characters back to back would run into the next frame (a log of a
    /// line that does not pace characters, such as `--port sim`) ends the timeout
    /// before that frame instead: its start is as logged, its length is not in the log.
    ///
    /// Likewise a request written at once on such a line, whose characters back to back
    /// would begin before the frame before it ended (a long Store Data, or one at a
    /// data rate the log does not say): its end is as logged, its characters share the
    /// time since that frame.
    fn expand(&mut self, next_start: Option<u64>) -> Result<Expanding, ParseError> {
        let ct = self.options.char_time_us();
        let Logged { t_us, role, ref bytes, line } = self.frame;
        let n = bytes.len() as u64;
        let mut step = ct;
        let first_end = match role {
            Role::Master => match t_us.checked_sub((n - 1) * ct) {
                Some(t) if t >= self.last_us => Some(t),
                _ if n > 1 && t_us > self.last_us => {
                    step = (t_us - self.last_us) / n;
                    self.compressed += 1;
                    Some(t_us - (n - 1) * step)
                }
                _ => None,
            },
            Role::Slave => t_us.checked_add(ct),
        };
        let first_end = first_end.filter(|t| *t >= self.last_us).ok_or_else(|| {
            ParseError::at(line, "a frame that starts before the one before it ended: expected times in order")
        })?;
        if let (Role::Slave, Some(next)) = (role, next_start) {
            let room = next.saturating_sub(self.options.timeout_us()).saturating_sub(first_end);
            if n > 1 && (n - 1) * ct > room {
                step = room / (n - 1);
                self.compressed += 1;
            }
        }
        self.last_us = first_end + (n - 1) * step;
        Ok(Expanding { first_end, step, next: 0 })
    }

    /// When a frame's first start bit began.
    fn start_of(&self, f: &Logged) -> u64 {
        match f.role {
            Role::Master => f.t_us.saturating_sub(f.bytes.len() as u64 * self.options.char_time_us()),
            Role::Slave => f.t_us,
        }
    }
}

impl Reader<'_> {
    /// The next frame to hand out is expanded: `None` at the end of the log.
    fn next_expanded(&mut self) -> Option<Result<(), ParseError>> {
        // The look-ahead frame (or the next one read) becomes the frame, and the one
        // after it is read ahead.
        if self.has_ahead {
            std::mem::swap(&mut self.frame, &mut self.ahead);
        } else {
            match Self::next_frame(&mut self.source, &mut self.line, &mut self.frame) {
                Ok(true) => {}
                Ok(false) => return None,
                Err(e) => return Some(Err(e)),
            }
        }
        let more = Self::next_frame(&mut self.source, &mut self.line, &mut self.ahead);
        self.has_ahead = matches!(more, Ok(true));
        if let Err(e) = more {
            return Some(Err(e));
        }
        let next_start = self.has_ahead.then(|| self.start_of(&self.ahead));
        Some(self.expand(next_start).map(|x| self.expanding = Some(x)))
    }
}

impl Iterator for Reader<'_> {
    type Item = Result<Event, ParseError>;
    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(x) = &mut self.expanding {
                if let Some(b) = self.frame.bytes.get(x.next) {
                    let at_us = x.first_end + x.next as u64 * x.step;
                    x.next += 1;
                    let role = self.frame.role;
                    return Some(Ok(Event {
                        at_us,
                        channel: role as u8,
                        role: Some(role),
                        mark: Mark::Byte(*b),
                        late_us: 0,
                    }));
                }
                self.expanding = None;
            }
            if let Err(e) = self.next_expanded()? {
                return Some(Err(e));
            }
        }
    }
}

impl Capture for Reader<'_> {
    fn tolerance_us(&self) -> Option<u64> {
        self.tolerance_us
    }
    /// A line's characters at once (a long one's in several runs).
    fn next_run(&mut self) -> Option<Result<Run, ParseError>> {
        loop {
            if let Some(x) = &mut self.expanding {
                let rest = self.frame.bytes.get(x.next..).unwrap_or_default();
                let bytes = rest.get(..Run::REST + 1).unwrap_or(rest);
                let role = self.frame.role;
                let at_us = x.first_end + x.next as u64 * x.step;
                if let Some(run) = Run::of_bytes(at_us, x.step, role as u8, Some(role), bytes) {
                    x.next += bytes.len();
                    return Some(Ok(run));
                }
                self.expanding = None;
            }
            if let Err(e) = self.next_expanded()? {
                return Some(Err(e));
            }
        }
    }
    fn channels(&self) -> Vec<String> {
        vec!["M>".into(), "S<".into()]
    }
    fn assumptions(&self) -> Vec<String> {
        let mut a = vec![format!(
            "wire log: each frame's characters back to back at {} Bd ({} µs each); a gap inside a frame is not in the log",
            self.options.baud,
            self.options.char_time_us()
        )];
        if self.compressed > 0 {
            a.push(format!(
                "{} replies did not fit at that rate before the next frame (a line that does not pace characters): \
                 they were taken to end the timeout before it; their start is as logged",
                self.compressed
            ));
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Vec<Result<Event, ParseError>> {
        crate::capture::tests::read(super::super::Format::Wirelog, text)
    }

    #[test]
    fn a_request_ends_at_its_time_and_a_reply_starts_at_its_time() {
        let ev = read("      10.000 ms  M> 40 42 02\n      16.000 ms  S< 40 42 00 00 00 00 02\n");
        let ev: Vec<Event> = ev.into_iter().map(Result::unwrap).collect();
        assert_eq!(ev.len(), 10);
        assert_eq!((ev[0].at_us, ev[2].at_us), (10_000 - 2 * 1146, 10_000));
        assert_eq!((ev[3].at_us, ev[3].role), (16_000 + 1146, Some(Role::Slave)));
        assert_eq!(ev[9].at_us, 16_000 + 7 * 1146);
    }

    proptest::proptest! {
        /// Read a line at a time, a log hands out the events it hands out one by one,
        /// the error where it stands: lines longer than a run, replies squeezed
        /// before the next request, times out of order, a malformed line.
        #[test]
        fn runs_are_the_events(
            lines in proptest::collection::vec(
                (0u64..30_000, proptest::bool::ANY, 1usize..40, proptest::sample::select(vec!["", "garbage"])),
                0..12,
            ),
        ) {
            let mut text = String::new();
            let mut t_us = 5_000u64;
            for (gap, master, n, extra) in lines {
                t_us = (t_us + gap).saturating_sub(2_000);
                let bytes = vec!["40"; n].join(" ");
                let dir = if master { "M>" } else { "S<" };
                text += &format!("{}.{:03} ms  {dir} {bytes}{extra}\n", t_us / 1000, t_us % 1000);
            }
            let options = crate::capture::ReadOptions { baud: 9600, samplerate_hz: None };
            let open = || Reader::new(Box::new(text.as_bytes()), options).unwrap();
            let mut direct = open();
            let events: Vec<_> = direct.by_ref().collect();
            let mut capture = open();
            let mut by_run = Vec::new();
            while let Some(r) = capture.next_run() {
                match r {
                    Ok(r) => by_run.extend(r.events().map(Ok)),
                    Err(e) => by_run.push(Err(e)),
                }
            }
            proptest::prop_assert_eq!(&by_run, &events);
            proptest::prop_assert_eq!(capture.assumptions(), direct.assumptions());
            // Lines split across the reader's buffer (not read where they are) read the same.
            let split = Reader::new(Box::new(std::io::BufReader::with_capacity(7, text.as_bytes())), options).unwrap();
            proptest::prop_assert_eq!(split.collect::<Vec<_>>(), events);
        }
    }

    #[test]
    fn a_malformed_line_is_rejected_with_its_number() {
        let ev = read("10.000 ms  M> 40 42 02\n\nhello\n");
        let err = ev.into_iter().find_map(Result::err).unwrap();
        assert_eq!(err.line, 3);
        assert!(err.message.contains("expected"), "{err}");
    }

    proptest::proptest! {
        /// The exact reading of a logged time is the float reading, rounded to the µs.
        #[test]
        fn a_time_reads_as_its_rounded_value(us in 0u64..1_000_000_000_000, decimals in 0usize..=3) {
            let text = format!("{}.{:03}", us / 1000, us % 1000);
            let text = &text[..text.len() - (3 - decimals)];
            let text = text.trim_end_matches('.');
            let float = (text.parse::<f64>().unwrap() * 1000.0).round() as u64;
            proptest::prop_assert_eq!(ms_as_us(text), Some(float));
        }
    }

    proptest::proptest! {
        /// What the fast reading of the common form reads, the general reading reads
        /// the same (it leaves everything else to it): near-valid lines and any bytes.
        #[test]
        fn the_common_form_reads_as_the_general_form(
            line in "[ \t]{0,2}[0-9.]{1,14}[ \t]{1,2}(ms|MS|s)[ \t]{1,2}(M>|S<|M)([ \t][0-9a-fA-FxX]{1,3}){0,5}[ \t\x0b\x0c]?",
            noise in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..40),
        ) {
            for input in [line.as_bytes(), &noise[..]] {
                let mut bytes = Vec::new();
                if let Some((t_us, role)) = parse_common(input, &mut bytes) {
                    let text = std::str::from_utf8(input).unwrap().trim();
                    proptest::prop_assert_eq!(parse_line(text), Some((t_us, role, bytes)));
                }
            }
        }
    }

    proptest::proptest! {
        /// What the reading through the newline reads, the common reading reads the same
        /// of the line without its end: near-valid lines with any ends, and any bytes.
        #[test]
        fn the_reading_through_the_newline_reads_as_the_common_one(
            line in "[ \t]{0,3}[0-9.]{0,15}[ \t]{0,2}(ms|m)[ \t]{0,2}(M>|S<|M)([ \t]{0,2}[0-9a-fA-FxX\r]{1,3}){0,5}[ \t\r]{0,2}\n?[0-9 ]{0,3}",
            noise in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..40),
        ) {
            for input in [line.as_bytes(), &noise[..]] {
                let mut fast = Vec::new();
                if let Some((t_us, role, newline)) = read_common(input, LineEnd::Newline, &mut fast) {
                    proptest::prop_assert_eq!(input.get(newline), Some(&b'\n'));
                    let l = crate::capture::without_line_end(&input[..newline]);
                    let mut common = Vec::new();
                    proptest::prop_assert_eq!(parse_common(l, &mut common), Some((t_us, role)));
                    proptest::prop_assert_eq!(fast, common);
                }
            }
        }
    }

    /// The logs' own lines take the fast reading (else the bench measures the slow one).
    #[test]
    fn the_logs_own_lines_are_the_common_form() {
        let mut bytes = Vec::new();
        for (line, newline) in
            [(&b"    1234.567 ms  S< 40 52 E4 22 80 00 54\n"[..], 40), (b"12.5 ms  M>  40 42 02\r\n7", 22)]
        {
            let read =
                read_common(line, LineEnd::Newline, &mut bytes).map(|(t_us, role, n)| (t_us, role, n, bytes.clone()));
            let expected = parse_common(crate::capture::without_line_end(&line[..newline]), &mut bytes);
            assert_eq!(read.map(|(t, r, n, b)| (Some((t, r)), n, b)), Some((expected, newline, bytes.clone())));
        }
        let line = b"    1234.567 ms  S< 40 52 E4 22 80 00 54";
        assert_eq!(parse_common(line, &mut bytes), Some((1_234_567, Role::Slave)));
        assert_eq!(bytes, [0x40, 0x52, 0xE4, 0x22, 0x80, 0x00, 0x54]);
        assert_eq!(parse_common(b"10 ms\tM> ff", &mut bytes), Some((10_000, Role::Master)));
        for other in [&b"10.5 ms M> 0x40"[..], b"1e3 ms M> 40", b"# 10 ms M> 40", b"10.000 ms M> 40 \xc2\xa0", b""] {
            assert_eq!(parse_common(other, &mut bytes), None, "{}", String::from_utf8_lossy(other));
        }
        assert!(parse_line("10.5 ms M> 0x40").is_some(), "the general form reads what the common one leaves");
    }

    /// A line of valid bytes longer than the bound is refused as any long line is,
    /// whether it lies in the reader's buffer or not: memory stays bounded.
    #[test]
    fn a_line_of_valid_bytes_beyond_the_bound_is_an_error() {
        let long = format!("10.000 ms  M>{}\n", " 40".repeat(crate::capture::MAX_LINE / 3 + 1));
        for capacity in [8 * 1024, 256 * 1024] {
            let reader = std::io::BufReader::with_capacity(capacity, long.as_bytes());
            let options = crate::capture::ReadOptions { baud: 9600, samplerate_hz: None };
            let err = Reader::new(Box::new(reader), options).unwrap().find_map(Result::err).unwrap();
            assert!(err.message.contains("bytes or more"), "{err}");
            assert_eq!(err.line, 1);
        }
    }

    #[test]
    fn odd_times_are_read_or_refused() {
        assert_eq!(ms_as_us("1.2345"), Some(1235));
        assert_eq!(ms_as_us("1e3"), Some(1_000_000));
        assert_eq!(ms_as_us(".5"), Some(500));
        assert_eq!(ms_as_us("-1.000"), None);
        assert_eq!(ms_as_us("inf"), None);
        assert_eq!(ms_as_us("1.x"), None);
    }

    #[test]
    fn times_must_not_go_back() {
        let ev = read("20.000 ms  M> 40 42 02\n10.000 ms  S< 40 42 00 00 00 00 02\n");
        assert_eq!(ev.into_iter().find_map(Result::err).map(|e| e.line), Some(2));
    }

    /// Found by fuzzing: a time near u64::MAX overflowed the listener's sums.
    #[test]
    fn a_time_beyond_a_billion_seconds_is_an_error() {
        let ev = read("10.000 ms  M> 40 42 02\n18446744073709551 ms  S< 40 42 00 00 00 00 02\n");
        let err = ev.into_iter().find_map(Result::err).unwrap();
        assert_eq!(err.line, 2);
        assert!(err.message.contains("10^9 s"), "{err}");
    }
}
