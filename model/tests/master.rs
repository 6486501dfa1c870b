//! The master-side references against 000 chapter 3's tables, and together with the
//! slave: synchronisation recovers the full position over a sweep of angles and speeds.

use hiperface_model::fault::{FaultCode, FaultGroup, Severity, Variant};
use hiperface_model::master::fault_reaction::{self, AmplitudeWindow, MasterFault};
use hiperface_model::master::interpolation::{self, Interpolator};
use hiperface_model::master::quadrature::{self, Ab, Count, Counter};
use hiperface_model::master::signal::SignalSource;
use hiperface_model::master::sync::{self, Correction, FineAngle};
use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::{profiles, Slave};

mod common;
use common::sealed;

/// 000 Table 72 as printed: A(n-1) B(n-1) A(n) B(n) Counter.
const TABLE_72: &str = "
0 0 0 0 No action
0 0 0 1 +1
0 0 1 0 -1
0 0 1 1 Invalid
0 1 0 0 -1
0 1 0 1 No action
0 1 1 0 Invalid
0 1 1 1 +1
1 0 0 0 +1
1 0 0 1 Invalid
1 0 1 0 No action
1 0 1 1 -1
1 1 0 0 Invalid
1 1 0 1 -1
1 1 1 0 +1
1 1 1 1 No action";

#[test]
fn quadrature_equals_table_72_for_all_16_rows() {
    let mut rows = 0;
    for line in TABLE_72.lines().filter(|l| !l.is_empty()) {
        let f: Vec<&str> = line.splitn(5, ' ').collect();
        let bit = |i: usize| f[i] == "1";
        let want = match f[4] {
            "No action" => Count::NoAction,
            "+1" => Count::Up,
            "-1" => Count::Down,
            _ => Count::Invalid,
        };
        let got = quadrature::step(Ab { a: bit(0), b: bit(1) }, Ab { a: bit(2), b: bit(3) });
        assert_eq!(got, want, "{line}");
        rows += 1;
    }
    assert_eq!(rows, 16);
    // A forward cycle 00 -> 01 -> 11 -> 10 -> 00 counts +4.
    let mut c = Counter::new(0, Ab::default());
    for (a, b) in [(false, true), (true, true), (true, false), (false, false)] {
        c.sample(Ab { a, b });
    }
    assert_eq!((c.value, c.invalid), (4, 0));
}

/// The 16-row table of 000:3.2.5 as printed: f(i:i-1) a(4:3) q(n:5).
const SYNC_ROWS: &str = "
00 00 a
00 01 a
00 10 Invalid
00 11 a+1
01 00 a
01 01 a
01 10 a
01 11 Invalid
10 00 Invalid
10 01 a
10 10 a
10 11 a
11 00 a-1
11 01 Invalid
11 10 a
11 11 a";

#[test]
fn synchronisation_equals_the_16_row_table() {
    for line in SYNC_ROWS.lines().filter(|l| !l.is_empty()) {
        let f: Vec<&str> = line.split(' ').collect();
        let fq = u8::from_str_radix(f[0], 2).unwrap();
        let aq = u8::from_str_radix(f[1], 2).unwrap();
        let want = match f[2] {
            "a" => Correction::Same,
            "a+1" => Correction::PlusOne,
            "a-1" => Correction::MinusOne,
            _ => Correction::Invalid,
        };
        assert_eq!(sync::correction(fq, aq), want, "{line}");
        // The carry propagates into all higher bits: period 0x1F + 1 = 0x20.
        let absolute = (0x1F << 5) | ((aq as u64) << 3);
        let fine = FineAngle { value: (fq as u32) << 14, bits: 16 };
        let q = sync::init_counter(absolute, fine);
        match want {
            Correction::Invalid => assert_eq!(q, None),
            Correction::Same => assert_eq!(q, Some(0x1F * 4 + fq as i64)),
            Correction::PlusOne => assert_eq!(q, Some(0x20 * 4 + fq as i64)),
            Correction::MinusOne => assert_eq!(q, Some(0x1E * 4 + fq as i64)),
        }
    }
}

#[test]
fn octants_and_transformation_for_all_sign_combinations() {
    // 000:3.2.4 step 1 as printed: sin>=0, cos>=0, |sin|<|cos| -> octant.
    let table = [
        (true, true, true, 0),
        (true, true, false, 1),
        (true, false, false, 2),
        (true, false, true, 3),
        (false, false, true, 4),
        (false, false, false, 5),
        (false, true, false, 6),
        (false, true, true, 7),
    ];
    for s in -64i32..=64 {
        for c in -64i32..=64 {
            let o = interpolation::octant(s, c);
            let row = table.iter().find(|r| (r.0, r.1, r.2) == (s >= 0, c >= 0, s.abs() < c.abs())).unwrap();
            assert_eq!(o, row.3);
            let (x, y) = interpolation::transform(o, s, c);
            if s != 0 || c != 0 {
                assert!(x >= 0 && y > 0 && x <= y, "{s} {c} -> octant {o}: X {x}, Y {y}");
            }
        }
    }
}

/// Max angular error (degrees) of the fixed-point interpolation against atan2 over
/// the full circle, for a 16-bit ADC (amplitude 32767), 65536 angles.
fn max_error_degrees(nodes: u32, amplitude: f64) -> f64 {
    let ip = Interpolator::new(nodes).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..65536u32 {
        let phi = k as f64 / 65536.0 * std::f64::consts::TAU;
        let (s, c) = ((phi.sin() * amplitude).round() as i32, (phi.cos() * amplitude).round() as i32);
        let got = ip.angle(s, c).unwrap() as f64 / 4294967296.0 * 360.0;
        let want = (s as f64).atan2(c as f64).to_degrees().rem_euclid(360.0);
        let mut d = (got - want).abs();
        if d > 180.0 {
            d = 360.0 - d;
        }
        worst = worst.max(d);
    }
    worst
}

#[test]
fn interpolation_error_by_node_count() {
    // Measured (docs/src/master-side-references.md): 16 nodes 0.01815°, 32 nodes 0.00454°,
    // 64 nodes 0.00114° at 16 bit.
    let e16 = max_error_degrees(16, 32767.0);
    let e32 = max_error_degrees(32, 32767.0);
    let e64 = max_error_degrees(64, 32767.0);
    eprintln!("max error vs atan2: 16 nodes {e16:.5}°, 32 nodes {e32:.5}°, 64 nodes {e64:.5}°");
    assert!(e16 < 0.0182, "{e16}");
    assert!(e32 < 0.00455, "{e32}");
    assert!(e64 < 0.00115, "{e64}");
    assert!(e64 < e32 && e32 < e16);
    // A 10-bit ADC: quantisation dominates.
    let e10 = max_error_degrees(32, 511.0);
    eprintln!("10-bit ADC, 32 nodes: {e10:.4}°");
    assert!(e10 < 0.06, "{e10}");
    assert!(Interpolator::new(0).is_none() && Interpolator::new(48).is_none());
    assert_eq!(Interpolator::new(32).unwrap().angle(0, 0), None, "no signal");
}

#[test]
fn the_f64_reference_follows_atan2() {
    let mut worst: f64 = 0.0;
    for k in 0..100_000u32 {
        let phi = k as f64 / 100_000.0 * std::f64::consts::TAU;
        let (s, c) = (phi.sin(), phi.cos());
        let got = interpolation::reference_degrees(s, c).unwrap();
        let want = s.atan2(c).to_degrees().rem_euclid(360.0);
        let mut d = (got - want).abs();
        if d > 180.0 {
            d = 360.0 - d;
        }
        worst = worst.max(d);
    }
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn synchronisation_recovers_the_full_position_with_the_slave() {
    // SKM36: 128 periods per turn, 4096 turns. The absolute position is read at one
    // instant, the fine angle sampled at another: at speed they differ. The 16-row
    // table accepts one quadrant of difference: a window of ±25% of a period, 50% in
    // all (000:3.2.5 "tolerances within 50% of a sine/cosine period").
    let mut slave = Slave::operational(profiles::skm36());
    let ip = Interpolator::new(32).unwrap();
    let mut source = SignalSource::new(30_000).with_noise(20, 15, -10);
    let range = slave.profile().range();
    let mut checked = 0;
    for i in 0..20_000u64 {
        // Fine raw position in 1/1024 steps, spread over the range.
        let fine_pos = (i * 7_919_993_773) % (range * 1024);
        // The absolute read happened `lag` 1/1024-steps earlier or later (|lag| < 8 steps).
        let lag = ((i % 15) as i64 - 7) * 1024 - (i % 1000) as i64;
        let abs_pos = (fine_pos as i64 - lag).rem_euclid((range * 1024) as i64) as u64;
        slave.set_inputs(PhysicalInputs { position: abs_pos / 1024, ..PhysicalInputs::default() });
        let reply = slave.handle_frame(&[0x40, 0x42, 0x02], 0);
        let absolute = match reply.reply {
            hiperface_model::Reply::Frame(f) => match f.response {
                hiperface_model::Response::Position(p) => p as u64,
                r => panic!("{r:?}"),
            },
            _ => panic!("silent"),
        };
        // Fine angle from the signals: one period = 32 steps = 32 * 1024 sub-steps.
        let in_period = ((fine_pos % (32 * 1024)) << 32) / (32 * 1024);
        let (s, c) = source.sample(in_period as u32);
        let angle = ip.angle(s, c).unwrap();
        let fine = FineAngle { value: angle >> 16, bits: 16 };
        let q = sync::init_counter(absolute, fine).expect("valid combination");
        let full = sync::full_position(q, fine).unwrap();
        // The period must be the fine sample's true period (or a neighbour where the
        // fine angle wraps at the period boundary within the interpolation error).
        let true_period = (fine_pos / (32 * 1024)) as i64;
        let got_period = full >> 16;
        let wrap = (fine.value < 64 && got_period == true_period + 1)
            || (fine.value > 65_472 && got_period == true_period - 1);
        assert!(
            got_period == true_period || wrap,
            "i {i}: fine {fine_pos} abs {absolute} q {q} -> period {got_period}, want {true_period}"
        );
        checked += 1;
    }
    assert_eq!(checked, 20_000);
}

#[test]
fn a_phase_shift_breaks_synchronisation_unless_compensated() {
    // Set Position with a preset whose 5 LSBs differ from the raw phase: the absolute
    // quadrant no longer matches the signals (000:T13 note). 6Ch gives the shift back.
    let mut p = profiles::skm36();
    p.commands.insert(hiperface_model::CommandId::ReadSyncOffset);
    let mut slave = Slave::operational(p);
    slave.set_inputs(PhysicalInputs { position: 100 * 32, ..PhysicalInputs::default() }); // phase 0
    let preset = 100 * 32 + 16; // half a period of phase shift
    let mut req = vec![0x40, 0x43];
    req.extend_from_slice(&(preset as u32).to_be_bytes());
    req.push(0x55);
    slave.handle_frame(&sealed(&req), 0);
    let fine = FineAngle { value: 0, bits: 16 }; // the signals say quadrant 0
    let absolute = slave.position();
    assert_eq!(sync::init_counter(absolute, fine), None, "quadrant 2 vs 0: invalid");
    let shift = match slave.handle_frame(&[0x40, 0x6C, 0x2C], 0).reply {
        hiperface_model::Reply::Frame(f) => match f.response {
            hiperface_model::Response::SyncOffset(s) => s as u64,
            r => panic!("{r:?}"),
        },
        _ => panic!(),
    };
    // position + shift = raw (mod 32): synchronisation works again.
    assert!(sync::init_counter(absolute + shift, fine).is_some());
}

#[test]
fn fault_reaction_table_74() {
    let r = fault_reaction::reaction(FaultCode::MultiturnSync, Some(FaultGroup::Position));
    assert_eq!(r.severity, Severity::Critical);
    assert!(r.response.is_some_and(|t| t.contains("Replace Slave")));
    assert_eq!(fault_reaction::reaction(FaultCode::Watchdog, None).severity, Severity::Minor);
    assert_eq!(fault_reaction::reaction(FaultCode::Checksum, None).response, Some("Retry command."));
    // 06h stacked with 08h: only the user counter is lost, Minor and no action; 06h
    // alone stays Critical. // 000:T74 "06h + 08h"
    let init = Some(FaultGroup::Initialization);
    let narrowed =
        fault_reaction::reaction_to(FaultCode::InternalChecksum, init, Variant::With(FaultCode::CounterOverflow));
    assert_eq!((narrowed.severity, narrowed.response), (Severity::Minor, None));
    assert_eq!(fault_reaction::reaction(FaultCode::InternalChecksum, init).severity, Severity::Critical);
    // A linear encoder's 21h asks to check the sensor's assembly, a rotary one's to retry.
    let linear =
        fault_reaction::reaction_to(FaultCode::MultiturnAmplitude, Some(FaultGroup::Position), Variant::Linear);
    assert_eq!(linear.response, Some("Check assembly of sensor."));
    let rotary = fault_reaction::reaction(FaultCode::MultiturnAmplitude, Some(FaultGroup::Position));
    assert!(rotary.response.is_some_and(|t| t.starts_with("Retry command.")));
    // 1Ch: Major in the position group, Critical in the others group.
    assert_eq!(
        fault_reaction::reaction(FaultCode::AnalogMonitoring, Some(FaultGroup::Position)).severity,
        Severity::Major
    );
    assert_eq!(
        fault_reaction::reaction(FaultCode::AnalogMonitoring, Some(FaultGroup::Others)).severity,
        Severity::Critical
    );
    // Unknown codes get the worst case. // 000:T74
    let u = fault_reaction::reaction(FaultCode::Unknown(0x42), None);
    assert_eq!((u.severity, u.known), (Severity::Critical, false));
    // Every named code has a known reaction.
    for code in FaultCode::ALL.iter().skip(1) {
        assert!(fault_reaction::reaction(*code, None).known, "{code}");
    }
    // 004: amplitude window 800...1200 mV after 100 ms.
    let w = AmplitudeWindow::default();
    assert_eq!(w.check(700, 50), None, "settling");
    assert_eq!(w.check(700, 150), Some(MasterFault::Amplitude { vpp_mv: 700 }));
    assert_eq!(w.check(1000, 150), None);
    assert_eq!(fault_reaction::master_reaction(MasterFault::Timeout).severity, Severity::Major);
    assert_eq!(fault_reaction::MASTER_NOTES.len(), 4);
}

#[test]
fn beyond_a_quarter_period_the_table_can_refuse() {
    // Fine angle at 7.9 steps (quadrant 0), absolute 9 steps later (quadrant 2): invalid.
    let fine = FineAngle { value: ((7.9 / 32.0) * 65536.0) as u32, bits: 16 };
    assert_eq!(fine.quadrant(), 0);
    assert_eq!(sync::init_counter(10 * 32 + 16, fine), None);
    // 7.9 steps of difference never are: every fine position, lags up to 7 steps.
    for f in 0..32 * 64u64 {
        for lag in -7 * 64..=7 * 64i64 {
            let abs = ((100 * 32 * 64 + f as i64 + lag) / 64) as u64;
            let fine = FineAngle { value: ((f % (32 * 64)) * 65536 / (32 * 64)) as u32, bits: 16 };
            assert!(sync::init_counter(abs, fine).is_some(), "f {f} lag {lag}");
        }
    }
}

#[test]
fn runtime_synchronisation_follows_a_moving_shaft() {
    // Comparators: A = sin < 0, B = cos < 0, so that quadrants 0,1,2,3 give AB 00, 01,
    // 11, 10: +1 per quadrant forward (000:T72).
    let ab = |s: i32, c: i32| Ab { a: s < 0, b: c < 0 };
    let ip = Interpolator::default();
    assert_eq!(ip.nodes(), 32);
    let mut source = SignalSource::new(30_000).with_noise(10, 0, 0);
    // Start at period 1000 + 0.3; move forward 500 periods, back 800, in steps of 1/16 period.
    let step = 1u64 << 28; // 1/16 period in 2^32 units
    let mut pos: u64 = (1000u64 << 32) + (3 << 32) / 10;
    let sample = |src: &mut SignalSource, p: u64| src.sample(p as u32);
    let (s, c) = sample(&mut source, pos);
    let fine = FineAngle { value: ip.angle(s, c).unwrap() >> 16, bits: 16 };
    let absolute = pos >> 27; // 32 steps per period
    let mut counter = Counter::new(sync::init_counter(absolute, fine).unwrap(), ab(s, c));
    let moves: Vec<i64> = std::iter::repeat_n(1, 500 * 16).chain(std::iter::repeat_n(-1, 800 * 16)).collect();
    for dir in moves {
        pos = if dir > 0 { pos + step } else { pos - step };
        let (s, c) = sample(&mut source, pos);
        assert_ne!(counter.sample(ab(s, c)), Count::Invalid);
        let fine = FineAngle { value: ip.angle(s, c).unwrap() >> 16, bits: 16 };
        let full = sync::full_position(counter.value, fine).unwrap();
        let truth = (pos >> 16) as i64; // periods and 16 bits of fine angle
        assert!((full - truth).abs() < 8, "pos {pos:x}: full {full:x} truth {truth:x}");
    }
    assert_eq!(counter.invalid, 0);
}

/// The f64 reference of the interpolation is exact to 1e-9° over the whole circle
/// (the arctangent's series, its reduction and the octant's base), against std's.
#[test]
fn the_reference_angle_is_exact_all_around() {
    for tenth in 0..3600 {
        let deg = f64::from(tenth) / 10.0 + 0.03;
        let (s, c) = deg.to_radians().sin_cos();
        let got = interpolation::reference_degrees(s * 1000.0, c * 1000.0).unwrap();
        assert!((got - deg).abs() < 1e-9, "{deg}: {got}");
    }
    assert_eq!(interpolation::reference_degrees(0.0, 1.0), Some(0.0));
    assert_eq!(interpolation::reference_degrees(1.0, 0.0), Some(90.0));
    assert_eq!(interpolation::reference_degrees(0.0, 0.0), None);
    assert_eq!(interpolation::reference_degrees(0.0, -5.0), Some(180.0));
}

/// A fine angle's quadrant is its two top bits; with fewer than two bits there is
/// no quadrant to read (0). The full position carries a ±1 period where the fine
/// angle's quadrant and the counter's disagree by one across a period boundary.
#[test]
fn quadrants_and_the_carried_period() {
    assert_eq!(FineAngle { value: 0b11, bits: 2 }.quadrant(), 3);
    assert_eq!(FineAngle { value: 0b10_0000, bits: 6 }.quadrant(), 2);
    assert_eq!(FineAngle { value: 1, bits: 1 }.quadrant(), 0);
    assert_eq!(FineAngle { value: 0, bits: 0 }.quadrant(), 0);
    let fine = |q: u32| FineAngle { value: (q << 6) | 5, bits: 8 };
    // Counter in period 10, quadrant 3; the fine angle already in quadrant 0: period 11.
    assert_eq!(sync::full_position(10 * 4 + 3, fine(0)), Some((11 << 8) | (5)));
    // Counter in period 10, quadrant 0; the fine angle still in quadrant 3: period 9.
    assert_eq!(sync::full_position(10 * 4, fine(3)), Some((9 << 8) | (3 << 6) | 5));
    assert_eq!(sync::full_position(10 * 4 + 2, fine(2)), Some((10 << 8) | (2 << 6) | 5));
    assert_eq!(sync::full_position(10 * 4 + 2, fine(0)), None, "two quadrants apart");
}

/// Table 74 read as the master's reactions: which rows ask for a reset at once, the
/// group a stacked code is judged in, and where the table has a row per encoder kind
/// the rotary one is the default.
#[test]
fn fault_reactions_by_group_and_kind() {
    let critical_retry = fault_reaction::reaction(FaultCode::AngularOffset, Some(FaultGroup::Position));
    assert!(critical_retry.is_retry() && !critical_retry.is_reset(), "{critical_retry:?}");
    assert!(fault_reaction::reaction(FaultCode::AngularOffset, Some(FaultGroup::Initialization)).is_reset());
    assert!(!fault_reaction::reaction(FaultCode::Watchdog, None).is_reset(), "Minor: read and delete");
    assert_eq!(fault_reaction::stacked_group(FaultCode::AlignmentData), Some(FaultGroup::Initialization));
    assert_eq!(fault_reaction::stacked_group(FaultCode::Temperature), Some(FaultGroup::Others));
    assert_eq!(hiperface_model::fault::runtime_group(FaultCode::AlignmentData), Some(FaultGroup::Others));
    assert_eq!(hiperface_model::fault::runtime_group(FaultCode::AnalogLimits), Some(FaultGroup::Initialization));
    // Group unknown: the most severe of the primary rows, the rotary one, never the
    // linear one ("Check assembly of sensor.").
    let r = fault_reaction::reaction(FaultCode::MultiturnAmplitude, None);
    assert_eq!(r.response, Some("Retry command. If error persists, SW reset of Slave."), "{r:?}");
    let p = fault_reaction::reaction(FaultCode::MultiturnAmplitude, Some(FaultGroup::Position));
    assert_eq!(p.response, Some("Retry command. If error persists, SW reset of Slave."));
    // The amplitude window is inclusive and only after settling (004).
    let w = AmplitudeWindow::default();
    assert_eq!((w.min_mv, w.max_mv, w.settle_ms), (800, 1200, 100));
    assert_eq!(w.check(800, 100), None);
    assert_eq!(w.check(1200, 100), None);
    assert_eq!(w.check(799, 100), Some(MasterFault::Amplitude { vpp_mv: 799 }));
    assert_eq!(w.check(1201, 100), Some(MasterFault::Amplitude { vpp_mv: 1201 }));
    assert_eq!(w.check(1201, 99), None, "still settling");
}
