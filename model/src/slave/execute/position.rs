//! Position commands: the position group's state checks, Set Position and its
//! synchronised variants. // 000:T12, 000:T13, 000:T34, 000:T37 position group

use super::{Checks, Slave};
use crate::clause;
use crate::command::CommandId;
use crate::fault::FaultCode::*;
impl Slave {
    /// The state checks of position commands. // 000:2.3.4, 000:T12, 000:T37 position group
    pub(super) fn position_faults(&mut self, c: &mut Checks, reading: bool) -> Result<(), ()> {
        // A request already rejected (argument, access code) measures nothing: its
        // faults are only recorded as acceptable alternatives.
        let measured = c.first.is_none();
        c.check(self.locks.position, AngularOffset, clause::POSITION_LOCK);
        let linear = self.profile.resolution.is_linear();
        let mut newly_locked = false;
        for (fault, injected) in self.injected.position_faults() {
            if !injected {
                continue;
            }
            let answered = c.first.is_none();
            c.check(true, fault.code(), clause::POSITION_FAULTS);
            if measured && !answered {
                // "the first one is sent and the other error messages are stored"
                self.stack.push(fault.code());
            }
            newly_locked |= measured && fault.locks(linear);
        }
        c.check(self.inputs.led_current_ma > self.profile.led_current_max_ma, LedCurrent, clause::LED_CURRENT);
        let moving = if reading {
            self.inputs.speed.unsigned_abs() > self.profile.max_read_speed
        } else {
            // 000:T60: shaft motion during Set Position.
            self.inputs.speed != 0
        };
        c.check(moving, Speed, clause::SPEED);
        self.locks.position |= newly_locked;
        if c.first.is_some() {
            Err(())
        } else {
            Ok(())
        }
    }

    /// Set Position (43h, 63h) and Set Position with Synchronization (6Ah). Returns
    /// the preset actually used. // 000:T13, 000:T34, DESIGN:position
    pub(super) fn set_position(
        &mut self,
        c: &mut Checks,
        command: CommandId,
        preset: u32,
        code0: u8,
    ) -> Result<u64, ()> {
        let synchronize = command == CommandId::SetPositionWithSync;
        let range = self.profile.range();
        c.check(preset as u64 >= range, WrongArgument, clause::SET_POSITION);
        c.check(self.code0_wrong(code0), WrongAccessCode, clause::WRONG_ACCESS_CODE);
        // 000:T40: a locked position output answers 02h to Set Position, before any
        // memory fault.
        let _ = self.position_faults(c, false);
        self.memory_checks(c, command);
        if c.first.is_some() {
            return Err(());
        }
        let raw = self.inputs.position % range;
        let used = if synchronize { synchronized_preset(preset as u64, raw, range) } else { preset as u64 };
        self.nv.offset = (used + range - raw) % range;
        self.count_write();
        Ok(used)
    }
}

/// 6Ah: the value nearest to `preset` with the same 5 LSBs as the raw position (zero
/// phase shift), ties downward, modulo the range (a multiple of 32). // DESIGN:position
pub fn synchronized_preset(preset: u64, raw: u64, range: u64) -> u64 {
    let d = preset.wrapping_sub(raw) & 31;
    let candidate = if d <= 16 { preset + range - d } else { preset + (32 - d) };
    candidate % range
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    pub(super) fn synchronized_preset_keeps_the_raw_phase() {
        // 001:5.1.4: preset 0005D2C7h answered with 0005D2C1h.
        assert_eq!(synchronized_preset(0x0005_D2C7, 1, 1 << 20), 0x0005_D2C1);
        assert_eq!(synchronized_preset(16, 0, 1 << 20), 0, "ties downward");
        assert_eq!(synchronized_preset(17, 0, 1 << 20), 32);
        assert_eq!(synchronized_preset((1 << 20) - 1, 0, 1 << 20), 0, "wraps");
        assert_eq!(synchronized_preset(3, 5, 512), 5);
        assert_eq!(synchronized_preset(2, 30, 512), 510);
        for preset in 0..512 {
            for raw in [0u64, 1, 17, 31, 100] {
                let used = synchronized_preset(preset, raw, 512);
                assert_eq!(used % 32, raw % 32);
                let dist = (used + 512 - preset) % 512;
                assert!(dist <= 15 || 512 - dist <= 16, "{preset} {raw} {used}");
            }
        }
    }
}
