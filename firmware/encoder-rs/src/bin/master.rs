//! A HIPERFACE drive master firmware image for QEMU's `mps2-an385` board: the
//! project's reference master (`hiperface_model::master::reference`: the start-up flow
//! of 000:3.3.1, cyclic Read Position, the warning's codes read out, the fault
//! reaction of Table 74) behind the same interrupt-driven UART and timers as the
//! encoder image (src/main.rs). Its decisions are the model's; this image only does
//! what they say on the line, as `hiperface master --port` does on a host.
//!
//! - TIMER0 runs free at 25 MHz and is the clock; each received character is stamped
//!   from it in the receive interrupt (the end of its stop bit, 000:2.2.2).
//! - TIMER1 is the alarm: a wait's end, the line free for a request (a pause of the
//!   timeout after the last character either way, 000:2.2.2), a reply's end (the
//!   timeout after its last character) and the end of a reply's window.
//! - A request goes out from the transmit interrupt, a character each.
//!
//! `certify master --exec` starts it once per scenario with the harness's
//! pseudo-terminal as its UART (`qemu-system-arm ... -serial {port}`): a power-on of
//! the drive each time (docs/src/firmware.md, "The master image").
#![no_std]
#![no_main]
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

#[path = "../board.rs"]
mod board;
#[path = "../regs.rs"]
mod regs;

use board::{alarm, alarm_off, clock_start, now_us};
use core::cell::RefCell;
use cortex_m::interrupt::{free, CriticalSection, Mutex};
use cortex_m::peripheral::NVIC;
use cortex_m_rt::entry;
use hiperface_model::frame::Frame;
use hiperface_model::master::reference::{Action, Done, Options, ReferenceMaster};
use hiperface_model::{profiles, UartSettings};
use regs::{uart, Irq};

/// The line's settings: the encoder's default (000:T4); the reference master never
/// changes them.
const SETTINGS: UartSettings = UartSettings::DEFAULT;

/// The planted defect (feature `defect-master-short-pause`): the master takes a
/// transmission for ended, and the line for free, two character times after its last
/// character instead of the timeout (000:2.2.2), so its requests follow the encoder's
/// replies too soon.
const SHORT_PAUSE: bool = cfg!(feature = "defect-master-short-pause");

/// Where the drive is in its exchange with the encoder.
enum State {
    /// Waiting until the model's instant.
    Waiting { until_us: u64 },
    /// A request to send once the line is free.
    Ready { request: Frame, listen_ms: u16 },
    /// A request going out: how many of its characters are written.
    Sending { request: Frame, written: usize, listen_ms: u16 },
    /// Listening for the reply: the request's end, the window's end, what came.
    Listening { request_end_us: u64, window_end_us: u64, reply: Frame },
    /// The model is done.
    Stopped,
}

struct Drive {
    machine: ReferenceMaster,
    state: State,
    /// The end of the last character on the line, either way: the next request waits
    /// the timeout after it (000:2.2.2).
    idle_since_us: u64,
    timeout_us: u64,
    char_us: u64,
}

static DRIVE: Mutex<RefCell<Option<Drive>>> = Mutex::new(RefCell::new(None));

#[entry]
fn main() -> ! {
    clock_start();
    free(|cs| {
        let profile = profiles::srs50();
        let options = Options { polling_period_ms: 20, duration_ms: None };
        let mut machine = ReferenceMaster::new(profile, options);
        let first = machine.power_on();
        let mut drive = Drive {
            machine,
            state: State::Stopped,
            idle_since_us: 0,
            timeout_us: if SHORT_PAUSE { 2 * SETTINGS.char_time_us() } else { SETTINGS.timeout_us(profile.edition) },
            char_us: SETTINGS.char_time_us(),
        };
        uart::CTRL.write(0);
        uart::BAUDDIV.write(regs::PCLK_HZ / SETTINGS.baud.bits_per_second());
        uart::INTSTATUS.write(uart::INT_TX | uart::INT_RX | uart::INT_RXO);
        uart::CTRL.write(uart::CTRL_TX_EN | uart::CTRL_RX_EN | uart::CTRL_TX_INTEN | uart::CTRL_RX_INTEN);
        let now = now_us(cs);
        drive.act(first, now, cs);
        DRIVE.borrow(cs).replace(Some(drive));
    });
    // SAFETY: the handlers only take the state inside critical sections, and it is in
    // place before the lines are unmasked.
    unsafe {
        NVIC::unmask(Irq::Timer0);
        NVIC::unmask(Irq::Timer1);
        NVIC::unmask(Irq::Uart0Rx);
        NVIC::unmask(Irq::Uart0Tx);
    }
    loop {
        cortex_m::asm::wfi();
    }
}

impl Drive {
    /// Do what the model says.
    fn act(&mut self, action: Action, now: u64, cs: &CriticalSection) {
        self.state = match action {
            Action::Stop => State::Stopped,
            Action::WaitUntil(until_us) => State::Waiting { until_us },
            Action::Exchange { request, listen_ms } => State::Ready { request: request.encode(), listen_ms },
        };
        self.service(now, cs);
    }

    /// Move on where time allows, and arm the alarm for what comes next.
    fn service(&mut self, now: u64, cs: &CriticalSection) {
        match &mut self.state {
            State::Waiting { until_us } if *until_us <= now => {
                let action = self.machine.next(Done::Waited { now_us: now }, &mut |_| {});
                self.act(action, now_us(cs), cs)
            }
            State::Waiting { until_us } => alarm(Some(*until_us), now),
            // 000:2.2.2: a transmission ends with a pause of the timeout; the request
            // waits for it after whatever was last on the line.
            State::Ready { request, listen_ms } => {
                let free_at = self.idle_since_us + self.timeout_us;
                if now < free_at {
                    return alarm(Some(free_at), now);
                }
                let (request, listen_ms) = (*request, *listen_ms);
                let mut written = 0;
                if let Some(&first) = request.as_bytes().first() {
                    uart::DATA.write(first as u32);
                    written = 1;
                }
                self.state = State::Sending { request, written, listen_ms };
            }
            State::Sending { .. } | State::Stopped => {}
            State::Listening { request_end_us, window_end_us, reply } => {
                // A reply ends the timeout after its last character; nothing in the
                // window is no reply.
                let due = match reply.as_bytes() {
                    [] => *window_end_us,
                    _ => self.idle_since_us + self.timeout_us,
                };
                if now < due {
                    return alarm(Some(due), now);
                }
                let (request_end_us, reply) = (*request_end_us, *reply);
                let done = Done::Exchanged {
                    now_us: now,
                    request_end_us,
                    timeout_us: self.timeout_us,
                    reply: reply.as_bytes(),
                };
                let action = self.machine.next(done, &mut |_| {});
                self.act(action, now_us(cs), cs)
            }
        }
    }

    /// A character from the encoder at `at`.
    fn received(&mut self, byte: u8, at: u64) {
        // The line is free a timeout after its last character either way (000:2.2.2):
        // a character heard while the request still goes out (its end is reckoned a
        // character time ahead) does not move that back.
        self.idle_since_us = self.idle_since_us.max(at);
        if let State::Listening { reply, .. } = &mut self.state {
            // A reply longer than any frame is cut: what fits is graded by the model.
            let _ = reply.push(byte);
        }
    }

    /// The UART took the last character written: write the next, or listen.
    fn transmitted(&mut self, now: u64, cs: &CriticalSection) {
        let State::Sending { request, written, listen_ms } = &mut self.state else { return };
        if let Some(&next) = request.as_bytes().get(*written) {
            uart::DATA.write(next as u32);
            *written += 1;
            return;
        }
        // The last character leaves the transmit register now and ends a character
        // time later on a real line. A reply may start the timeout after it, and its
        // first character is complete a character time after that.
        let request_end_us = now + self.char_us;
        let window_end_us = request_end_us + self.timeout_us + u64::from(*listen_ms) * 1000 + self.char_us;
        self.idle_since_us = request_end_us;
        self.state = State::Listening { request_end_us, window_end_us, reply: Frame::new() };
        self.service(now, cs);
    }
}

/// Run `f` on the drive inside a critical section with the time of entry.
fn with_drive(f: impl FnOnce(&mut Drive, u64, &CriticalSection)) {
    free(|cs| {
        let now = now_us(cs);
        if let Ok(mut cell) = DRIVE.borrow(cs).try_borrow_mut() {
            if let Some(drive) = cell.as_mut() {
                f(drive, now, cs);
            }
        }
    });
}

#[no_mangle]
extern "C" fn UART0_RX() {
    with_drive(|drive, at, cs| {
        uart::INTSTATUS.write(uart::INT_RX | uart::INT_RXO);
        while uart::STATE.read() & uart::STATE_RXFULL != 0 {
            if uart::STATE.read() & uart::STATE_RXOVERRUN != 0 {
                uart::STATE.write(uart::STATE_RXOVERRUN);
            }
            let byte = uart::DATA.read() as u8;
            drive.received(byte, at);
        }
        drive.service(at, cs);
    });
}

#[no_mangle]
extern "C" fn UART0_TX() {
    with_drive(|drive, now, cs| {
        uart::INTSTATUS.write(uart::INT_TX);
        if uart::STATE.read() & uart::STATE_TXFULL == 0 {
            drive.transmitted(now, cs);
        }
    });
}

#[no_mangle]
extern "C" fn TIMER1() {
    with_drive(|drive, now, cs| {
        alarm_off();
        drive.service(now, cs);
    });
}
