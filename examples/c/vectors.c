/*
 * Replay golden vector files through the C API, as a C implementation's test suite
 * would: for each vector, the slave of its setup, then each step's request and the
 * device's reply graded by the oracle; the verdict must be the one the vector expects
 * (PASS for every step but the last, whose verdict the vector names). Checksum
 * examples are checked with hf_checksum, printed table rows with hf_table_evaluate.
 *
 *   vectors FILE.json...
 *
 * Prints per file how many vectors of each kind were replayed, and every vector that
 * disagrees; exit 0 if none does, 1 if one does, 2 for a file it cannot read.
 */
#include <stdio.h>
#include <string.h>
#include "hiperface.h"

static const char *verdict_name(HfVerdict v) { return hf_verdict_name((int)v); }

/* The step's physical inputs over the slave's (only those the step sets). */
static int apply_inputs(HfSlave *s, const HfVectorStep *st) {
    HfInputs now;
    if (st->inputs_set == 0) return 0;
    if (hf_slave_inputs(s, &now) != HF_STATUS_OK) return -1;
    if (st->inputs_set & HF_INPUT_POSITION) now.position = st->inputs.position;
    if (st->inputs_set & HF_INPUT_SPEED) now.speed = st->inputs.speed;
    if (st->inputs_set & HF_INPUT_TEMPERATURE) now.temperature_c = st->inputs.temperature_c;
    if (st->inputs_set & HF_INPUT_LED_CURRENT) now.led_current_ma = st->inputs.led_current_ma;
    return hf_slave_set_inputs(s, &now) == HF_STATUS_OK ? 0 : -1;
}

/* Replay a vector of steps; 0 if every step got the verdict the vector expects. */
static int replay_steps(const HfVectors *vs, size_t i, const HfVector *v) {
    HfSlave *s = NULL;
    if (hf_vector_start(vs, i, NULL, 0, &s) != HF_STATUS_OK) {
        printf("  %s: its setup cannot be made\n", v->id);
        return -1;
    }
    int bad = 0;
    for (size_t n = 0; n < v->steps && !bad; n++) {
        HfVectorStep st;
        HfGrade g;
        HfVerdict want = n + 1 == v->steps ? v->expected : HF_VERDICT_PASS;
        if (hf_vector_step(vs, i, n, &st) != HF_STATUS_OK || apply_inputs(s, &st) != 0) {
            printf("  %s: step %zu cannot be read\n", v->id, n + 1);
            bad = 1;
            break;
        }
        /* exact: the model's own world, every value graded exactly (as vectors verify) */
        if (hf_oracle_grade(s, st.request, st.request_len, st.at_us, st.has_reply ? st.reply : NULL,
                            st.reply_len, true, st.uart_fault, &g) != HF_STATUS_OK) {
            printf("  %s: step %zu not graded\n", v->id, n + 1);
            bad = 1;
        } else if (g.verdict != want) {
            printf("  %s: step %zu graded %s [%s] %s; the vector expects %s\n", v->id, n + 1,
                   verdict_name(g.verdict), g.clause, g.reason, verdict_name(want));
            bad = 1;
        }
    }
    hf_slave_free(s);
    return bad ? -1 : 0;
}

static int replay_checksum(const HfVectors *vs, size_t i, const HfVector *v) {
    HfChecksumExample c;
    uint8_t sum;
    if (hf_vector_checksum_example(vs, i, &c) != HF_STATUS_OK || hf_checksum(c.frame, c.frame_len, &sum) != HF_STATUS_OK) {
        printf("  %s: the checksum example cannot be read\n", v->id);
        return -1;
    }
    HfVerdict got = sum == c.printed ? HF_VERDICT_PASS : HF_VERDICT_FAIL;
    if (got != v->expected) {
        printf("  %s: XOR %02Xh, printed %02Xh: %s; the vector expects %s\n", v->id, sum, c.printed,
               verdict_name(got), verdict_name(v->expected));
        return -1;
    }
    return 0;
}

static int replay_table(const HfVectors *vs, size_t i, const HfVector *v) {
    HfTableCase t;
    char answer[HF_TEXT_LEN];
    if (hf_vector_table_case(vs, i, &t) != HF_STATUS_OK) {
        printf("  %s: the table row cannot be read\n", v->id);
        return -1;
    }
    if (hf_table_evaluate(t.table, t.input, answer, sizeof answer) != HF_STATUS_OK) {
        printf("  %s: %s / %s: %s\n", v->id, t.table, t.input, answer);
        return -1;
    }
    HfVerdict got = strcmp(answer, t.output) == 0 ? HF_VERDICT_PASS : HF_VERDICT_FAIL;
    if (got != v->expected) {
        printf("  %s: %s %s: the model says `%s`, printed `%s`; the vector expects %s\n", v->id, t.table,
               t.input, answer, t.output, verdict_name(v->expected));
        return -1;
    }
    return 0;
}

int main(int argc, char **argv) {
    int failed = 0;
    size_t total = 0;
    if (argc < 2) {
        fprintf(stderr, "usage: vectors FILE.json...\n");
        return 2;
    }
    for (int a = 1; a < argc; a++) {
        HfVectors *vs = NULL;
        char error[512];
        if (hf_vectors_load(argv[a], &vs, error, sizeof error) != HF_STATUS_OK) {
            fprintf(stderr, "%s\n", error);
            return 2;
        }
        size_t count = hf_vectors_count(vs), kinds[3] = {0, 0, 0}, wrong = 0;
        for (size_t i = 0; i < count; i++) {
            HfVector v;
            int r;
            if (hf_vector_get(vs, i, &v) != HF_STATUS_OK) {
                printf("  vector %zu cannot be read\n", i);
                wrong++;
                continue;
            }
            switch (v.kind) {
            case HF_VECTOR_KIND_STEPS: r = replay_steps(vs, i, &v); break;
            case HF_VECTOR_KIND_CHECKSUM_EXAMPLE: r = replay_checksum(vs, i, &v); break;
            case HF_VECTOR_KIND_TABLE_CASE: r = replay_table(vs, i, &v); break;
            default: printf("  %s: a kind this program does not know\n", v.id); r = -1; break;
            }
            if ((size_t)v.kind < 3) kinds[v.kind]++;
            if (r != 0) wrong++;
        }
        printf("%s: %zu vectors (%zu of steps, %zu checksum examples, %zu table rows): %s\n", argv[a], count,
               kinds[0], kinds[1], kinds[2], wrong ? "SOME DISAGREE" : "all as the vectors say");
        if (wrong) failed = 1;
        total += count;
        hf_vectors_free(vs);
    }
    printf("%zu vectors replayed through the C API\n", total);
    return failed;
}
