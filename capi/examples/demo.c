/* raypipe's C ABI, a worked example: one RTI test with its stage signals, a batch, and an
 * error. Build (from the repository root, after `cargo build --release -p raypipe-capi`):
 *
 *   cc -O2 -Icapi/include capi/examples/demo.c target/release/libraypipe_capi.a \
 *      -lpthread -ldl -lm -o demo && ./demo
 *
 * or against the shared library: ... target/release/libraypipe_capi.so -Wl,-rpath,target/release
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "raypipe.h"

/* binary32 encodings of the values below */
static uint64_t f32(float x) {
    uint32_t b;
    memcpy(&b, &x, 4);
    return b;
}

int main(void) {
    RpUnit *rti = NULL;
    if (rp_unit_new("rti", "f32", NULL, &rti) != RP_OK) {
        fprintf(stderr, "rp_unit_new: %s\n", rp_last_error());
        return 1;
    }
    /* a ray from (0.25, 0.25, -1) along +z, t in [0, 10], against the triangle
     * (0,0,0) (1,0,0) (0,1,0): a hit at t = 1, u = v = 0.25 */
    uint64_t in[17] = {f32(0.25f), f32(0.25f), f32(-1.0f), f32(0.0f), f32(0.0f), f32(1.0f),
                       f32(0.0f),  f32(10.0f), f32(0.0f),  f32(0.0f), f32(0.0f), f32(1.0f),
                       f32(0.0f),  f32(0.0f),  f32(0.0f),  f32(1.0f), f32(0.0f)};
    uint64_t out[5];
    size_t ns = rp_unit_stages(rti);
    uint64_t *stages = calloc(ns, sizeof *stages);
    if (rp_rti(rti, in, out, stages) != RP_OK) {
        fprintf(stderr, "rp_rti: %s\n", rp_last_error());
        return 1;
    }
    printf("raypipe %s: rti f32 valid %" PRIu64 " hit %" PRIu64 " t %08" PRIx64 " u %08" PRIx64
           " v %08" PRIx64 "\n",
           rp_version(), out[0], out[1], out[2], out[3], out[4]);
    for (size_t i = 0; i < ns; i++)
        printf("  %-10s %08" PRIx64 "\n", rp_unit_stage_name(rti, i), stages[i]);
    free(stages);

    /* the same test 1000 times in one call (the SIMD kernels) */
    enum { N = 1000 };
    uint64_t *rows = malloc(sizeof(uint64_t) * 17 * N), *outs = malloc(sizeof(uint64_t) * 5 * N);
    for (int k = 0; k < N; k++) memcpy(rows + 17 * k, in, sizeof in);
    if (rp_eval_batch(rti, N, rows, 17 * N, outs, 5 * N) != RP_OK) {
        fprintf(stderr, "rp_eval_batch: %s\n", rp_last_error());
        return 1;
    }
    printf("batch of %d: last t %08" PRIx64 "\n", N, outs[5 * (N - 1) + 2]);
    free(rows);
    free(outs);

    /* bad input is an error code and a message, never a crash */
    RpUnit *bad = NULL;
    int rc = rp_unit_new("rti", "f33", NULL, &bad);
    printf("rp_unit_new(\"f33\") = %d: %s\n", rc, rp_last_error());
    rp_unit_free(rti);
    return 0;
}
