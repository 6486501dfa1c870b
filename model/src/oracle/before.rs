//! What the oracle reads of the model's state before a request: the device's profile,
//! how the slave listens at the instant the request is processed, whether that instant
//! falls within its power-up windows, and, for a Read Data request, what the model
//! knows of each byte it reads. A few hundred bytes taken from the slave before it
//! handles the request, so that a caller grading every exchange of a capture does not
//! copy the whole model (its 4 080 bytes of field memory) for each one.

use crate::command::CommandId;
use crate::frame::MAX_FIELD_BYTES;
use crate::profile::Profile;
use crate::request::{Request, RequestFrame};
use crate::slave::fields::Contents;
use crate::slave::Slave;

/// The slave's state before a request, as far as the oracle reads it.
#[derive(Debug, Clone, Copy)]
pub struct Before {
    profile: Profile,
    /// The settings byte the slave listens with at the request's instant (000:T28).
    active: Option<u8>,
    within_power_up: bool,
    /// A Read Data request's field and offset, and what the model knew of each byte
    /// it reads (`None` past the field's end).
    read: Option<ReadBytes>,
}

#[derive(Debug, Clone, Copy)]
struct ReadBytes {
    field: u8,
    offset: u8,
    contents: [Option<Contents>; MAX_FIELD_BYTES],
}

impl Before {
    /// What the oracle will read of `slave` for `request` processed at `at_us`; taken
    /// before the slave handles it.
    pub fn of(slave: &Slave, request: &[u8], at_us: u64) -> Before {
        // Only a Read Data request is decoded: the oracle reads no other request's bytes.
        let read_data = CommandId::of_frame(request) == CommandId::ReadData;
        let read = match read_data.then(|| RequestFrame::decode(request).map(|r| r.request)) {
            Some(Ok(Request::ReadData { field, offset, count, .. })) => {
                let fields = &slave.nonvolatile().fields;
                let mut contents = [None; MAX_FIELD_BYTES];
                for (i, c) in contents.iter_mut().enumerate().take(usize::from(count)) {
                    *c = fields.contents(field, usize::from(offset) + i);
                }
                Some(ReadBytes { field, offset, contents })
            }
            _ => None,
        };
        Before {
            profile: *slave.profile(),
            active: slave.listening_settings(at_us).map(|s| s.byte()),
            within_power_up: within_power_up(slave, at_us),
            read,
        }
    }

    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    /// The settings byte the slave listened with.
    pub fn active_settings(&self) -> Option<u8> {
        self.active
    }

    /// Whether the request came within the power-up windows (000:T9).
    pub fn within_power_up(&self) -> bool {
        self.within_power_up
    }

    /// What the model knew of byte `offset + i` of `field`, where the request read it.
    pub fn read_contents(&self, field: u8, offset: u8, i: usize) -> Option<Contents> {
        let r = self.read.as_ref().filter(|r| (r.field, r.offset) == (field, offset))?;
        r.contents.get(i).copied().flatten()
    }
}

/// Whether `at_us` falls within the power-up windows of the slave's last power-on or
/// reset (000:T9: until the switch to the stored settings, and a little past it,
/// where a slave's clock and a master's may differ).
fn within_power_up(slave: &Slave, at_us: u64) -> bool {
    const PAST_THE_SWITCH_US: u64 = 100_000;
    let windows_us = u64::from(slave.profile().user_settings_ms) * 1000 + PAST_THE_SWITCH_US;
    slave.power_up().since_us.is_some_and(|since| at_us < since.saturating_add(windows_us))
}
