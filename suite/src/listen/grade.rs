//! Grading one exchange the listener heard: the reply's form and timing, and its
//! content where a listener can know it (it does not know the encoder's stored state).

use super::{HeardExchange, Listener, Open, ReplyHeard};
use crate::exchange::{Exchange, HeardLate};
use crate::line::Window;
use crate::verdict::timing::{self, TimingMode};
use crate::verdict::{CaseVerdict, Finding};
use hiperface_model::command::CommandId;
use hiperface_model::oracle::{Before, Deviation};
use hiperface_model::request::RequestFrame;
use hiperface_model::response::ResponseFrame;
use hiperface_model::slave::Reply;

impl Listener {
    /// Grade one exchange (its reply's characters and bytes, if one was heard): the
    /// reply's form and timing, and its content where the listener can know it.
    pub(super) fn exchange(&mut self, open: Open, reply: Option<ReplyHeard>, out: &mut impl FnMut(&HeardExchange)) {
        let edition = self.options.profile.edition;
        let command = open.command();
        // The timeout the encoder framed the request with (its settings may have changed
        // since the capture began: 57h and a reset). // 000:T28/settings
        let timeout_us = self.shadow.timeout_us(open.end_us);
        let complete_us = open.end_us.saturating_add(timeout_us);
        let (reply, observed, decoded) = match reply {
            Some(r) => (Some(r.heard), Some(r.bytes), Some(r.decoded)),
            None => (None, None, None),
        };
        let frame = decoded.as_ref().and_then(|d| d.as_ref().ok());
        // What the oracle reads of the state before the request; the whole model is
        // kept only where the request carries a Code0 the encoder may know and the
        // model not (a capture's every exchange would copy it otherwise).
        let mut before = Before::of(&self.shadow, &open.bytes, complete_us);
        let code0 = code0_of(&open.bytes);
        let kept = code0.map(|_| self.shadow.clone());
        let mut expected = self.shadow.handle_frame(&open.bytes, complete_us);
        let accepted = code0.filter(|_| model_refused_encoder_took(&expected, frame));
        if let (Some(code0), Some(mut kept)) = (accepted, kept) {
            // The encoder took a Code0 the model refused: the listener does not know
            // the codes, so that one is the encoder's. // 000:T26
            kept.adopt_access_code(0, code0);
            before = Before::of(&kept, &open.bytes, complete_us);
            self.shadow = kept;
            expected = self.shadow.handle_frame(&open.bytes, complete_us);
        }
        let grade = self.oracle.grade_decoded(&before, &open.bytes, &expected, decoded);
        let mut findings = Vec::new();
        if let Some(f) = Finding::graded(&grade, &open.bytes) {
            let knowable = grade.deviation().is_some_and(|d| knowable(&d, &open.bytes));
            findings.push(if knowable {
                f
            } else {
                Finding::unknown(format!(
                    "not graded: {f}; the listener does not know the encoder's stored state or its address"
                ))
            });
        }
        if let Some(r) = reply.as_ref().filter(|r| r.chars.iter().any(|c| c.fault.is_some())) {
            let n = r.chars.iter().filter(|c| c.fault.is_some()).count();
            findings.push(Finding::unknown(format!(
                "{n} characters of the reply had a parity or framing error as captured: the line, the tap or the encoder"
            )));
        }
        let mut response_ms = None;
        let mut request = open.bytes;
        let mut reply_chars = None;
        if let (Some(r), Reply::Frame(_)) = (reply, expected.reply) {
            let heard_late = HeardLate { request_end_us: open.end_late_us, reply_start_us: r.first_late_us() };
            let settings = self.shadow.listening_settings(open.end_us).unwrap_or(self.options.settings);
            let x = Exchange {
                request,
                stray: Vec::new(),
                sent_start_us: open.start_us,
                request_end: Window::exact(open.end_us),
                reply_start: r.chars.first().map(|c| Window::exact(c.at_us.saturating_sub(self.char_us))),
                reply: r.chars,
                trailing: Vec::new(),
                settings,
                timeout_us,
                pause_us: settings.pause_us(edition),
                harness_late_us: 0,
                request_write_us: 0,
                line_late: Default::default(),
                device_held: Default::default(),
                heard_late,
            };
            let limits = self.options.profile.response_limit(command);
            findings.extend(timing::grade(&x, limits, self.options.tolerance_us, TimingMode::Strict, edition));
            if let Some(t) = timing::at_most_us(&x) {
                response_ms = Some(t as f64 / 1000.0);
                self.summary.response_time(command, t);
            }
            request = x.request;
            reply_chars = Some(x.reply);
        }
        // What a well-formed reply tells of the encoder's world (as `certify` does on a
        // real device).
        if let (Some(frame), true) = (frame, findings.is_empty()) {
            self.shadow.adopt_reply(&frame.response);
        }
        self.follow(complete_us);
        let heard = HeardExchange {
            t_ms: open.end_us as f64 / 1000.0,
            command,
            request,
            reply: observed,
            response_ms,
            verdict: findings.iter().fold(CaseVerdict::Pass, |v, f| v.worst(f.verdict())),
            findings,
        };
        self.summary.exchange(&heard);
        out(&heard);
        // Its buffers serve the frames to come.
        self.spare.keep_bytes(heard.request);
        if let Some(bytes) = heard.reply {
            self.spare.keep_bytes(bytes);
        }
        if let Some(chars) = reply_chars {
            self.spare.keep_chars(chars);
        }
    }
}

/// Whether the model refused a request for its access code and the encoder accepted
/// it (a reply of the command's own form, not an error).
fn model_refused_encoder_took(expected: &hiperface_model::slave::Outcome, heard: Option<&ResponseFrame>) -> bool {
    use hiperface_model::response::Response;
    use hiperface_model::FaultCode::WrongAccessCode;
    let refused = match expected.reply {
        Reply::Frame(f) => f.response == Response::Error(WrongAccessCode) || expected.also.contains(WrongAccessCode),
        Reply::Silent(_) => false,
    };
    refused && heard.is_some_and(|h| !matches!(h.response, Response::Error(_)))
}

/// The Code0 a request carries, if its command has one (000:T26).
fn code0_of(request: &[u8]) -> Option<u8> {
    use hiperface_model::command::AccessCodeRule;
    // The command table says which commands carry one; only those are decoded.
    let spec = CommandId::of_frame(request).spec()?;
    if spec.access != AccessCodeRule::Code0 {
        return None;
    }
    RequestFrame::decode(request).ok().and_then(|r| r.request.code0())
}

/// A deviation the listener can see whatever the encoder's stored state: the reply's
/// form, its address echo to a request that named one, a warning bit with "no fault".
fn knowable(d: &Deviation, request: &[u8]) -> bool {
    match d {
        Deviation::Malformed(_) | Deviation::WarningWithoutCode => true,
        Deviation::WrongAddress { .. } => request.first() != Some(&0xFF),
        _ => false,
    }
}
