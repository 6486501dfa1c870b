//! A recorded session between a master and the reference encoder (profile SRS50),
//! with defects that can be injected: what `decode` and `monitor` are tested on.

/// ms per character at 9600 Bd, 8E1.
pub const CT: f64 = 1.146;
/// The timeout at 9600 Bd, ms.
pub const TIMEOUT: f64 = 5.73;

/// Reference-encoder exchanges as the project logs them.
pub const CYCLE: [(&str, &str); 3] =
    [("40 52 12", "40 52 E4 22 80 00 54"), ("40 50 10", "40 50 00 10"), ("40 42 02", "40 42 00 00 00 00 02")];

/// One exchange: the request ends (its last stop bit) at `request_end_ms`, the reply
/// starts (its first start bit) at `reply_start_ms`.
pub struct Exchange {
    pub request_end_ms: f64,
    pub request: Vec<u8>,
    pub reply_start_ms: f64,
    pub reply: Vec<u8>,
}

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace().map(|b| u8::from_str_radix(b, 16).unwrap()).collect()
}

/// `cycles` cycles, an exchange every `period_ms` from 10 ms, replies 2 ms after the
/// timeout; `edit` may change an exchange's reply and its response time.
pub fn session(cycles: usize, period_ms: f64, edit: impl Fn(usize, &str) -> Option<(String, f64)>) -> Vec<Exchange> {
    (0..cycles * CYCLE.len())
        .map(|i| {
            let (req, reply) = CYCLE[i % CYCLE.len()];
            let (reply, rt) = edit(i, reply).unwrap_or((reply.to_string(), 2.0));
            let t = 10.0 + period_ms * i as f64;
            Exchange { request_end_ms: t, request: hex(req), reply_start_ms: t + TIMEOUT + rt, reply: hex(&reply) }
        })
        .collect()
}

/// The session (an exchange every 40 ms) as the project's wire log: the request stamped at the end of its last
/// character, the reply at its first start bit.
pub fn wirelog(cycles: usize, edit: impl Fn(usize, &str) -> Option<(String, f64)>) -> String {
    let spaced = |b: &[u8]| b.iter().map(|b| format!("{b:02X}")).collect::<Vec<_>>().join(" ");
    session(cycles, 40.0, edit)
        .iter()
        .map(|x| {
            format!(
                "{:12.3} ms  M> {}\n{:12.3} ms  S< {}\n",
                x.request_end_ms,
                spaced(&x.request),
                x.reply_start_ms,
                spaced(&x.reply)
            )
        })
        .collect()
}

/// A late reply on the 4th exchange (`late_ms` after the timeout: 000:T10 allows
/// 5 ms), a wrong checksum on the 8th.
pub fn defective(late_ms: f64) -> impl Fn(usize, &str) -> Option<(String, f64)> {
    move |i, reply| match i {
        3 => Some((reply.to_string(), late_ms)),
        7 => Some(("40 50 00 11".to_string(), 2.0)),
        _ => None,
    }
}

/// The verdict of each exchange line of `decode`'s or `monitor`'s output, in order.
pub fn verdicts(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.contains(" ms  ") && l.contains(" M> "))
        .filter_map(|l| l.split_whitespace().nth(2).map(str::to_string))
        .collect()
}
