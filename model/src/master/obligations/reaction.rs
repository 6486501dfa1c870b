//! What the master's requests say of its reactions to what the encoder told it:
//! reading the warning's codes, retrying after a protocol error, resetting after a
//! critical fault, reading the Extended Type Label. // 000:3.3.1, 000:3.3.4, 000:T73-T74

use super::{Observation, Observer, Rule, RETRY_BOUND};
use crate::address::AddressByte;
use crate::command::CommandId;
use crate::fault::FaultCode;
use crate::request::RequestFrame;
use crate::settings::UartSettings;

/// What the encoder's last reply asked of the master.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Pending {
    Nothing,
    /// A protocol error to this request: the next request should be it again.
    Retry(CommandId),
    /// A critical fault whose reaction is a SW reset, within so many requests.
    Reset {
        left: u8,
    },
}

/// The codes the master read from the stack since its last other request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) struct StackRead {
    codes: [FaultCode; 4],
    len: usize,
}

impl StackRead {
    pub(super) const EMPTY: StackRead = StackRead { codes: [FaultCode::NoFault; 4], len: 0 };

    /// The stack holds four codes (000:2.3.4); a fifth read starts over.
    pub(super) fn push(&mut self, code: FaultCode) {
        if self.len == self.codes.len() {
            *self = StackRead::EMPTY;
        }
        if let Some(slot) = self.codes.get_mut(self.len) {
            *slot = code;
            self.len += 1;
        }
    }

    pub(super) fn codes(&self) -> &[FaultCode] {
        self.codes.get(..self.len).unwrap_or(&[])
    }
}

impl Observer {
    /// A well-formed request: the address, and what it says of the master's reactions.
    /// `end`: when its last character was complete.
    pub(super) fn request(&mut self, rf: RequestFrame, end: u64, start: u64, out: &mut impl FnMut(Observation)) {
        let command = rf.request.command();
        let mut report =
            |rule| out(Observation { rule, at_us: start, measured_us: None, command: Some(command), data_rates: None });
        if let AddressByte::Unknown(_) = rf.address {
            report(Rule::AddressFormat);
        }
        let timeout = self.timeout_us();
        let own = rf.address.addresses(self.address());
        if own {
            if let Some(t0) = self.started_us {
                let since = start.saturating_sub(t0);
                if since < self.profile.default_window_ms as u64 * 1000 {
                    self.kept_default = true;
                }
            }
            let max_ms = self.profile.response_limit(command).max_ms as u64;
            self.window_until_us = (command != CommandId::EncoderReset)
                .then_some(end.saturating_add(timeout).saturating_add(max_ms * 1000));
        }
        // Reactions, from the most specific.
        match command {
            CommandId::EncoderReset => {
                self.started_us = Some(end.saturating_add(timeout));
                self.after_reset = true;
                self.kept_default = false;
                self.settings = UartSettings::DEFAULT;
                self.clear_reactions();
            }
            CommandId::ReadEncoderStatus => {
                self.memo.status_read = true;
                self.memo.warning_left = None;
                self.memo.warning_reported = false;
            }
            CommandId::ReadPosition => {
                // Only where the power-on was seen: "after a power-on" (000:3.3.1).
                if !self.memo.status_read && !self.memo.status_reported && self.started_us.is_some() {
                    self.memo.status_reported = true;
                    report(Rule::StatusNotRead);
                }
                if self.memo.sync_fault {
                    report(Rule::PositionAfterSyncFault);
                }
                if self.memo.unknown_code {
                    report(Rule::UnknownCodeIgnored);
                    self.memo.unknown_code = false;
                }
                if self.memo.label_pending {
                    report(Rule::ExtendedTypeLabelNotRead);
                    self.memo.label_pending = false;
                }
            }
            CommandId::ReadData => {
                if let crate::request::Request::ReadData { field: 0xFF, .. } = rf.request {
                    self.memo.label_pending = false;
                }
            }
            _ => {}
        }
        // Reading the stack (50h) and resetting (53h) are the reactions themselves.
        if !matches!(command, CommandId::EncoderReset | CommandId::ReadEncoderStatus) {
            self.memo.stack_read = StackRead::EMPTY;
            match self.memo.warning_left {
                Some(0 | 1) => {
                    report(Rule::WarningIgnored);
                    self.memo.warning_left = None;
                    self.memo.warning_reported = true;
                }
                Some(n) => self.memo.warning_left = Some(n - 1),
                None => {}
            }
            match self.memo.pending {
                Pending::Retry(c) if c != command => {
                    report(Rule::NoRetry);
                    self.memo.pending = Pending::Nothing;
                }
                Pending::Reset { left } if left <= 1 => {
                    report(Rule::NoResetAfterCriticalFault);
                    self.memo.pending = Pending::Nothing;
                }
                Pending::Reset { left } => self.memo.pending = Pending::Reset { left: left - 1 },
                _ => {}
            }
        }
        // The same request failing again and again.
        let repeats = match self.memo.last_request {
            Some((r, n)) if r == rf && matches!(self.memo.pending, Pending::Retry(_)) => n.saturating_add(1),
            _ => 1,
        };
        if repeats == RETRY_BOUND + 1 {
            report(Rule::UnboundedRetry);
        }
        self.memo.last_request = Some((rf, repeats));
    }
}
