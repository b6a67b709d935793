/* include/specconv_spectrum.h against the spectral file `convert` writes of the colour a
 * compact file stores (tests/it/compact.rs builds and runs this; the dumps come from
 * tests/compact_check.py dump):
 *
 *   decode_check HEADER TEXELS BAKED    every stored texel of level 0 (nine values, made six by
 *                                       scs_texel_of_stored): within one half step of the
 *                                       baked half at every band, and within the half step of
 *                                       the larger neighbour of the baked file's linear
 *                                       interpolation at 1,000 random wavelengths (the
 *                                       tolerances of python/tests/test_compact.py); prints
 *                                       the counts and the largest errors, exit 0 when all pass
 *   decode_check --parse-only TEXT      parses TEXT: "parsed bands=N" (exit 0) or
 *                                       "refused: why" (exit 3); never a crash
 *   decode_check --bands TEXT           parses TEXT: its wavelengths (17 digits) on a line
 *                                       (exit 0) or "refused: why" (exit 3)
 *   decode_check --mutate TEXT N        parses N damaged copies of TEXT (truncated, bytes
 *                                       changed to the grammar's own characters, spans cut
 *                                       or repeated) and decodes a few texels with each one
 *                                       parsed: "mutations=N parsed=P refused=R" (exit 0)
 *   decode_check --reference HEADER TABLE
 *                                       testdata/compact/reference's texels (item 47.4): each
 *                                       row's nine stored values made six by
 *                                       scs_texel_of_stored (bit for bit the table's) and decoded
 *                                       within a float32 bound of the library's spectrum, NaN
 *                                       where it is NaN; "reference rows=N worst=W" (exit 0),
 *                                       the failures first (exit 1)
 *   decode_check --print TEXT TEXELS    each texel's spectrum at the bands, a line each (9
 *                                       digits: the float itself; python/tests/test_compact.py
 *                                       holds it to the other decoders)
 */
#define SPECCONV_SPECTRUM_IMPLEMENTATION
#include "specconv_spectrum.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void die(const char *what, const char *path) {
    fprintf(stderr, "decode_check: %s: %s\n", path, what);
    exit(2);
}

static char *slurp(const char *path) {
    FILE *f = fopen(path, "rb");
    char *buf;
    long len;
    if (!f) die("cannot open", path);
    if (fseek(f, 0, SEEK_END) || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) die("cannot seek", path);
    buf = (char *)malloc((size_t)len + 1);
    if (!buf) die("out of memory", path);
    if (fread(buf, 1, (size_t)len, f) != (size_t)len) die("cannot read", path);
    buf[len] = '\0';
    fclose(f);
    return buf;
}

/* A dump: "rows cols", then (baked only) a line of cols wavelengths, then rows × cols numbers. */
static float *read_table(const char *path, long *rows, long cols, double *wl) {
    FILE *f = fopen(path, "r");
    long c, i;
    float *v;
    if (!f) die("cannot open", path);
    if (fscanf(f, "%ld %ld", rows, &c) != 2 || *rows < 0 || c != cols) die("bad first line", path);
    for (i = 0; wl && i < cols; i++)
        if (fscanf(f, "%lf", &wl[i]) != 1) die("bad wavelengths", path);
    v = (float *)malloc(sizeof(float) * (size_t)(*rows * cols + 1));
    if (!v) die("out of memory", path);
    for (i = 0; i < *rows * cols; i++) {
        double d;
        if (fscanf(f, "%lf", &d) != 1) die("too few numbers", path);
        v[i] = (float)d; /* 9 digits: the float itself */
    }
    fclose(f);
    return v;
}

/* The spacing of half floats at |v| (their subnormals' below 2^-14). */
static double half_spacing(double v) {
    int e;
    double a = fabs(v);
    if (a < ldexp(1, -14)) a = ldexp(1, -14);
    frexp(a, &e); /* a = f · 2^e, f in [0.5, 1): floor(log2 a) = e − 1 */
    return ldexp(1, e - 1 - 10);
}

/* v rounded to the nearest half (ties to even, as the file's writer rounds). */
static double to_half(double v) {
    double h;
    if (isnan(v)) return v;
    h = rint(v / half_spacing(v)) * half_spacing(v);
    return fabs(h) > 65504 ? copysign(INFINITY, v) : h;
}

static uint64_t rng_state = 34;
static double uniform(double lo, double hi) { /* xorshift64*: fixed seed, same draws each run */
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return lo + (hi - lo) * (double)((rng_state * 2685821657736338717ULL) >> 11) * 0x1p-53;
}

static long below(long k) { return (long)(uniform(0, 1) * (double)k) % (k > 0 ? k : 1); }

/* The --mutate mode: hostile texts near a valid one, where a parser's mistakes hide. */
static int mutate(const char *path, long count) {
    static const char alphabet[] = " \n0123456789.-+eEnaifxyXYZ";
    static const float probes[4][6] = {
        {0.2f, 0.3f, 0.1f, 0, 0, 0}, {0, 0, 0, 1, -1, 1}, {-1, 2, 0.5f, 0, 0, 0}, {1e30f, 1, 1, 1e30f, 0, 0}};
    char *text = slurp(path), *copy, err[256];
    long len = (long)strlen(text), i, parsed = 0, refused = 0;
    float out[4096];
    copy = (char *)malloc((size_t)len * 2 + 2);
    if (!copy) die("out of memory", path);
    for (i = 0; i < count; i++) {
        long l = len, edits = 1 + below(4), e;
        scs_model *m;
        memcpy(copy, text, (size_t)len + 1);
        for (e = 0; e < edits && l > 0; e++) {
            long at = below(l), span = 1 + below(40);
            switch (below(4)) {
            case 0: l = at; copy[l] = '\0'; break; /* truncated */
            case 1: copy[at] = alphabet[below((long)sizeof alphabet - 1)]; break;
            case 2: /* a span cut */
                if (at + span > l) span = l - at;
                memmove(copy + at, copy + at + span, (size_t)(l - at - span) + 1);
                l -= span;
                break;
            default: /* a span repeated (a line twice, a number doubled), within 2 × len */
                if (at + span > l) span = l - at;
                if (l + span > 2 * len) break;
                memmove(copy + at + span, copy + at, (size_t)(l - at) + 1);
                l += span;
                break;
            }
        }
        m = scs_model_parse(copy, err, sizeof err);
        if (!m) {
            refused++;
            continue;
        }
        parsed++;
        if (scs_bands(m) <= (int)(sizeof out / sizeof out[0])) {
            int p;
            for (p = 0; p < 4; p++) {
                scs_decode_bands(m, probes[p], out);
                (void)scs_decode_at(m, probes[p], 555.5);
            }
        }
        scs_model_free(m);
    }
    printf("mutations=%ld parsed=%ld refused=%ld\n", count, parsed, refused);
    free(copy);
    free(text);
    return 0;
}

/* The --print mode. */
static int print_bands(const char *header, const char *texels) {
    char err[512], *text = slurp(header);
    scs_model *m = scs_model_parse(text, err, sizeof err);
    long rows, t;
    int b;
    float *tex, *out;
    free(text);
    if (!m) die(err, header);
    tex = read_table(texels, &rows, 6, NULL);
    out = (float *)malloc(sizeof(float) * (size_t)scs_bands(m));
    if (!out) die("out of memory", texels);
    for (t = 0; t < rows; t++) {
        scs_decode_bands(m, tex + 6 * t, out);
        for (b = 0; b < scs_bands(m); b++) printf(b ? " %.9g" : "%.9g", (double)out[b]);
        printf("\n");
    }
    free(out);
    free(tex);
    scs_model_free(m);
    return 0;
}

/* Whether two floats are the same value (NaN equal to NaN). */
static int same_float(float a, float b) { return (isnan(a) && isnan(b)) || a == b; }

static int reference(const char *header, const char *table) {
    char err[512], *text = slurp(header), *body = slurp(table), *line, *next;
    scs_model *m = scs_model_parse(text, err, sizeof err);
    long rows = 0, bad = 0;
    double worst = 0;
    float *got, *want;
    int n, b, k;
    free(text);
    if (!m) die(err, header);
    n = scs_bands(m);
    got = (float *)malloc(sizeof(float) * (size_t)n);
    want = (float *)malloc(sizeof(float) * (size_t)n);
    if (!got || !want) die("out of memory", table);
    for (line = body; line && *line; line = next) {
        float stored[9], texel[6], six[6];
        double size = 1;
        char *p = line, *end;
        next = strchr(line, '\n');
        if (next) *next++ = '\0';
        if (!strstr(line, " = ")) continue;
        for (k = 0; k < 9; k++, p = end) stored[k] = strtof(p, &end);
        if (strncmp(p, " =", 2)) die("a row is not 9 = 6 = bands", table);
        for (p += 2, k = 0; k < 6; k++, p = end) texel[k] = strtof(p, &end);
        if (strncmp(p, " =", 2)) die("a row is not 9 = 6 = bands", table);
        for (p += 2, b = 0; b < n; b++, p = end) want[b] = strtof(p, &end);
        scs_texel_of_stored(m, stored, six);
        for (k = 0; k < 6; k++) {
            if (!same_float(six[k], texel[k]) && bad++ < 10)
                printf("row %ld value %d: %.9g, the table's %.9g\n", rows, k, six[k], texel[k]);
            if (isfinite(texel[k])) size += fabs(texel[k]);
        }
        scs_decode_bands(m, six, got);
        for (b = 0; b < n; b++) {
            double d;
            if (isnan(got[b]) || isnan(want[b])) {
                if (isnan(got[b]) != isnan(want[b]) && bad++ < 10)
                    printf("row %ld band %d: %.9g, the library's %.9g\n", rows, b, got[b], want[b]);
                continue;
            }
            /* A float32 bound: 2^-16 of the texel's size (1 + the sum of its values' magnitudes). */
            d = got[b] == want[b] ? 0 : fabs((double)got[b] - (double)want[b]) / (size * 0x1p-16);
            if (d > worst) worst = d;
            if (d > 1 && bad++ < 10) printf("row %ld band %d: %.9g, the library's %.9g\n", rows, b, got[b], want[b]);
        }
        rows++;
    }
    printf("reference rows=%ld worst=%.4f%s\n", rows, worst, bad ? " FAILED" : "");
    free(body);
    free(got);
    free(want);
    scs_model_free(m);
    return bad || rows == 0;
}

int main(int argc, char **argv) {
    char err[512], *text;
    scs_model *m;
    long texels, rows, t, j, bad = 0, nan_texels = 0, band_values = 0, at_values = 0;
    int n, b, k;
    const int draws = 1000;
    double *wl, *at, max_band = 0, sum_band = 0, max_at = 0;
    float *tex, *baked, *got;

    if (argc == 3 && !strcmp(argv[1], "--parse-only")) {
        text = slurp(argv[2]);
        m = scs_model_parse(text, err, sizeof err);
        free(text);
        if (!m) {
            printf("refused: %s\n", err);
            return 3;
        }
        printf("parsed bands=%d\n", scs_bands(m));
        scs_model_free(m);
        return 0;
    }
    if (argc == 3 && !strcmp(argv[1], "--bands")) {
        int b;
        text = slurp(argv[2]);
        m = scs_model_parse(text, err, sizeof err);
        free(text);
        if (!m) {
            printf("refused: %s\n", err);
            return 3;
        }
        for (b = 0; b < scs_bands(m); b++) printf(b ? " %.17g" : "%.17g", scs_wavelengths(m)[b]);
        printf("\n");
        scs_model_free(m);
        return 0;
    }
    if (argc == 4 && !strcmp(argv[1], "--mutate")) return mutate(argv[2], atol(argv[3]));
    if (argc == 4 && !strcmp(argv[1], "--print")) return print_bands(argv[2], argv[3]);
    if (argc == 4 && !strcmp(argv[1], "--reference")) return reference(argv[2], argv[3]);
    if (argc != 4) {
        fprintf(stderr, "usage: decode_check HEADER TEXELS BAKED | --parse-only TEXT\n");
        return 2;
    }
    text = slurp(argv[1]);
    m = scs_model_parse(text, err, sizeof err);
    free(text);
    if (!m) die(err, argv[1]);
    n = scs_bands(m);
    wl = (double *)malloc(sizeof(double) * (size_t)n);
    at = (double *)malloc(sizeof(double) * draws);
    got = (float *)malloc(sizeof(float) * (size_t)n);
    if (!wl || !at || !got) die("out of memory", argv[1]);
    tex = read_table(argv[2], &texels, 9, NULL);
    baked = read_table(argv[3], &rows, n, wl);
    if (rows != texels) die("not as many texels as the compact file's", argv[3]);
    for (b = 0; b < n; b++)
        if (fabs(wl[b] - scs_wavelengths(m)[b]) > 1e-9) die("other wavelengths than the header's", argv[3]);
    for (k = 0; k < draws; k++) at[k] = uniform(wl[0], wl[n - 1]);

    for (t = 0; t < texels; t++) {
        const float *want = baked + t * n;
        float texel[6];
        int has_nan = 0;
        scs_texel_of_stored(m, tex + t * 9, texel);
        scs_decode_bands(m, texel, got);
        /* At the bands: the half the file stores, within one step of the decoded value's. */
        for (b = 0; b < n; b++) {
            double steps;
            if (isnan(want[b]) || isnan(got[b])) {
                if (isnan(want[b]) != isnan(got[b])) {
                    if (bad++ < 10) printf("texel %ld band %d: NaN in one only (%g, %g)\n", t, b, want[b], got[b]);
                }
                has_nan = 1;
                continue;
            }
            steps = fabs(to_half(got[b]) - want[b]) / half_spacing(want[b]);
            band_values++;
            sum_band += steps;
            if (steps > max_band) max_band = steps;
            if (steps > 1 + 1e-9 && bad++ < 10)
                printf("texel %ld band %d: %.9g against %.9g, %.3f half steps\n", t, b, got[b], want[b], steps);
        }
        if (has_nan) {
            nan_texels++;
            continue;
        }
        /* At random wavelengths: the baked file's linear interpolation, within the half step
         * of the larger neighbour. */
        for (k = 0; n > 1 && k < draws; k++) {
            double mine = scs_decode_at(m, texel, at[k]), theirs, step, steps;
            for (j = 1; j < n - 1 && wl[j] < at[k]; j++) {}
            theirs = want[j - 1] + (want[j] - want[j - 1]) * (at[k] - wl[j - 1]) / (wl[j] - wl[j - 1]);
            step = half_spacing(fmax(fabs(want[j]), fabs(want[j - 1])));
            steps = fabs(mine - theirs) / step;
            at_values++;
            if (steps > max_at) max_at = steps;
            if (!(steps <= 1 + 1e-9) && bad++ < 10)
                printf("texel %ld at %.4f nm: %.9g against %.9g, %.3f half steps\n", t, at[k], mine, theirs, steps);
        }
    }
    printf("texels=%ld bands=%d nan_texels=%ld band_values=%ld max_band_steps=%.4f mean_band_steps=%.6f "
           "wavelength_values=%ld max_wavelength_steps=%.4f failures=%ld\n",
           texels, n, nan_texels, band_values, max_band, band_values ? sum_band / band_values : 0.0,
           at_values, max_at, bad);
    if (band_values && sum_band / band_values > 0.01) {
        printf("mean error above 0.01 half steps\n");
        bad++;
    }
    printf(bad ? "FAIL\n" : "ok\n");
    free(wl);
    free(at);
    free(got);
    free(tex);
    free(baked);
    scs_model_free(m);
    return bad ? 1 : 0;
}
