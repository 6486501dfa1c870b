//! The harness as HIPERFACE master: one exchange is a request, the pause the
//! protocol mandates, and the reply framed by the inter-character timeout exactly as
//! the model's data link frames it. Every read is bounded in time.

use crate::line::{Line, LineError};
use hiperface_model::datalink::{DataLink, RxChar};
use hiperface_model::frame::MAX_FRAME;
use hiperface_model::{Edition, UartSettings};

/// One request and what came back.
#[derive(Debug, Clone)]
pub struct Exchange {
    pub request: Vec<u8>,
    /// Characters that arrived before the request was sent (outside any reply).
    pub stray: Vec<RxChar>,
    /// When the master began writing the request.
    pub sent_start_us: u64,
    /// Receive time of the request's last character at the slave.
    pub sent_end_us: u64,
    /// When the slave's frame timeout after the request elapsed (000:2.2.2).
    pub complete_us: u64,
    /// The reply's characters; empty for silence.
    pub reply: Vec<RxChar>,
    pub settings: UartSettings,
    pub timeout_us: u64,
}

impl Exchange {
    pub fn reply_bytes(&self) -> Option<Vec<u8>> {
        (!self.reply.is_empty()).then(|| self.reply.iter().map(|c| c.byte).collect())
    }

    /// When the reply's first start bit began.
    pub fn reply_start_us(&self) -> Option<u64> {
        self.reply.first().map(|c| c.at_us.saturating_sub(self.settings.char_time_us()))
    }

    /// The longest idle time between two characters of the reply.
    pub fn max_gap_us(&self) -> u64 {
        let ct = self.settings.char_time_us();
        self.reply.windows(2).map(|w| w[1].at_us.saturating_sub(w[0].at_us).saturating_sub(ct)).max().unwrap_or(0)
    }

    /// Reply start relative to the end of the request's timeout, µs (negative: early).
    pub fn response_time_us(&self) -> Option<i64> {
        self.reply_start_us().map(|s| s as i64 - self.complete_us as i64)
    }
}

/// The master on a line.
pub struct Master<L: Line> {
    pub line: L,
    edition: Edition,
    /// End of the last activity on the line; the next request waits a timeout after it.
    idle_since_us: u64,
}

impl<L: Line> Master<L> {
    pub fn new(line: L, edition: Edition) -> Master<L> {
        Master { line, edition, idle_since_us: 0 }
    }

    pub fn timeout_us(&self) -> u64 {
        self.line.settings().timeout_us(self.edition)
    }

    /// Send `request` and collect the reply. `max_response_ms` bounds the wait for
    /// the first character (after the request's timeout), with the line's tolerance.
    pub fn exchange(&mut self, request: &[u8], max_response_ms: u16) -> Result<Exchange, LineError> {
        let settings = self.line.settings();
        let timeout = self.timeout_us();
        let ct = settings.char_time_us();
        // 000:2.2.2: the end of a transmission is a pause of at least the timeout.
        // Never more than a frame's time ahead of now, whatever a babbling line reported.
        let now = self.line.now_us();
        let ready = (self.idle_since_us + timeout).min(now + MAX_FRAME as u64 * ct + timeout);
        let mut stray = Vec::new();
        while let Some(c) = self.line.recv(ready)? {
            stray.push(c);
        }
        self.line.wait_until(ready)?;
        let sent_start_us = self.line.now_us();
        let sent_end_us = self.line.send(request)?;
        let complete_us = sent_end_us + timeout;
        let deadline = complete_us + max_response_ms as u64 * 1000 + ct + self.line.tolerance_us() + timeout;
        let mut reply = Vec::new();
        let mut link = DataLink::new(timeout);
        if let Some(first) = self.line.recv(deadline)? {
            link.receive(first);
            reply.push(first);
            // Further characters belong to the reply until the data link's timeout
            // elapses; a device that never stops talking is cut off after two frames' worth.
            while let Some(until) = link.deadline().filter(|_| reply.len() < 2 * MAX_FRAME) {
                match self.line.recv(until.saturating_sub(1))? {
                    Some(c) => {
                        link.receive(c);
                        reply.push(c);
                    }
                    None => break,
                }
            }
        }
        let end = reply.last().map_or(complete_us.max(self.line.now_us()), |c| c.at_us);
        self.idle_since_us = end;
        Ok(Exchange {
            request: request.to_vec(),
            stray,
            sent_start_us,
            sent_end_us,
            complete_us,
            reply,
            settings,
            timeout_us: timeout,
        })
    }

    /// Wait on an idle line until `t_us`, collecting anything that arrives.
    pub fn listen_until(&mut self, t_us: u64) -> Result<Vec<RxChar>, LineError> {
        let mut got = Vec::new();
        while let Some(c) = self.line.recv(t_us)? {
            got.push(c);
            self.idle_since_us = c.at_us;
        }
        Ok(got)
    }

    pub fn now_us(&mut self) -> u64 {
        self.line.now_us()
    }
}
