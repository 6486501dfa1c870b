//! The codecs and the data link: decoders total and round-tripping, command bytes,
//! well-formed requests of every command, the data link's framing.

use super::{exhaust, sample};
use crate::targets;
use hiperface_model::command::CommandByte;
use hiperface_model::RequestFrame;
use proptest::prelude::*;

/// Decoding never panics, and what decodes re-encodes to the same bytes.
pub fn request_decoder_is_total(frame: &[u8]) -> bool {
    match RequestFrame::decode(frame) {
        Ok(r) => r.encode().as_bytes() == frame,
        Err(_) => true,
    }
}

pub fn decoders_are_total(data: &[u8]) -> bool {
    targets::decode(data);
    true
}

pub fn command_byte_round_trips(b: u8) -> bool {
    match CommandByte::decode(b) {
        Some(c) => c.byte() == b,
        None => b & 0x40 == 0,
    }
}

/// The data link never merges characters a timeout apart, loses none, never panics.
pub fn datalink_frames(timeout: u16, chars: &[(u8, u16)]) -> bool {
    targets::datalink_of(timeout, chars.iter().map(|(b, g)| (*b, *g, None)));
    true
}

/// The longest request frame: Store Data with 128 data bytes after its 4 header
/// bytes, with address, command and checksum. // 000:T22
pub const MAX_REQUEST: usize = 2 + 132 + 1;

/// Store Data's row of the command table.
pub const STORE_DATA_ROW: u8 = {
    let table = hiperface_model::COMMAND_TABLE;
    let mut row = 0;
    while row < table.len() && table[row].id.byte() != hiperface_model::CommandId::StoreData.byte() {
        row += 1;
    }
    row as u8
};

/// A well-formed request decodes as its command and encodes back to the same bytes.
/// The command is row `row` of the command table (modulo its length); its data bytes
/// are the first of `data` (as many as the command takes; Store Data takes all of
/// `data`, 5 to 132 bytes, and its count byte is set to match). Allocation-free, so
/// that Kani checks this same function.
pub fn request_round_trips(row: u8, data: &[u8]) -> bool {
    use hiperface_model::command::DataLength;
    let table = hiperface_model::COMMAND_TABLE;
    let Some(spec) = table.get(row as usize % table.len()) else {
        return false;
    };
    let n = match spec.master_data {
        DataLength::Fixed(n) => n as usize,
        DataLength::Range { .. } => data.len(),
        DataLength::NoFrame => 0,
    };
    let mut frame = [0u8; MAX_REQUEST];
    let (Some(d), true) = (data.get(..n), spec.master_data.accepts(n)) else {
        return false; // outside the domain: the caller gave too few bytes
    };
    frame[0] = 0x40;
    frame[1] = spec.id.byte();
    let Some(slot) = frame.get_mut(2..2 + n) else { return false };
    slot.copy_from_slice(d);
    if spec.id == hiperface_model::CommandId::StoreData {
        frame[4] = (n - 4) as u8; // 000:T22: the count byte matches the data bytes
    }
    frame[2 + n] = hiperface_model::checksum::xor(&frame[..2 + n]);
    let body = &frame[..3 + n];
    match RequestFrame::decode(body) {
        Ok(r) => r.request.command() == spec.id && r.encode().as_bytes() == body,
        Err(_) => false,
    }
}

/// Every frame of 0 to 3 bytes, exhaustively, and `samples` frames of 4 to `max` bytes.
pub(super) fn short_exhaustive_then_sampled(
    max: usize,
    samples: u32,
    prop: impl Fn(&[u8]) -> bool,
) -> Result<u64, String> {
    let short = (0..=0xFFu32).map(|a| vec![a as u8]).chain((0..=0xFFFFu32).map(|x| vec![(x >> 8) as u8, x as u8]));
    let three = (0..=0xFF_FFFFu32).map(|x| vec![(x >> 16) as u8, (x >> 8) as u8, x as u8]);
    let n = 1 + exhaust(short.chain(three), |f| prop(f))?;
    Ok(n + sample(prop::collection::vec(any::<u8>(), 4..=max), samples, |f| prop(f))?)
}
