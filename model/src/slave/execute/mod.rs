//! Executing one addressed frame: the order of checks, every command, the fault
//! model. // DESIGN:order, 000:2.4.2, 000:2.4.3

use super::{CodeSet, Outcome, Reply, Silence, Slave};
use crate::address::{AddressByte, SlaveAddress};
use crate::clause::{self, Normative};
use crate::command::CommandId;
use crate::fault::FaultCode::{self, *};
use crate::profile::AnalogSource;
use crate::request::{Request, RequestChecks};
use crate::response::{Response, ResponseFrame, Version};
use crate::settings::{Edition, UartSettings};
use crate::slave::powerup::CommState;

mod data_fields;
mod position;

/// Status of the Extended Type Label in Data Field Status: 64 bytes (size bits 011),
/// code disabled, Code0, read-only, exists (DESIGN:fields).
pub const EXTENDED_TYPE_LABEL_STATUS: u8 = 0x83;
pub const EXTENDED_TYPE_LABEL_FIELD: u8 = 0xFF;

/// Collects every error condition that holds, in check order: the first is answered,
/// the others are acceptable alternatives.
#[derive(Default)]
struct Checks {
    first: Option<(FaultCode, Normative)>,
    also: CodeSet,
}

impl Checks {
    fn check(&mut self, condition: bool, code: FaultCode, clause: Normative) {
        if condition {
            match self.first {
                None => self.first = Some((code, clause)),
                Some((first, _)) if first != code => self.also.insert(code),
                Some(_) => {}
            }
        }
    }

    /// An alternative code that is acceptable but never preferred.
    fn tolerate(&mut self, condition: bool, code: FaultCode) {
        if condition {
            self.also.insert(code);
        }
    }
}

/// What a command produced before the reply is framed.
enum Done {
    Ok(Response, Normative),
    Err(FaultCode, Normative),
    Reset,
}

impl Slave {
    pub(super) fn execute(&mut self, bytes: &[u8], uart_fault: bool, overflowed: bool, at_us: u64) -> Outcome {
        // 1) Not our address: silent. // DESIGN:order, 000:2.3.1
        let own = self.nv.address;
        match bytes.first() {
            Some(b) if AddressByte::decode(*b).addresses(own) => {}
            _ => return silent(Silence::NotAddressed, clause::ADDRESS),
        }
        // 000:T9: any request in the default window keeps the default settings.
        if self.state(at_us) == CommState::DefaultCommunication {
            self.power.kept_default = true;
        }

        let mut c = Checks::default();
        let (request, decoded) = RequestChecks::with_request(bytes);
        self.protocol_checks(&mut c, &request, bytes.len(), uart_fault, overflowed);
        let mut then_settings = None;
        // The request is the command the checks found with the data between command
        // byte and checksum: the checks passed, so it decodes. (Not decoded again from
        // the bytes: a model checker that knows the command byte but not the checksum
        // then sees one command here, not every command of the table.)
        let data = bytes.get(2..bytes.len().saturating_sub(1)).unwrap_or(&[]);
        let decoded = decoded.or_else(|| request.command.map(|id| Request::from_data(id, data)));
        let done = match (c.first, decoded) {
            (Some((code, clause)), _) => Done::Err(code, clause),
            (None, Some(Ok(request))) => self.command(request, &mut c, &mut then_settings),
            // Unreachable: protocol_checks found no fault the decoder could report.
            (None, _) => Done::Err(WrongLength, clause::WRONG_LENGTH),
        };

        let (response, clause) = match done {
            Done::Reset => {
                self.initialize(at_us);
                return Outcome {
                    reply: Reply::Silent(Silence::Reset),
                    clause: clause::ENCODER_RESET,
                    also: c.also,
                    then_settings: None,
                };
            }
            Done::Ok(r, clause) => (r, clause),
            Done::Err(code, clause) => (Response::Error(code), clause),
        };
        self.monitor(&response);
        let reply = ResponseFrame { address: self.nv.address.byte(), warning: !self.stack.is_empty(), response };
        let then_settings = if matches!(response, Response::Error(_)) { None } else { then_settings };
        if let Some(s) = then_settings {
            self.temp_settings = Some(s);
        }
        Outcome { reply: Reply::Frame(reply), clause, also: c.also, then_settings }
    }

    /// Steps 2-6 of the check order: UART fault, length, checksum, command, length.
    fn protocol_checks(&self, c: &mut Checks, request: &RequestChecks, len: usize, uart_fault: bool, overflowed: bool) {
        c.check(uart_fault, Parity, clause::PARITY_ERROR);
        c.check(request.too_short || overflowed, WrongLength, clause::WRONG_LENGTH);
        c.check(request.bad_checksum.is_some(), Checksum, clause::CHECKSUM_ERROR);
        match request.command {
            Some(id) if self.profile.commands.contains(id) => {
                c.check(request.wrong_length, WrongLength, clause::WRONG_LENGTH)
            }
            // A command of the table the device lacks is unknown to it. // 000:T49
            _ if len >= 2 => c.check(true, UnknownCommand, clause::UNKNOWN_COMMAND),
            _ => {}
        }
    }

    /// Others-group monitoring, "checked prior to every Slave response message":
    /// faults unrelated to the command go onto the stack. // 000:T58, 000:T59
    fn monitor(&mut self, response: &Response) {
        let p = &self.profile;
        let t = self.inputs.temperature_c;
        if t < p.temperature_min_c || t > p.temperature_max_c {
            self.stack.push(Temperature);
        }
        let position_answer = matches!(response, Response::Error(LedCurrent));
        if self.inputs.led_current_ma > p.led_current_max_ma && !position_answer {
            self.stack.push(LedCurrent);
        }
    }

    /// Faults of the non-volatile memory, for the commands whose table rows list them:
    /// 06h after an internal checksum error at start-up (000:T44; also 57h, which T44
    /// names), 05h while the I2C bus is down (000:T43). 05h is acceptable where 06h
    /// applies (000:T43 and T44 disagree on which one a locked command answers).
    fn memory_checks(&self, c: &mut Checks, command: CommandId) {
        let Some(spec) = command.spec() else { return };
        let lockable = spec.lists(InternalChecksum) || command == CommandId::SetSerialInterface;
        let nv = self.locks.nonvolatile && lockable;
        c.check(nv, InternalChecksum, clause::NV_LOCK);
        c.tolerate(nv && spec.lists(I2cBus), I2cBus);
        let i2c = self.injected.i2c() && spec.lists(I2cBus);
        c.check(i2c, I2cBus, clause::I2C_BUS);
    }

    fn code0_wrong(&self, code0: u8) -> bool {
        code0 != self.nv.codes[0]
    }

    fn count_write(&mut self) {
        self.eeprom_writes = self.eeprom_writes.saturating_add(1);
    }

    fn command(&mut self, request: Request, c: &mut Checks, then_settings: &mut Option<UartSettings>) -> Done {
        // The clause a successful reply follows: the command's, unless a rule of its own
        // shaped the reply (the legacy counter's overflow).
        let mut spec_clause = request.command().spec().map_or(clause::COMMANDS, |s| s.clause);
        let result = match request {
            Request::ReadPosition => self.position_faults(c, true).map(|()| Response::Position(self.position() as u32)),
            Request::SetPosition { preset, code0 } | Request::SetPositionInternalSync { preset, code0 } => {
                self.set_position(c, request.command(), preset, code0).map(|_| match request {
                    Request::SetPosition { .. } => Response::PositionSet,
                    _ => Response::PositionInternalSyncSet,
                })
            }
            Request::SetPositionWithSync { preset, code0 } => self
                .set_position(c, CommandId::SetPositionWithSync, preset, code0)
                .map(|used| Response::PositionWithSyncSet(used as u32)),
            Request::ReadAnalogValue { channel } => {
                let ch = self.profile.analog_channel(channel);
                c.check(ch.is_none(), WrongArgument, clause::READ_ANALOG);
                match (c.first, ch) {
                    (None, Some(ch)) => {
                        let reading = match ch.source {
                            AnalogSource::Temperature => self.inputs.temperature_c as i32,
                            AnalogSource::LedCurrent => self.inputs.led_current_ma as i32,
                        };
                        Ok(Response::AnalogValue { channel, value: ch.encoding.encode(reading) })
                    }
                    _ => Err(()),
                }
            }
            Request::ReadCounter => {
                self.memory_checks(c, request.command());
                ok_if(c, Response::Counter(self.nv.counter))
            }
            Request::IncrementCounter => self.increment_counter(c, &mut spec_clause),
            Request::ResetCounter { code0 } => {
                c.check(self.code0_wrong(code0), WrongAccessCode, clause::WRONG_ACCESS_CODE);
                self.memory_checks(c, request.command());
                if c.first.is_none() {
                    self.nv.counter = 0;
                    self.count_write();
                }
                ok_if(c, Response::CounterReset)
            }
            Request::ReadData { field, offset, count, code } => self.read_data(c, field, offset, count, code),
            Request::StoreData { field, offset, code, data } => {
                self.store_data(c, field, offset, code, data.as_bytes())
            }
            Request::DataFieldStatus { field } => {
                c.check(self.locks.data_fields, PartitionTable, clause::INIT_FAULTS);
                self.memory_checks(c, request.command());
                let status = match field {
                    EXTENDED_TYPE_LABEL_FIELD if self.profile.extended_type_label.is_some() => {
                        Some(EXTENDED_TYPE_LABEL_STATUS)
                    }
                    _ => self.nv.fields.status(field).map(|s| s.0),
                };
                c.check(status.is_none(), WrongFieldNumber, clause::WRONG_FIELD_NUMBER);
                match status {
                    Some(status) => ok_if(c, Response::FieldStatus { field, status }),
                    None => Err(()),
                }
            }
            Request::CreateDataField { field, status, code } => self.create_data_field(c, field, status, code),
            Request::MemoryStatus => {
                self.memory_checks(c, request.command());
                ok_if(
                    c,
                    Response::MemoryStatus {
                        free_blocks: self.nv.fields.free_blocks(),
                        fields: self.nv.fields.count(),
                    },
                )
            }
            Request::SetAccessCode { number, old, new } => {
                let current = self.nv.codes.get(number as usize).copied();
                c.check(current.is_none(), WrongArgument, clause::SET_ACCESS_CODE);
                c.check(current.is_some_and(|cur| cur != old), WrongAccessCode, clause::WRONG_ACCESS_CODE);
                self.memory_checks(c, request.command());
                match (c.first, self.nv.codes.get_mut(number as usize)) {
                    (None, Some(slot)) => {
                        *slot = new;
                        self.count_write();
                        Ok(Response::AccessCodeSet { number })
                    }
                    _ => Err(()),
                }
            }
            Request::ReadEncoderStatus => {
                // An Others condition is "checked prior to every Slave response message"
                // (000:T58, T59): one that holds now is active, and 00h says that none is
                // (000:T27), so it is on the stack before the stack is read. The
                // monitoring of the reply then stacks it again while it holds.
                self.monitor(&Response::EncoderStatus(NoFault));
                Ok(Response::EncoderStatus(self.stack.pop(self.profile.stack_order)))
            }
            Request::ReadTypeLabel => {
                self.memory_checks(c, request.command());
                ok_if(
                    c,
                    Response::TypeLabel {
                        // DESIGN:52h: the stored settings byte.
                        settings: self.nv.settings.byte(),
                        type_code: self.profile.type_code,
                        memory_blocks: self.profile.memory_blocks,
                        option: self.profile.option_code,
                    },
                )
            }
            Request::EncoderReset => return Done::Reset,
            Request::SetEncoderAddress { address, code0 } => {
                let new = SlaveAddress::new(address);
                c.check(new.is_none(), WrongArgument, clause::SET_ADDRESS);
                c.check(self.code0_wrong(code0), WrongAccessCode, clause::WRONG_ACCESS_CODE);
                self.memory_checks(c, request.command());
                match (c.first, new) {
                    (None, Some(new)) => {
                        // 000:T30: the response already uses the new address.
                        self.nv.address = new;
                        self.count_write();
                        Ok(Response::AddressSet)
                    }
                    _ => Err(()),
                }
            }
            Request::ReadVersion => {
                self.memory_checks(c, request.command());
                ok_if(
                    c,
                    Response::Version(Version {
                        serial: self.profile.serial,
                        firmware: self.profile.firmware,
                        date: self.profile.firmware_date,
                    }),
                )
            }
            Request::SetSerialInterface { settings, code0 } => {
                let new = self.acceptable_settings(settings);
                c.check(new.is_none(), WrongArgument, clause::SETTINGS_BYTE);
                c.check(self.code0_wrong(code0), WrongAccessCode, clause::WRONG_ACCESS_CODE);
                self.memory_checks(c, request.command());
                match (c.first, new) {
                    (None, Some(new)) => {
                        // 000:T32: used only after an encoder reset or power cycle.
                        self.nv.settings = new;
                        self.count_write();
                        Ok(Response::SerialInterfaceSet { settings })
                    }
                    _ => Err(()),
                }
            }
            Request::TemporarilySetSerialInterface { settings } => {
                let new = self.acceptable_settings(settings);
                c.check(new.is_none(), WrongArgument, clause::SETTINGS_BYTE);
                match (c.first, new) {
                    (None, Some(new)) => {
                        // 000:T33: the reply still uses the previous settings.
                        *then_settings = Some(new);
                        Ok(Response::SerialInterfaceTemporarilySet { settings })
                    }
                    _ => Err(()),
                }
            }
            Request::SensorAdjustment { option, code0 } => {
                let known = self.profile.adjustment_option(option);
                c.check(known.is_none(), WrongArgument, clause::SENSOR_ADJUSTMENT);
                c.check(self.code0_wrong(code0), WrongAccessCode, clause::WRONG_ACCESS_CODE);
                match (c.first, known) {
                    (None, Some(o)) => {
                        self.count_write();
                        Ok(Response::SensorAdjusted { option, status: o.status })
                    }
                    _ => Err(()),
                }
            }
            Request::ReadSyncOffset => {
                // DESIGN:position: position + value = raw (mod 32).
                Ok(Response::SyncOffset(((32 - self.nv.offset % 32) % 32) as u8))
            }
        };
        match (result, c.first) {
            (Ok(r), None) => Done::Ok(r, spec_clause),
            (_, Some((code, clause))) => Done::Err(code, clause),
            // A command returned Err without recording why: a model defect, answered as 0Dh.
            (Err(()), None) => Done::Err(WrongArgument, clause::WRONG_ARGUMENT),
        }
    }

    /// Settings the device accepts: a defined byte and a data rate it supports.
    fn acceptable_settings(&self, byte: u8) -> Option<UartSettings> {
        UartSettings::decode(byte).ok().filter(|s| self.profile.supports_baud(s.baud))
    }

    fn increment_counter(&mut self, c: &mut Checks, success: &mut Normative) -> Result<Response, ()> {
        const MAX: u32 = 0xFF_FFFF;
        self.memory_checks(c, CommandId::IncrementCounter);
        let full = self.nv.counter >= MAX;
        match self.profile.edition {
            // 000:T46: at FFFFFFh the counter stays and increment answers 08h.
            Edition::Current => c.check(full, CounterOverflow, clause::COUNTER_OVERFLOW),
            // 002:47h: "any overflow is shown by the ERROR bit".
            Edition::Legacy if full && c.first.is_none() => {
                self.stack.push(CounterOverflow);
                *success = clause::LEGACY_COUNTER;
            }
            Edition::Legacy => {}
        }
        if c.first.is_some() {
            return Err(());
        }
        if !full {
            self.nv.counter += 1;
            self.count_write();
        }
        Ok(Response::CounterIncremented)
    }
}

fn ok_if(c: &Checks, r: Response) -> Result<Response, ()> {
    if c.first.is_some() {
        Err(())
    } else {
        Ok(r)
    }
}

fn silent(why: Silence, clause: Normative) -> Outcome {
    Outcome { reply: Reply::Silent(why), clause, also: CodeSet::default(), then_settings: None }
}
