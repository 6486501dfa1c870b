//! The invariant's inductive step, sampled: the parts of a state as proptest draws
//! them, the twins of the whole-step harnesses (one command or a family from any state
//! satisfying the invariant), and the error stack's and the data field table's parts
//! of the invariant on their own.

use super::sample;
use crate::inductive;
use hiperface_model::slave::stack::STACK_DEPTH;
use hiperface_model::FaultCode;
use proptest::prelude::*;

/// [`inductive::Parts`] as proptest samples them: biased towards parts that make a
/// state satisfying the invariant (valid address and settings bytes, codes of the fault
/// table on the stack, fields that exist), with any value among them now and then.
pub fn parts_strategy() -> impl Strategy<Value = inductive::Parts> {
    let settings = || {
        prop_oneof![
            // Data rates mostly from 1200 Bd up: a SEK37 has no 600 Bd.
            19 => (prop_oneof![29 => 1u8..7, 1 => Just(0u8)], prop::sample::select(vec![0x00u8, 0x20, 0x30]), any::<bool>(), any::<bool>())
                .prop_map(|(baud, parity, long, standard)| baud | parity | u8::from(long) << 6 | u8::from(standard) << 7),
            1 => any::<u8>(),
        ]
    };
    let codes: Vec<u8> = FaultCode::ALL.iter().map(|c| c.byte()).filter(|b| *b != 0).collect();
    let nv = (
        prop_oneof![19 => 0x40u8..=0x5F, 1 => any::<u8>()],
        settings(),
        settings(),
        any::<bool>(),
        settings(),
        any::<[u8; 4]>(),
        // Offsets below the range of a SEK37 (512 steps) and of larger devices.
        prop_oneof![16 => 0u64..512, 1 => 0u64..32_768, 1 => any::<u64>()],
        prop_oneof![6 => 0u32..=0xFF_FFFF, 2 => Just(0xFF_FFFF), 1 => Just(0xFF_FFFE), 1 => any::<u32>()],
    );
    // Field sizes mostly small, so that three fields fit a legacy device's 8 blocks too.
    let status =
        prop_oneof![3 => any::<u8>().prop_map(|b| (b | 0x80) & !0x06), 1 => any::<u8>().prop_map(|b| b | 0x80)];
    let fields = (0u8..=inductive::MAX_FIELDS as u8, prop::array::uniform3(status));
    let stack = (0u8..=STACK_DEPTH as u8, prop::array::uniform4(prop::sample::select(codes)));
    let power = (any::<bool>(), 0u64..2_000_000, any::<bool>(), any::<[bool; 3]>());
    let inputs = (
        any::<u64>(),
        -20_000i32..20_000,
        -60i16..150,
        0u16..100,
        any::<bool>(),
        prop::array::uniform7(prop_oneof![5 => Just(false), 1 => Just(true)]),
    );
    (nv, fields, stack, power, inputs).prop_map(
        |(
            (address, settings, boot_settings, temporary, temporary_settings, codes, offset, counter),
            (field_count, statuses),
            (stack_len, stack),
            (settled, since_us, kept_default, locks),
            (position, speed, temperature_c, led_current_ma, i2c_fault, position_faults),
        )| inductive::Parts {
            address,
            settings,
            boot_settings,
            temporary,
            temporary_settings,
            codes,
            offset,
            counter,
            field_count,
            statuses,
            stack_len,
            stack,
            settled,
            since_us,
            // Kept default settings only after a power-up (else the invariant rejects
            // the parts: kept once in ten samples, to check that it does).
            kept_default: kept_default && (!settled || since_us % 10 == 0),
            locks,
            position,
            speed,
            temperature_c,
            led_current_ma,
            i2c_fault,
            position_faults,
        },
    )
}

/// The twin of an inductive harness: sampled parts (those that build a state
/// satisfying the invariant), each command of the family with sampled bytes, time and
/// UART fault. Fails when fewer than half the samples build a state (a vacuous run).
pub fn inductive_sampled(profile: hiperface_model::Profile, family: &[(u8, usize)], cases: u32) -> Result<u64, String> {
    inductive_sampled_shaped(profile, family, cases, |_| {})
}

/// [`inductive_sampled`] with each frame first made one of a part of the command's
/// frames by `shape` (a harness whose domain is that part has this twin).
pub fn inductive_sampled_shaped(
    profile: hiperface_model::Profile,
    family: &[(u8, usize)],
    cases: u32,
    shape: fn(&mut [u8]),
) -> Result<u64, String> {
    use std::sync::atomic::{AtomicU64, Ordering};
    let built = AtomicU64::new(0);
    let frame = any::<[u8; inductive::MAX_FAMILY_FRAME]>();
    // Most frames to the own address or broadcast with their checksum right, so that the
    // command's own code runs (Kani takes every byte).
    let to = prop_oneof![6 => Just(0u8), 2 => Just(1u8), 1 => Just(2u8)];
    let sealed = prop_oneof![4 => Just(true), 1 => Just(false)];
    let strategy =
        (parts_strategy(), frame, to, sealed, 0u64..3_000_000, prop_oneof![4 => Just(false), 1 => Just(true)]);
    let n = sample(strategy, cases, |(parts, frame, to, sealed, now, fault)| {
        let Some(state) = parts.build(profile) else { return true };
        built.fetch_add(1, Ordering::Relaxed);
        family.iter().all(|&(command, data)| {
            let mut frame = inductive::request_of(frame, command, data);
            match to {
                0 => frame[0] = state.nonvolatile().address.byte(),
                1 => frame[0] = 0xFF,
                _ => {}
            }
            let frame = &mut frame[..3 + data];
            shape(frame);
            if *sealed {
                let (sum, body) = frame.split_last_mut().expect("3 bytes or more");
                *sum = hiperface_model::checksum::xor(body);
            }
            inductive::step_keeps_invariant(&state, frame, *now, *fault)
        })
    })?;
    let built = built.load(Ordering::Relaxed);
    if built * 2 < n {
        return Err(format!("only {built} of {n} samples built a state satisfying the invariant"));
    }
    Ok(built)
}

/// The stack's inductive step on sampled stacks and operations: codes mostly from a
/// few (so that duplicates and full stacks occur), now and then any byte.
pub(super) fn stack_steps() -> Result<u64, String> {
    let code = || prop_oneof![4 => prop::sample::select(vec![0x00u8, 0x01, 0x07, 0x1E, 0x22, 0xFF]), 1 => any::<u8>()];
    let strategy = (prop::array::uniform4(code()), 0u8..=4, any::<u8>(), code());
    sample(strategy, 50_000, |(codes, len, op, c)| inductive::stack_step_keeps_invariant(*codes, *len, *op, *c))
}

/// The data field table's inductive step on sampled tables and operations: sizes
/// mostly small and memories mostly tight, so that tables fill up, resizes are
/// refused and the last field is deleted.
pub(super) fn fields_steps() -> Result<u64, String> {
    let step = (
        prop::array::uniform3(any::<u8>()),
        0u8..=3,
        prop_oneof![3 => 0u8..12, 1 => any::<u8>()],
        any::<u8>(),
        prop_oneof![3 => 0u8..4, 1 => any::<u8>()],
        any::<u8>(),
    )
        .prop_map(|(statuses, count, capacity, op, number, status)| inductive::FieldsStep {
            statuses,
            count,
            capacity,
            op,
            number,
            status,
        });
    sample(step, 50_000, inductive::fields_step_keeps_invariant)
}
