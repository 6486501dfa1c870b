//! The mutated model (hiperface-model-mutated) as an encoder on the suite's virtual
//! line: characters in, transmissions out, converted field by field between the two
//! crates' types. The conversions read fields, never the copy's own encoders
//! (`UartSettings::byte`), so that a mutant changes what the device does, not how the
//! harness reads it.
//!
//! A panic of the mutated model is the device's crash: from then on it neither listens
//! nor answers, as firmware that stops in its panic handler.

use hiperface_model as model;
use hiperface_model::datalink::RxChar;
use hiperface_model::slave::inputs::{InitFault, PositionFault};
use hiperface_model::{Edition, Transmission, UartSettings};
use hiperface_model_mutated as dut;
use hiperface_suite::line::virtual_line::SlaveDevice;
use hiperface_suite::world::World;
use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::rc::Rc;

/// Where a device says it crashed, readable after the line that owned it is gone.
pub type CrashNote = Rc<RefCell<Option<String>>>;

/// The model's settings in the copy's types.
pub fn to_dut_settings(s: UartSettings) -> dut::UartSettings {
    use dut::settings::{Baud as DB, BusMode as DM, Parity as DP, TimeoutSelect as DT};
    use model::settings::{Baud, BusMode, Parity, TimeoutSelect};
    dut::UartSettings {
        baud: match s.baud {
            Baud::B600 => DB::B600,
            Baud::B1200 => DB::B1200,
            Baud::B2400 => DB::B2400,
            Baud::B4800 => DB::B4800,
            Baud::B9600 => DB::B9600,
            Baud::B19200 => DB::B19200,
            Baud::B38400 => DB::B38400,
        },
        parity: match s.parity {
            Parity::None => DP::None,
            Parity::Even => DP::Even,
            Parity::Odd => DP::Odd,
        },
        timeout: match s.timeout {
            TimeoutSelect::Short => DT::Short,
            TimeoutSelect::Long => DT::Long,
        },
        bus: match s.bus {
            BusMode::BusSlave => DM::BusSlave,
            BusMode::Standard => DM::Standard,
        },
    }
}

/// The copy's settings in the model's types.
pub fn from_dut_settings(s: dut::UartSettings) -> UartSettings {
    use dut::settings::{Baud as DB, BusMode as DM, Parity as DP, TimeoutSelect as DT};
    use model::settings::{Baud, BusMode, Parity, TimeoutSelect};
    UartSettings {
        baud: match s.baud {
            DB::B600 => Baud::B600,
            DB::B1200 => Baud::B1200,
            DB::B2400 => Baud::B2400,
            DB::B4800 => Baud::B4800,
            DB::B9600 => Baud::B9600,
            DB::B19200 => Baud::B19200,
            DB::B38400 => Baud::B38400,
        },
        parity: match s.parity {
            DP::None => Parity::None,
            DP::Even => Parity::Even,
            DP::Odd => Parity::Odd,
        },
        timeout: match s.timeout {
            DT::Short => TimeoutSelect::Short,
            DT::Long => TimeoutSelect::Long,
        },
        bus: match s.bus {
            DM::BusSlave => BusMode::BusSlave,
            DM::Standard => BusMode::Standard,
        },
    }
}

fn to_dut_char(c: RxChar) -> dut::RxChar {
    use dut::UartFault as D;
    use model::UartFault as M;
    dut::RxChar {
        byte: c.byte,
        at_us: c.at_us,
        fault: c.fault.map(|f| match f {
            M::Parity => D::Parity,
            M::Framing => D::Framing,
            M::Noise => D::Noise,
            M::Overrun => D::Overrun,
        }),
    }
}

/// A transmission of the copy in the model's types; `None` where its frame does not
/// fit a frame (a mutant that made one too long: the line carries what fits).
fn from_dut_transmission(t: dut::Transmission) -> Option<Transmission> {
    let frame = model::Frame::from_bytes(t.frame.as_bytes()).ok()?;
    Some(Transmission {
        frame,
        earliest_start_us: t.earliest_start_us,
        latest_start_us: t.latest_start_us,
        settings: from_dut_settings(t.settings),
        then_settings: t.then_settings.map(from_dut_settings),
    })
}

/// The copy's profile for a profile of the model: the copy's own built-in profile of
/// the same name, with the same stored settings.
pub fn dut_profile(p: &model::Profile) -> Option<dut::Profile> {
    let mut d = dut::profiles::builtin(p.name.as_str())?;
    d.settings = to_dut_settings(p.settings);
    d.stack_order = match p.stack_order {
        model::profile::StackOrder::OldestFirst => dut::profile::StackOrder::OldestFirst,
        model::profile::StackOrder::NewestFirst => dut::profile::StackOrder::NewestFirst,
    };
    Some(d)
}

/// The copy's start-up fault of the same row of the table (by its place in `ALL`, a
/// constant of the copy: no code of the copy's runs to convert it).
fn to_dut_init_fault(f: InitFault) -> Option<dut::slave::inputs::InitFault> {
    let i = InitFault::ALL.iter().position(|x| *x == f)?;
    dut::slave::inputs::InitFault::ALL.get(i).copied()
}

/// The copy's position fault of the same row (as [`to_dut_init_fault`]).
fn to_dut_position_fault(f: PositionFault) -> Option<dut::slave::inputs::PositionFault> {
    let i = PositionFault::ALL.iter().position(|x| *x == f)?;
    dut::slave::inputs::PositionFault::ALL.get(i).copied()
}

/// The copy's slave for profile `p`, past its power-up, in `world` (as `World::apply`
/// puts the lockstep model in it): its inputs set, its start-up faults found, its
/// position faults present. Unguarded: the caller catches a panic.
pub fn build_slave(p: dut::Profile, world: &World) -> dut::Slave {
    let mut s = dut::Slave::operational(p);
    if let Some(i) = world.inputs {
        s.set_inputs(dut::slave::inputs::PhysicalInputs {
            position: i.position,
            speed: i.speed,
            temperature_c: i.temperature_c,
            led_current_ma: i.led_current_ma,
        });
    }
    if !world.init_faults.is_empty() {
        let faults: Vec<_> = world.init_faults.iter().filter_map(|f| to_dut_init_fault(*f)).collect();
        s.power_up_with(faults, true);
    }
    for f in world.position_faults.iter().filter_map(|f| to_dut_position_fault(*f)) {
        s.inject_position_fault(f, true);
    }
    if world.i2c_fault {
        s.inject_i2c_fault(true);
    }
    s
}

/// The copy's edition for the model's.
pub fn to_dut_edition(e: Edition) -> dut::Edition {
    match e {
        Edition::Current => dut::Edition::Current,
        Edition::Legacy => dut::Edition::Legacy,
    }
}

/// The mutated slave on the virtual line.
pub struct MutatedEncoder {
    slave: dut::Slave,
    edition: Edition,
    /// The panic's message, once the model panicked: the device is dead.
    crashed: CrashNote,
}

impl MutatedEncoder {
    /// The mutated slave for `profile`, past its power-up (as the catalogue's model);
    /// `Err` for a profile the copy does not have, or where building it panicked.
    pub fn operational(profile: &model::Profile) -> Result<MutatedEncoder, String> {
        MutatedEncoder::in_world(profile, &World::default())
    }

    /// As [`MutatedEncoder::operational`], in `world` (as `World::apply` puts the
    /// lockstep model in it): its inputs set, its start-up faults found, its position
    /// faults present.
    pub fn in_world(profile: &model::Profile, world: &World) -> Result<MutatedEncoder, String> {
        MutatedEncoder::in_config(profile, world, None)
    }

    /// As [`MutatedEncoder::in_world`], with the counter at `counter` where given.
    pub fn in_config(profile: &model::Profile, world: &World, counter: Option<u32>) -> Result<MutatedEncoder, String> {
        let p = guarded(|| dut_profile(profile))?
            .ok_or_else(|| format!("no built-in profile {}", profile.name.as_str()))?;
        let slave = guarded(|| {
            let mut s = build_slave(p, world);
            if let Some(n) = counter {
                s.set_counter(n);
            }
            s
        })?;
        Ok(MutatedEncoder { slave, edition: profile.edition, crashed: CrashNote::default() })
    }

    /// Where the device notes its crash.
    pub fn crash_note(&self) -> CrashNote {
        self.crashed.clone()
    }

    fn dead(&self) -> bool {
        self.crashed.borrow().is_some()
    }

    /// The slave, for a world to be set on it.
    pub fn slave_mut(&mut self) -> &mut dut::Slave {
        &mut self.slave
    }

    fn run<T>(&mut self, f: impl FnOnce(&mut dut::Slave) -> Option<T>) -> Option<T> {
        if self.dead() {
            return None;
        }
        match guarded(|| f(&mut self.slave)) {
            Ok(v) => v,
            Err(why) => {
                *self.crashed.borrow_mut() = Some(why);
                None
            }
        }
    }
}

/// Run `f`, a panic taken as a value: its message.
pub fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic".into())
    })
}

impl SlaveDevice for MutatedEncoder {
    fn receive(&mut self, ch: RxChar) -> Option<Transmission> {
        let c = to_dut_char(ch);
        self.run(|s| s.receive(c)?.transmission.and_then(from_dut_transmission))
    }

    fn poll(&mut self, now_us: u64) -> Option<Transmission> {
        self.run(|s| s.poll(now_us)?.transmission.and_then(from_dut_transmission))
    }

    fn next_deadline(&self, now_us: u64) -> Option<u64> {
        if self.dead() {
            return None;
        }
        guarded(|| self.slave.next_deadline(now_us)).ok().flatten()
    }

    fn listening_settings(&self, now_us: u64) -> Option<UartSettings> {
        if self.dead() {
            return None;
        }
        guarded(|| self.slave.listening_settings(now_us).map(from_dut_settings)).ok().flatten()
    }

    fn edition(&self) -> Edition {
        self.edition
    }

    fn describe(&self) -> String {
        format!("a mutant of the model in virtual time ({:?} edition)", self.edition)
    }
}
