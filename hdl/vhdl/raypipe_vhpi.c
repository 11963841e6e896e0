/* raypipe's live model for VHDL testbenches: VHPIDIRECT entry points over the C ABI
 * (capi/include/raypipe.h) in the types GHDL passes: names as NUL-padded string(1 to 64),
 * encodings as VHDL integers (32-bit two's complement: formats of at most 32 bits), arrays as
 * pointers to their elements, a handle as a small integer. Built into a shared library by
 * hdl/vhdl/live_run, which names it in raypipe_vhpi.vhd's foreign attributes (GHDL's mcode
 * backend loads it when the simulation starts). Errors go to stderr and come back as a
 * negative code (the C ABI's code, negated). */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "raypipe.h"

#define MAX_UNITS 64
static RpUnit *units[MAX_UNITS];
static RpCover *covers[MAX_UNITS];

static void name(char *dst, const char *src) {
    memcpy(dst, src, 64);
    dst[64] = '\0';
}

static RpUnit *unit(int32_t h) {
    return h >= 0 && h < MAX_UNITS ? units[h] : NULL;
}

int32_t rp_vhpi_new(const char *u, const char *f, const char *o) {
    char un[65], fm[65], op[65];
    name(un, u);
    name(fm, f);
    name(op, o);
    for (int32_t h = 0; h < MAX_UNITS; h++) {
        if (units[h] != NULL) continue;
        int rc = rp_unit_new(un, fm, op, &units[h]);
        if (rc != RP_OK) {
            fprintf(stderr, "rp_unit_new(%s, %s, \"%s\") = %d: %s\n", un, fm, op, rc, rp_last_error());
            return -rc;
        }
        if (rp_unit_width(units[h]) > 32) {
            fprintf(stderr, "rp_vhpi_new: %s has %u bits; VHDL integers hold 32\n", fm, rp_unit_width(units[h]));
            rp_unit_free(units[h]);
            units[h] = NULL;
            return -RP_ERR_ARGUMENT;
        }
        return h;
    }
    fprintf(stderr, "rp_vhpi_new: more than %d units\n", MAX_UNITS);
    return -RP_ERR_ARGUMENT;
}

/* what 0: inputs, 1: outputs, 2: stage signals, 3: the format's width */
int32_t rp_vhpi_count(int32_t h, int32_t what) {
    RpUnit *u = unit(h);
    switch (what) {
        case 0: return (int32_t)rp_unit_inputs(u);
        case 1: return (int32_t)rp_unit_outputs(u);
        case 2: return (int32_t)rp_unit_stages(u);
        default: return (int32_t)rp_unit_width(u);
    }
}

int32_t rp_vhpi_out_width(int32_t h, int32_t i) {
    return i < 0 ? 0 : (int32_t)rp_unit_output_width(unit(h), (size_t)i);
}

int32_t rp_vhpi_stage_width(int32_t h, int32_t i) {
    return i < 0 ? 0 : (int32_t)rp_unit_stage_width(unit(h), (size_t)i);
}

int32_t rp_vhpi_encode(int32_t h, double x) {
    uint64_t b = 0;
    if (rp_encode(unit(h), x, &b) != RP_OK) {
        fprintf(stderr, "rp_encode: %s\n", rp_last_error());
        return 0;
    }
    return (int32_t)(uint32_t)b;
}

/* one test: in[0 .. inputs-1] -> out[0 .. outputs-1], stg[0 .. stages-1]; *rc 0 or -code */
void rp_vhpi_eval(int32_t h, const int32_t *in, int32_t *out, int32_t *stg, int32_t *rc) {
    RpUnit *u = unit(h);
    uint64_t i64[64], o64[8], s64[256];
    size_t ni = rp_unit_inputs(u), no = rp_unit_outputs(u), ns = rp_unit_stages(u);
    uint32_t w = rp_unit_width(u);
    uint64_t mask = w >= 64 ? ~0ull : (1ull << w) - 1;
    if (ni > 64 || no > 8 || ns > 256) {
        *rc = -RP_ERR_LENGTH;
        return;
    }
    for (size_t k = 0; k < ni; k++) i64[k] = (uint64_t)(uint32_t)in[k] & mask;
    int r = rp_eval(u, i64, ni, o64, 8, s64, ns);
    if (r != RP_OK) {
        fprintf(stderr, "rp_eval: %s\n", rp_last_error());
        *rc = -r;
        return;
    }
    for (size_t k = 0; k < no; k++) out[k] = (int32_t)(uint32_t)o64[k];
    for (size_t k = 0; k < ns; k++) stg[k] = (int32_t)(uint32_t)s64[k];
    *rc = 0;
}

/* a coverage recorder of the unit u, format f, options o (docs/coverage.md): its handle, or
 * a negative code */
int32_t rp_vhpi_cover_new(const char *u, const char *f, const char *o) {
    char un[65], fm[65], op[65];
    name(un, u);
    name(fm, f);
    name(op, o);
    for (int32_t c = 0; c < MAX_UNITS; c++) {
        if (covers[c] != NULL) continue;
        int rc = rp_cover_new(un, fm, op, &covers[c]);
        if (rc != RP_OK) {
            fprintf(stderr, "rp_cover_new(%s, %s, \"%s\") = %d: %s\n", un, fm, op, rc, rp_last_error());
            return -rc;
        }
        return c;
    }
    fprintf(stderr, "rp_vhpi_cover_new: more than %d recorders\n", MAX_UNITS);
    return -RP_ERR_ARGUMENT;
}

/* counts the input row in[0 .. inputs of unit h - 1] into recorder c; *rc 0 or -code */
void rp_vhpi_cover_add(int32_t c, int32_t h, const int32_t *in, int32_t *rc) {
    RpUnit *u = unit(h);
    RpCover *r = c >= 0 && c < MAX_UNITS ? covers[c] : NULL;
    uint64_t i64[64];
    size_t ni = rp_unit_inputs(u);
    uint32_t w = rp_unit_width(u);
    uint64_t mask = w >= 64 ? ~0ull : (1ull << w) - 1;
    if (ni > 64) {
        *rc = -RP_ERR_LENGTH;
        return;
    }
    for (size_t k = 0; k < ni; k++) i64[k] = (uint64_t)(uint32_t)in[k] & mask;
    int e = rp_cover_add(r, i64, ni);
    if (e != RP_OK) fprintf(stderr, "rp_cover_add: %s\n", rp_last_error());
    *rc = -e;
}

/* writes recorder c's coverage file to the path p (NUL-padded string(1 to 256)) and frees the
 * recorder; the rows recorded, or a negative code */
int32_t rp_vhpi_cover_write(int32_t c, const char *p) {
    char path[257];
    RpCover *r = c >= 0 && c < MAX_UNITS ? covers[c] : NULL;
    memcpy(path, p, 256);
    path[256] = '\0';
    int e = rp_cover_write(r, path);
    if (e != RP_OK) {
        fprintf(stderr, "rp_cover_write(%s): %s\n", path, rp_last_error());
        return -e;
    }
    int32_t rows = (int32_t)rp_cover_rows(r);
    rp_cover_free(r);
    covers[c] = NULL;
    return rows;
}
