/*
 * A tiny HIPERFACE encoder in C (Read Position, Read Encoder Status), as a firmware's
 * host-side unit test would hold it, graded by the reference oracle through the C API.
 *
 *   tiny_encoder            every reply PASSes; exit 0
 *   tiny_encoder --defect   the encoder computes its checksum without the address byte
 *                           (a classic slip): the oracle FAILs its replies; exit 1
 *
 * Each request is fed to the encoder under test; its reply (the bytes it would put on
 * the wire) goes with the request to hf_oracle_grade, which prints the verdict, the
 * clause and the reason.
 */
#include <stdio.h>
#include <string.h>
#include "hiperface.h"

static int defect;

/* The encoder under test: fills `reply`, returns its length (0: silent). */
static size_t encoder(const uint8_t *req, size_t len, uint8_t *reply) {
    if (len != 3) return 0;
    size_t n = 0;
    reply[n++] = req[0];                 /* its address: 000:T5 */
    switch (req[1]) {
    case 0x42:                           /* Read Position: 32 bits, MSB first */
        reply[n++] = 0x42;
        reply[n++] = 0x00; reply[n++] = 0x00; reply[n++] = 0x12; reply[n++] = 0x34;
        break;
    case 0x50:                           /* Read Encoder Status: no fault */
        reply[n++] = 0x50;
        reply[n++] = 0x00;
        break;
    default:                             /* Unknown command: error 0Bh */
        reply[n++] = 0x50 | 0x80;
        reply[n++] = 0x0B;
        break;
    }
    uint8_t sum = 0;
    for (size_t i = defect ? 1 : 0; i < n; i++) sum ^= reply[i];  /* 000:2.3.3 */
    reply[n++] = sum;
    return n;
}

int main(int argc, char **argv) {
    defect = argc > 1 && strcmp(argv[1], "--defect") == 0;
    HfSlave *model = NULL;
    if (hf_slave_new("SRS50", &model) != HF_STATUS_OK) {
        fprintf(stderr, "no model\n");
        return 2;
    }
    const uint8_t requests[][3] = {{0x40, 0x42, 0x02}, {0x40, 0x50, 0x10}, {0x40, 0x42, 0x02}};
    int failed = 0;
    uint64_t at_us = 10000;
    for (size_t i = 0; i < sizeof requests / sizeof requests[0]; i++) {
        uint8_t reply[HF_MAX_FRAME];
        size_t n = encoder(requests[i], 3, reply);
        HfGrade g;
        HfStatus s = hf_oracle_grade(model, requests[i], 3, at_us, n ? reply : NULL, n, false, false, &g);
        if (s != HF_STATUS_OK) {
            fprintf(stderr, "grade: status %d\n", (int)s);
            return 2;
        }
        const char *v = hf_verdict_name((int)g.verdict);
        printf("%02X %02X %02X -> %s [%s] %s\n", requests[i][0], requests[i][1], requests[i][2], v, g.clause, g.reason);
        failed |= g.verdict == HF_VERDICT_FAIL;
        at_us += 20000;
    }
    hf_slave_free(model);
    return failed;
}
