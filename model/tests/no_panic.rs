//! Nothing panics on any input: decoders, the data link and the slave, driven by
//! arbitrary bytes, times and faults (proptest).

use hiperface_model::datalink::{RxChar, UartFault};
use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::{profiles, CommandId, RequestFrame, ResponseFrame, Slave};
use proptest::prelude::*;

fn any_char() -> impl Strategy<Value = (u8, u16, Option<u8>)> {
    (any::<u8>(), any::<u16>(), proptest::option::weighted(0.05, 0u8..4))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn decoders_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300), to in any::<u8>()) {
        let _ = RequestFrame::decode(&bytes);
        let _ = ResponseFrame::decode(&bytes, CommandId::decode(to));
    }

    #[test]
    fn the_slave_never_panics_and_keeps_its_invariants(
        profile in 0usize..profiles::BUILTIN.len(),
        frames in proptest::collection::vec((0u8..3, proptest::collection::vec(any::<u8>(), 0..20)), 1..40),
        chars in proptest::collection::vec(any_char(), 0..200),
        position in any::<u64>(), speed in any::<i32>(), temperature in any::<i16>(), led in any::<u16>(),
    ) {
        let mut s = Slave::operational((profiles::BUILTIN[profile].1)());
        s.set_inputs(PhysicalInputs { position, speed, temperature_c: temperature, led_current_ma: led });
        // Whole frames, mostly well-formed and addressed to the slave.
        for (kind, body) in frames {
            let mut f = match kind { 0 => vec![0x40], 1 => vec![0xFF], _ => vec![] };
            f.extend(body);
            if kind < 2 { let x = hiperface_model::checksum::xor(&f); f.push(x); }
            let _ = s.handle_frame(&f, 0);
            prop_assert!(s.error_stack().len() <= 4);
            let fields = &s.nonvolatile().fields;
            prop_assert!(fields.used_blocks() <= fields.capacity_blocks() as u32);
            prop_assert!(s.nonvolatile().offset < s.profile().range());
            prop_assert!(s.nonvolatile().counter <= 0xFF_FFFF);
        }
        // Characters through the data link, with faults and any gaps.
        let mut t = 0u64;
        for (byte, gap, fault) in chars {
            t += gap as u64;
            let fault = fault.map(|f| [UartFault::Parity, UartFault::Framing, UartFault::Noise, UartFault::Overrun][f as usize]);
            if let Some(step) = s.receive(RxChar { byte, at_us: t, fault }) {
                if let Some(tx) = step.transmission {
                    prop_assert!(tx.earliest_start_us <= tx.latest_start_us);
                    prop_assert!(hiperface_model::checksum::is_valid(tx.frame.as_bytes()));
                }
            }
        }
        let _ = s.poll(u64::MAX);
    }
}
