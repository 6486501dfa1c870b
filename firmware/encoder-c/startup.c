/* The image's start: the vector table (the Cortex-M3's 16 system vectors and the
 * AN385's external lines), the reset handler that lays out memory and calls main,
 * and a default handler for every line the image does not use. */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern int main(void);

void Reset_Handler(void);
void Default_Handler(void);
void UART0_RX_Handler(void);
void UART0_TX_Handler(void);
void TIMER0_Handler(void);
void TIMER1_Handler(void);

/* Nothing the image does faults; were it to, it falls silent, as a device without a
 * watchdog would, and the harness reports a silent device. */
void Default_Handler(void) {
    __asm__ volatile("cpsid i");
    for (;;) {
        __asm__ volatile("wfi");
    }
}

void Reset_Handler(void) {
    /* .data from its load address, .bss zeroed: what C expects before main. */
    const uint32_t *from = &_sidata;
    for (uint32_t *to = &_sdata; to < &_edata;) {
        *to++ = *from++;
    }
    for (uint32_t *to = &_sbss; to < &_ebss;) {
        *to++ = 0;
    }
    main();
    Default_Handler();
}

typedef void (*Vector)(void);

__attribute__((section(".vectors"), used)) const Vector vectors[16 + 32] = {
    [0] = (Vector)&_estack,
    [1] = Reset_Handler,
    [2] = Default_Handler, /* NMI */
    [3] = Default_Handler, /* HardFault */
    [4] = Default_Handler, /* MemManage */
    [5] = Default_Handler, /* BusFault */
    [6] = Default_Handler, /* UsageFault */
    [11] = Default_Handler, /* SVCall */
    [14] = Default_Handler, /* PendSV */
    [15] = Default_Handler, /* SysTick */
    [16 + 0] = UART0_RX_Handler,
    [16 + 1] = UART0_TX_Handler,
    [16 + 8] = TIMER0_Handler,
    [16 + 9] = TIMER1_Handler,
};
