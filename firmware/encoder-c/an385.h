/* The few registers of QEMU's mps2-an385 board (Cortex-M3) this image uses, in one
 * place. Sources as for the Rust image's regs.rs: ARM DDI0479C ("APB UART", "APB
 * timer"), ARM AN385 (memory and interrupt maps), and QEMU 7.2's models of them
 * (hw/arm/mps2.c, hw/char/cmsdk-apb-uart.c, hw/timer/cmsdk-apb-timer.c). */
#ifndef AN385_H
#define AN385_H

#include <stdint.h>

#define REG(addr) (*(volatile uint32_t *)(addr))

/* The APB peripherals' clock: 25 MHz (mps2.c SYSCLK_FRQ). */
#define PCLK_HZ 25000000u
#define TICKS_PER_US (PCLK_HZ / 1000000u)

/* CMSDK APB UART0, QEMU's first serial port (-serial pty). */
#define UART0_BASE 0x40004000u
#define UART_DATA REG(UART0_BASE + 0x00)      /* write: send; read: take (clears RXFULL) */
#define UART_STATE REG(UART0_BASE + 0x04)     /* 0 TX full, 1 RX full, 3 RX overrun (w1c) */
#define UART_CTRL REG(UART0_BASE + 0x08)      /* 0 TX en, 1 RX en, 2 TX int en, 3 RX int en */
#define UART_INTSTATUS REG(UART0_BASE + 0x0C) /* 0 TX, 1 RX, 3 RX overrun; write 1 to clear */
#define UART_BAUDDIV REG(UART0_BASE + 0x10)   /* PCLK / baud, at least 16 */

#define UART_STATE_TXFULL (1u << 0)
#define UART_STATE_RXFULL (1u << 1)
#define UART_STATE_RXOVERRUN (1u << 3)
#define UART_CTRL_TX_EN (1u << 0)
#define UART_CTRL_RX_EN (1u << 1)
#define UART_CTRL_TX_INTEN (1u << 2)
#define UART_CTRL_RX_INTEN (1u << 3)
#define UART_INT_TX (1u << 0)
#define UART_INT_RX (1u << 1)
#define UART_INT_RXO (1u << 3)

/* CMSDK APB timers: 32-bit down-counters at PCLK that reload from RELOAD and
 * interrupt as they pass from 1 to 0. TIMER0 is the clock, TIMER1 the alarm. */
#define TIMER0_BASE 0x40000000u
#define TIMER1_BASE 0x40001000u
#define TIMER_CTRL(base) REG((base) + 0x00)      /* 0 enable, 3 interrupt enable */
#define TIMER_VALUE(base) REG((base) + 0x04)     /* the count */
#define TIMER_RELOAD(base) REG((base) + 0x08)    /* writing it sets the count too */
#define TIMER_INTSTATUS(base) REG((base) + 0x0C) /* 0 pending; write 1 to clear */
#define TIMER_EN (1u << 0)
#define TIMER_IRQEN (1u << 3)

/* The AN385's interrupt lines this image uses (mps2.c). */
#define IRQ_UART0_RX 0
#define IRQ_UART0_TX 1
#define IRQ_TIMER0 8
#define IRQ_TIMER1 9

/* The NVIC's set-enable register for lines 0-31. */
#define NVIC_ISER0 REG(0xE000E100u)

#endif
