/*
 * A tiny HIPERFACE master (the drive side) in C, written from the specification (000)
 * alone, that certifies itself in-process with the suite's master scenario catalogue
 * (hf_certify_master, in virtual time, no I/O). It talks to one encoder at 40h in the
 * default settings (9600 Baud, 8E1, 55 bit timeout): after power-on it waits out the
 * initialization, reads the error stack, the type label (and the Extended Type Label
 * for type FFh), then polls the position cyclically; it reads the stack out when a
 * reply carries the warning bit, retries after protocol errors, resets the encoder
 * after critical faults and stops reading the position after a multiturn sync fault.
 *
 *   tiny_master [--defect] [--junit PATH]
 *
 *   (no option)     the conformant master: exit 0 if the run is PASSED
 *   --defect        the same master computing its checksum without the address byte
 *                   (a classic slip): its frames are no requests, FAILED on 000:2.3;
 *                   exit 1
 *   --junit PATH    also write the report as JUnit XML to PATH
 *
 * Prints each scenario that is not PASS (verdict, id) with its findings
 * ("VERDICT [clause] message"), the time the certification took, then the outcome.
 * Exit 0 PASSED, 1 FAILED, 2 otherwise.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include "hiperface.h"

/* ---------------------------------------------------------------- the figures */

enum {
    ADDRESS = 0x40,     /* 000:T5: the encoder's address (default 40h) */
    WARNING_BIT = 0x80, /* 000:T6 bit 7, 000:2.3.4 */
    STATUS = 0x50,      /* 000:2.3.4: an error response is 50h + code; 000:T27 */
    CODE0 = 0x55,       /* 000:T8: default access code */
    ETL_FIELD = 0xFF,   /* 000:T19-T21: the Extended Type Label is data field FFh */
    ETL_LEN = 64,       /* 000:T20: its minimum length */
    MAX_RETRIES = 3,    /* 000:T74 "Retry command": bounded */
    MAX_STACK_READS = 8,/* 000:2.3.4: four entries at most; a bound against a stuck bit */
    MAX_RESETS = 1,     /* 000:T37 Initialization: "a software reset first. If this didn't
                           succeed a power cycle should be done" (not the master's to do) */
};

/* 000:T4, 000:2.2.2 in the default settings (000:T9): 9600 Baud, start + 8 data + even
 * parity + stop = 11 bits a character, timeout 55 bit times = 5.73 ms. */
#define BAUD 9600u
#define CHAR_BITS 11u
#define TIMEOUT_US 5730u     /* ceil(55 / 9600 s) */
#define PAUSE_US 6000u       /* 000:2.2.2: at least the timeout, with a margin */
#define CHAR_US 1146u        /* ceil(11 / 9600 s) */
/* 000:T9: Initialization lasts 100 ms, "shall not exceed 200 ms after power-on/reset":
 * waiting 200 ms is safe for any encoder; 000:T29 asks for at least 100 ms. */
#define INIT_US 200000u
#define WINDOW_END_US 900000u   /* 000:T9: Default Communication ends without a request */
#define SETTINGS_END_US 1100000u/* 000:T9: ... and the UART is off until 1100 ms */
#define GUARD_US 10000u
#define PERIOD_US 20000u     /* 000:3.2.2: cyclic request, well inside the run's period */

typedef enum Task { T_STATUS, T_TYPE, T_ETL, T_POLL, T_RESET } Task;

typedef struct Master {
    bool defect;
    /* the line */
    uint64_t line_free_us;  /* no request may start before (000:2.2.2 pause) */
    uint64_t next_us;       /* when the current task's request is due */
    bool waiting;           /* a request is out, its reply not yet ended */
    uint8_t req[8];
    uint64_t req_start_us, deadline_us;
    uint8_t rx[HF_MAX_FRAME];
    size_t rx_len;
    uint64_t rx_last_us;
    /* the application */
    Task task, resume;      /* resume: where a stack read-out returns to */
    uint64_t resume_us;
    unsigned resume_retries;/* ... with the retries it had used */
    bool startup_readout;   /* the status read after power-on/reset (000:3.3.1) */
    uint64_t epoch_us;      /* power-on or the execution of Encoder Reset (000:T29) */
    bool answered;          /* a valid reply since epoch: the encoder is Operational */
    uint64_t codes;         /* codes read out of the stack in this read-out (bit = code) */
    unsigned retries, stack_reads, pos_errors;
    unsigned resets;        /* resets without a good position read since */
    bool no_position;       /* 000:T74 22h: only sine/cosine until shut-down; or the
                               worst case (000:3.3.4): motor stop, status polled only */
} Master;

/* ---------------------------------------------------------------- frames */

/* 000:2.3.3: XOR over all frame bytes including the address. */
static uint8_t xor_of(const uint8_t *b, size_t n) {
    uint8_t x = 0;
    for (size_t i = 0; i < n; i++) x ^= b[i];
    return x;
}

/* 000:T10: the maximum response time of the commands this master sends, ms. */
static uint32_t response_ms(uint8_t cmd) {
    switch (cmd) {
    case 0x42: return 10;
    case 0x4A: return 30;
    default: return 5; /* 50h, 52h */
    }
}

/* The reply's length (address, command, slave data of 000:T12/T21/T27/T28, checksum). */
static size_t reply_len(const Master *m) {
    switch (m->req[1]) {
    case 0x42: return 7;
    case 0x52: return 7;
    case 0x4A: return 6 + m->req[4];
    default: return 4; /* 50h */
    }
}

static bool has(const Master *m, unsigned code) { return code < 64 && (m->codes >> code) & 1; }

/* The codes of 000:2.4.3 (000:T38-T68); 00h is "no fault" (000:T27). */
static bool known(uint8_t code) {
    return code <= 0x12 || (code >= 0x1C && code <= 0x24);
}

/* 000:3.3.4: "the worst-case fault reaction to unknown fault codes (i.e. motor stop)";
 * and a critical fault a reset did not cure (000:T37: a power cycle is due). The
 * position is no longer read; the status is still polled (000:3.2.2). */
static void stop(Master *m) { m->no_position = true; }

/* ---------------------------------------------------------------- the tasks */

static void go(Master *m, Task t, uint64_t at) {
    m->task = t;
    m->next_us = at;
    m->retries = 0;
}

/* After a reply: on to `t` at `at`, unless the warning bit asks for the stack to be
 * read out first (000:2.3.4, 000:3.2.2). */
static void then(Master *m, bool warning, Task t, uint64_t at) {
    if (!warning) {
        go(m, t, at);
        return;
    }
    m->resume = t;
    m->resume_us = at;
    m->resume_retries = 0;
    m->startup_readout = false;
    m->codes = m->stack_reads = 0;
    go(m, T_STATUS, 0);
}

/* 000:T74: the worst of the codes read out of the stack decides. */
static void readout_done(Master *m) {
    if (has(m, 0x22)) stop(m); /* Multiturn sync: no position any more */
    /* Initialization faults, critical: "SW reset of Slave". 06h alone or with others
     * too, except 06h + 08h (invalid user counter value), minor. */
    bool critical = has(m, 0x01) || has(m, 0x02) || has(m, 0x03) || has(m, 0x04) ||
                    has(m, 0x05) || has(m, 0x1D) || has(m, 0x20) || has(m, 0x21);
    uint64_t besides = m->codes & ~((1ull << 0x06) | (1ull << 0x08) | 1ull);
    if (has(m, 0x06) && (besides != 0 || !has(m, 0x08))) critical = true;
    if (m->codes >> 63) stop(m); /* an unknown code */
    m->codes = 0;
    if (critical && m->resets < MAX_RESETS) {
        go(m, T_RESET, 0);
        return;
    }
    if (critical) stop(m);
    if (m->startup_readout) {
        go(m, T_TYPE, 0); /* start-up goes on: type label (000:3.3.1, 000:T19) */
    } else {
        go(m, m->resume, m->resume_us);
        m->retries = m->resume_retries;
    }
}

/* No reply, a broken one, or a protocol error: retry, with a bound (000:T74), after
 * the stack if the warning bit asks for it. */
static void retry(Master *m, uint64_t now, bool warning) {
    unsigned tries = m->retries + 1;
    if (tries <= MAX_RETRIES) {
        then(m, warning, m->task, 0);
        if (warning) m->resume_retries = tries;
        else m->retries = tries;
        return;
    }
    switch (m->task) {
    case T_STATUS: readout_done(m); break;
    case T_TYPE:
    case T_ETL: then(m, warning, T_POLL, 0); break; /* not identified: poll anyway */
    default: then(m, warning, T_POLL, now + PERIOD_US); break;
    }
}

/* A reply has ended: the timeout passed after its last character (000:2.2.2). */
static void handle(Master *m, uint64_t now) {
    const uint8_t *r = m->rx;
    size_t n = m->rx_len;
    uint8_t cmd = m->req[1];
    m->rx_len = 0; /* the next reply starts afresh */
    /* 000:2.3: address, command, data, checksum; 000:2.3.3 the checksum */
    bool error = n == 4 && (r[1] & 0x7F) == STATUS && cmd != STATUS; /* 000:2.3.4 */
    if (n < 3 || xor_of(r, n) != 0 || r[0] != ADDRESS ||
        (!error && ((r[1] & 0x7F) != cmd || n != reply_len(m)))) {
        retry(m, now, false);
        return;
    }
    m->answered = true;
    bool warning = (r[1] & WARNING_BIT) != 0;
    uint8_t code = r[2];
    /* 000:T37: protocol errors (09h...0Dh) are answered, never stacked, so a 50h reply
     * carrying one is an error response too. */
    if (cmd == STATUS && code >= 0x09 && code <= 0x0D) error = true;

    if (error) {
        if (code >= 0x09 && code <= 0x0D) { /* 000:T74 Protocol: retry command */
            retry(m, now, warning); /* D0h: the stack first (000:2.3.4 Figure 10) */
            return;
        }
        if (cmd == 0x42) {
            if (code == 0x22 || !known(code)) {
                /* 000:T74: multiturn sync fault, stop reading the position; 000:3.3.4:
                 * an unknown code, the worst case */
                stop(m);
                then(m, warning, T_POLL, now + PERIOD_US);
            } else if (code == 0x1F) { /* 000:T74 speed too high: major, go on polling */
                then(m, warning, T_POLL, now + PERIOD_US);
            } else if (++m->pos_errors >= 2) {
                /* 000:T74 Position, critical: "Retry command. If error persists, SW
                 * reset of Slave."; persisting after the reset: stop */
                if (m->resets < MAX_RESETS) {
                    then(m, warning, T_RESET, 0);
                } else {
                    stop(m);
                    then(m, warning, T_POLL, now + PERIOD_US);
                }
            } else {
                then(m, warning, T_POLL, 0); /* the retry */
            }
            return;
        }
        /* 52h, 4Ah: a data fault (000:T74: check the field): go on without it */
        then(m, warning, T_POLL, 0);
        return;
    }

    switch (m->task) {
    case T_STATUS: /* 000:T27: one code a read; the warning bit stays until all are out */
        if (known(code)) m->codes |= 1ull << code;
        else m->codes |= 1ull << 63; /* unknown: worst case (000:3.3.4) */
        if (warning && ++m->stack_reads < MAX_STACK_READS) {
            go(m, T_STATUS, 0);
        } else {
            readout_done(m);
        }
        break;
    case T_TYPE: /* 000:T28, 000:T19: type FFh has the Extended Type Label */
        then(m, warning, r[3] == 0xFF ? T_ETL : T_POLL, 0);
        break;
    case T_ETL: /* 000:T21: field, offset, count echoed; 000:T20 offset 00h: XOR of all */
        if (r[2] != ETL_FIELD || r[3] != 0 || r[4] != ETL_LEN || xor_of(r + 5, ETL_LEN) != 0) {
            retry(m, now, warning);
            return;
        }
        then(m, warning, T_POLL, 0);
        break;
    default: /* T_POLL: 000:T12 the position, MSB first */
        m->pos_errors = 0;
        m->resets = 0;
        then(m, warning, T_POLL, m->req_start_us + PERIOD_US);
        break;
    }
}

/* ---------------------------------------------------------------- the line */

static uint64_t frame_us(size_t len) { return ((uint64_t)len * CHAR_BITS * 1000000u + BAUD - 1) / BAUD; }

/* 000:T9, 000:3.3.1: until the encoder has answered, it may leave Default
 * Communication at 900 ms and change settings until 1100 ms: no request then. */
static uint64_t not_in_settings_change(const Master *m, uint64_t at, size_t len) {
    if (m->answered) return at;
    uint64_t ends = at + frame_us(len) + TIMEOUT_US;
    if (ends + GUARD_US > m->epoch_us + WINDOW_END_US && at < m->epoch_us + SETTINGS_END_US + GUARD_US)
        return m->epoch_us + SETTINGS_END_US + GUARD_US;
    return at;
}

static void send(Master *m, uint64_t now, HfMasterAction *a) {
    uint8_t *q = m->req;
    size_t n = 0;
    q[n++] = ADDRESS;
    Task t = m->task;
    if (t == T_POLL && m->no_position) { /* 000:3.2.2 poll faults with the status instead */
        then(m, true, T_POLL, now + PERIOD_US);
        t = T_STATUS;
    }
    switch (t) {
    case T_STATUS: q[n++] = 0x50; break;             /* Read Encoder Status, 000:T27 */
    case T_TYPE: q[n++] = 0x52; break;               /* Read Type Label, 000:T28 */
    case T_ETL:                                      /* Read Data, 000:T21 */
        q[n++] = 0x4A;
        q[n++] = ETL_FIELD;
        q[n++] = 0x00;     /* offset */
        q[n++] = ETL_LEN;  /* count */
        q[n++] = CODE0;    /* no code needed, but the byte must be there */
        break;
    case T_RESET: q[n++] = 0x53; break;              /* Encoder Reset, 000:T29 */
    default: q[n++] = 0x42; break;                   /* Read Position, 000:T12 */
    }
    /* 000:2.3.3: the XOR of every byte, the address too; the defect leaves it out. */
    q[n] = m->defect ? xor_of(q + 1, n - 1) : xor_of(q, n);
    n += 1;
    memcpy(a->data, q, n);
    a->len = n;
    a->start_us = now;
    a->bps = BAUD; /* 000:T9 default communication */
    m->req_start_us = now;
    uint64_t end = now + frame_us(n);
    m->line_free_us = end + PAUSE_US; /* 000:2.2.2: our frame ends with the timeout */
    if (t == T_RESET) {
        /* 000:T29: executed after the request's timeout; wait that plus the
         * initialization, then start up again as after power-on (000:3.3.1). */
        m->resets++;
        m->pos_errors = 0;
        m->epoch_us = end + TIMEOUT_US;
        m->answered = false;
        m->startup_readout = true;
        m->codes = m->stack_reads = 0;
        go(m, T_STATUS, m->epoch_us + INIT_US);
        return;
    }
    m->waiting = true;
    /* 000:T8/T10: the reply starts within the response time after the timeout */
    m->deadline_us = end + TIMEOUT_US + response_ms(q[1]) * 1000u + CHAR_US + 2000u;
}

static void power_on(void *context) {
    Master *m = context;
    *m = (Master){.defect = m->defect};
    /* 000:T9, 000:3.3.1: no UART communication during Initialization; then the
     * status after power-on, in the Default Communication window. */
    m->startup_readout = true;
    go(m, T_STATUS, INIT_US);
}

static void step(void *context, uint64_t now, const HfHeardChar *heard, size_t heard_len,
                 HfMasterAction *a) {
    Master *m = context;
    for (size_t i = 0; i < heard_len; i++) {
        if (m->waiting && m->rx_len < sizeof m->rx) m->rx[m->rx_len++] = heard[i].byte;
        m->rx_last_us = heard[i].at_us;
        /* 000:2.2.2: the encoder's transmission ends with a pause of the timeout; the
         * next request waits for it. */
        uint64_t free_at = heard[i].at_us + PAUSE_US;
        if (free_at > m->line_free_us) m->line_free_us = free_at;
    }
    if (m->waiting) {
        bool ended;
        if (m->rx_len > 0)
            ended = now >= m->rx_last_us + TIMEOUT_US;
        else
            ended = now >= m->deadline_us;
        if (!ended) {
            a->wake_us = m->rx_len > 0 ? m->rx_last_us + TIMEOUT_US : m->deadline_us;
            return;
        }
        m->waiting = false;
        handle(m, now);
    }
    uint64_t at = m->next_us > m->line_free_us ? m->next_us : m->line_free_us;
    at = not_in_settings_change(m, at, m->task == T_ETL ? 7 : 3);
    if (at > now) {
        a->wake_us = at;
        return;
    }
    send(m, now, a);
    a->wake_us = m->waiting ? m->deadline_us : m->next_us;
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
    Master m = {0};
    const char *junit = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--defect") == 0) {
            m.defect = true;
        } else if (strcmp(argv[i], "--junit") == 0 && i + 1 < argc) {
            junit = argv[++i];
        } else {
            fprintf(stderr, "usage: %s [--defect] [--junit PATH]\n", argv[0]);
            return 2;
        }
    }

    HfMaster master = {.power_on = power_on, .step = step, .context = &m};
    HfCertifyMasterOptions options = {.name = m.defect ? "tiny_master --defect" : "tiny_master"};
    HfReport *report = NULL;
    char why[512] = "";
    double start = now_ms();
    HfStatus status = hf_certify_master("SRS50", &master, &options, &report, why, sizeof why);
    double took = now_ms() - start;
    if (status != HF_STATUS_OK) {
        fprintf(stderr, "hf_certify_master: %s: %s\n", hf_status_name((int)status), why);
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
    printf("certified in %.3f ms\n", took);
    printf("%s\n", hf_outcome_name((int)outcome));
    hf_report_free(report);
    return rc;
}
