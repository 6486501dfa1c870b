//! Position: read, set, set with synchronization, sensor adjustment, synchronization
//! offset, legacy 63h. // 000:T12, 000:T13, 000:T34-T36, 002:63h

use super::{always, case, code0, decoded, lacks, read_position};
use crate::slave::{Case, CaseError, Ctx};
use hiperface_model::{CommandId, Profile, Request, Response};

fn with_6a(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::SetPositionWithSync, "6Ah is optional and the profile lacks it; a profile with 6Ah runs it")
}
fn with_6b(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::SensorAdjustment, "6Bh is optional and the profile lacks it; a profile with 6Bh runs it")
}
fn with_6c(p: &Profile) -> Option<&'static str> {
    lacks(p, CommandId::ReadSyncOffset, "6Ch is optional and the profile lacks it; a profile with 6Ch runs it")
}
fn with_63(p: &Profile) -> Option<&'static str> {
    lacks(
        p,
        CommandId::SetPositionInternalSync,
        "63h exists in the legacy edition only; a legacy profile (Legacy-SRS) runs it",
    )
}

pub const READ: Case = case!("position.read", "Read Position", [READ_POSITION], Nothing, always, |c| {
    for _ in 0..3 {
        c.request(Request::ReadPosition)?;
    }
    Ok(())
});

pub const SET: Case = case!(
    "position.set",
    "Set Position at standstill to a preset other than the position, read back; errors for range and code",
    [SET_POSITION, READ_POSITION, POSITION_POLICY, READ_SYNC_OFFSET],
    Writes,
    always,
    |c| {
        let (a, code0) = (c.address(), code0(c));
        let range = c.profile().range();
        let Some(p0) = read_position(c)? else {
            return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
        };
        let phase0 = read_sync_offset(c)?.map(|s| (p0 as u64 + s as u64) % 32);
        if let Ok(r) = u32::try_from(range) {
            c.request(Request::SetPosition { preset: r, code0 })?; // outside the range: 0Dh
        }
        c.request(Request::SetPosition { preset: p0, code0: !code0 })?;
        // A preset other than the position read: a device that acknowledges and does
        // nothing reads back the old position.
        let moved = ((p0 as u64 + range / 2 + 5) % range) as u32;
        c.request(Request::SetPosition { preset: moved, code0 })?;
        let g = c.guard(a, Request::SetPosition { preset: p0, code0 });
        check_position(c, format!("Set Position {moved:08X}h"), hiperface_model::clause::SET_POSITION)?;
        let p1 = read_position(c)?;
        // 000:T36: the offset added to the position gives the sin/cos phase, which a
        // shaft at standstill keeps.
        if let (Some(phase0), Some(p1)) = (phase0, p1) {
            if let Some(s1) = read_sync_offset(c)? {
                c.check(
                    (p1 as u64 + s1 as u64) % 32 == phase0,
                    format!("Read Synchronization Offset {s1} after Set Position: position + offset is not the phase it was before ({phase0})"),
                    hiperface_model::clause::READ_SYNC_OFFSET,
                );
            }
        }
        c.request(Request::SetPosition { preset: p0, code0 })?;
        c.release(g);
        check_position(c, format!("Set Position {p0:08X}h (back)"), hiperface_model::clause::SET_POSITION)
    }
);

pub const SYNC: Case = case!(
    "position.sync",
    "Set Position with Synchronization rounds to the sin/cos phase, up and down, and reads back; restored",
    [SET_POSITION_SYNC, POSITION_POLICY, POSITION_RESOLUTION, READ_SYNC_OFFSET],
    Writes,
    with_6a,
    |c| {
        let (a, code0) = (c.address(), code0(c));
        let range = c.profile().range();
        let Some(p0) = read_position(c)? else {
            return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
        };
        let g = c.guard(a, Request::SetPosition { preset: p0, code0 });
        // 7 and 25 steps on: a phase of the preset below and above half a period, so
        // that the rounding goes down in one and up in the other (or the phases fall
        // the other way round): both in phase with the shaft, which does not move.
        let mut phases = Vec::new();
        for step in [7u64, 25] {
            let preset = ((p0 as u64 + step) % range) as u32;
            let used = used_preset(c.request(Request::SetPositionWithSync { preset, code0 })?.reply.as_deref());
            let Some(used) = used else { continue };
            phases.push(used % 32);
            let what = format!("Set Position with Synchronization (used {used:08X}h)");
            check_position(c, what, hiperface_model::clause::SET_POSITION_SYNC)?;
            if let Some(s) = read_sync_offset(c)? {
                c.check(
                    s == 0,
                    format!("Read Synchronization Offset {s} after Set Position with Synchronization: no phase shift is left"),
                    hiperface_model::clause::READ_SYNC_OFFSET,
                );
            }
        }
        if let [x, y] = phases[..] {
            c.check(
                x == y,
                format!("two presets used at standstill have different phases ({x} and {y} of 32)"),
                hiperface_model::clause::SET_POSITION_SYNC,
            );
        }
        c.request(Request::SetPosition { preset: p0, code0 })?;
        c.release(g);
        Ok(())
    }
);

/// The preset a Set Position with Synchronization reply says it used.
fn used_preset(reply: Option<&[u8]>) -> Option<u32> {
    match decoded(reply, CommandId::SetPositionWithSync) {
        Some(Response::PositionWithSyncSet(used)) => Some(used),
        _ => None,
    }
}

/// Read Position after a request that sets it: the position the model holds after that
/// request (the preset where the device took it, the old one where it refused, the
/// value it said it used), or a FAIL on `rule`. Where the position cannot be read
/// (locked, 02h) the oracle grades the reply and nothing more is checked.
fn check_position(c: &mut Ctx<'_>, after: String, rule: hiperface_model::clause::Normative) -> Result<(), CaseError> {
    let expected = c.model.position();
    let Some(p) = read_position(c)? else { return Ok(()) };
    c.check(
        u64::from(p) == expected,
        format!("Read Position after {after} gives {}, not {expected:08X}h", shown(Some(p))),
        rule,
    );
    Ok(())
}

/// A position read, or that there was none.
fn shown(p: Option<u32>) -> String {
    p.map_or("no position".into(), |p| format!("{p:08X}h"))
}

/// Read Synchronization Offset where the profile has it: the offset, `None` where the
/// profile lacks the command or the reply is none.
fn read_sync_offset(c: &mut Ctx<'_>) -> Result<Option<u8>, CaseError> {
    if !c.profile().commands.contains(CommandId::ReadSyncOffset) {
        return Ok(None);
    }
    let reply = c.request(Request::ReadSyncOffset)?.reply;
    Ok(match decoded(reply.as_deref(), CommandId::ReadSyncOffset) {
        Some(Response::SyncOffset(s)) => Some(s),
        _ => None,
    })
}

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

pub const ADJUSTMENT: Case = case!(
    "adjustment.run",
    "Sensor Adjustment with each option of the profile: the option echoed and the data sheet's status",
    [SENSOR_ADJUSTMENT],
    Adjustment,
    with_6b,
    |c| {
        let code0 = code0(c);
        let profile = c.profile();
        for o in profile.adjustment.iter().flatten() {
            c.request(Request::SensorAdjustment { option: o.option, code0 })?;
        }
        Ok(())
    }
);

pub const LEGACY_SET_POSITION_SYNC: Case = case!(
    "legacy.set-position-sync",
    "Legacy 63h at standstill: a preset other than the position, read back; restored",
    [LEGACY_SET_POSITION_SYNC],
    Writes,
    with_63,
    |c| {
        let (a, code0) = (c.address(), code0(c));
        let range = c.profile().range();
        let Some(p0) = read_position(c)? else {
            return Ok(()); // not a position (e.g. locked, 02h): the oracle graded it
        };
        c.request(Request::SetPositionInternalSync { preset: p0, code0: !code0 })?;
        let moved = ((p0 as u64 + range / 2 + 5) % range) as u32;
        c.request(Request::SetPositionInternalSync { preset: moved, code0 })?;
        let g = c.guard(a, Request::SetPositionInternalSync { preset: p0, code0 });
        check_position(c, format!("63h with preset {moved:08X}h"), hiperface_model::clause::LEGACY_SET_POSITION_SYNC)?;
        c.request(Request::SetPositionInternalSync { preset: p0, code0 })?;
        c.release(g);
        c.request(Request::ReadPosition).map(drop)
    }
);

pub const SYNC_OFFSET: Case =
    case!("position.sync-offset", "Read Synchronization Offset", [READ_SYNC_OFFSET], Nothing, with_6c, |c| {
        c.request(Request::ReadSyncOffset).map(drop)
    });
