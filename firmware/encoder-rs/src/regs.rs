//! The few registers this image uses, for QEMU's `mps2-an385` board: no maintained
//! peripheral access crate exists for the AN385 (or for the CMSDK peripherals), so
//! they are defined here, in one place.
//!
//! Sources: ARM Cortex-M System Design Kit Technical Reference Manual (DDI0479C),
//! "APB UART" and "APB timer"; ARM Application Note 385 (MPS2 with Cortex-M3),
//! memory map and interrupt map; and QEMU 7.2's models of them, which are what this
//! image runs on: hw/arm/mps2.c (addresses, interrupt numbers, the 25 MHz SYSCLK),
//! hw/char/cmsdk-apb-uart.c and hw/timer/cmsdk-apb-timer.c (register behaviour).

use core::ptr::{read_volatile, write_volatile};

/// The APB peripherals' clock (PCLK = SYSCLK on the AN385): 25 MHz. // mps2.c SYSCLK_FRQ
pub const PCLK_HZ: u32 = 25_000_000;
/// Timer ticks per µs at PCLK.
pub const TICKS_PER_US: u64 = (PCLK_HZ / 1_000_000) as u64;

/// One 32-bit memory-mapped register.
#[derive(Clone, Copy)]
pub struct Reg(usize);

impl Reg {
    pub fn read(self) -> u32 {
        // SAFETY: the address is one of the device registers below, 4-aligned and
        // always mapped on this board; a volatile read has no other effect than the
        // device's own (reading UART DATA takes the character, as intended).
        unsafe { read_volatile(self.0 as *const u32) }
    }

    pub fn write(self, value: u32) {
        // SAFETY: as for `read`; these registers hold no Rust data.
        unsafe { write_volatile(self.0 as *mut u32, value) }
    }
}

/// CMSDK APB UART. UART0 at 0x4000_4000 is QEMU's first serial port (`-serial pty`).
pub mod uart {
    use super::Reg;

    const BASE: usize = 0x4000_4000;
    /// Write: the character to send. Read: the character received (clears RXFULL).
    pub const DATA: Reg = Reg(BASE);
    /// Bit 0 TX buffer full, bit 1 RX buffer full, bit 2 TX overrun, bit 3 RX overrun
    /// (the overrun bits are write-1-to-clear).
    pub const STATE: Reg = Reg(BASE + 0x04);
    /// Bit 0 TX enable, 1 RX enable, 2 TX interrupt enable, 3 RX interrupt enable,
    /// 4 TX overrun interrupt enable, 5 RX overrun interrupt enable.
    pub const CTRL: Reg = Reg(BASE + 0x08);
    /// Bit 0 TX, 1 RX, 2 TX overrun, 3 RX overrun; write 1 to clear.
    pub const INTSTATUS: Reg = Reg(BASE + 0x0C);
    /// PCLK / baud; at least 16 (QEMU ignores smaller values).
    pub const BAUDDIV: Reg = Reg(BASE + 0x10);

    pub const STATE_TXFULL: u32 = 1 << 0;
    pub const STATE_RXFULL: u32 = 1 << 1;
    pub const STATE_RXOVERRUN: u32 = 1 << 3;
    pub const CTRL_TX_EN: u32 = 1 << 0;
    pub const CTRL_RX_EN: u32 = 1 << 1;
    pub const CTRL_TX_INTEN: u32 = 1 << 2;
    pub const CTRL_RX_INTEN: u32 = 1 << 3;
    pub const INT_TX: u32 = 1 << 0;
    pub const INT_RX: u32 = 1 << 1;
    pub const INT_RXO: u32 = 1 << 3;
}

/// CMSDK APB timer: a 32-bit down-counter at PCLK that reloads from RELOAD and
/// raises its interrupt as it goes from 1 to 0. TIMER0 at 0x4000_0000, TIMER1 at
/// 0x4000_1000.
#[derive(Clone, Copy)]
pub struct Timer(usize);

/// TIMER0: the free-running clock.
pub const CLOCK_TIMER: Timer = Timer(0x4000_0000);
/// TIMER1: the deadline alarm.
pub const ALARM_TIMER: Timer = Timer(0x4000_1000);

impl Timer {
    /// Bit 0 enable, bit 3 interrupt enable.
    pub const fn ctrl(self) -> Reg {
        Reg(self.0)
    }
    /// The current count; writing it sets the count.
    pub const fn value(self) -> Reg {
        Reg(self.0 + 0x04)
    }
    /// The reload value; writing it sets the count too.
    pub const fn reload(self) -> Reg {
        Reg(self.0 + 0x08)
    }
    /// Bit 0: the interrupt is pending; write 1 to clear.
    pub const fn intstatus(self) -> Reg {
        Reg(self.0 + 0x0C)
    }
}

pub const TIMER_EN: u32 = 1 << 0;
pub const TIMER_IRQEN: u32 = 1 << 3;

/// The AN385's interrupt lines this image uses (mps2.c: UART0 RX 0, TX 1; TIMER0 8,
/// TIMER1 9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u16)]
pub enum Irq {
    Uart0Rx = 0,
    Uart0Tx = 1,
    Timer0 = 8,
    Timer1 = 9,
}

// SAFETY: each number is a valid external interrupt line of the AN385's NVIC.
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        self as u16
    }
}

/// One entry of the vector table: a handler or a reserved word.
pub union Vector {
    handler: unsafe extern "C" fn(),
    reserved: usize,
}

extern "C" {
    fn UART0_RX();
    fn UART0_TX();
    fn TIMER0();
    fn TIMER1();
    fn DefaultHandler();
}

/// The external interrupt vectors (cortex-m-rt places them after its own 16 with the
/// `device` feature). Lines this image does not use go to cortex-m-rt's default
/// handler; the four it uses are `#[no_mangle]` functions in main.rs.
#[link_section = ".vector_table.interrupts"]
#[no_mangle]
// Evaluated at compile time: an index out of range fails the build, it cannot panic.
#[allow(clippy::indexing_slicing)]
pub static __INTERRUPTS: [Vector; 32] = {
    let mut v = [const { Vector { reserved: 0 } }; 32];
    let mut i = 0;
    while i < 32 {
        v[i] = Vector { handler: DefaultHandler };
        i += 1;
    }
    v[0] = Vector { handler: UART0_RX };
    v[1] = Vector { handler: UART0_TX };
    v[8] = Vector { handler: TIMER0 };
    v[9] = Vector { handler: TIMER1 };
    v
};
