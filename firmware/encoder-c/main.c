/* A HIPERFACE encoder (slave) firmware image in C for QEMU's mps2-an385 board
 * (Cortex-M3): the project's reference slave model, linked as the C library
 * libhiperface.a built for the target without `std`, behind an interrupt-driven UART
 * and two hardware timers. The same design as the Rust image (firmware/encoder-rs),
 * in the toolchain a C team uses (arm-none-eabi-gcc); docs/src/firmware.md.
 *
 * - TIMER0 runs free at 25 MHz and is the image's clock: each received character is
 *   stamped from it in the UART's receive interrupt, which the model takes as the end
 *   of the character's stop bit (000:2.2.2).
 * - TIMER1 is the deadline alarm, armed for the model's next deadline (a request's
 *   character timeout, 000:2.2.2; a power-up state change, 000:T9) and for a reply's
 *   start; its interrupt polls the model and starts a reply that is due.
 * - The reply goes out from the UART's transmit interrupt, a character each.
 * - The model's stored settings live in RAM: a simulated EEPROM, lost when QEMU stops.
 * - Every interrupt has the same priority, so none preempts another and the model is
 *   only ever touched by one of them at a time; main only sleeps.
 *
 * Planted defects, each a compile-time switch (make DEFECT=...), for the
 * certification to find (docs/src/firmware.md):
 * - DEFECT_TIMEOUT_X4: the alarm waits four times the delay asked for, so the reply
 *   starts late (000:T10).
 * - DEFECT_TX_LOSES_LAST: the transmit interrupt takes "buffer not full" for "done"
 *   once a reply is longer than 8 characters: its last character is never written.
 * - DEFECT_REQUEST_LOG_ON_STACK: every received character is logged into a 16-byte
 *   buffer on the receive interrupt's stack without a bound: a request longer than 16
 *   characters (a long Store Data) overwrites the interrupt's return and the image
 *   faults, silent from then on.
 * - DEFECT_RX_DEAF_AFTER_REPLY: the receiver, switched off while the image transmits
 *   (an RS-485 half-duplex habit against hearing its own echo), is switched back on
 *   10 ms after a reply's last character instead of at once: the first characters of
 *   a request that follows the reply after the timeout (000:2.2.2) are lost. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "an385.h"
#include "hiperface.h"

/* The profile the harness is run with (`--profile SRS50`). */
#define PROFILE "SRS50"

#ifdef DEFECT_TIMEOUT_X4
#define ALARM_FACTOR 4u
#else
#define ALARM_FACTOR 1u
#endif

/* The slave's storage: hf_slave_size() bytes at hf_slave_align(), checked at boot. */
static _Alignas(16) uint8_t slave_storage[8192];
static HfSlave *slave;

/* A reply the model decided on, waiting for its start (000:2.2.2: not before the
 * request's timeout has elapsed; 000:T10: within the command's maximum response time). */
static HfTransmission pending;
static bool has_pending;
/* The reply going out, and how many of its characters are written. */
static HfTransmission sending;
static size_t written;
static bool is_sending;
/* The data rate the UART is set to, bit/s (0: not yet set). */
static uint32_t uart_bps;
#ifdef DEFECT_RX_DEAF_AFTER_REPLY
/* When the last reply's last character was written. */
static uint64_t reply_end_us;
#endif
/* TIMER0's wraps (2^32 ticks each, 171.8 s at 25 MHz): the clock's upper bits. */
static uint32_t wraps;

/* The time since boot in µs, from TIMER0 and its wraps. Called from the interrupts,
 * which do not preempt one another: a wrap not counted yet shows as TIMER0's pending
 * bit, read on both sides of the count so that count and wrap agree. */
static uint64_t now_us(void) {
    uint32_t before, value, after;
    do {
        before = TIMER_INTSTATUS(TIMER0_BASE) & 1u;
        value = TIMER_VALUE(TIMER0_BASE);
        after = TIMER_INTSTATUS(TIMER0_BASE) & 1u;
    } while (before != after);
    /* A down-counter: the ticks into this period are 2^32 - value. */
    uint64_t ticks = ((uint64_t)(wraps + before) << 32) + (uint32_t)(0u - value);
    return ticks / TICKS_PER_US;
}

static void clock_start(void) {
    TIMER_CTRL(TIMER0_BASE) = 0;
    TIMER_RELOAD(TIMER0_BASE) = 0xFFFFFFFFu;
    TIMER_INTSTATUS(TIMER0_BASE) = 1;
    TIMER_CTRL(TIMER0_BASE) = TIMER_EN | TIMER_IRQEN;
    TIMER_CTRL(TIMER1_BASE) = 0;
    TIMER_INTSTATUS(TIMER1_BASE) = 1;
}

/* Arm TIMER1 to interrupt at `at` (a clock reading), or disarm it. */
static void alarm(bool armed, uint64_t at, uint64_t now) {
    TIMER_CTRL(TIMER1_BASE) = 0;
    TIMER_INTSTATUS(TIMER1_BASE) = 1;
    if (!armed) {
        return;
    }
    uint64_t delay_us = at > now ? (at - now) * ALARM_FACTOR : 0;
    /* Rounded up to a tick so that the alarm never comes before the deadline; one
     * beyond a count (171 s) interrupts early and is armed again. */
    uint64_t ticks = delay_us * TICKS_PER_US;
    if (ticks == 0) {
        ticks = 1;
    }
    if (ticks > 0xFFFFFFFFu) {
        ticks = 0xFFFFFFFFu;
    }
    TIMER_RELOAD(TIMER1_BASE) = (uint32_t)ticks;
    TIMER_CTRL(TIMER1_BASE) = TIMER_EN | TIMER_IRQEN;
}

/* Set the data rate (000:T28). The CMSDK UART is 8N1 only: no parity bit to send or
 * check, which the emulated line (a pseudo-terminal) has not either. */
static void set_rate(uint32_t bps) {
    if (bps != 0 && bps != uart_bps) {
        UART_BAUDDIV = PCLK_HZ / bps;
        uart_bps = bps;
    }
}

/* Take what the model sends by `now`: a new reply replaces one not yet started (the
 * master spoke again before it was due; the model answers the last request). */
static void take(uint64_t now) {
    HfTransmission t;
    if (hf_slave_poll(slave, now, &t) == HF_STATUS_OK) {
        pending = t;
        has_pending = true;
    }
}

/* Start the pending reply if it is due and the line is free: in the settings the
 * request came in (000:T33, a 67h reply too). */
static void start_due(uint64_t now) {
    if (is_sending || !has_pending || pending.earliest_start_us > now) {
        return;
    }
    sending = pending;
    has_pending = false;
    set_rate(sending.settings.bits_per_second);
    written = 0;
    if (sending.len > 0) {
        UART_DATA = sending.frame[0];
        written = 1;
    }
    is_sending = true;
}

/* The next instant with work: the model's deadline, or a reply's start. */
static bool next_due(uint64_t now, uint64_t *at) {
    uint64_t model;
    bool has_model = hf_slave_next_deadline(slave, now, &model) == HF_STATUS_OK;
    bool has_reply = !is_sending && has_pending;
    if (has_model && has_reply) {
        *at = model < pending.earliest_start_us ? model : pending.earliest_start_us;
    } else if (has_model) {
        *at = model;
    } else if (has_reply) {
        *at = pending.earliest_start_us;
    }
    return has_model || has_reply;
}

/* Poll the model at `now`, start a reply that is due, keep the UART in the settings
 * the model listens with (67h, 53h, the power-up windows of 000:T9), and arm the
 * alarm for what comes next. Bounded: after a poll the model's next deadline lies
 * after `now`, and a due reply is started, so a second round finds nothing due. */
static void service(uint64_t now) {
    uint64_t at = 0;
    bool armed = false;
    for (int round = 0; round < 4; round++) {
        take(now);
        start_due(now);
        if (!is_sending) {
            HfUartSettings s;
            if (hf_slave_listening(slave, now, &s) == HF_STATUS_OK) {
                set_rate(s.bits_per_second);
            }
        }
        armed = next_due(now, &at);
        if (!armed || at > now) {
            break;
        }
        now = now_us();
    }
    alarm(armed, at, now);
}

/* ---- Interrupt handlers (the vector table is in startup.c) ---- */

/* UART0 receive: stamp each character with the clock at once and hand it to the
 * model; a character can close the frame before it, whose reply the poll gives. */
void UART0_RX_Handler(void) {
    uint64_t at = now_us();
#ifdef DEFECT_REQUEST_LOG_ON_STACK
    static size_t logged;
    static uint64_t last_at;
    volatile uint8_t log[16] __attribute__((unused));
    /* A new request begins after a pause of more than two characters at 9600 Bd. */
    if (at - last_at > 2300) {
        logged = 0;
    }
    last_at = at;
#endif
    /* Cleared before the character is taken: one arriving after it raises it again. */
    UART_INTSTATUS = UART_INT_RX | UART_INT_RXO;
    while (UART_STATE & UART_STATE_RXFULL) {
        /* An overrun lost a character: a UART fault, answered 09h (000:T47). */
        uint8_t fault = HF_FAULT_NONE;
        if (UART_STATE & UART_STATE_RXOVERRUN) {
            fault = HF_FAULT_OVERRUN;
            UART_STATE = UART_STATE_RXOVERRUN;
        }
        uint8_t byte = (uint8_t)UART_DATA;
#ifdef DEFECT_REQUEST_LOG_ON_STACK
        /* The defect: no bound on the log's index. */
        log[logged++] = byte;
#endif
#ifdef DEFECT_RX_DEAF_AFTER_REPLY
        /* The defect: a character within 10 ms of a reply's end is never heard. */
        if (reply_end_us != 0 && at < reply_end_us + 10000) {
            continue;
        }
#endif
        hf_slave_receive(slave, byte, at, fault);
        take(at);
    }
    service(at);
}

/* UART0 transmit: the last character is out; write the next or finish the reply. */
void UART0_TX_Handler(void) {
    uint64_t now = now_us();
    UART_INTSTATUS = UART_INT_TX;
    if (!is_sending || (UART_STATE & UART_STATE_TXFULL)) {
        return;
    }
#ifdef DEFECT_TX_LOSES_LAST
    size_t end = sending.len > 8 ? sending.len - 1 : sending.len;
#else
    size_t end = sending.len;
#endif
    if (written < end) {
        UART_DATA = sending.frame[written++];
        return;
    }
    is_sending = false;
#ifdef DEFECT_RX_DEAF_AFTER_REPLY
    reply_end_us = now;
#endif
    service(now);
}

/* TIMER0 wrapped: count it (the clock's upper bits). */
void TIMER0_Handler(void) {
    TIMER_INTSTATUS(TIMER0_BASE) = 1;
    wraps++;
}

/* TIMER1: a deadline is due. */
void TIMER1_Handler(void) {
    TIMER_CTRL(TIMER1_BASE) = 0;
    TIMER_INTSTATUS(TIMER1_BASE) = 1;
    service(now_us());
}

int main(void) {
    clock_start();
    /* Storage as the library asks; otherwise the image stays silent (a harness then
     * reports a silent device, never a wrong one). */
    if (hf_slave_size() > sizeof slave_storage || (uintptr_t)slave_storage % hf_slave_align() != 0) {
        return 1;
    }
    if (hf_slave_init(slave_storage, sizeof slave_storage, PROFILE, &slave) != HF_STATUS_OK) {
        return 1;
    }
    /* Power-on at the clock's reading: the power-up sequence of 000:T9
     * (initialization, the default window, then the stored settings). */
    hf_slave_power_on(slave, now_us());
    UART_CTRL = 0;
    UART_INTSTATUS = UART_INT_TX | UART_INT_RX | UART_INT_RXO;
    UART_CTRL = UART_CTRL_TX_EN | UART_CTRL_RX_EN | UART_CTRL_TX_INTEN | UART_CTRL_RX_INTEN;
    service(now_us());
    NVIC_ISER0 = (1u << IRQ_UART0_RX) | (1u << IRQ_UART0_TX) | (1u << IRQ_TIMER0) | (1u << IRQ_TIMER1);
    for (;;) {
        /* Everything happens in the interrupts. */
        __asm__ volatile("wfi");
    }
}
