//! The configurations a defective encoder is certified in: every built-in profile as it
//! ships, its world unknown to the harness (the first sweep: a device on a line);
//! every built-in profile in worlds given to the run, as in-process certification
//! takes them (the second: what only the encoder's world provokes, graded exactly);
//! every stored settings byte each profile accepts (the third).

use hiperface_model::slave::inputs::{InitFault, PhysicalInputs, PositionFault};
use hiperface_model::{profiles, Profile, UartSettings};
use hiperface_suite::world::World;

/// A profile with its stored settings and the world the run is given (none: the
/// default world, unknown to the harness), named `SRS50`, `SRS50@E4h` or `SRS50 hot`.
#[derive(Debug, Clone)]
pub struct Config {
    pub name: String,
    pub profile: Profile,
    pub world: World,
    /// The device's counter at the start, where not 0: what the harness adopts from
    /// the device (graded by range), not a world it is given.
    pub counter: Option<u32>,
}

/// Every built-in profile with its own stored settings.
pub fn shipped() -> Vec<Config> {
    profiles::BUILTIN
        .iter()
        .map(|(name, make)| Config { name: name.to_string(), profile: make(), world: World::default(), counter: None })
        .collect()
}

/// The worlds of the second sweep, for a profile: each named by what it provokes.
pub fn worlds(p: &Profile) -> Vec<(String, World)> {
    let inputs = |f: &dyn Fn(&mut PhysicalInputs)| {
        let mut i = PhysicalInputs::default();
        f(&mut i);
        World { inputs: Some(i), ..World::default() }
    };
    let mut w = vec![
        // A shaft away from 0: positions graded exactly.
        ("turned".to_string(), inputs(&|i| i.position = 0x0012_3457)),
        // Others-group monitoring, raised before every reply while the cause lasts (000:T58, T59).
        ("hot".to_string(), inputs(&|i| i.temperature_c = p.temperature_max_c.saturating_add(5))),
        ("cold".to_string(), inputs(&|i| i.temperature_c = p.temperature_min_c.saturating_sub(5))),
        ("led-current".to_string(), inputs(&|i| i.led_current_ma = p.led_current_max_ma.saturating_add(1))),
        // Too fast to read the position (000:T36).
        (
            "moving".to_string(),
            inputs(&|i| i.speed = i32::try_from(p.max_read_speed).unwrap_or(i32::MAX).saturating_add(1)),
        ),
    ];
    for f in InitFault::ALL {
        w.push((format!("start-up {}", f.name()), World { init_faults: vec![f], ..World::default() }));
    }
    // Two start-up codes and a temperature: three codes, read out in order.
    w.push((
        "start-up watchdog+counter, hot".into(),
        World {
            init_faults: vec![InitFault::Watchdog, InitFault::Counter],
            ..inputs(&|i| i.temperature_c = p.temperature_max_c.saturating_add(5))
        },
    ));
    // Five codes: the stack holds four, the oldest goes (000:2.3.4).
    w.push((
        "five codes".into(),
        World {
            init_faults: vec![InitFault::AlignmentData, InitFault::Watchdog, InitFault::Counter],
            ..inputs(&|i| i.temperature_c = p.temperature_max_c.saturating_add(5))
        },
    ));
    for f in PositionFault::ALL {
        w.push((format!("position {}", f.name()), World { position_faults: vec![f], ..World::default() }));
    }
    w.push(("i2c bus down".into(), World { i2c_fault: true, ..World::default() }));
    w
}

/// Every built-in profile in every world of [`worlds`].
pub fn in_worlds() -> Vec<Config> {
    let mut all = Vec::new();
    for (name, make) in profiles::BUILTIN {
        let p = make();
        for (w, world) in worlds(&p) {
            all.push(Config { name: format!("{name} {w}"), profile: p, world, counter: None });
        }
        // The counter at its end (000:T17, T46; 002:47h): an increment overflows.
        all.push(Config {
            name: format!("{name} counter FFFFFFh"),
            profile: p,
            world: World::default(),
            counter: Some(0xFF_FFFF),
        });
        // The stack read newest first, where a data sheet says so: several codes.
        let mut newest = p;
        newest.stack_order = hiperface_model::profile::StackOrder::NewestFirst;
        for (w, world) in worlds(&p).into_iter().filter(|(w, _)| w.contains('+') || w == "five codes") {
            all.push(Config { name: format!("{name} newest-first {w}"), profile: newest, world, counter: None });
        }
    }
    all
}

/// Every built-in profile with every stored settings byte it accepts (its data rates,
/// every parity, both timeouts, both bus modes).
pub fn every_setting() -> Vec<Config> {
    let mut all = Vec::new();
    for (name, make) in profiles::BUILTIN {
        for byte in 0..=255u8 {
            let mut p = make();
            let Ok(settings) = UartSettings::decode(byte) else { continue };
            if settings == p.settings {
                continue;
            }
            p.settings = settings;
            if p.validate().is_ok() {
                all.push(Config {
                    name: format!("{name}@{byte:02X}h"),
                    profile: p,
                    world: World::default(),
                    counter: None,
                });
            }
        }
    }
    all
}
