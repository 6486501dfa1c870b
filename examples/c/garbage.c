/*
 * Every function of the C API called with null pointers, short buffers and random
 * bytes: each answers with a status code, none crashes. Built with AddressSanitizer
 * and UndefinedBehaviorSanitizer (scripts/c-examples.sh), so that a read or write out
 * of bounds stops the run.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hiperface.h"

#define CHECK(cond) do { if (!(cond)) { fprintf(stderr, "%s:%d: %s\n", __FILE__, __LINE__, #cond); return 1; } } while (0)

/* An encoder that answers anything: random lengths (past the buffer's too), random
 * bytes, random start times and settings bytes. */
static void random_answer(void *context, const HfHeard *heard, HfAnswer *answer) {
    unsigned *calls = context;
    ++*calls;
    (void)heard;
    answer->len = (size_t)(rand() % (HF_MAX_FRAME + 40));
    for (size_t i = 0; i < HF_MAX_FRAME; i++) answer->reply[i] = (uint8_t)rand();
    answer->start_us = (rand() % 4 == 0) ? (uint64_t)rand() << 20 : heard->complete_us + (uint64_t)(rand() % 3000);
    answer->then_settings = (int16_t)(rand() % 400 - 100);
    answer->restarts = rand() % 8 == 0;
}

static void silent(void *context, const HfHeard *heard, HfAnswer *answer) {
    (void)context; (void)heard; (void)answer;
}

/* A master that sends random bytes at random times and rates, and asks to be woken at
 * random times (some in the past). */
static void random_master(void *context, uint64_t now_us, const HfHeardChar *heard, size_t heard_len,
                          HfMasterAction *action) {
    unsigned *calls = context;
    ++*calls;
    for (size_t i = 0; i < heard_len; i++) (void)heard[i].byte;
    action->len = (size_t)(rand() % (HF_MAX_FRAME + 40)) * (rand() % 3 == 0);
    for (size_t i = 0; i < HF_MAX_FRAME; i++) action->data[i] = (uint8_t)rand();
    action->start_us = (rand() % 5 == 0) ? (uint64_t)rand() << 12 : now_us + (uint64_t)(rand() % 30000);
    action->bps = (uint32_t[]){0, 1, 600, 9600, 38400, 4000000000u}[rand() % 6];
    action->wake_us = (rand() % 4 == 0) ? 0 : now_us + (uint64_t)(rand() % 50000) - 10000 * (rand() % 2);
}

static void count_power_on(void *context) {
    (void)context;
}

int main(void) {
    uint8_t out8 = 0, buf[HF_MAX_FRAME + 8];
    size_t n = 0;
    HfRequest req;
    HfTransmission tx;
    HfGrade g;
    HfSlave *s = NULL;

    /* Null pointers. */
    CHECK(hf_checksum(NULL, 3, &out8) == HF_STATUS_NULL);
    CHECK(hf_checksum(buf, 3, NULL) == HF_STATUS_NULL);
    CHECK(!hf_frame_is_valid(NULL, 3));
    CHECK(hf_frame_seal(NULL, 2, 3, &n) == HF_STATUS_NULL);
    CHECK(hf_frame_seal(buf, 2, 3, NULL) == HF_STATUS_NULL);
    CHECK(hf_request_decode(NULL, 3, &req, NULL) == HF_STATUS_NULL);
    CHECK(hf_request_decode(buf, 3, NULL, NULL) == HF_STATUS_NULL);
    CHECK(hf_slave_new(NULL, &s) == HF_STATUS_NULL);
    CHECK(hf_slave_new("SRS50", NULL) == HF_STATUS_NULL);
    CHECK(hf_slave_init(NULL, 1 << 16, "SRS50", &s) == HF_STATUS_NULL);
    CHECK(hf_slave_receive(NULL, 0x40, 0, HF_FAULT_NONE) == HF_STATUS_NULL);
    CHECK(hf_slave_poll(NULL, 0, &tx) == HF_STATUS_NULL);
    uint64_t due;
    HfUartSettings settings;
    CHECK(hf_slave_power_on(NULL, 0) == HF_STATUS_NULL);
    CHECK(hf_slave_next_deadline(NULL, 0, &due) == HF_STATUS_NULL);
    CHECK(hf_slave_listening(NULL, 0, &settings) == HF_STATUS_NULL);
    CHECK(hf_oracle_grade(NULL, buf, 3, 0, NULL, 0, false, false, &g) == HF_STATUS_NULL);
    HfInputs in = {0};
    CHECK(hf_slave_inputs(NULL, &in) == HF_STATUS_NULL);
    CHECK(hf_slave_set_inputs(NULL, &in) == HF_STATUS_NULL);
    hf_slave_free(NULL);

    /* Short buffers, bad arguments. */
    CHECK(hf_frame_seal(buf, 3, 3, &n) == HF_STATUS_SHORT_BUFFER);
    CHECK(hf_slave_new("no such profile", &s) == HF_STATUS_UNKNOWN_PROFILE);
    uint8_t small[16];
    CHECK(hf_slave_init(small, sizeof small, "SRS50", &s) == HF_STATUS_SHORT_BUFFER);
    void *storage = aligned_alloc(hf_slave_align(), (hf_slave_size() + hf_slave_align()) / hf_slave_align() * hf_slave_align());
    CHECK(storage != NULL);
    CHECK(hf_slave_init((char *)storage + 1, hf_slave_size(), "SRS50", &s) == HF_STATUS_SHORT_BUFFER);
    CHECK(hf_slave_init(storage, hf_slave_size(), "SRS50", &s) == HF_STATUS_OK);
    CHECK(hf_slave_receive(s, 0x40, 0, 99) == HF_STATUS_INVALID);
    CHECK(hf_slave_poll(s, 0, NULL) == HF_STATUS_NULL);
    CHECK(hf_slave_next_deadline(s, 0, NULL) == HF_STATUS_NULL);
    CHECK(hf_slave_listening(s, 0, NULL) == HF_STATUS_NULL);
    CHECK(hf_slave_inputs(s, NULL) == HF_STATUS_NULL);
    CHECK(hf_slave_set_inputs(s, NULL) == HF_STATUS_NULL);
    CHECK(hf_oracle_grade(s, buf, 3, 0, NULL, 0, false, false, NULL) == HF_STATUS_NULL);

    /* Random bytes through everything that reads bytes. */
    srand(1);
    uint64_t t = 0;
    for (int round = 0; round < 20000; round++) {
        size_t len = (size_t)(rand() % (int)sizeof buf);
        for (size_t i = 0; i < len; i++) buf[i] = (uint8_t)rand();
        CHECK(hf_checksum(buf, len, &out8) == HF_STATUS_OK);
        (void)hf_frame_is_valid(buf, len);
        HfStatus d = hf_request_decode(buf, len, &req, &out8);
        CHECK(d == HF_STATUS_OK || d == HF_STATUS_INVALID);
        CHECK(d != HF_STATUS_OK || req.data_len <= HF_MAX_REQUEST_DATA);
        t += (uint64_t)(rand() % 20000);
        in.position = (uint64_t)rand() << 16 | (uint64_t)rand();
        in.temperature_c = (int16_t)(rand() % 400 - 200);
        in.led_current_ma = (uint16_t)rand();
        in.speed = rand() - RAND_MAX / 2;
        CHECK(hf_slave_set_inputs(s, &in) == HF_STATUS_OK);
        CHECK(hf_slave_receive(s, buf[0], t, (uint8_t)(rand() % 5)) == HF_STATUS_OK);
        HfStatus p = hf_slave_poll(s, t, &tx);
        CHECK(p == HF_STATUS_OK || p == HF_STATUS_NOTHING);
        CHECK(p != HF_STATUS_OK || tx.len <= HF_MAX_FRAME);
        /* Now and then a power-on at any time: the deadline and the settings after it
         * are answered, never anything else. */
        if (rand() % 50 == 0) CHECK(hf_slave_power_on(s, t) == HF_STATUS_OK);
        HfStatus n = hf_slave_next_deadline(s, t, &due);
        CHECK(n == HF_STATUS_NOTHING || (n == HF_STATUS_OK && due >= t));
        HfStatus l = hf_slave_listening(s, t, &settings);
        CHECK(l == HF_STATUS_NOTHING || (l == HF_STATUS_OK && settings.bits_per_second >= 600));
        size_t reply_len = (size_t)(rand() % 12);
        CHECK(hf_oracle_grade(s, buf, len, t, rand() % 4 ? buf + 1 : NULL, reply_len, rand() % 2, rand() % 2, &g) == HF_STATUS_OK);
        CHECK(g.verdict <= HF_VERDICT_FAIL && memchr(g.clause, 0, sizeof g.clause) && memchr(g.reason, 0, sizeof g.reason));
        /* The enums' names: any int, a static string ("?" outside the enum). */
        int any = rand() - RAND_MAX / 2;
        CHECK(strlen(hf_status_name(any)) > 0 && strlen(hf_verdict_name(any)) > 0);
        CHECK(strlen(hf_fault_name(any)) > 0 && strlen(hf_vector_kind_name(any)) > 0);
    }
    CHECK(strcmp(hf_verdict_name(HF_VERDICT_NON_STRICT), "NON-STRICT") == 0 && strcmp(hf_verdict_name(3), "?") == 0);
    CHECK(strcmp(hf_status_name(HF_STATUS_SHORT_BUFFER), "SHORT_BUFFER") == 0 && strcmp(hf_status_name(-1), "?") == 0);
    /* A copy of a slave, and slaves of TOML text: nulls, short storage, broken text. */
    void *copy = aligned_alloc(hf_slave_align(), (hf_slave_size() + hf_slave_align()) / hf_slave_align() * hf_slave_align());
    HfSlave *c = NULL;
    char error[64];
    CHECK(copy != NULL);
    CHECK(hf_slave_copy(NULL, copy, hf_slave_size(), &c) == HF_STATUS_NULL);
    CHECK(hf_slave_copy(s, NULL, hf_slave_size(), &c) == HF_STATUS_NULL);
    CHECK(hf_slave_copy(s, copy, hf_slave_size(), NULL) == HF_STATUS_NULL);
    CHECK(hf_slave_copy(s, copy, 8, &c) == HF_STATUS_SHORT_BUFFER);
    CHECK(hf_slave_copy(s, storage, hf_slave_size(), &c) == HF_STATUS_INVALID);
    CHECK(hf_slave_copy(s, copy, hf_slave_size(), &c) == HF_STATUS_OK);
    CHECK(hf_slave_poll(c, t, &tx) == HF_STATUS_OK || hf_slave_poll(c, t, &tx) == HF_STATUS_NOTHING);
    CHECK(hf_slave_from_toml(NULL, NULL, 0, &c, error, sizeof error) == HF_STATUS_NULL);
    CHECK(hf_slave_from_toml("x", NULL, 0, NULL, error, sizeof error) == HF_STATUS_NULL);
    CHECK(hf_slave_from_toml("not = [toml", NULL, 0, &c, error, sizeof error) == HF_STATUS_INVALID);
    CHECK(memchr(error, 0, sizeof error) != NULL && error[0] != 0);
    CHECK(hf_slave_from_toml("not = [toml", NULL, 0, &c, NULL, 0) == HF_STATUS_INVALID);
    CHECK(hf_slave_from_toml("not = [toml", NULL, 0, &c, error, 1) == HF_STATUS_INVALID && error[0] == 0);
    CHECK(hf_slave_from_toml("\xff\xfe", NULL, 0, &c, error, sizeof error) == HF_STATUS_INVALID);
    for (int round = 0; round < 2000; round++) {
        char text[64];
        size_t len = (size_t)(rand() % (int)(sizeof text - 1));
        for (size_t i = 0; i < len; i++) text[i] = (char)(rand() % 255 + 1);
        text[len] = 0;
        HfStatus st = hf_slave_from_toml(text, copy, hf_slave_size(), &c, error, sizeof error);
        CHECK(st == HF_STATUS_INVALID && memchr(error, 0, sizeof error) != NULL);
    }
    free(copy);

    /* Vector files: nulls, files that are not vector files, indexes past the end. */
    HfVectors *vs = NULL;
    HfVector v;
    HfVectorStep st;
    HfChecksumExample ce;
    HfTableCase tc;
    char answer[8];
    CHECK(hf_vectors_load(NULL, &vs, error, sizeof error) == HF_STATUS_NULL);
    CHECK(hf_vectors_load("vectors/documents.json", NULL, error, sizeof error) == HF_STATUS_NULL);
    CHECK(hf_vectors_load("/no/such/file.json", &vs, error, sizeof error) == HF_STATUS_INVALID && error[0] != 0);
    CHECK(hf_vectors_load("vectors/schema.json", &vs, NULL, 0) == HF_STATUS_INVALID);
    CHECK(hf_vectors_count(NULL) == 0);
    CHECK(hf_vector_get(NULL, 0, &v) == HF_STATUS_NULL);
    CHECK(hf_vector_step(NULL, 0, 0, &st) == HF_STATUS_NULL);
    CHECK(hf_vector_start(NULL, 0, NULL, 0, &c) == HF_STATUS_NULL);
    CHECK(hf_vector_checksum_example(NULL, 0, &ce) == HF_STATUS_NULL);
    CHECK(hf_vector_table_case(NULL, 0, &tc) == HF_STATUS_NULL);
    hf_vectors_free(NULL);
    CHECK(hf_vectors_load("vectors/documents.json", &vs, error, sizeof error) == HF_STATUS_OK);
    size_t count = hf_vectors_count(vs);
    CHECK(count > 0);
    CHECK(hf_vector_get(vs, count, &v) == HF_STATUS_INVALID);
    CHECK(hf_vector_get(vs, 0, NULL) == HF_STATUS_NULL);
    CHECK(hf_vector_step(vs, count, 0, &st) == HF_STATUS_INVALID);
    CHECK(hf_vector_start(vs, count, NULL, 0, &c) == HF_STATUS_INVALID);
    CHECK(hf_vector_start(vs, 0, NULL, 0, NULL) == HF_STATUS_NULL);
    for (size_t i = 0; i < count; i++) {
        CHECK(hf_vector_get(vs, i, &v) == HF_STATUS_OK);
        CHECK(hf_vector_step(vs, i, v.steps, &st) == HF_STATUS_INVALID);
        CHECK(hf_vector_step(vs, i, 0, NULL) == HF_STATUS_NULL || v.steps == 0);
        CHECK(v.kind == HF_VECTOR_KIND_CHECKSUM_EXAMPLE || hf_vector_checksum_example(vs, i, &ce) == HF_STATUS_INVALID);
        CHECK(v.kind == HF_VECTOR_KIND_TABLE_CASE || hf_vector_table_case(vs, i, &tc) == HF_STATUS_INVALID);
        CHECK(v.kind == HF_VECTOR_KIND_STEPS || hf_vector_start(vs, i, NULL, 0, &c) == HF_STATUS_INVALID);
        /* Storage too small for the vector's slave. */
        CHECK(v.kind != HF_VECTOR_KIND_STEPS || hf_vector_start(vs, i, small, sizeof small, &c) == HF_STATUS_SHORT_BUFFER);
    }
    hf_vectors_free(vs);
    CHECK(hf_table_evaluate(NULL, "0 0 0 0", answer, sizeof answer) == HF_STATUS_NULL);
    CHECK(hf_table_evaluate("quadrature", NULL, answer, sizeof answer) == HF_STATUS_NULL);
    CHECK(hf_table_evaluate("quadrature", "0 0 0 0", NULL, 8) == HF_STATUS_NULL);
    CHECK(hf_table_evaluate("quadrature", "0 1 1 1", answer, sizeof answer) == HF_STATUS_OK);
    CHECK(hf_table_evaluate("quadrature", "0 0 0 0", answer, 3) == HF_STATUS_SHORT_BUFFER && answer[2] == 0);
    CHECK(hf_table_evaluate("quadrature", "0 0 0 0", answer, 0) == HF_STATUS_SHORT_BUFFER);
    CHECK(hf_table_evaluate("no such table", "1", answer, sizeof answer) != HF_STATUS_OK);
    for (int round = 0; round < 2000; round++) {
        char table[16], input[32];
        for (size_t i = 0; i + 1 < sizeof input; i++) input[i] = (char)(rand() % 255 + 1);
        input[rand() % (int)sizeof input] = 0;
        input[sizeof input - 1] = 0;
        strcpy(table, (const char *[]){"quadrature", "sync", "octant", "fault-reaction", "x"}[rand() % 5]);
        HfStatus e = hf_table_evaluate(table, input, answer, sizeof answer);
        CHECK(e == HF_STATUS_INVALID || e == HF_STATUS_SHORT_BUFFER || e == HF_STATUS_OK);
        CHECK(memchr(answer, 0, sizeof answer) != NULL);
    }

    free(storage);
    /* Certification in-process: nulls, bad profiles and globs, a garbage encoder. */
    HfReport *report = (HfReport *)&n;
    CHECK(hf_certify("SRS50", silent, NULL, NULL, NULL, error, sizeof error) == HF_STATUS_NULL);
    CHECK(hf_certify("SRS50", NULL, NULL, NULL, &report, error, sizeof error) == HF_STATUS_NULL && report == NULL);
    CHECK(hf_certify(NULL, silent, NULL, NULL, &report, NULL, 0) == HF_STATUS_NULL);
    CHECK(hf_certify("NO-SUCH", silent, NULL, NULL, &report, error, sizeof error) == HF_STATUS_UNKNOWN_PROFILE);
    HfCertifyOptions bad = {0};
    bad.profile_toml = "name = [";
    CHECK(hf_certify(NULL, silent, NULL, &bad, &report, error, 3) == HF_STATUS_INVALID && strlen(error) < 3);
    HfCertifyOptions none = {0};
    none.cases = "no.such.case";
    CHECK(hf_certify("SRS50", silent, NULL, &none, &report, error, sizeof error) == HF_STATUS_INVALID);
    /* The command line's glob grammar: braces, commas, exclusions; unpaired braces select nothing. */
    const char *globs[] = {"{identity.status,protocol.checksum}", "protocol.{checksum,length}",
                           "protocol.*,!protocol.{parity,argument,unknown-command}"};
    for (size_t g = 0; g < sizeof globs / sizeof globs[0]; g++) {
        HfCertifyOptions chosen = {0};
        unsigned chosen_calls = 0;
        chosen.cases = globs[g];
        CHECK(hf_certify("SRS50", random_answer, &chosen_calls, &chosen, &report, error, sizeof error) == HF_STATUS_OK);
        CHECK(hf_report_case_count(report) == 2);
        hf_report_free(report);
    }
    none.cases = "{identity.status";
    CHECK(hf_certify("SRS50", silent, NULL, &none, &report, error, sizeof error) == HF_STATUS_INVALID);
    /* A world whose fault names no fault has: refused, the name in the error. */
    HfWorld unheard = {.init_faults = "watchdog, dog"};
    HfCertifyOptions worldly = {.world = &unheard};
    CHECK(hf_certify("SRS50", silent, NULL, &worldly, &report, error, sizeof error) == HF_STATUS_INVALID);
    CHECK(report == NULL && strstr(error, "unknown start-up fault `dog`") != NULL);
    unheard = (HfWorld){.position_faults = "watchdog"};
    CHECK(hf_certify("SRS50", silent, NULL, &worldly, &report, error, sizeof error) == HF_STATUS_INVALID);
    CHECK(strstr(error, "unknown position fault `watchdog`") != NULL);
    /* A world that reads, with a garbage encoder: a report, never a crash. */
    HfInputs hot = {.temperature_c = 200, .led_current_ma = 60};
    unheard = (HfWorld){.inputs = &hot, .init_faults = "watchdog,counter", .position_faults = "", .i2c_fault = true};
    unsigned worldly_calls = 0;
    CHECK(hf_certify("SRS50", random_answer, &worldly_calls, &worldly, &report, error, sizeof error) == HF_STATUS_OK);
    CHECK(worldly_calls > 0 && hf_report_outcome(report) != HF_OUTCOME_PASSED);
    hf_report_free(report);
    CHECK(hf_report_outcome(NULL) == HF_OUTCOME_INCOMPLETE);
    CHECK(hf_report_case_count(NULL) == 0);
    CHECK(hf_report_text(NULL, HF_REPORT_FORM_JSON) == NULL);
    hf_report_free(NULL);
    /* The catalogues, as `certify slave --list` and `certify master --list` print them. */
    CHECK(strstr(hf_catalogue(HF_CATALOGUE_SLAVE_CASES), "| `identity.type-label` |") != NULL);
    CHECK(strstr(hf_catalogue(HF_CATALOGUE_MASTER_SCENARIOS), "| `startup.default` |") != NULL);
    CHECK(hf_catalogue(2) == NULL && hf_catalogue(-1) == NULL);
    for (int run = 0; run < 3; run++) {
        unsigned calls = 0;
        srand(7 + run);
        CHECK(hf_certify("SRS50", random_answer, &calls, NULL, &report, error, sizeof error) == HF_STATUS_OK);
        CHECK(calls > 0 && hf_report_outcome(report) != HF_OUTCOME_PASSED);
        size_t cases = hf_report_case_count(report);
        HfCase c;
        HfFinding f;
        CHECK(hf_report_case(report, cases, &c) == HF_STATUS_INVALID);
        CHECK(hf_report_case(report, 0, NULL) == HF_STATUS_NULL);
        for (size_t i = 0; i < cases; i++) {
            CHECK(hf_report_case(report, i, &c) == HF_STATUS_OK && strlen(c.id) > 0);
            CHECK(hf_report_finding(report, i, c.findings, &f) == HF_STATUS_INVALID);
            for (size_t k = 0; k < c.findings; k++) CHECK(hf_report_finding(report, i, k, &f) == HF_STATUS_OK);
        }
        for (int form = -2; form < 6; form++) {
            const char *text = hf_report_text(report, form);
            CHECK((text != NULL) == (form >= 0 && form < 4));
            CHECK(text == NULL || text == hf_report_text(report, form));
        }
        hf_report_free(report);
    }
    /* A master certified in-process: nulls, bad globs, a garbage master. */
    HfMaster no_step = {count_power_on, NULL, NULL};
    unsigned master_calls = 0;
    HfMaster garbage_master = {count_power_on, random_master, &master_calls};
    HfMaster no_power_on = {NULL, random_master, &master_calls};
    CHECK(hf_certify_master("SRS50", &garbage_master, NULL, NULL, error, sizeof error) == HF_STATUS_NULL);
    CHECK(hf_certify_master("SRS50", NULL, NULL, &report, error, sizeof error) == HF_STATUS_NULL && report == NULL);
    CHECK(hf_certify_master("SRS50", &no_step, NULL, &report, error, sizeof error) == HF_STATUS_NULL);
    CHECK(hf_certify_master(NULL, &garbage_master, NULL, &report, NULL, 0) == HF_STATUS_NULL);
    CHECK(hf_certify_master("NO-SUCH", &garbage_master, NULL, &report, error, sizeof error) == HF_STATUS_UNKNOWN_PROFILE);
    HfCertifyMasterOptions bad_master = {0};
    bad_master.profile_toml = "name = [";
    CHECK(hf_certify_master(NULL, &garbage_master, &bad_master, &report, error, 3) == HF_STATUS_INVALID);
    HfCertifyMasterOptions no_scenario = {0};
    no_scenario.scenarios = "no.such.scenario";
    CHECK(hf_certify_master("SRS50", &garbage_master, &no_scenario, &report, error, sizeof error) == HF_STATUS_INVALID);
    HfCertifyMasterOptions bad_declaration = {0};
    const uint8_t not_a_command[] = {0x4A, 0x99};
    bad_declaration.not_used = not_a_command;
    bad_declaration.not_used_len = sizeof not_a_command;
    CHECK(hf_certify_master("SRS50", &garbage_master, &bad_declaration, &report, error, sizeof error) == HF_STATUS_INVALID);
    for (int run = 0; run < 3; run++) {
        srand(11 + run);
        HfCertifyMasterOptions some = {0};
        some.scenarios = (const char *[]){"startup.*", "reply.*,fault.*", "*"}[run];
        some.polling_period_ms = (uint32_t)(rand() % 3) * 500;
        some.name = run == 1 ? "garbage" : NULL;
        const uint8_t declared[] = {0x4A, 0x42};
        some.not_used = run == 0 ? declared : NULL;
        some.not_used_len = run == 0 ? sizeof declared : 99;
        HfMaster *m = run == 2 ? &no_power_on : &garbage_master;
        CHECK(hf_certify_master("SRS50", m, &some, &report, error, sizeof error) == HF_STATUS_OK);
        CHECK(master_calls > 0 && hf_report_outcome(report) != HF_OUTCOME_PASSED);
        size_t scenarios = hf_report_case_count(report);
        HfCase c;
        HfFinding f;
        CHECK(scenarios > 0 && hf_report_case(report, scenarios, &c) == HF_STATUS_INVALID);
        for (size_t i = 0; i < scenarios; i++) {
            CHECK(hf_report_case(report, i, &c) == HF_STATUS_OK && strlen(c.id) > 0);
            for (size_t k = 0; k < c.findings; k++) CHECK(hf_report_finding(report, i, k, &f) == HF_STATUS_OK);
        }
        for (int form = 0; form < 4; form++) CHECK(hf_report_text(report, form) != NULL);
        hf_report_free(report);
    }
    for (int v = -3; v < 10; v++) {
        CHECK(hf_case_verdict_name(v) != NULL && hf_outcome_name(v) != NULL && hf_report_form_name(v) != NULL);
    }
    CHECK(strcmp(hf_case_verdict_name(99), "?") == 0 && strcmp(hf_outcome_name(HF_OUTCOME_FAILED), "FAILED") == 0);

    printf("garbage: every call answered with a status code\n");
    return 0;
}
