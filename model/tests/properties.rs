//! Properties of the model's behaviour (proptest).

use hiperface_model::slave::inputs::PhysicalInputs;
use hiperface_model::{profiles, Reply, Response, ResponseFrame, Slave};
use proptest::prelude::*;

mod common;
use common::sealed;

fn response(s: &mut Slave, body: &[u8]) -> Option<ResponseFrame> {
    match s.handle_frame(&sealed(body), 0).reply {
        Reply::Frame(f) => Some(f),
        Reply::Silent(_) => None,
    }
}

/// A field size in blocks, and an offset and data that fit in it.
fn field_write() -> impl Strategy<Value = (u8, u8, Vec<u8>)> {
    (0u8..8).prop_flat_map(|blocks| {
        let size = (blocks as usize + 1) * 16;
        (1usize..=size)
            .prop_flat_map(move |len| (Just(blocks), 0..=(size - len) as u8, prop::collection::vec(any::<u8>(), len)))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// Stored data reads back unchanged. // 000:T21, 000:T22
    #[test]
    fn stored_data_reads_back((blocks, offset, data) in field_write()) {
        let mut s = Slave::operational(profiles::srm50());
        prop_assert!(response(&mut s, &[0x40, 0x4D, 0, 0xC0 | blocks, 0x55]).is_some());
        let mut store = vec![0x40, 0x4B, 0, offset, data.len() as u8, 0x55];
        store.extend(&data);
        prop_assert_eq!(response(&mut s, &store).map(|r| r.response), Some(Response::DataStored { field: 0, offset, count: data.len() as u8 }));
        match response(&mut s, &[0x40, 0x4A, 0, offset, data.len() as u8, 0x55]).map(|r| r.response) {
            Some(Response::Data { data: back, .. }) => prop_assert_eq!(back.as_bytes(), &data[..]),
            other => prop_assert!(false, "{:?}", other),
        }
    }

    /// Create and delete sequences keep memory consistent: free blocks in Memory
    /// Status always equal capacity minus the sizes in Data Field Status. // 000:T25
    #[test]
    fn create_and_delete_keep_memory_consistent(ops in prop::collection::vec((0u8..4, 0u8..8), 1..30)) {
        let mut s = Slave::operational(profiles::kuebler_s36());
        for (op, size) in ops {
            let count = s.nonvolatile().fields.count();
            match op {
                0 | 1 => { response(&mut s, &[0x40, 0x4D, count, 0xC0 | size, 0x55]); }
                2 if count > 0 => {
                    let st = s.nonvolatile().fields.status(count - 1).unwrap();
                    response(&mut s, &[0x40, 0x4D, count - 1, st.attributes(), 0x55]);
                }
                _ if count > 0 => { response(&mut s, &[0x40, 0x4D, count - 1, 0xC0 | size, 0x55]); }
                _ => {}
            }
            let (free, fields) = match response(&mut s, &[0x40, 0x4E]).map(|r| r.response) {
                Some(Response::MemoryStatus { free_blocks, fields }) => (free_blocks, fields),
                other => return Err(TestCaseError::fail(format!("{other:?}"))),
            };
            let mut used = 0u32;
            for n in 0..fields {
                match response(&mut s, &[0x40, 0x4C, n]).map(|r| r.response) {
                    Some(Response::FieldStatus { status, .. }) => used += (status & 7) as u32 + 1,
                    other => return Err(TestCaseError::fail(format!("{other:?}"))),
                }
            }
            prop_assert_eq!(free as u32 + used, 0x16);
            prop_assert_eq!(response(&mut s, &[0x40, 0x4C, fields]).map(|r| r.response), Some(Response::Error(hiperface_model::FaultCode::WrongFieldNumber)));
        }
    }

    /// Set Position then Read Position at standstill returns the preset. // 000:T13
    #[test]
    fn set_position_then_read_returns_the_preset(raw in any::<u64>(), preset in 0u32..(32768 * 4096)) {
        let mut s = Slave::operational(profiles::srm50());
        s.set_inputs(PhysicalInputs { position: raw, ..PhysicalInputs::default() });
        let p = preset.to_be_bytes();
        prop_assert!(response(&mut s, &[0x40, 0x43, p[0], p[1], p[2], p[3], 0x55]).is_some_and(|r| r.response == Response::PositionSet));
        prop_assert_eq!(response(&mut s, &[0x40, 0x42]).map(|r| r.response), Some(Response::Position(preset)));
    }

    /// A request with a corrupted checksum draws 0Ah or silence, and never changes state.
    /// // 000:T48
    #[test]
    fn a_corrupted_checksum_changes_nothing(body in prop::collection::vec(any::<u8>(), 1..20), flip in 1u8..=255) {
        let mut s = Slave::operational(profiles::reference());
        let before = s.clone();
        let mut f = sealed(&body);
        let n = f.len() - 1;
        f[n] ^= flip;
        let reply = s.handle_frame(&f, 0).reply;
        match reply {
            Reply::Silent(_) => {}
            Reply::Frame(r) => prop_assert!(matches!(r.response, Response::Error(hiperface_model::FaultCode::Checksum | hiperface_model::FaultCode::WrongLength)), "{:?}", r),
        }
        prop_assert!(s.nonvolatile() == before.nonvolatile(), "EEPROM changed");
        prop_assert_eq!(s.error_stack(), before.error_stack());
    }
}
