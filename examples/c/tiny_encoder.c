/*
 * A tiny HIPERFACE encoder (slave) in C, written from the specification (000) alone,
 * that certifies itself in-process with the suite's whole catalogue (hf_certify, in
 * virtual time). It supports Read Position (42h), Read Encoder Status (50h), Read Type
 * Label (52h) and Encoder Reset (53h); every other command is an unknown command.
 *
 *   tiny_encoder [--defect] [--temperature C [--ignore-temperature]] [--junit PATH]
 *
 *   (no option)     the conformant encoder: exit 0 if the run is PASSED
 *   --defect        the same encoder computing its checksum without the address byte
 *                   (a classic slip): FAILED on 000:2.3.3; exit 1
 *   --temperature C the encoder's sensor reads C degrees Celsius, and the run is told
 *                   so (HfCertifyOptions.world): outside the data sheet's -40...115
 *                   it raises the warning 1Eh before every reply (000:T59), graded
 *                   exactly
 *   --ignore-temperature  the defect of never checking the temperature: FAILED where
 *                   the warning is missing
 *   --junit PATH    also write the report as JUnit XML to PATH
 *
 * Prints each case that is not PASS (verdict, id) with its findings
 * ("VERDICT [clause] message"), the time the certification took, then the outcome.
 * Exit 0 PASSED, 1 FAILED, 2 otherwise.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "hiperface.h"

/* The device's data sheet, as the suite reads it. */
static const char PROFILE[] =
    "name = \"TINY\"\n"
    "edition = \"current\"\n"
    "adjustment = []\n"
    "stack_order = \"oldest-first\"\n"
    "\n"
    "[identity]\n"
    "type_code = 0x22\n"
    "option_code = 0x00\n"
    "serial = \"000000001\"\n"
    "firmware = \"tiny-encoder\"\n"
    "firmware_date = \"26.11.26\"\n"
    "pinned = []\n"
    "\n"
    "[interface]\n"
    "address = 0x40\n"
    "settings = 0xE4\n"
    "baud_rates = [1200, 2400, 4800, 9600, 19200, 38400]\n"
    "\n"
    "[commands]\n"
    "supported = [0x42, 0x50, 0x52, 0x53]\n"
    "\n"
    "[memory]\n"
    "total_blocks = 0x80\n"
    "user_blocks = 0x70\n"
    "\n"
    "[resolution]\n"
    "kind = \"rotary\"\n"
    "periods_per_turn = 1024\n"
    "turns = 1\n"
    "\n"
    "[limits]\n"
    "temperature_min_c = -40\n"
    "temperature_max_c = 115\n"
    "led_current_max_ma = 50\n"
    "max_read_speed = 6000\n"
    "\n"
    "[timing]\n"
    "init_ms = 100\n"
    "default_window_ms = 900\n"
    "user_settings_ms = 1100\n"
    "adjustment_response_ms = 40\n";

/* ---------------------------------------------------------------- the device */

enum {
    OWN_ADDRESS = 0x40,       /* 000:T5: 010x xxxxb, default 40h */
    BROADCAST = 0xFF,         /* 000:2.3.1 */
    DEFAULT_SETTINGS = 0xE4,  /* 000:T28: 9600 Baud, 8 bits even parity, 55 bit timeout, standard slave */
    STORED_SETTINGS = 0xE4,   /* the user-defined settings in EEPROM (000:T32): the defaults */
    TYPE_CODE = 0x22,         /* 000:T28 byte 1, 000:T19: a legacy type code, no Extended Type Label */
    MEMORY_BLOCKS = 0x80,     /* 000:T28 byte 2: total memory, 16-byte blocks (2048 bytes) */
    OPTION_CODE = 0x00,       /* 000:T28 byte 3: "for new HIPERFACE Slaves this value is always 00h" */
    ERROR_BIT = 0x80,         /* 000:T6 bit 7, the warning bit of 000:2.3.4 */
    STATUS_COMMAND = 0x50,    /* 000:2.3.4 error response: 50h + error code */
    STACK_SIZE = 4,           /* 000:2.3.4: up to four operational faults */
};

/* Error codes (000:2.4.3). */
enum {
    E_PARITY = 0x09,          /* 000:T47: any UART fault of the request */
    E_CHECKSUM = 0x0A,        /* 000:T48 */
    E_UNKNOWN_COMMAND = 0x0B, /* 000:T49 */
    E_WRONG_LENGTH = 0x0C,    /* 000:T50 */
};

/* 000:T11: 32 steps per sine period; 1024 periods x 32 = 32768 steps per turn, one turn:
 * valid values 0...7FFFh. The shaft of this tiny device never turns: it stands at
 * TINY_POSITION (any value of the measuring range is a valid Read Position answer,
 * 000:T12; -DTINY_POSITION=0 builds the same device standing at 0).
 * Without a world in the options the run grades a position by its range; with one,
 * exactly, so the world given says where the shaft stands (main). */
#define STEPS_PER_TURN (1024u * 32u)
#ifndef TINY_POSITION
#define TINY_POSITION 0x1234u
#endif

/* 000:T9 (with the profile's [timing]): after power-on or Encoder Reset. */
#define INIT_US 100000u           /* Initialization: no UART communication */
#define DEFAULT_WINDOW_US 900000u /* Default Communication, unless a request came */
#define USER_SETTINGS_US 1100000u /* Change of communication settings: no UART until then */

/* The data sheet's temperature limits ([limits] above): outside them, warning 1Eh. */
#define TEMPERATURE_MIN_C (-40)
#define TEMPERATURE_MAX_C 115
#define E_TEMPERATURE 0x1E        /* 000:T59 Encoder temperature critical: warning bit */

/* The time from the request's timeout to the reply's start bit: well within every
 * command's maximum response time (000:T10: 5 ms at least). */
#define TURNAROUND_US 200u

typedef struct Encoder {
    bool defect;           /* the checksum slip */
    bool ignore_temperature; /* the other defect: the sensor never looked at */
    int16_t temperature_c; /* what the sensor reads */
    uint8_t address;
    /* The power-up state machine (000:T9); the run starts long past power-up. */
    bool restarted;        /* an Encoder Reset was executed ... */
    uint64_t reset_at_us;  /* ... at this moment (the request's timeout, 000:T29) */
    bool settled;          /* a request came in the default window, or 1100 ms passed */
    /* The error stack of operational faults (000:2.3.4, 000:T27), oldest first. */
    uint8_t stack[STACK_SIZE];
    size_t stacked;
} Encoder;

/* UART figures of a settings byte (000:T28, 000:T4, 000:2.2.2). */
static uint32_t baud_of(uint8_t settings) {
    static const uint32_t rates[8] = {600, 1200, 2400, 4800, 9600, 19200, 38400, 9600};
    return rates[settings & 0x07];
}

static uint64_t character_us(uint8_t settings) {
    /* start bit, 8 data bits, a parity bit unless "no parity" (bits 4...5 = 00), stop bit */
    uint32_t bits = 1 + 8 + (((settings >> 4) & 0x03) != 0 ? 1 : 0) + 1;
    uint32_t baud = baud_of(settings);
    return ((uint64_t)bits * 1000000u + baud - 1) / baud;
}

static uint64_t timeout_us(uint8_t settings) {
    /* 000:2.2.2: 22 or 55 bit times (bit 6), default 55 = 5.73 ms at 9600 Baud */
    uint32_t bits = (settings & 0x40) ? 55 : 22;
    uint32_t baud = baud_of(settings);
    return ((uint64_t)bits * 1000000u + baud - 1) / baud;
}

/* An operational fault detected: stored once until read out (000:T27); a fifth
 * drops the oldest. */
static void stack_push(Encoder *e, uint8_t code) {
    for (size_t i = 0; i < e->stacked; i++)
        if (e->stack[i] == code) return;
    if (e->stacked == STACK_SIZE) {
        memmove(e->stack, e->stack + 1, STACK_SIZE - 1);
        e->stacked--;
    }
    e->stack[e->stacked++] = code;
}

/* 000:T27: one active warning or error per Read Encoder Status, 00h if none. */
static uint8_t stack_pop(Encoder *e) {
    if (e->stacked == 0) return 0x00;
    uint8_t code = e->stack[0];
    memmove(e->stack, e->stack + 1, e->stacked - 1);
    e->stacked--;
    return code;
}

/* 000:T59: the temperature "will be checked prior to every Slave response message";
 * outside the limits it is stacked (the warning bit set, 000:2.3.4). */
static void monitor(Encoder *e) {
    if (e->ignore_temperature) return;
    if (e->temperature_c < TEMPERATURE_MIN_C || e->temperature_c > TEMPERATURE_MAX_C)
        stack_push(e, E_TEMPERATURE);
}

/* 000:2.3.3: XOR over all frame bytes including the address. */
static uint8_t xor_of(const uint8_t *bytes, size_t len) {
    uint8_t sum = 0;
    for (size_t i = 0; i < len; i++) sum ^= bytes[i];
    return sum;
}

static void seal(const Encoder *e, HfAnswer *a) {
    /* the defect: the address byte left out of the checksum */
    a->reply[a->len] = e->defect ? xor_of(a->reply + 1, a->len - 1) : xor_of(a->reply, a->len);
    a->len++;
}

/* Whether this request is heard (000:T9). The UART is off during Initialization and
 * while the communication settings change: a frame whose first start bit came while
 * it was off is lost (its characters are not received whole). In the Default
 * Communication window a request counts once it is terminated (000:2.2.2: a message is
 * "considered terminated and processed" after the timeout): one still arriving when
 * the window closes at 900 ms is lost with the UART. */
static bool listening(Encoder *e, const HfHeard *h) {
    if (!e->restarted || e->settled) return true;
    uint64_t char_us = character_us(DEFAULT_SETTINGS);
    uint64_t start = h->first_us > char_us ? h->first_us - char_us : 0;
    if (start < e->reset_at_us + INIT_US) return false; /* Initialization */
    if (h->complete_us <= e->reset_at_us + DEFAULT_WINDOW_US) {
        /* Default Communication: any single request makes it Operational (default) */
        e->settled = true;
        return true;
    }
    /* No request by 900 ms: Change of communication settings until 1100 ms */
    if (start < e->reset_at_us + USER_SETTINGS_US) return false;
    e->settled = true; /* Operational (user-defined communication) */
    return true;
}

static bool supported(uint8_t command) {
    return command == 0x42 || command == 0x50 || command == 0x52 || command == 0x53;
}

/* The encoder: called once per request frame, once its timeout has passed. */
static void encoder(void *context, const HfHeard *h, HfAnswer *a) {
    Encoder *e = context;
    if (h->len == 0 || !listening(e, h)) return;

    /* 000:2.3.1: own address or broadcast; another slave's frame is not answered.
     * The reply carries the own address, also to a broadcast. */
    uint8_t address = h->bytes[0];
    if (address != e->address && address != BROADCAST) return;

    uint8_t error = 0;
    uint8_t command = h->len > 1 ? h->bytes[1] : 0;
    if (h->uart_fault != HF_FAULT_NONE) {
        error = E_PARITY;                 /* 000:T47: not parsed further, no action */
    } else if (h->char_count < 3 || h->char_count > h->len) {
        error = E_WRONG_LENGTH;           /* 000:T50: no room for command and checksum,
                                             or longer than any frame (000:T22) */
    } else if (xor_of(h->bytes, h->len) != 0) {
        error = E_CHECKSUM;               /* 000:2.3.3, 000:T48 */
    } else if (!supported(command)) {
        error = E_UNKNOWN_COMMAND;        /* 000:T49, 000:3.2.2: this device's subset */
    } else if (h->len != 3) {
        error = E_WRONG_LENGTH;           /* 000:T50: 42h, 50h, 52h, 53h carry no data
                                             (000:T12, T27, T28, T29) */
    }

    /* Read Encoder Status reads the stack first; every other reply is checked now */
    if (error || command != 0x50) monitor(e);
    a->len = 0;
    a->reply[a->len++] = e->address;
    if (error) {
        /* 000:2.3.4 Error Response: 50h + code; D0h if a warning is pending too */
        a->reply[a->len++] = STATUS_COMMAND | (e->stacked ? ERROR_BIT : 0);
        a->reply[a->len++] = error;
    } else {
        switch (command) {
        case 0x42: {                      /* Read Position, 000:T12 */
            uint32_t p = (uint32_t)(TINY_POSITION) % STEPS_PER_TURN;
            a->reply[a->len++] = command | (e->stacked ? ERROR_BIT : 0);
            a->reply[a->len++] = (uint8_t)(p >> 24); /* unsigned 32 bit, MSB first */
            a->reply[a->len++] = (uint8_t)(p >> 16);
            a->reply[a->len++] = (uint8_t)(p >> 8);
            a->reply[a->len++] = (uint8_t)p;
            break;
        }
        case 0x50: {                      /* Read Encoder Status, 000:T27 */
            uint8_t status = stack_pop(e);
            monitor(e); /* a condition still present is stacked again (000:T59) */
            /* the warning bit stays until every entry is read out (000:2.3.4) */
            a->reply[a->len++] = command | (e->stacked ? ERROR_BIT : 0);
            a->reply[a->len++] = status;
            break;
        }
        case 0x52:                        /* Read Type Label, 000:T28 */
            a->reply[a->len++] = command | (e->stacked ? ERROR_BIT : 0);
            a->reply[a->len++] = STORED_SETTINGS;
            a->reply[a->len++] = TYPE_CODE;
            a->reply[a->len++] = MEMORY_BLOCKS;
            a->reply[a->len++] = OPTION_CODE;
            break;
        case 0x53:                        /* Encoder Reset, 000:T29: no response */
            /* executed once the request's timeout elapsed (now); then power-up as
             * after power-on (000:T9); the stack and the warning are cleared
             * (000:2.3.4); address and settings are kept */
            e->restarted = true;
            e->reset_at_us = h->complete_us;
            e->settled = false;
            e->stacked = 0;
            a->len = 0;
            a->then_settings = STORED_SETTINGS;
            a->restarts = true;
            return;
        }
    }
    seal(e, a);
    /* 000:2.2.2: after the request's timeout; 000:T10: within the response time */
    uint64_t after_timeout = h->last_us + timeout_us(DEFAULT_SETTINGS);
    uint64_t start = h->complete_us > after_timeout ? h->complete_us : after_timeout;
    a->start_us = start + TURNAROUND_US;
}

/* ---------------------------------------------------------------- the run */

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static int write_junit(HfReport *report, const char *path) {
    const char *text = hf_report_text(report, HF_REPORT_FORM_JUNIT);
    if (!text) {
        fprintf(stderr, "no JUnit text\n");
        return -1;
    }
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return -1;
    }
    int ok = fputs(text, f) >= 0;
    ok = (fclose(f) == 0) && ok;
    if (!ok) perror(path);
    return ok ? 0 : -1;
}

int main(int argc, char **argv) {
    Encoder e = {.address = OWN_ADDRESS, .temperature_c = 25};
    const char *junit = NULL;
    bool told = false; /* --temperature: the run is told the encoder's world */
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--defect") == 0) {
            e.defect = true;
        } else if (strcmp(argv[i], "--ignore-temperature") == 0) {
            e.ignore_temperature = true;
        } else if (strcmp(argv[i], "--temperature") == 0 && i + 1 < argc) {
            e.temperature_c = (int16_t)atoi(argv[++i]);
            told = true;
        } else if (strcmp(argv[i], "--junit") == 0 && i + 1 < argc) {
            junit = argv[++i];
        } else {
            fprintf(stderr, "usage: %s [--defect] [--temperature C [--ignore-temperature]] [--junit PATH]\n",
                    argv[0]);
            return 2;
        }
    }

    HfCertifyOptions options = {.profile_toml = PROFILE};
    /* The world the encoder was put in, told to the run so that it grades exactly:
     * the shaft where this device stands, the temperature its sensor reads. */
    HfInputs inputs = {.position = TINY_POSITION, .speed = 0, .temperature_c = e.temperature_c,
                       .led_current_ma = 10};
    HfWorld world = {.inputs = &inputs};
    if (told) options.world = &world;
    HfReport *report = NULL;
    char why[512] = "";
    double start = now_ms();
    HfStatus status = hf_certify(NULL, encoder, &e, &options, &report, why, sizeof why);
    double took = now_ms() - start;
    if (status != HF_STATUS_OK) {
        fprintf(stderr, "hf_certify: %s: %s\n", hf_status_name((int)status), why);
        hf_report_free(report);
        return 2;
    }

    size_t cases = hf_report_case_count(report);
    for (size_t i = 0; i < cases; i++) {
        HfCase c;
        if (hf_report_case(report, i, &c) != HF_STATUS_OK || c.verdict == HF_CASE_VERDICT_PASS)
            continue;
        printf("%s %s\n", hf_case_verdict_name((int)c.verdict), c.id);
        for (size_t k = 0; k < c.findings; k++) {
            HfFinding f;
            if (hf_report_finding(report, i, k, &f) == HF_STATUS_OK)
                printf("  %s [%s] %s\n", hf_case_verdict_name((int)f.verdict), f.clause, f.message);
        }
    }
    HfOutcome outcome = hf_report_outcome(report);
    int rc = outcome == HF_OUTCOME_PASSED ? 0 : outcome == HF_OUTCOME_FAILED ? 1 : 2;
    if (junit && write_junit(report, junit) != 0) rc = 2;
    printf("%zu cases certified in %.1f ms\n", cases, took);
    printf("%s\n", hf_outcome_name((int)outcome));
    hf_report_free(report);
    return rc;
}
