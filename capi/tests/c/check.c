/* raypipe's C ABI from C: hand-worked results in binary32 (every value exact), the batch
 * against single tests in several formats, and every error path. Prints "N passed, M failed"
 * and exits non-zero when a check fails. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "raypipe.h"

static int passed, failed;

#define CHECK(cond, ...)                                             \
    do {                                                             \
        if (cond) {                                                  \
            passed++;                                                \
        } else {                                                     \
            failed++;                                                \
            printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);   \
            printf(__VA_ARGS__);                                     \
            printf(" (last error: %s)\n", rp_last_error());          \
        }                                                            \
    } while (0)

static uint64_t f32(float x) {
    uint32_t b;
    memcpy(&b, &x, 4);
    return b;
}

static RpUnit *unit(const char *u, const char *f, const char *o) {
    RpUnit *h = NULL;
    int rc = rp_unit_new(u, f, o, &h);
    CHECK(rc == RP_OK && h != NULL, "rp_unit_new(%s, %s, %s) = %d", u, f, o ? o : "(null)", rc);
    return h;
}

/* a ray from (0.25, 0.25, -1) along +z against (0,0,0) (1,0,0) (0,1,0): det = -1 (e1 . (d x
 * e2)), u' = v' = -0.25, t' = -1, so t = 1, u = v = 0.25, all exact */
static void rti_by_hand(void) {
    RpUnit *u = unit("rti", "f32", NULL);
    uint64_t in[17] = {f32(0.25f), f32(0.25f), f32(-1.0f), f32(0.0f), f32(0.0f), f32(1.0f),
                       f32(0.0f),  f32(10.0f), f32(0.0f),  f32(0.0f), f32(0.0f), f32(1.0f),
                       f32(0.0f),  f32(0.0f),  f32(0.0f),  f32(1.0f), f32(0.0f)};
    uint64_t out[5] = {9, 9, 9, 9, 9};
    CHECK(rp_rti(u, in, out, NULL) == RP_OK, "rp_rti");
    CHECK(out[0] == 1 && out[1] == 1, "valid %" PRIu64 " hit %" PRIu64, out[0], out[1]);
    CHECK(out[2] == 0x3f800000 && out[3] == 0x3e800000 && out[4] == 0x3e800000,
          "t %" PRIx64 " u %" PRIx64 " v %" PRIx64, out[2], out[3], out[4]);
    /* t = 1 beyond tmax = 0.5: valid, no hit */
    in[7] = f32(0.5f);
    CHECK(rp_rti(u, in, out, NULL) == RP_OK && out[0] == 1 && out[1] == 0, "tmax 0.5: %" PRIu64 " %" PRIu64, out[0], out[1]);
    /* back faces culled: det = -1 < 0 fails the culling test */
    RpUnit *c = unit("rti", "f32", "--cull");
    in[7] = f32(10.0f);
    CHECK(rp_rti(c, in, out, NULL) == RP_OK && out[0] == 0 && out[1] == 0, "culled: %" PRIu64 " %" PRIu64, out[0], out[1]);
    /* the stage signals: as many as the handle names, det among them = -1 */
    size_t ns = rp_unit_stages(u);
    CHECK(ns > 10, "%zu stage signals", ns);
    uint64_t st[256];
    CHECK(ns <= 256 && rp_rti(u, in, out, st) == RP_OK, "stages");
    int found = 0;
    for (size_t i = 0; i < ns; i++)
        if (strcmp(rp_unit_stage_name(u, i), "det") == 0) found = st[i] == f32(-1.0f);
    CHECK(found, "det = -1 among the stage signals");
    CHECK(rp_unit_stage_name(u, ns) == NULL, "no name past the end");
    rp_unit_free(c);
    rp_unit_free(u);
}

/* a ray from (0, 0, -2) along (0.5, 0.5, 1) against the box [-1, 1]^3: 1/d = (2, 2, 1), x and
 * y slabs [-2, 2], z slab [1, 3]: t_near 1, t_far 2 */
static void slab_by_hand(void) {
    const char *variants[] = {"--variant plain", "--variant conservative", "--variant directed",
                              "--variant take-on-false", "--variant embree"};
    for (int k = 0; k < 5; k++) {
        RpUnit *u = unit("slab", "f32", variants[k]);
        uint64_t in[14] = {f32(0.0f),  f32(0.0f),  f32(-2.0f), f32(0.5f), f32(0.5f),
                           f32(1.0f),  f32(0.0f),  f32(10.0f), f32(-1.0f), f32(-1.0f),
                           f32(-1.0f), f32(1.0f),  f32(1.0f),  f32(1.0f)};
        uint64_t out[3];
        CHECK(rp_slab(u, in, out, NULL) == RP_OK && out[0] == 1, "%s: hit %" PRIu64, variants[k], out[0]);
        /* plain and take-on-false compute exactly here; the others widen or round outward */
        if (k == 0 || k == 3)
            CHECK(out[1] == f32(1.0f) && out[2] == f32(2.0f), "%s: %" PRIx64 " %" PRIx64, variants[k], out[1], out[2]);
        else
            CHECK(out[1] <= f32(1.0f) && out[2] >= f32(2.0f), "%s: %" PRIx64 " %" PRIx64, variants[k], out[1], out[2]);
        rp_unit_free(u);
    }
}

static void op_by_hand(void) {
    RpUnit *u = unit("op", "f32", NULL);
    uint64_t r, c;
    CHECK(rp_op(u, 0, f32(1.5f), f32(2.25f), &r, &c) == RP_OK && r == f32(3.75f) && c == 0, "add %" PRIx64, r);
    CHECK(rp_op(u, 2, f32(1.5f), f32(2.25f), &r, &c) == RP_OK && r == f32(3.375f), "mul %" PRIx64, r);
    CHECK(rp_op(u, 4, f32(1.5f), f32(2.25f), &r, &c) == RP_OK && c == 1 && r == 0, "lt %" PRIu64, c);
    CHECK(rp_op(u, 5, f32(2.25f), f32(1.5f), &r, &c) == RP_OK && c == 0, "le %" PRIu64, c);
    /* binary16: 1 + 2^-11 is a tie between 1 and 1 + 2^-10; it rounds to even (1) */
    RpUnit *h = unit("op", "fp16", NULL);
    CHECK(rp_op(h, 0, 0x3c00, 0x1000, &r, &c) == RP_OK && r == 0x3c00, "fp16 tie %" PRIx64, r);
    rp_unit_free(h);
    rp_unit_free(u);
}

/* conversions: round to nearest even from binary64, exact back */
static void encode_decode(void) {
    RpUnit *a = unit("op", "f32", NULL), *h = unit("op", "fp16", NULL), *q = unit("op", "q16.16", NULL);
    uint64_t b = 0;
    double x = 0;
    CHECK(rp_encode(a, 0.1, &b) == RP_OK && b == 0x3dcccccd, "f32 0.1 = %" PRIx64, b);
    CHECK(rp_encode(h, 1.0 / 3.0, &b) == RP_OK && b == 0x3555, "fp16 1/3 = %" PRIx64, b);
    CHECK(rp_encode(h, 65520.0, &b) == RP_OK && b == 0x7c00, "fp16 65520 rounds to inf: %" PRIx64, b);
    CHECK(rp_encode(q, 1.5, &b) == RP_OK && b == 0x18000, "q16.16 1.5 = %" PRIx64, b);
    CHECK(rp_decode(h, 0x3c00, &x) == RP_OK && x == 1.0, "fp16 0x3c00 = %g", x);
    CHECK(rp_decode(h, 0x0001, &x) == RP_OK && x == 0x1p-24, "fp16 least subnormal = %g", x);
    CHECK(rp_decode(q, 0xffff8000, &x) == RP_OK && x == -0.5, "q16.16 -0.5 = %g", x);
    CHECK(rp_decode(h, 0x10000, &x) == RP_ERR_ARGUMENT, "17 bits for fp16");
    CHECK(rp_encode(a, 1.0, NULL) == RP_ERR_NULL, "null bits");
    RpUnit *r = unit("rti", "f32", NULL);
    CHECK(rp_unit_output_width(r, 0) == 1 && rp_unit_output_width(r, 2) == 32 && rp_unit_output_width(r, 5) == 0, "output widths");
    size_t ns = rp_unit_stages(r), bits = 0;
    for (size_t i = 0; i < ns; i++) bits += rp_unit_stage_width(r, i);
    CHECK(bits == 1673, "the f32 recip-mul stage row is 1673 bits, got %zu", bits);
    rp_unit_free(r);
    rp_unit_free(q);
    rp_unit_free(h);
    rp_unit_free(a);
}

static uint64_t lcg(uint64_t *s) {
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 11;
}

/* random rows of the format's width: the batch (SIMD kernels) equals one test at a time */
static void batch_equals_single(const char *unitname, const char *fmt, int width) {
    RpUnit *u = unit(unitname, fmt, NULL);
    size_t ni = rp_unit_inputs(u), no = rp_unit_outputs(u);
    enum { N = 777 };
    uint64_t *in = malloc(sizeof(uint64_t) * ni * N), *out = malloc(sizeof(uint64_t) * no * N);
    uint64_t s = 42, mask = width == 64 ? ~0ull : (1ull << width) - 1;
    for (size_t k = 0; k < ni * N; k++) in[k] = lcg(&s) & mask;
    if (strcmp(unitname, "op") == 0)
        for (size_t k = 0; k < N; k++) in[k * ni] %= 6;
    CHECK(rp_eval_batch(u, N, in, ni * N, out, no * N) == RP_OK, "%s %s batch", unitname, fmt);
    int same = 1;
    for (size_t k = 0; k < N; k++) {
        uint64_t one[8];
        CHECK(rp_eval(u, in + k * ni, ni, one, 8, NULL, 0) == RP_OK, "%s %s row %zu", unitname, fmt, k);
        if (memcmp(one, out + k * no, no * sizeof(uint64_t)) != 0) same = 0;
    }
    CHECK(same, "%s %s: batch rows equal single tests", unitname, fmt);
    free(in);
    free(out);
    rp_unit_free(u);
}

static void errors(void) {
    RpUnit *u = NULL;
    CHECK(rp_unit_new("rti", "f33", NULL, &u) == RP_ERR_ARGUMENT && u == NULL, "bad format");
    CHECK(strstr(rp_last_error(), "f33") != NULL, "the message names the format");
    CHECK(rp_unit_new("bvh", "f32", NULL, &u) == RP_ERR_ARGUMENT, "bad unit");
    CHECK(rp_unit_new("rti", "f32", "--frobnicate", &u) == RP_ERR_ARGUMENT, "bad option");
    CHECK(rp_unit_new("rti", "f32", "--det-threshold -1", &u) == RP_ERR_ARGUMENT, "negative threshold");
    CHECK(rp_unit_new("slab", "q16.16", "--variant conservative", &u) == RP_ERR_ARGUMENT, "a promise fixed point cannot keep");
    CHECK(rp_unit_new("slab", "f32", "--cull", &u) == RP_ERR_ARGUMENT, "an rti option on slab");
    CHECK(rp_unit_new(NULL, "f32", NULL, &u) == RP_ERR_NULL, "null unit");
    CHECK(rp_unit_new("rti", "f32", NULL, NULL) == RP_ERR_NULL, "null out");
    RpUnit *r = unit("rti", "f32", NULL);
    uint64_t in[17] = {0}, out[5];
    CHECK(rp_rti(NULL, in, out, NULL) == RP_ERR_NULL, "null handle");
    CHECK(rp_rti(r, NULL, out, NULL) == RP_ERR_NULL, "null inputs");
    CHECK(rp_rti(r, in, NULL, NULL) == RP_ERR_NULL, "null outputs");
    CHECK(rp_slab(r, in, out, NULL) == RP_ERR_UNIT, "slab call on an rti unit");
    CHECK(rp_eval(r, in, 16, out, 5, NULL, 0) == RP_ERR_LENGTH, "16 inputs");
    CHECK(rp_eval(r, in, 17, out, 4, NULL, 0) == RP_ERR_LENGTH, "room for 4 outputs");
    uint64_t st[4];
    CHECK(rp_eval(r, in, 17, out, 5, st, 4) == RP_ERR_LENGTH, "room for 4 stage signals");
    CHECK(rp_eval(r, in, 17, out, 5, st, 0) == RP_OK, "n_stages 0: no stage signals asked for");
    CHECK(rp_eval_batch(r, 2, in, 17, out, 10) == RP_ERR_LENGTH, "2 rows in 17 values");
    CHECK(rp_eval_batch(r, SIZE_MAX, in, 17, out, 10) == RP_ERR_LENGTH, "a count that overflows");
    uint64_t raw[18];
    CHECK(rp_rti(r, (const uint64_t *)((unsigned char *)raw + 1), out, NULL) == RP_ERR_ALIGN, "misaligned inputs");
    in[3] = 1ull << 32;
    CHECK(rp_rti(r, in, out, NULL) == RP_ERR_ARGUMENT, "an encoding wider than f32");
    CHECK(strstr(rp_last_error(), "bits above") != NULL, "the message says why");
    RpUnit *o = unit("op", "f32", NULL);
    uint64_t res, cmp;
    CHECK(rp_op(o, 9, 0, 0, &res, &cmp) == RP_ERR_ARGUMENT, "op code 9");
    CHECK(rp_op(o, 0, 0, 0, NULL, &cmp) == RP_ERR_NULL, "null result");
    CHECK(rp_op(o, 0, 0, 0, &res, &cmp) == RP_OK && rp_last_error()[0] == '\0', "success clears the message");
    CHECK(rp_unit_inputs(NULL) == 0 && rp_unit_stages(NULL) == 0 && rp_unit_stage_name(NULL, 0) == NULL, "null queries");
    rp_unit_free(NULL);
    rp_unit_free(o);
    rp_unit_free(r);
}

int main(void) {
    rti_by_hand();
    slab_by_hand();
    op_by_hand();
    encode_decode();
    const char *fmts[] = {"f32", "fp16", "bf16", "e8m16", "q16.16", "q8.24:divide", "e5m10:ftz"};
    const int widths[] = {32, 16, 16, 25, 32, 32, 16};
    for (int k = 0; k < 7; k++) {
        batch_equals_single("rti", fmts[k], widths[k]);
        batch_equals_single("slab", fmts[k], widths[k]);
        batch_equals_single("op", fmts[k], widths[k]);
    }
    errors();
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
