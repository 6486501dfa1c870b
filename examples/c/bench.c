/*
 * Benchmark: exchanges graded through the C API, as a firmware's unit tests grade
 * their encoder's frames (Read Encoder Status with the model's own reply): the grades
 * alone on one slave; each on a fresh copy of a slave set up once (hf_slave_copy: a
 * test's own state); each on a slave built anew from its profile (hf_slave_init).
 * Target (issue 31): 5 000 000 vectors/s.
 *
 *   bench [SECONDS]
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "hiperface.h"

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec / 1e9;
}

int main(int argc, char **argv) {
    double seconds = argc > 1 ? atof(argv[1]) : 2.0;
    size_t size = (hf_slave_size() + hf_slave_align()) / hf_slave_align() * hf_slave_align();
    void *storage = aligned_alloc(hf_slave_align(), size);
    HfSlave *s = NULL;
    const uint8_t request[] = {0x40, 0x50, 0x10};
    const uint8_t reply[] = {0x40, 0x50, 0x00, 0x10};
    HfGrade g;
    if (!storage || hf_slave_init(storage, size, "SRS50", &s) != HF_STATUS_OK) return 2;

    long n = 0;
    double start = now(), elapsed;
    do {
        for (int i = 0; i < 10000; i++, n++) {
            hf_oracle_grade(s, request, 3, 10000, reply, 4, true, false, &g);
        }
        elapsed = now() - start;
    } while (elapsed < seconds);
    if (g.verdict != HF_VERDICT_PASS) { fprintf(stderr, "not a PASS: %s\n", g.reason); return 1; }
    printf("grades on one slave: %.0f exchanges/s\n", (double)n / elapsed);

    void *base_storage = aligned_alloc(hf_slave_align(), size);
    HfSlave *base = NULL;
    if (!base_storage || hf_slave_init(base_storage, size, "SRS50", &base) != HF_STATUS_OK) return 2;
    n = 0;
    start = now();
    do {
        for (int i = 0; i < 10000; i++, n++) {
            hf_slave_copy(base, storage, size, &s);
            hf_oracle_grade(s, request, 3, 10000, reply, 4, true, false, &g);
        }
        elapsed = now() - start;
    } while (elapsed < seconds);
    if (g.verdict != HF_VERDICT_PASS) { fprintf(stderr, "not a PASS: %s\n", g.reason); return 1; }
    printf("vectors (a copy of a slave set up once, one exchange): %.0f vectors/s\n", (double)n / elapsed);

    n = 0;
    start = now();
    do {
        for (int i = 0; i < 10000; i++, n++) {
            hf_slave_init(storage, size, "SRS50", &s);
            hf_oracle_grade(s, request, 3, 10000, reply, 4, true, false, &g);
        }
        elapsed = now() - start;
    } while (elapsed < seconds);
    printf("vectors (a slave built from its profile, one exchange): %.0f vectors/s\n", (double)n / elapsed);
    free(storage);
    free(base_storage);
    return 0;
}
