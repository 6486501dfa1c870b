//! Position: read, set, set with synchronization, sensor adjustment, synchronization
//! offset, legacy 63h. // 000:T12, 000:T13, 000:T34-T36, 002:63h

use super::{always, case, code0, lacks, read_position};
use crate::slave::Case;
use hiperface_model::{CommandId, Profile, Request};

fn with_6a(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::SetPositionWithSync, "6Ah is optional and the profile lacks it")
}
fn with_6b(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::SensorAdjustment, "6Bh is optional and the profile lacks it")
}
fn with_6c(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::ReadSyncOffset, "6Ch is optional and the profile lacks it")
}
fn with_63(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::SetPositionInternalSync, "63h exists in the legacy edition only")
}

pub const READ: Case = case!("position.read", "Read Position", [READ_POSITION], Nothing, always, |c| {
    for _ in 0..3 {
        c.request(Request::ReadPosition)?;
    }
    Ok(())
});

pub const SET: Case = case!(
    "position.set",
    "Set Position at standstill, then Read Position; errors for range and code",
    [SET_POSITION, READ_POSITION, POSITION_POLICY],
    Writes,
    always,
    |c| {
        let code0 = code0(c);
        let range = c.profile().range();
        let Some(p0) = read_position(c)? else {
            return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
        };
        if let Ok(r) = u32::try_from(range) {
            c.request(Request::SetPosition { preset: r, code0 })?; // outside the range: 0Dh
        }
        c.request(Request::SetPosition { preset: p0, code0: !code0 })?;
        // Setting the position it reads keeps the offset: a real write, nothing changed.
        c.request(Request::SetPosition { preset: p0, code0 })?;
        let p1 = read_position(c)?;
        c.check(
            p1 == Some(p0),
            "Read Position after Set Position differs from the preset",
            hiperface_model::clause::SET_POSITION,
        );
        Ok(())
    }
);

pub const SYNC: Case = case!(
    "position.sync",
    "Set Position with Synchronization keeps the phase; restored",
    [SET_POSITION_SYNC, POSITION_POLICY, POSITION_RESOLUTION],
    Writes,
    with_6a,
    |c| {
        let (a, code0) = (c.address(), code0(c));
        let Some(p0) = read_position(c)? else {
            return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
        };
        let shifted = ((p0 as u64 + 7) % c.profile().range()) as u32;
        c.request(Request::SetPositionWithSync { preset: shifted, code0 })?;
        let g = c.guard(a, Request::SetPosition { preset: p0, code0 });
        c.request(Request::SetPosition { preset: p0, code0 })?;
        c.release(g);
        Ok(())
    }
);

pub const ADJUSTMENT_ERRORS: Case = case!(
    "adjustment.errors",
    "Sensor Adjustment refuses unknown options and wrong codes",
    [SENSOR_ADJUSTMENT],
    Writes,
    with_6b,
    |c| {
        let code0 = code0(c);
        let profile = c.profile();
        let unknown = (0u8..=0xFF).find(|o| profile.adjustment_option(*o).is_none()).unwrap_or(0xFF);
        c.request(Request::SensorAdjustment { option: unknown, code0 })?;
        // Only error paths: a real adjustment may change the device's calibration.
        let known = profile.adjustment.iter().flatten().next().map_or(0, |o| o.option);
        c.request(Request::SensorAdjustment { option: known, code0: !code0 }).map(drop)
    }
);

pub const LEGACY_SET_POSITION_SYNC: Case = case!(
    "legacy.set-position-sync",
    "Legacy 63h at standstill keeps the position it is given",
    [LEGACY_SET_POSITION_SYNC],
    Writes,
    with_63,
    |c| {
        let code0 = code0(c);
        let Some(p0) = read_position(c)? else {
            return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
        };
        c.request(Request::SetPositionInternalSync { preset: p0, code0: !code0 })?;
        c.request(Request::SetPositionInternalSync { preset: p0, code0 })?;
        c.request(Request::ReadPosition).map(drop)
    }
);

pub const SYNC_OFFSET: Case =
    case!("position.sync-offset", "Read Synchronization Offset", [READ_SYNC_OFFSET], Nothing, with_6c, |c| {
        c.request(Request::ReadSyncOffset).map(drop)
    });
