//! A HIPERFACE encoder (slave) firmware image for QEMU's `mps2-an385` board
//! (Cortex-M3, CMSDK APB UART and timers): the project's reference slave model
//! (`hiperface_model::Slave`) as its protocol engine, behind an interrupt-driven UART
//! and two hardware timers. docs/src/firmware.md says how to build, run and certify it.
//!
//! - TIMER0 runs free at 25 MHz and is the image's clock: every received character is
//!   stamped from it in the UART's receive interrupt, which the model takes as the end
//!   of the character's stop bit (000:2.2.2: "UART interrupts are generated at the end
//!   of the first received character").
//! - TIMER1 is the deadline alarm: it is armed for the model's next deadline (the
//!   character timeout that ends a request, 000:2.2.2; a power-up state change,
//!   000:T9) and for a reply's start; its interrupt polls the model and starts a
//!   reply that is due.
//! - The reply goes out from the UART's transmit interrupt, a character each.
//! - Stored settings (the model's EEPROM: address, access codes, data fields, offset,
//!   counter, stored UART settings) live in RAM: a simulated EEPROM, lost when QEMU
//!   stops (a power-off). An Encoder Reset (53h) keeps them, as 000:T29 says.
#![no_std]
#![no_main]
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod board;
mod regs;

use board::{clock_start, now_us};
use core::cell::RefCell;
use cortex_m::interrupt::{free, CriticalSection, Mutex};
use cortex_m::peripheral::NVIC;
use cortex_m_rt::entry;
use hiperface_model::{profiles, RxChar, Slave, Transmission, UartFault, UartSettings};
use regs::{uart, Irq};

/// The encoder's state: the model and what is on its way out.
struct Encoder {
    slave: Slave,
    /// A reply the model decided on, waiting for its start (000:2.2.2: not before
    /// the request's timeout has elapsed; 000:T10: within the command's maximum
    /// response time).
    pending: Option<Transmission>,
    /// The reply going out and how many of its characters are written.
    sending: Option<(Transmission, usize)>,
    /// The data rate the UART is set to, bit/s.
    baud: u32,
}

static ENCODER: Mutex<RefCell<Option<Encoder>>> = Mutex::new(RefCell::new(None));

/// The profile the harness is run with (`--profile SRS50`).
fn profile() -> hiperface_model::Profile {
    profiles::srs50()
}

#[entry]
fn main() -> ! {
    clock_start();
    free(|cs| {
        // Power-on at the clock's 0: the model goes through its power-up sequence
        // (000:T9: initialization, the default window, the stored settings).
        let mut slave = Slave::new(profile());
        slave.power_cycle(now_us(cs));
        let mut enc = Encoder { slave, pending: None, sending: None, baud: 0 };
        uart_start(&mut enc, UartSettings::DEFAULT);
        let now = now_us(cs);
        enc.service(now);
        ENCODER.borrow(cs).replace(Some(enc));
    });
    // SAFETY: the handlers only take the state inside critical sections, and the
    // state is in place before the lines are unmasked.
    unsafe {
        NVIC::unmask(Irq::Timer0);
        NVIC::unmask(Irq::Timer1);
        NVIC::unmask(Irq::Uart0Rx);
        NVIC::unmask(Irq::Uart0Tx);
    }
    loop {
        // Everything happens in the interrupts.
        cortex_m::asm::wfi();
    }
}

// ---- The alarm (TIMER1; board.rs has the clock) ----

/// How much longer than asked the alarm waits: 1 in the clean image.
const DEFECT_FACTOR: u64 = if cfg!(feature = "defect-timeout-x4") {
    4
} else if cfg!(feature = "defect-timeout-x2") {
    2
} else {
    1
};

/// Arm the alarm for `at_us`, or disarm it. The planted defect (features
/// `defect-timeout-x2`, `defect-timeout-x4`): the alarm waits twice (four times) the
/// delay, so a request's character timeout (000:2.2.2) is taken as over late and the
/// reply starts late (000:T10).
fn alarm(at_us: Option<u64>, now_us: u64) {
    let late = at_us.map(|at| now_us.saturating_add(at.saturating_sub(now_us).saturating_mul(DEFECT_FACTOR)));
    board::alarm(late, now_us);
}

// ---- The UART ----

fn uart_start(enc: &mut Encoder, settings: UartSettings) {
    uart::CTRL.write(0);
    set_baud(enc, settings);
    uart::INTSTATUS.write(uart::INT_TX | uart::INT_RX | uart::INT_RXO);
    uart::CTRL.write(uart::CTRL_TX_EN | uart::CTRL_RX_EN | uart::CTRL_TX_INTEN | uart::CTRL_RX_INTEN);
}

/// Set the data rate of `settings` (000:T28). The CMSDK UART is 8N1 only: it has no
/// parity bit to send or check, which the emulated line (a pseudo-terminal) has not
/// either (docs/src/firmware.md, "What a pseudo-terminal cannot show").
fn set_baud(enc: &mut Encoder, settings: UartSettings) {
    let baud = settings.baud.bits_per_second();
    if baud != enc.baud {
        uart::BAUDDIV.write(regs::PCLK_HZ / baud);
        enc.baud = baud;
    }
}

impl Encoder {
    /// A character came in at `at_us`.
    fn receive(&mut self, byte: u8, at_us: u64, fault: Option<UartFault>) {
        if let Some(step) = self.slave.receive(RxChar { byte, at_us, fault }) {
            self.take(step.transmission);
        }
    }

    fn take(&mut self, transmission: Option<Transmission>) {
        // A new reply replaces one not yet started: the master spoke again before
        // it was due, and the model answers the last request.
        if let Some(t) = transmission {
            self.pending = Some(t);
        }
    }

    /// Poll the model at `now`, start a reply that is due, keep the UART in the
    /// settings the model listens with, and arm the alarm for what comes next.
    fn service(&mut self, now: u64) {
        let mut now = now;
        // Bounded: after a poll the model's next deadline lies after `now`, and a due
        // reply is started, so a second round finds nothing due.
        for _ in 0..4 {
            if let Some(step) = self.slave.poll(now) {
                self.take(step.transmission);
            }
            self.start_due(now);
            if self.sending.is_none() {
                // Follow the model's listening settings (67h, 53h, the power-up
                // windows of 000:T9).
                if let Some(s) = self.slave.listening_settings(now) {
                    set_baud(self, s);
                }
            }
            match self.next_due(now) {
                Some(at) if at <= now => now = free(now_us),
                next => return alarm(next, now),
            }
        }
        alarm(self.next_due(now), now);
    }

    /// The next instant with work: the model's deadline, or a reply's start.
    fn next_due(&self, now: u64) -> Option<u64> {
        let model = self.slave.next_deadline(now);
        let reply = match self.sending {
            Some(_) => None, // the transmit interrupt starts the next one
            None => self.pending.as_ref().map(|t| t.earliest_start_us),
        };
        match (model, reply) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Start the pending reply if it is due and the line is free.
    fn start_due(&mut self, now: u64) {
        if self.sending.is_some() {
            return;
        }
        let Some(t) = self.pending.take_if(|t| t.earliest_start_us <= now) else { return };
        // Sent with the settings the request came in (000:T33: a 67h reply too).
        set_baud(self, t.settings);
        let mut written = 0;
        if let Some(&first) = t.frame.as_bytes().first() {
            uart::DATA.write(first as u32);
            written = 1;
        }
        self.sending = Some((t, written));
    }

    /// The UART has taken the last character: write the next, or finish the reply.
    fn transmitted(&mut self, now: u64) {
        let Some((t, written)) = self.sending.as_mut() else { return };
        if let Some(&next) = t.frame.as_bytes().get(*written) {
            uart::DATA.write(next as u32);
            *written += 1;
            return;
        }
        self.sending = None;
        self.service(now);
    }
}

// ---- Interrupt handlers (the vector table is in regs.rs) ----

/// Run `f` on the encoder inside a critical section with the time of entry.
fn with_encoder(f: impl FnOnce(&mut Encoder, u64, &CriticalSection)) {
    free(|cs| {
        let now = now_us(cs);
        if let Ok(mut cell) = ENCODER.borrow(cs).try_borrow_mut() {
            if let Some(enc) = cell.as_mut() {
                f(enc, now, cs);
            }
        }
    });
}

/// UART0 receive: stamp each character with the clock at once and hand it to the
/// model.
#[no_mangle]
extern "C" fn UART0_RX() {
    with_encoder(|enc, at, _| {
        // Clear the interrupt before taking the character: one arriving after it
        // raises the interrupt again.
        uart::INTSTATUS.write(uart::INT_RX | uart::INT_RXO);
        while uart::STATE.read() & uart::STATE_RXFULL != 0 {
            let state = uart::STATE.read();
            // An overrun lost a character: reported as a UART fault, 09h (000:T47).
            let fault = (state & uart::STATE_RXOVERRUN != 0).then_some(UartFault::Overrun);
            if fault.is_some() {
                uart::STATE.write(uart::STATE_RXOVERRUN);
            }
            let byte = uart::DATA.read() as u8;
            enc.receive(byte, at, fault);
        }
        enc.service(at);
    });
}

/// UART0 transmit: the last character is out.
#[no_mangle]
extern "C" fn UART0_TX() {
    with_encoder(|enc, now, _| {
        uart::INTSTATUS.write(uart::INT_TX);
        if uart::STATE.read() & uart::STATE_TXFULL == 0 {
            enc.transmitted(now);
        }
    });
}

/// TIMER1: a deadline is due.
#[no_mangle]
extern "C" fn TIMER1() {
    with_encoder(|enc, now, _| {
        board::alarm_off();
        enc.service(now);
    });
}
