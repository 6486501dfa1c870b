//! What both images (the encoder, src/main.rs, and the master, src/bin/master.rs) do
//! with the board besides their UART: the clock (TIMER0 and its wraps), the alarm
//! (TIMER1), and falling silent on a panic.

use crate::regs::{ALARM_TIMER, CLOCK_TIMER, TICKS_PER_US, TIMER_EN, TIMER_IRQEN};
use core::cell::Cell;
use core::panic::PanicInfo;
use cortex_m::interrupt::{free, CriticalSection, Mutex};

/// TIMER0's wraps (2^32 ticks each, 171.8 s at 25 MHz): the clock's upper bits.
static WRAPS: Mutex<Cell<u32>> = Mutex::new(Cell::new(0));

/// Start the clock (TIMER0 running free) with the alarm (TIMER1) off.
pub fn clock_start() {
    CLOCK_TIMER.ctrl().write(0);
    // Writing RELOAD sets the count too; the counter wraps every 2^32 ticks.
    CLOCK_TIMER.reload().write(u32::MAX);
    CLOCK_TIMER.intstatus().write(1);
    CLOCK_TIMER.ctrl().write(TIMER_EN | TIMER_IRQEN);
    alarm_off();
}

/// The time since boot in µs, from TIMER0 and its wraps. Inside a critical section
/// the wrap interrupt cannot run: a wrap it has not counted yet shows as its pending
/// bit, read on both sides of the count so that count and wrap agree.
pub fn now_us(cs: &CriticalSection) -> u64 {
    let wraps = WRAPS.borrow(cs).get() as u64;
    let (pending, value) = loop {
        let before = CLOCK_TIMER.intstatus().read() & 1;
        let value = CLOCK_TIMER.value().read();
        let after = CLOCK_TIMER.intstatus().read() & 1;
        if before == after {
            break (before as u64, value);
        }
    };
    // A down-counter: the ticks into this period are 2^32 - value (0 just as it wraps).
    let ticks = ((wraps + pending) << 32) + 0u32.wrapping_sub(value) as u64;
    ticks / TICKS_PER_US
}

/// Stop TIMER1 and clear its interrupt.
pub fn alarm_off() {
    ALARM_TIMER.ctrl().write(0);
    ALARM_TIMER.intstatus().write(1);
}

/// Arm TIMER1 to interrupt at `at_us` (a clock reading), or disarm it.
pub fn alarm(at_us: Option<u64>, now_us: u64) {
    alarm_off();
    let Some(at) = at_us else { return };
    // Rounded up to a tick so that the alarm never comes before the deadline; a
    // deadline beyond one count (171 s) interrupts early and is armed again.
    let ticks = at.saturating_sub(now_us).saturating_mul(TICKS_PER_US).clamp(1, u32::MAX as u64) as u32;
    // Writing RELOAD sets the count too.
    ALARM_TIMER.reload().write(ticks);
    ALARM_TIMER.ctrl().write(TIMER_EN | TIMER_IRQEN);
}

/// TIMER0 wrapped: count it (the clock's upper bits).
#[no_mangle]
extern "C" fn TIMER0() {
    free(|cs| {
        CLOCK_TIMER.intstatus().write(1);
        let w = WRAPS.borrow(cs);
        w.set(w.get().wrapping_add(1));
    });
}

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    // Nothing in either image panics on what it receives (the model denies panics);
    // were it to, the device falls silent, as a watchdog-less one would, and the
    // harness reports a silent device.
    cortex_m::interrupt::disable();
    loop {
        cortex_m::asm::wfi();
    }
}
