//! Frames as bytes: what the suite builds requests from.

use hiperface_model::checksum;

/// A request body with its checksum appended. // 000:2.3.3
pub fn sealed(body: &[u8]) -> Vec<u8> {
    let mut frame = body.to_vec();
    frame.push(checksum::xor(body));
    frame
}
