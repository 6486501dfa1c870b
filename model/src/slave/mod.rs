//! The slave: the executable specification of a HIPERFACE encoder, sans-IO.
//!
//! Long because: the slave's state and its entry points (receive, poll, handle_frame)
//! are one state machine over the same fields; the check order, the commands, the
//! fields, the stack and the power-up are files of their own.
//!
//! Characters go in with their receive time ([`Slave::receive`]); time advances with
//! [`Slave::poll`]; when a frame is complete the slave answers with a [`Step`] saying
//! what it received, what it decided and, if it replies, what to send, in which
//! window and with which UART settings. [`Slave::handle_frame`] skips the data link
//! for callers that already hold a whole frame.

pub mod act;
mod execute;
pub mod fields;
pub mod inputs;
mod outcome;
pub mod powerup;
pub mod stack;

use crate::address::SlaveAddress;
use crate::command::CommandId;
use crate::datalink::{DataLink, ReceivedFrame, RxChar};
use crate::fault::FaultCode;
use crate::profile::Profile;
use crate::settings::UartSettings;
use fields::DataFields;
use inputs::{InitFault, InjectedFaults, PhysicalInputs, PositionFault};
use powerup::{CommState, PowerUp};
use stack::ErrorStack;

pub use outcome::{CodeSet, Outcome, Reply, Silence, Step, Transmission};

/// What survives a reset or power cycle (EEPROM).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct NonVolatile {
    pub address: SlaveAddress,
    /// Stored UART settings (57h), used from the next reset on.
    pub settings: UartSettings,
    /// Code0...Code3. // 000:T26
    pub codes: [u8; 4],
    /// Set Position offset, `0..range`.
    pub offset: u64,
    /// 24-bit counter. // 000:T16
    pub counter: u32,
    pub fields: DataFields,
}

/// Locks left by faults until the next reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Locks {
    /// Position output locked: Read/Set Position answer 02h. // 000:2.3.4
    pub position: bool,
    /// Internal checksum error at start-up: NV commands answer 06h. // 000:T44
    pub nonvolatile: bool,
    /// Partitioning table destroyed: data field commands answer 03h. // 000:T41
    pub data_fields: bool,
}

/// A HIPERFACE slave.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Slave {
    profile: Profile,
    nv: NonVolatile,
    stack: ErrorStack,
    power: PowerUp,
    /// Stored settings as of the last power-on or reset.
    boot_settings: UartSettings,
    /// 67h settings, until reset.
    temp_settings: Option<UartSettings>,
    link: DataLink,
    inputs: PhysicalInputs,
    injected: InjectedFaults,
    locks: Locks,
    eeprom_writes: u32,
}

impl Slave {
    /// A slave in its factory state, powered on at time 0.
    pub fn new(profile: Profile) -> Slave {
        let nv = NonVolatile {
            address: profile.address,
            settings: profile.settings,
            codes: [0x55; 4],
            offset: 0,
            counter: 0,
            fields: DataFields::new(profile.user_memory_blocks),
        };
        let boot_settings = nv.settings;
        let mut s =
            Slave::from_parts(profile, nv, ErrorStack::new(), PowerUp::at(0), boot_settings, None, Locks::default());
        s.initialize(0);
        s
    }

    /// A slave in a state given part by part, for proofs that start from any state
    /// satisfying an invariant the caller assumes (proofs/src/inductive/): the data
    /// link empty, the physical inputs and injected faults at their defaults (set them
    /// with [`Slave::set_inputs`] and the `inject_*` functions), no EEPROM write counted.
    pub fn from_parts(
        profile: Profile,
        nv: NonVolatile,
        stack: ErrorStack,
        power: PowerUp,
        boot_settings: UartSettings,
        temp_settings: Option<UartSettings>,
        locks: Locks,
    ) -> Slave {
        Slave {
            link: DataLink::new(UartSettings::DEFAULT.timeout_us(profile.edition)),
            profile,
            nv,
            stack,
            power,
            boot_settings,
            temp_settings,
            inputs: PhysicalInputs::default(),
            injected: InjectedFaults::default(),
            locks,
            eeprom_writes: 0,
        }
    }

    /// A slave powered on long ago: Operational with its stored settings at any time,
    /// for callers that only exchange frames.
    pub fn operational(profile: Profile) -> Slave {
        let mut s = Slave::new(profile);
        s.settle();
        s
    }

    /// Declare the power-up windows over: Operational with the stored settings from
    /// now on, at any time argument.
    pub fn settle(&mut self) {
        self.power = PowerUp::settled();
    }

    /// Power-on or reset: volatile state starts again; initialization faults are found.
    fn initialize(&mut self, at_us: u64) {
        self.power = PowerUp::at(at_us);
        self.stack.clear();
        self.temp_settings = None;
        self.boot_settings = self.nv.settings;
        self.link.clear();
        self.locks = Locks::default();
        for (fault, injected) in self.injected.init_faults() {
            if !injected {
                continue;
            }
            let e = fault.effect();
            // 000:T38-T46: stored "along with the internal checksum error".
            if e.with_checksum_error {
                self.stack.push(FaultCode::InternalChecksum);
                self.locks.nonvolatile = true;
            }
            self.stack.push(e.code);
            self.locks.position |= e.locks_position;
            self.locks.data_fields |= e.locks_data_fields;
        }
    }

    /// Power cycle at `at_us`: EEPROM contents survive.
    pub fn power_cycle(&mut self, at_us: u64) {
        self.initialize(at_us);
    }

    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    pub fn nonvolatile(&self) -> &NonVolatile {
        &self.nv
    }

    pub fn error_stack(&self) -> &ErrorStack {
        &self.stack
    }

    pub fn locks(&self) -> Locks {
        self.locks
    }

    pub fn inputs(&self) -> PhysicalInputs {
        self.inputs
    }

    /// Set the physical inputs for the following steps.
    pub fn set_inputs(&mut self, inputs: PhysicalInputs) {
        self.inputs = inputs;
    }

    /// Inject or clear an initialization fault; it shows from the next power-on or reset.
    pub fn inject_init_fault(&mut self, fault: InitFault, on: bool) {
        self.injected.set_init(fault, on);
    }

    /// Power up again at t = 0 with these start-up faults present, so that they are
    /// found (000:T38-T46); `settled`: the power-up windows are over at once.
    pub fn power_up_with(&mut self, faults: impl IntoIterator<Item = InitFault>, settled: bool) {
        for f in faults {
            self.inject_init_fault(f, true);
        }
        self.power_cycle(0);
        if settled {
            self.settle();
        }
    }

    /// Inject or clear a position fault; it shows on the next position command.
    pub fn inject_position_fault(&mut self, fault: PositionFault, on: bool) {
        self.injected.set_position(fault, on);
    }

    /// Set the counter (24 bit; larger values are clamped), e.g. to adopt a device's
    /// value or to reach the overflow at FFFFFFh.
    pub fn set_counter(&mut self, value: u32) {
        self.nv.counter = value.min(0xFF_FFFF);
    }

    /// Adopt the non-volatile state a real device reports (black-box runs): its data
    /// field statuses with its free memory (contents unknown, read FFh) and its
    /// counter. Returns `false`, changing nothing, if the statuses do not fit.
    pub fn adopt(&mut self, field_statuses: &[u8], free_blocks: u8, counter: u32) -> bool {
        let used: u32 = field_statuses.iter().map(|s| fields::FieldStatus(*s).blocks() as u32).sum();
        let Ok(capacity) = u8::try_from(used + free_blocks as u32) else { return false };
        match DataFields::from_statuses(capacity, field_statuses) {
            Some(f) => {
                self.nv.fields = f;
                self.set_counter(counter);
                true
            }
            None => false,
        }
    }

    /// Adopt a position a real device reported: the shaft (the raw position input)
    /// is where that position says, given the model's offset. The device's world,
    /// not its EEPROM: nothing is written. `false` if the value is outside the range.
    pub fn adopt_position(&mut self, reported: u64) -> bool {
        let range = self.profile.range();
        if reported >= range {
            return false;
        }
        // The offset is below the range (Set Position and adopt_preset reduce it).
        self.inputs.position = (reported + range - self.nv.offset) % range;
        true
    }

    /// Adopt the preset a real device reports it used (Set Position with
    /// Synchronization may round differently where the documents leave it open): the
    /// model's offset becomes the one that gives that position. `false` if outside
    /// the range.
    pub fn adopt_preset(&mut self, used: u64) -> bool {
        let range = self.profile.range();
        if used >= range {
            return false;
        }
        self.nv.offset = (used + range - self.inputs.position % range) % range;
        true
    }

    /// The data fields' contents replaced by `memory`, the old ones returned: for proofs
    /// that step a slave from any contents and compare what is left
    /// (proofs/src/contents.rs). Changes nothing else (not an EEPROM write).
    pub fn replace_field_memory(&mut self, memory: fields::FieldMemory) -> fields::FieldMemory {
        self.nv.fields.replace_memory(memory)
    }

    /// Whether `other` is in the same state but the field memory's contents, for two
    /// slaves of one profile: every other part compared (each named, so that a part
    /// added to the slave must be added here), the field table by its count, capacity
    /// and fields' statuses (the slots past the count are 0 in every table: no
    /// operation writes them). The profile is not compared: it is the slave's from its
    /// construction on (nothing writes it). For proofs that compare two steps from one
    /// state (proofs/src/contents.rs), where the contents' 4 080 bytes, the table's 255
    /// slots and the profile's 32-byte name compared byte by byte are loops past the
    /// harnesses' unwind bound.
    pub fn same_but_contents(&self, other: &Slave) -> bool {
        let Slave {
            profile: _,
            nv,
            stack,
            power,
            boot_settings,
            temp_settings,
            link,
            inputs,
            injected,
            locks,
            eeprom_writes,
        } = self;
        let NonVolatile { address, settings, codes, offset, counter, fields } = nv;
        let o = &other.nv;
        (address, settings, codes, offset, counter) == (&o.address, &o.settings, &o.codes, &o.offset, &o.counter)
            && fields.same_but_contents(&o.fields)
            && (stack, power, boot_settings, temp_settings, link)
                == (&other.stack, &other.power, &other.boot_settings, &other.temp_settings, &other.link)
            && (inputs, injected, locks, eeprom_writes)
                == (&other.inputs, &other.injected, &other.locks, &other.eeprom_writes)
    }

    /// Adopt data-field bytes a real device returned for bytes the model did not
    /// know (see [`fields::Contents`]). Not an EEPROM write.
    pub fn adopt_field_data(&mut self, number: u8, offset: u8, data: &[u8]) -> bool {
        // The same bookkeeping as a store: the bytes are in memory and known.
        self.nv.fields.write(number, offset, data)
    }

    /// Adopt what a real device's reply says of its world: a position, the preset a
    /// Set Position with Synchronization used, data-field bytes. `false` for a reply
    /// that tells nothing to adopt or a value the model cannot take.
    pub fn adopt_reply(&mut self, response: &crate::response::Response) -> bool {
        use crate::response::Response;
        match *response {
            Response::Position(p) => self.adopt_position(p as u64),
            Response::PositionWithSyncSet(used) => self.adopt_preset(used as u64),
            Response::Data { field, offset, data } => self.adopt_field_data(field, offset, data.as_bytes()),
            _ => false,
        }
    }

    /// Adopt access code `number` (Code0...Code3) as `code`: a real device accepted a
    /// request that presented it, so it is the code the device stores. A listener
    /// learns the codes this way; nothing is written. `false` for a number beyond
    /// Code3. // 000:T26
    pub fn adopt_access_code(&mut self, number: usize, code: u8) -> bool {
        match self.nv.codes.get_mut(number) {
            Some(stored) => {
                *stored = code;
                true
            }
            None => false,
        }
    }

    /// Take the internal I2C bus down or bring it back. // 000:T43
    pub fn inject_i2c_fault(&mut self, on: bool) {
        self.injected.set_i2c(on);
    }

    /// EEPROM writes done since creation (successful writing commands).
    pub fn eeprom_writes(&self) -> u32 {
        self.eeprom_writes
    }

    /// Count EEPROM writes from zero again. The count is the model's bookkeeping, no
    /// part of the device's state: no command reads it, so a model checker that
    /// compares states leaves it out this way.
    pub fn reset_eeprom_writes(&mut self) {
        self.eeprom_writes = 0;
    }

    /// Since when the slave is powered on or reset, and whether it kept the default
    /// settings. // 000:T9
    pub fn power_up(&self) -> PowerUp {
        self.power
    }

    /// Move the slave's clock from `now_us` to `to_us`: its power-up and the frame in
    /// its data link move by the same amount, so that it does at and after `to_us`
    /// what it would have done at and after `now_us` (it reads time only against
    /// them). A power-up whose windows can no longer change anything (000:T9: after
    /// the initialization once the default settings are kept, after the change of
    /// settings otherwise) becomes one long past ([`PowerUp::settled`], keeping the
    /// default settings where it did), so that slaves that differ only in how long
    /// ago they were powered on become equal: for model checking with a master
    /// (proofs/src/master_fixpoint/joint.rs). Times before `now_us - to_us` would move to 0.
    pub fn rebase(&mut self, now_us: u64, to_us: u64) {
        let moved = |t: u64| t.saturating_add(to_us).saturating_sub(now_us);
        if let Some(since) = self.power.since_us {
            let p = &self.profile;
            let windows = match self.power.kept_default {
                true => p.init_ms,
                false => p.init_ms.max(p.default_window_ms).max(p.user_settings_ms),
            };
            let over = now_us >= since.saturating_add(windows as u64 * 1000);
            self.power.since_us = if over { None } else { Some(moved(since)) };
        }
        self.link.rebase(now_us, to_us);
    }

    /// The stored settings as of the last power-on or reset: those the Operational
    /// state uses. // 000:T32
    pub fn boot_settings(&self) -> UartSettings {
        self.boot_settings
    }

    /// The settings a Temporarily Set Serial Interface set, until the next reset. // 000:T33
    pub fn temporary_settings(&self) -> Option<UartSettings> {
        self.temp_settings
    }

    pub fn state(&self, now_us: u64) -> CommState {
        self.power.state(&self.profile, now_us)
    }

    /// The settings the slave listens with now; `None` while it does not listen.
    pub fn listening_settings(&self, now_us: u64) -> Option<UartSettings> {
        let base = self.power.settings(&self.profile, now_us, self.boot_settings)?;
        Some(self.temp_settings.unwrap_or(base))
    }

    /// The settings the slave listens with now or, while it does not listen
    /// (initialization, the change of settings), the ones it will listen with next:
    /// what a master that talks now should send in, so that no part of its frame
    /// reaches the slave in other settings. // 000:T9
    pub fn settings_heard_next(&self, now_us: u64) -> UartSettings {
        let mut t = now_us;
        // The power-up states change at most three times (000:T9).
        for _ in 0..4 {
            if let Some(s) = self.listening_settings(t) {
                return s;
            }
            match self.power.next_change(&self.profile, t) {
                Some(next) => t = next,
                None => break,
            }
        }
        UartSettings::DEFAULT
    }

    /// Whether the power-up state changes by itself after `from_us` and no later than
    /// `to_us` (000:T9): a frame whose characters arrive across such a change is heard
    /// in part, or in two settings.
    pub fn state_changes_within(&self, from_us: u64, to_us: u64) -> bool {
        self.power.next_change(&self.profile, from_us).is_some_and(|t| t <= to_us)
    }

    /// The frame timeout now (with the listening settings, or the defaults).
    pub fn timeout_us(&self, now_us: u64) -> u64 {
        self.listening_settings(now_us).unwrap_or(UartSettings::DEFAULT).timeout_us(self.profile.edition)
    }

    /// The reported position: raw + offset, modulo the measuring range.
    pub fn position(&self) -> u64 {
        let range = self.profile.range();
        (self.inputs.position % range + self.nv.offset) % range
    }

    /// Take a received character. Returns the previous frame's step if this character
    /// shows that frame ended.
    pub fn receive(&mut self, ch: RxChar) -> Option<Step> {
        let done = self.poll(ch.at_us);
        if self.listening_settings(ch.at_us).is_none() {
            return done;
        }
        self.link.set_timeout(self.timeout_us(ch.at_us));
        let closed = self.link.receive(ch).map(|f| self.process(f));
        done.or(closed)
    }

    /// Advance time: a frame whose timeout has elapsed is processed.
    pub fn poll(&mut self, now_us: u64) -> Option<Step> {
        let deadline = self.link.deadline()?;
        if now_us < deadline {
            return None;
        }
        let frame = self.link.poll(deadline)?;
        Some(self.process(frame))
    }

    /// The next time [`Slave::poll`] has work: a frame's timeout or a state change.
    pub fn next_deadline(&self, now_us: u64) -> Option<u64> {
        let state_change = self.power.next_change(&self.profile, now_us);
        match (self.link.deadline(), state_change) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// A frame the caller's own data link delimited, processed when its timeout
    /// elapsed (`frame.complete_us`), as [`Slave::receive`] and [`Slave::poll`]
    /// process the frames of the slave's own: for a device built around the model that
    /// frames requests itself (a test encoder with another timeout).
    pub fn process(&mut self, frame: ReceivedFrame) -> Step {
        let at = frame.complete_us;
        let settings = self.listening_settings(at);
        let outcome = match settings {
            None => Outcome::NOT_LISTENING,
            Some(_) => self.execute(frame.bytes.as_bytes(), frame.uart_fault.is_some(), frame.overflowed(), at),
        };
        let transmission = match (outcome.reply, settings) {
            (Reply::Frame(rf), Some(settings)) => {
                let command = CommandId::of_frame(frame.bytes.as_bytes());
                let max_ms = self.profile.response_limit(command).max_ms;
                Some(Transmission {
                    frame: rf.encode(),
                    earliest_start_us: at,
                    latest_start_us: at + max_ms as u64 * 1000,
                    settings,
                    then_settings: outcome.then_settings,
                })
            }
            _ => None,
        };
        Step { received: frame, outcome, transmission }
    }

    /// Network and application layer on a whole frame, processed at `at_us` (when its
    /// timeout elapsed). `uart_fault`: a character had a parity or framing fault;
    /// `overflowed`: more characters arrived than any frame has.
    pub fn handle_frame(&mut self, bytes: &[u8], at_us: u64) -> Outcome {
        self.handle(bytes, false, at_us)
    }

    /// As [`Slave::handle_frame`], for a frame with a UART fault in some character.
    pub fn handle_faulty_frame(&mut self, bytes: &[u8], at_us: u64) -> Outcome {
        self.handle(bytes, true, at_us)
    }

    /// As [`Slave::handle_frame`], with or without a UART fault as `uart_fault` says:
    /// for a proof that takes both at once (a bounded model checker then runs the
    /// step once with the fault symbolic, not once per case).
    pub fn handle(&mut self, bytes: &[u8], uart_fault: bool, at_us: u64) -> Outcome {
        match self.listening_settings(at_us) {
            None => Outcome::NOT_LISTENING,
            Some(_) => self.execute(bytes, uart_fault, false, at_us),
        }
    }
}
