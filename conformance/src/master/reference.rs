//! The reference master: the start-up flow of 000:3.3.1 (Figure 17), cyclic Read
//! Position, the warning's codes read out, and the fault reaction of Table 74. It is
//! what `certify master` is checked against (every scenario PASS, no NON-STRICT), and
//! a bench tool: on a real encoder it prints the identity and the position.

use crate::exchange::BusMaster;
use crate::line::{Line, LineError};
use hiperface_model::fault;
use hiperface_model::master::fault_reaction::{self, Reaction};
use hiperface_model::response::{Response, ResponseFrame};
use hiperface_model::{CommandId, FaultCode, Profile, Request, RequestFrame};

/// How the reference master runs.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Period of Read Position, ms.
    pub polling_period_ms: u64,
    /// Stop after this long (line time), ms; `None`: until the line fails.
    pub duration_ms: Option<u64>,
}

/// Retries of one request before a SW reset (000:T74 "If error persists, SW reset").
const RETRIES: u32 = 3;
/// SW resets before the master gives up position reads (worst case: motor stop).
const RESETS: u32 = 3;

/// What the master did, for the operator.
pub trait Console {
    fn line(&mut self, text: &str);
}

impl<F: FnMut(&str)> Console for F {
    fn line(&mut self, text: &str) {
        self(text)
    }
}

enum Outcome {
    Reply(ResponseFrame),
    /// No reply, or one that does not decode.
    Nothing,
}

struct Run<'a, L: Line> {
    master: &'a mut BusMaster<L>,
    profile: Profile,
    console: &'a mut dyn Console,
    resets: u32,
    /// Position reads stopped (22h, or faults that persist): sin/cos only.
    position_stopped: bool,
}

/// Run the reference master on `master`'s line (opened at power-on of the encoder).
pub fn run<L: Line>(
    master: &mut BusMaster<L>,
    profile: Profile,
    options: Options,
    console: &mut dyn Console,
) -> Result<(), LineError> {
    let mut run = Run { master, profile, console, resets: 0, position_stopped: false };
    run.start_up()?;
    loop {
        let now = run.master.now_us();
        if options.duration_ms.is_some_and(|d| now >= d * 1000) {
            return Ok(());
        }
        if run.position_stopped {
            // Nothing more to read cyclically: the status now and then.
            run.master.line.wait_until(now + 100_000)?;
            run.read_status()?;
            continue;
        }
        run.cycle()?;
        let next = run.master.now_us() + options.polling_period_ms * 1000;
        run.master.line.wait_until(next)?;
    }
}

impl<L: Line> Run<'_, L> {
    /// 000:3.3.1: wait for initialization, read the status (and react), read the type
    /// label. Default settings throughout: the encoder is kept in default communication.
    fn start_up(&mut self) -> Result<(), LineError> {
        let init_us = self.profile.init_ms as u64 * 1000;
        // A margin over the initialization time for the master's own start.
        self.master.line.wait_until(init_us + 20_000)?;
        self.read_status()?;
        if let Outcome::Reply(r) = self.ask(Request::ReadTypeLabel)? {
            if let Response::TypeLabel { type_code, .. } = r.response {
                self.console.line(&format!("type label: type {type_code:02X}h"));
                // FFh: the encoder's parameters are in the Extended Type Label. // 000:T19
                if type_code == 0xFF {
                    let label = Request::ReadData { field: 0xFF, offset: 0, count: 64, code: 0 };
                    if let Outcome::Reply(r) = self.ask(label)? {
                        if let Response::Data { data, .. } = r.response {
                            let ok = hiperface_model::checksum::xor(data.as_bytes()) == 0;
                            self.console.line(&format!(
                                "extended type label: {} bytes, checksum {}",
                                data.len(),
                                if ok { "ok" } else { "wrong" }
                            ));
                        }
                    }
                }
            }
        }
        if let Outcome::Reply(r) = self.ask(Request::ReadVersion)? {
            if let Response::Version(v) = r.response {
                let text = |b: &[u8]| String::from_utf8_lossy(b).trim_end_matches(['\0', ' ']).to_string();
                let (serial, firmware, date) = (text(&v.serial), text(&v.firmware), text(&v.date));
                self.console.line(&format!("serial {serial}, firmware {firmware}, date {date}"));
            }
        }
        Ok(())
    }

    /// Read Encoder Status until the stack is empty (four codes at most, 000:2.3.4),
    /// then react to the codes read, together (000:T74 "06h + 08h").
    fn read_status(&mut self) -> Result<(), LineError> {
        let mut codes = Vec::new();
        for _ in 0..5 {
            let Outcome::Reply(r) = self.ask(Request::ReadEncoderStatus)? else { break };
            match r.response {
                // Empty, and no warning left: done. (A warning with 00h: a fault stacked
                // after the read; read again.)
                Response::EncoderStatus(FaultCode::NoFault) if !r.warning => break,
                Response::EncoderStatus(FaultCode::NoFault) => {}
                Response::EncoderStatus(code) => {
                    self.console.line(&format!("status: {code}"));
                    codes.push(code);
                }
                _ => break,
            }
        }
        for (code, reaction) in fault_reaction::stack_reactions(&codes) {
            if self.react(code, reaction)? {
                return Ok(());
            }
        }
        Ok(())
    }

    /// One cycle: Read Position, with retries and the reactions of Table 74.
    fn cycle(&mut self) -> Result<(), LineError> {
        for _ in 0..=RETRIES {
            match self.ask(Request::ReadPosition)? {
                Outcome::Reply(r) => match r.response {
                    Response::Position(p) => {
                        self.console.line(&format!("position {p}"));
                        return Ok(());
                    }
                    Response::Error(code) => {
                        self.console.line(&format!("Read Position: {code}"));
                        let reaction = fault_reaction::reaction(code, fault::runtime_group(code));
                        if self.react(code, reaction)? {
                            return Ok(());
                        }
                    }
                    _ => {}
                },
                Outcome::Nothing => self.console.line("Read Position: no valid reply"),
            }
        }
        // The error persists: SW reset. // 000:T74
        self.reset()
    }

    /// React to `code` as `reaction` says (000:T74); true when the reaction ends the
    /// current attempt.
    fn react(&mut self, code: FaultCode, reaction: Reaction) -> Result<bool, LineError> {
        match code.byte() {
            // "Retry command." // 000:T74 protocol group
            0x09..=0x0D => Ok(false),
            // "Only use sine/cosine based position until shut-down. Replace Slave."
            0x22 => {
                self.console.line("multiturn sync fault: position reads stopped (sin/cos only)");
                self.position_stopped = true;
                Ok(true)
            }
            _ if !reaction.known => {
                // The worst case (motor stop): reset, and stop if it persists. // 000:3.3.4
                self.console.line(&format!("unknown fault code {code}: worst-case reaction"));
                self.reset()?;
                Ok(true)
            }
            _ if reaction.is_reset() => {
                self.reset()?;
                Ok(true)
            }
            _ => Ok(false),
        }
    }

    /// Encoder Reset, then the timeout plus the initialization time (000:T29), then the
    /// start-up again; position reads stop after too many.
    fn reset(&mut self) -> Result<(), LineError> {
        if self.resets >= RESETS {
            self.console.line("the fault persists after SW resets: position reads stopped");
            self.position_stopped = true;
            return Ok(());
        }
        self.resets += 1;
        self.console.line("SW reset (53h)");
        let x = self.master.exchange(&self.frame(Request::EncoderReset), 0)?;
        let ready = x.request_end.latest_us + x.timeout_us + self.profile.init_ms as u64 * 1000 + 20_000;
        self.master.line.wait_until(ready)?;
        self.read_status()
    }

    fn frame(&self, request: Request) -> Vec<u8> {
        let address = hiperface_model::AddressByte::Slave(self.profile.address);
        RequestFrame::new(address, request).encode().as_bytes().to_vec()
    }

    /// One request; the reply if it decodes. A reply with the warning bit has the
    /// stack read out before anything else (000:2.3.4).
    fn ask(&mut self, request: Request) -> Result<Outcome, LineError> {
        let command = request.command();
        let limit = self.profile.response_limit(command).max_ms;
        let x = self.master.exchange(&self.frame(request), limit.saturating_add(10))?;
        let bytes = x.reply_bytes().unwrap_or_default();
        let outcome = match ResponseFrame::decode(&bytes, command) {
            Ok(r) if !x.reply.is_empty() => Outcome::Reply(r),
            _ => Outcome::Nothing,
        };
        if let Outcome::Reply(r) = &outcome {
            if r.warning && command != CommandId::ReadEncoderStatus {
                self.read_status()?;
            }
        }
        Ok(outcome)
    }
}
