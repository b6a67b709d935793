/* specconv_spectrum.h: decode specconv's compact textures (docs/compact.md) in C99.
 *
 * Single header, stb style: include it anywhere for the declarations, and in exactly one .c
 * file write
 *
 *     #define SPECCONV_SPECTRUM_IMPLEMENTATION
 *     #include "specconv_spectrum.h"
 *
 * for the code. Needs libc and libm only (link with -lm). It lives in include/ because it is
 * the one file a C program copies or puts on its include path; it has no sources beside it.
 *
 * A compact texel is six floats (X, Y, Z, u0, u1, u2); the model that turns it into a spectrum
 * is the text of the file's `specconvCompact` attribute, which scs_model_parse reads. A file
 * stores nine values a texel (R G B U.0 U.1 U.2 UF.0 UF.1 UF.2: the colour in the working
 * space the text names, u as half, u as float32), which scs_texel_of_stored turns into six:
 *
 *     char err[256];
 *     scs_model *m = scs_model_parse(header_text, err, sizeof err);
 *     if (!m) { fprintf(stderr, "%s\n", err); return 1; }
 *     float *r = malloc(sizeof(float) * (size_t)scs_bands(m));
 *     scs_decode_bands(m, texel, r);               // at scs_wavelengths(m)
 *     float at550 = scs_decode_at(m, texel, 550.0); // any wavelength
 *     free(r);
 *     scs_model_free(m);
 *
 * The parser refuses anything the decoder would rely on and not find (counts, finite numbers,
 * a tree whose nodes are each reached once from the root, leaf maps in range); a model, once
 * parsed, is read only: decoding is thread-safe and allocates nothing.
 */
#ifndef SPECCONV_SPECTRUM_H
#define SPECCONV_SPECTRUM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct scs_model scs_model;

/* The model of a `specconv compact 2` header text, or NULL with a message in err (errlen
 * bytes, always terminated when errlen > 0; err may be NULL). Free it with scs_model_free. */
scs_model *scs_model_parse(const char *text, char *err, size_t errlen);
void scs_model_free(scs_model *m);

/* The output grid: scs_bands(m) wavelengths in nm, increasing. */
int scs_bands(const scs_model *m);
const double *scs_wavelengths(const scs_model *m);

/* The spectrum of a texel (X, Y, Z, u0, u1, u2) at the model's wavelengths: out holds
 * scs_bands(m) values. A NaN or infinite X, Y or Z (or u, with clip 1) gives NaN in every
 * band. */
void scs_decode_bands(const scs_model *m, const float texel[6], float *out);

/* The six values the decoders take from the nine a file stores (R G B U.0 U.1 U.2 UF.0 UF.1
 * UF.2): the colour's XYZ, M · (R, G, B) with M the text's `rgb` matrix, summed in double in
 * this order and rounded to float once; u = U + UF (one of them is 0). */
void scs_texel_of_stored(const scs_model *m, const float stored[9], float texel[6]);

/* The working space's matrix to XYZ (the text's `rgb` line), 9 numbers row by row. */
const double *scs_rgb_to_xyz(const scs_model *m);

/* The spectrum at any wavelength: the linear interpolation of the two neighbouring bands
 * (held flat beyond the ends), as a reader of the spectral file interpolates. */
float scs_decode_at(const scs_model *m, const float texel[6], double wavelength_nm);

/* ---- ENCODER: texels from colours (docs/compact.md, "Texels from colours in C") ----------
 *
 * A renderer that keeps its RGB textures makes the texels at load, as pbrt-v4 and Mitsuba
 * make rgb2spec's coefficients: the colour as it is, and u, the dual unknowns of the bounded
 * projection (min ½‖r − r₀‖² s.t. A·r = c, 0 ≤ r ≤ 1; outside the object-colour solid, r₀
 * projected onto the nearest colour of its surface in CIELAB with the colour a penalty, and u
 * for that one; the perfect white within its rounding, or a grey brighter, r ≡ 1 with
 * u = (0, t, 0)), as specconv's library makes
 * them (specconv_spectral::compact::Compact::encode_f32). No allocation: the caller passes a
 * workspace of scs_encode_work_size(m) bytes (at most SCS_ENCODE_WORK_MAX, aligned for double),
 * one per thread; the model is only read. Every loop has a fixed bound (docs/compact.md). */

/* What the encoder did with a colour (the library's counts). */
enum {
    SCS_IN_RANGE = 0,   /* the model's spectrum is in [0, 1] (or the header's clip is 0): u = 0 */
    SCS_PROJECTED = 1,  /* projected onto the colour: u ≠ 0 */
    SCS_OUTSIDE = 2,    /* outside the object-colour solid: the nearest colour of its surface */
    SCS_NOT_FINITE = 3  /* NaN or ±∞ in the colour: u = 0, and the texel decodes to NaN */
};

/* Bytes of workspace scs_encode_xyz needs for m: 7 doubles a band. */
size_t scs_encode_work_size(const scs_model *m);
#define SCS_ENCODE_WORK_MAX (7 * (size_t)100000 * sizeof(double))

/* The texel (X, Y, Z, u0, u1, u2) of the colour xyz (CIE XYZ, white Y = 1, the colour the
 * texture means: any value, HDR, negative and NaN included) into texel; returns SCS_IN_RANGE,
 * SCS_PROJECTED, SCS_OUTSIDE or SCS_NOT_FINITE. work: scs_encode_work_size(m) bytes. */
int scs_encode_xyz(const scs_model *m, const float xyz[3], float texel[6], void *work);

/* The same from a linear RGB colour and the working space's matrix to XYZ (row major, white
 * Y = 1: XYZ = to_xyz · rgb, computed in double and rounded to float, as a texture's colour
 * converted to XYZ in float32 is). */
int scs_encode_rgb(const scs_model *m, const double to_xyz[9], const float rgb[3], float texel[6],
                   void *work);

#ifdef __cplusplus
}
#endif

#endif /* SPECCONV_SPECTRUM_H */

#ifdef SPECCONV_SPECTRUM_IMPLEMENTATION
#ifndef SPECCONV_SPECTRUM_IMPLEMENTED
#define SPECCONV_SPECTRUM_IMPLEMENTED

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The numbers this header shares with the library, made from its constants (what each means
 * is said where the library defines it, named beside it). The grammar's limits (docs/compact.md,
 * "The header text"): at most SCS_MAX_DEPTH splits from the root to a leaf (decoding walks the
 * tree with a fixed stack, no allocation, no recursion; specconv's models are 3 to 6 deep), at
 * most SCS_MAX_BANDS bands, the dark level SCS_DARK, blend widths up to SCS_MAX_WIDTH. The
 * encoder's: the dual's Newton steps and tolerances, the CIELAB search's, the penalty of an
 * outside colour's projection, the perfect white's rule (with OpenColorIO's D65 xy). */
/* BEGIN GENERATED: the library's constants (by `cargo run -p specconv-dev -- generate`, from c_header.rs) */
#define SCS_MAX_DEPTH              64            /* compact::MAX_DEPTH */
#define SCS_MAX_BANDS              100000        /* compact::MAX_BANDS */
#define SCS_WHOLE_STEPS            1e-9          /* Grid::WHOLE_STEPS */
#define SCS_DARK                   0.01          /* compact::DARK */
#define SCS_MAX_WIDTH              0.5           /* compact::MAX_WIDTH */
#define SCS_DUAL_STEPS_            60            /* solid::DUAL_STEPS */
#define SCS_RESIDUAL_              1e-13         /* solid::RESIDUAL */
#define SCS_STALLED_RESIDUAL_      1e-9          /* solid::STALLED_RESIDUAL */
#define SCS_HESSIAN_FLOOR_         1e-12         /* solid::HESSIAN_FLOOR */
#define SCS_STEP_FLOOR_            1e-15         /* solid::STEP_FLOOR */
#define SCS_PSI_ROUNDING_          1e-15         /* solid::PSI_ROUNDING */
#define SCS_ARMIJO_                1e-4          /* solid::ARMIJO */
#define SCS_POLISH_HALVINGS_       40            /* solid::POLISH_HALVINGS */
#define SCS_STRONGER_PENALTIES_    8             /* solid::STRONGER_PENALTIES */
#define SCS_NEAREST_STEPS_         80            /* nearest::STEPS */
#define SCS_NEAREST_SUB_           50            /* nearest::SUB_STEPS */
#define SCS_NEAREST_TRIES_         64            /* nearest::TRIES */
#define SCS_NEAREST_MU_START_      0.001         /* nearest::MU_START */
#define SCS_NEAREST_MU_SHRINK_     0.25          /* nearest::MU_SHRINK */
#define SCS_NEAREST_MU_FLOOR_      1e-9          /* nearest::MU_FLOOR */
#define SCS_NEAREST_MU_GROW_       8.0           /* nearest::MU_GROW */
#define SCS_NEAREST_MU_CAP_        1e12          /* nearest::MU_CAP */
#define SCS_NEAREST_SUB_TOLERANCE_ 1e-10         /* nearest::SUB_TOLERANCE */
#define SCS_NEAREST_SETTLED_PHI_   1e-10         /* nearest::SETTLED_PHI */
#define SCS_NEAREST_SETTLED_MOVE_  1e-12         /* nearest::SETTLED_MOVE */
#define SCS_REGULARISED_STEPS_     200           /* bounded::REGULARISED_STEPS */
#define SCS_REGULARISATION_        1e-9          /* bounded::REGULARISATION */
#define SCS_WHITE_ROUNDING_        1.9073486328125e-6 /* bounded::WHITE_ROUNDING */
#define SCS_SAME_WHITE_            0.001         /* bounded::SAME_WHITE */
#define SCS_D65_X_                 0.3127        /* SRGB.white[0] */
#define SCS_D65_Y_                 0.329         /* SRGB.white[1] */
/* END GENERATED: the library's constants */

typedef struct {
    int leaf;         /* 1: a leaf of map k; 0: a split */
    int axis;         /* 0: x, 1: y */
    double value;     /* v */
    double width;     /* w */
    long below, above; /* node indices */
    long k;           /* the leaf's map */
} scs_node_;

struct scs_model {
    int n;          /* bands */
    double *wl;     /* n wavelengths, nm */
    double white[2];
    double dark;
    double blend;
    int clip;
    double rgb[9];  /* the working space's matrix to XYZ, rows of X, Y, Z */
    long nodes_n;
    scs_node_ *nodes;
    long maps_n;
    double *maps;   /* maps_n × 4 × n: Tx, Ty, Tz, o of each leaf */
    double *b;      /* 3 × n: a_X, a_Y, a_Z */
};

static void scs_fail_(char *err, size_t errlen, int line, const char *fmt, ...) {
    va_list ap;
    size_t used = 0;
    if (!err || errlen == 0) return;
    if (line > 0) {
        int k = snprintf(err, errlen, "line %d: ", line);
        used = k < 0 ? 0 : (size_t)k < errlen ? (size_t)k : errlen - 1;
    }
    va_start(ap, fmt);
    vsnprintf(err + used, errlen - used, fmt, ap);
    va_end(ap);
}

/* The next space-separated word of *p, terminated in place; NULL at the line's end. */
static char *scs_word_(char **p) {
    char *s = *p, *w;
    while (*s == ' ' || *s == '\t') s++;
    if (!*s) { *p = s; return NULL; }
    w = s;
    while (*s && *s != ' ' && *s != '\t') s++;
    if (*s) *s++ = '\0';
    *p = s;
    return w;
}

/* Whether the line's first word is `word`, the line left as it is. */
static int scs_first_is_(const char *line, const char *word) {
    size_t k = strlen(word);
    while (*line == ' ' || *line == '\t') line++;
    return !strncmp(line, word, k) && (line[k] == '\0' || line[k] == ' ' || line[k] == '\t');
}

/* Whether a line has the grammar's form: no control character, a keyword of a-z then a-z, 0-9
 * or _ up to the first space, and (but for `model`, whose rest is any text) fields separated by
 * single spaces, none empty. NULL when it has, else why not. */
static const char *scs_line_form_(const char *line) {
    static const char *const known[] = {"hash", "grid", "wavelengths", "white", "dark", "blend",
                                        "clip", "rgb", "node", "map", "b", NULL};
    const char *const *k;
    const char *c;
    int model = !strncmp(line, "model", 5) && (line[5] == ' ' || !line[5]);
    for (c = line; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) return "a control character (a tab, a CR, ...)";
    if (!(*line >= 'a' && *line <= 'z')) return "no keyword (a-z, then a-z, 0-9 or _) at the start";
    for (c = line; *c && *c != ' '; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_'))
            return "no keyword (a-z, then a-z, 0-9 or _) at the start";
    if (model || !*c) return NULL;
    /* Lines of other keywords are skipped, whatever their fields. */
    for (k = known; *k; k++)
        if ((size_t)(c - line) == strlen(*k) && !strncmp(line, *k, (size_t)(c - line))) break;
    if (!*k) return NULL;
    for (; *c; c++)
        if (*c == ' ' && (c[1] == ' ' || !c[1])) return "an empty field (two spaces, or a space at the end)";
    return NULL;
}

/* A number of the grammar, the whole word: [+-]?(D+(.D*)?|.D+)([eE][+-]?D+)?, ASCII digits
 * (strtod alone would take hex, inf, nan and leading spaces, which other readers refuse), finite
 * once read. strtod reads the C locale's decimal point, which is what a program gets unless it
 * calls setlocale. */
static int scs_number_(const char *w, double *out) {
    char *end;
    const char *c;
    size_t digits = 0;
    double v;
    if (!w || !*w) return 0;
    c = w + (*w == '+' || *w == '-');
    for (; *c >= '0' && *c <= '9'; c++) digits++;
    if (*c == '.')
        for (c++; *c >= '0' && *c <= '9'; c++) digits++;
    if (!digits) return 0;
    if (*c == 'e' || *c == 'E') {
        c++;
        c += *c == '+' || *c == '-';
        if (!(*c >= '0' && *c <= '9')) return 0;
        while (*c >= '0' && *c <= '9') c++;
    }
    if (*c) return 0;
    v = strtod(w, &end);
    if (*end || !isfinite(v)) return 0;
    *out = v;
    return 1;
}

/* A non-negative index below `limit` (itself below LONG_MAX), the whole word, digits only. */
static int scs_index_(const char *w, long limit, long *out) {
    long v = 0;
    if (!w || !*w) return 0;
    for (; *w; w++) {
        if (*w < '0' || *w > '9') return 0;
        v = v * 10 + (*w - '0');
        if (v >= limit) return 0; /* also stops before any overflow */
    }
    *out = v;
    return 1;
}

/* Reads exactly `count` numbers of the rest of a line into out. */
static int scs_numbers_(char **p, double *out, long count) {
    long i;
    for (i = 0; i < count; i++)
        if (!scs_number_(scs_word_(p), out + i)) return 0;
    return scs_word_(p) == NULL;
}

/* Whether grid (START END STEP) is a grid of the library (0 < START <= END, STEP > 0, END −
 * START a whole number of steps to SCS_WHOLE_STEPS relative, at most SCS_MAX_BANDS bands) whose bands are
 * the n wavelengths wl exactly: START + i × STEP, the product rounded, then the sum. */
static int scs_grid_is_(const double grid[3], const double *wl, long n) {
    double intervals, whole;
    long i;
    if (!(grid[0] > 0 && grid[2] > 0 && grid[1] >= grid[0])) return 0;
    intervals = (grid[1] - grid[0]) / grid[2];
    whole = floor(intervals + 0.5);
    if (fabs(intervals - whole) > SCS_WHOLE_STEPS * (intervals > 1 ? intervals : 1)) return 0;
    if (whole + 1 > SCS_MAX_BANDS || (long)whole + 1 != n) return 0;
    for (i = 0; i < n; i++) {
        volatile double step = grid[2] * (double)i; /* rounded: no fused multiply-add */
        if (wl[i] != grid[0] + step) return 0;
    }
    return 1;
}

static void *scs_alloc_(size_t count, size_t size) {
    if (count == 0) count = 1;
    if (count > (size_t)-1 / size) return NULL;
    return calloc(count, size);
}

void scs_model_free(scs_model *m) {
    if (!m) return;
    free(m->wl);
    free(m->nodes);
    free(m->maps);
    free(m->b);
    free(m);
}

scs_model *scs_model_parse(const char *text, char *err, size_t errlen) {
    scs_model *m = NULL;
    char *buf = NULL, *p, *next;
    char **lines = NULL;
    long nlines = 0, i, leaves = 0;
    size_t len;
    int seen_white = 0, seen_dark = 0, seen_blend = 0, seen_clip = 0, seen_b[3] = {0, 0, 0};
    int seen_model = 0, seen_hash = 0, seen_grid = 0, seen_rgb = 0;
    double grid[3] = {0, 0, 0};
    char *map_seen = NULL, *node_seen = NULL, *reached = NULL, *map_used = NULL;
    long *stack = NULL;
    int *depth = NULL;

    if (err && errlen) err[0] = '\0';
    if (!text) { scs_fail_(err, errlen, 0, "no text"); return NULL; }
    len = strlen(text);
    /* Every count below is bounded by the text's length, which fits a long with room. */
    if (len > (size_t)1 << 30) { scs_fail_(err, errlen, 0, "text longer than 1 GiB"); return NULL; }
    buf = (char *)malloc(len + 1);
    m = (scs_model *)scs_alloc_(1, sizeof *m);
    if (!buf || !m) goto oom;
    memcpy(buf, text, len + 1);

    /* The lines, split in place ("\r\n" read as "\n"). */
    for (p = buf, nlines = 1; *p; p++) nlines += *p == '\n';
    lines = (char **)scs_alloc_((size_t)nlines, sizeof *lines);
    if (!lines) goto oom;
    for (p = buf, i = 0; p; p = next, i++) {
        next = strchr(p, '\n');
        if (next) *next++ = '\0';
        if (*p && p[strlen(p) - 1] == '\r') p[strlen(p) - 1] = '\0';
        lines[i] = p;
    }
    if (strcmp(lines[0], "specconv compact 2") != 0) {
        if (!strncmp(lines[0], "specconv compact ", 17))
            scs_fail_(err, errlen, 1,
                      "compact version '%.20s', which this header does not read (it reads "
                      "`specconv compact 2`): convert the texture again, or use the header that "
                      "came with the specconv that wrote it", lines[0] + 17);
        else
            scs_fail_(err, errlen, 1, "not a text of `specconv compact 2`");
        goto fail;
    }
    for (i = 1; i < nlines; i++) {
        const char *why = lines[i][0] ? scs_line_form_(lines[i]) : NULL;
        if (why) { scs_fail_(err, errlen, (int)i + 1, "%s", why); goto fail; }
    }

    /* First pass (docs/compact.md, "The header text"): the wavelengths fix n, and the node
     * and map lines their counts, before any line is read that depends on them. */
    for (i = 1; i < nlines; i++) {
        char *q = lines[i];
        if (scs_first_is_(q, "wavelengths")) {
            scs_word_(&q);
            long count = 0;
            const char *r;
            if (m->wl) { scs_fail_(err, errlen, (int)i + 1, "a second wavelengths line"); goto fail; }
            /* Count the words without cutting them, then read them. */
            for (r = q; *r;) {
                while (*r == ' ' || *r == '\t') r++;
                if (!*r) break;
                count++;
                while (*r && *r != ' ' && *r != '\t') r++;
            }
            if (count < 1 || count > SCS_MAX_BANDS) {
                scs_fail_(err, errlen, (int)i + 1, "%ld wavelengths (1 to %d)", count, SCS_MAX_BANDS);
                goto fail;
            }
            m->n = (int)count;
            m->wl = (double *)scs_alloc_((size_t)count, sizeof(double));
            if (!m->wl) goto oom;
            if (!scs_numbers_(&q, m->wl, count)) {
                scs_fail_(err, errlen, (int)i + 1, "a wavelength is not a finite number");
                goto fail;
            }
            for (count = 1; count < m->n; count++)
                if (!(m->wl[count] > m->wl[count - 1])) {
                    scs_fail_(err, errlen, (int)i + 1, "wavelengths not increasing");
                    goto fail;
                }
            lines[i] = NULL; /* done with */
        } else if (scs_first_is_(q, "node")) {
            m->nodes_n++;
        } else if (scs_first_is_(q, "map")) {
            m->maps_n++;
        }
    }
    if (!m->wl) { scs_fail_(err, errlen, 0, "no wavelengths line"); goto fail; }
    if (m->nodes_n < 1) { scs_fail_(err, errlen, 0, "no nodes"); goto fail; }
    if (m->maps_n < 1) { scs_fail_(err, errlen, 0, "no maps"); goto fail; }
    /* Each of a map's 4n numbers takes at least two characters: a text too short for its
     * maps is refused before they are allocated, so memory stays bounded by the text. */
    if ((double)m->maps_n * 4.0 * (double)m->n * 2.0 > (double)len) {
        scs_fail_(err, errlen, 0, "%ld map lines of 4 × %d numbers do not fit in %lu characters",
                  m->maps_n, m->n, (unsigned long)len);
        goto fail;
    }
    m->nodes = (scs_node_ *)scs_alloc_((size_t)m->nodes_n, sizeof *m->nodes);
    m->maps = (double *)scs_alloc_((size_t)m->maps_n, 4 * (size_t)m->n * sizeof(double));
    m->b = (double *)scs_alloc_(3, (size_t)m->n * sizeof(double));
    node_seen = (char *)scs_alloc_((size_t)m->nodes_n, 1);
    map_seen = (char *)scs_alloc_((size_t)m->maps_n, 1);
    if (!m->nodes || !m->maps || !m->b || !node_seen || !map_seen) goto oom;

    /* Second pass: everything else. Unknown first words are skipped, as the doc asks. */
    for (i = 1; i < nlines; i++) {
        char *q = lines[i], *w;
        int ln = (int)i + 1;
        if (!q || !(w = scs_word_(&q))) continue;
        if (!strcmp(w, "model")) {
            if (seen_model++) goto bad;
        } else if (!strcmp(w, "hash")) {
            char *h = scs_word_(&q);
            if (seen_hash++ || !h || strlen(h) != 16 || strspn(h, "0123456789abcdef") != 16 || scs_word_(&q)) goto bad;
        } else if (!strcmp(w, "grid")) {
            if (seen_grid++ || !scs_numbers_(&q, grid, 3)) goto bad;
        } else if (!strcmp(w, "white")) {
            if (seen_white++ || !scs_numbers_(&q, m->white, 2)) goto bad;
        } else if (!strcmp(w, "dark")) {
            if (seen_dark++ || !scs_numbers_(&q, &m->dark, 1) || m->dark != SCS_DARK) goto bad;
        } else if (!strcmp(w, "blend")) {
            if (seen_blend++ || !scs_numbers_(&q, &m->blend, 1) || m->blend < 0 || m->blend > SCS_MAX_WIDTH) goto bad;
        } else if (!strcmp(w, "clip")) {
            char *v = scs_word_(&q);
            if (seen_clip++ || !v || scs_word_(&q) || (strcmp(v, "0") && strcmp(v, "1"))) goto bad;
            m->clip = v[0] == '1';
        } else if (!strcmp(w, "rgb")) {
            if (seen_rgb++ || !scs_numbers_(&q, m->rgb, 9)) goto bad;
        } else if (!strcmp(w, "node")) {
            long k;
            scs_node_ *nd;
            char *kind;
            if (!scs_index_(scs_word_(&q), m->nodes_n, &k) || node_seen[k]++) {
                scs_fail_(err, errlen, ln, "node index out of range (%ld nodes) or repeated", m->nodes_n);
                goto fail;
            }
            nd = &m->nodes[k];
            kind = scs_word_(&q);
            if (kind && !strcmp(kind, "leaf")) {
                nd->leaf = 1;
                if (!scs_index_(scs_word_(&q), m->maps_n, &nd->k) || scs_word_(&q)) {
                    scs_fail_(err, errlen, ln, "leaf map out of range (%ld maps)", m->maps_n);
                    goto fail;
                }
                leaves++;
            } else if (kind && !strcmp(kind, "split")) {
                char *axis = scs_word_(&q);
                double v[1];
                if (!axis || (strcmp(axis, "x") && strcmp(axis, "y"))) goto bad;
                nd->axis = axis[0] == 'y';
                if (!scs_number_(scs_word_(&q), &nd->value)) goto bad;
                if (!scs_index_(scs_word_(&q), m->nodes_n, &nd->below) ||
                    !scs_index_(scs_word_(&q), m->nodes_n, &nd->above)) {
                    scs_fail_(err, errlen, ln, "split's node out of range (%ld nodes)", m->nodes_n);
                    goto fail;
                }
                if (!scs_numbers_(&q, v, 1)) goto bad; /* its range: once blend is read */
                nd->width = v[0];
            } else {
                goto bad;
            }
        } else if (!strcmp(w, "map")) {
            long k;
            if (!scs_index_(scs_word_(&q), m->maps_n, &k) || map_seen[k]++) {
                scs_fail_(err, errlen, ln, "map index out of range (%ld maps) or repeated", m->maps_n);
                goto fail;
            }
            if (!scs_numbers_(&q, m->maps + (size_t)k * 4 * (size_t)m->n, 4 * (long)m->n)) {
                scs_fail_(err, errlen, ln, "a map needs 4 × %d finite numbers", m->n);
                goto fail;
            }
        } else if (!strcmp(w, "b")) {
            char *row = scs_word_(&q);
            int r = !row ? -1 : !strcmp(row, "X") ? 0 : !strcmp(row, "Y") ? 1 : !strcmp(row, "Z") ? 2 : -1;
            if (r < 0 || seen_b[r]++ || !scs_numbers_(&q, m->b + (size_t)r * (size_t)m->n, m->n)) {
                scs_fail_(err, errlen, ln, "b needs X, Y or Z once and %d finite numbers", m->n);
                goto fail;
            }
        }
        continue;
    bad:
        scs_fail_(err, errlen, ln, "malformed `%s` line or a repeated one", w);
        goto fail;
    }
    if (!seen_model || !seen_hash || !seen_grid || !seen_white || !seen_dark || !seen_blend || !seen_clip ||
        !seen_rgb) {
        scs_fail_(err, errlen, 0, "model, hash, grid, white, dark, blend, clip and rgb lines are required");
        goto fail;
    }
    if (!scs_grid_is_(grid, m->wl, m->n)) {
        scs_fail_(err, errlen, 0, "the wavelengths line is not the grid's (START + i * STEP)");
        goto fail;
    }
    /* With blend > 0 a split blends over [blend, SCS_MAX_WIDTH]; the hard switch's are 0. */
    for (i = 0; i < m->nodes_n; i++) {
        double wd = m->nodes[i].width;
        if (!m->nodes[i].leaf && (m->blend > 0 ? !(wd >= m->blend && wd <= SCS_MAX_WIDTH) : wd != 0)) {
            scs_fail_(err, errlen, 0, "node %ld's width is outside [blend, %g] (0 with blend 0)", i, SCS_MAX_WIDTH);
            goto fail;
        }
    }
    if (!seen_b[0] || !seen_b[1] || !seen_b[2]) {
        scs_fail_(err, errlen, 0, "b X, b Y and b Z lines are required");
        goto fail;
    }
    /* Counting the lines counted numbering mistakes too: every index in range, none twice,
     * so each of 0..count-1 was given. */

    /* The tree ("Blend weights"): from node 0, every node reached exactly once (no cycle, no
     * shared or unreached node), no deeper than SCS_MAX_DEPTH, one leaf per map. */
    if (leaves != m->maps_n) {
        scs_fail_(err, errlen, 0, "%ld leaves for %ld maps (one map per leaf)", leaves, m->maps_n);
        goto fail;
    }
    reached = (char *)scs_alloc_((size_t)m->nodes_n, 1);
    map_used = (char *)scs_alloc_((size_t)m->maps_n, 1);
    stack = (long *)scs_alloc_((size_t)m->nodes_n, sizeof(long));
    depth = (int *)scs_alloc_((size_t)m->nodes_n, sizeof(int));
    if (!reached || !map_used || !stack || !depth) goto oom;
    {
        long top = 0, count = 0;
        stack[top] = 0;
        depth[top++] = 0;
        while (top > 0) {
            long k = stack[--top];
            int d = depth[top];
            const scs_node_ *nd = &m->nodes[k];
            if (reached[k]++) {
                scs_fail_(err, errlen, 0, "node %ld is reached twice: the nodes are no tree", k);
                goto fail;
            }
            if (d > SCS_MAX_DEPTH) {
                scs_fail_(err, errlen, 0, "the tree is deeper than %d", SCS_MAX_DEPTH);
                goto fail;
            }
            /* Each node is pushed at most once before the check above fails, so the stack,
             * of nodes_n entries, cannot overflow: a second push of a node means it has two
             * parents, caught when it is popped; at most nodes_n pushes precede that. */
            count++;
            if (nd->leaf) {
                if (map_used[nd->k]++) {
                    scs_fail_(err, errlen, 0, "map %ld belongs to two leaves", nd->k);
                    goto fail;
                }
            } else {
                if (top + 2 > m->nodes_n) {
                    scs_fail_(err, errlen, 0, "the nodes are no tree (more children than nodes)");
                    goto fail;
                }
                stack[top] = nd->below;
                depth[top++] = d + 1;
                stack[top] = nd->above;
                depth[top++] = d + 1;
            }
        }
        if (count != m->nodes_n) {
            scs_fail_(err, errlen, 0, "%ld of %ld nodes are not reached from node 0", m->nodes_n - count, m->nodes_n);
            goto fail;
        }
    }
    goto done;

oom:
    scs_fail_(err, errlen, 0, "out of memory");
fail:
    scs_model_free(m);
    m = NULL;
done:
    free(buf);
    free(lines);
    free(node_seen);
    free(map_seen);
    free(reached);
    free(map_used);
    free(stack);
    free(depth);
    return m;
}

int scs_bands(const scs_model *m) { return m->n; }

const double *scs_wavelengths(const scs_model *m) { return m->wl; }

const double *scs_rgb_to_xyz(const scs_model *m) { return m->rgb; }

void scs_texel_of_stored(const scs_model *m, const float stored[9], float texel[6]) {
    int i;
    for (i = 0; i < 3; i++) {
        const double *row = m->rgb + 3 * i;
        double v = row[0] * (double)stored[0] + row[1] * (double)stored[1];
        v += row[2] * (double)stored[2];
        texel[i] = (float)v;
        texel[3 + i] = stored[3 + i] + stored[6 + i];
    }
}

/* The texel's colour, chromaticity and λ_dark ("The rule"); 0 when X, Y or Z is not finite,
 * or u where the rule adds it (clip 1). */
typedef struct {
    double c[3], u[3], xy[2], dark;
} scs_texel_;

static int scs_read_texel_(const scs_model *m, const float t[6], scs_texel_ *out) {
    double s;
    int i;
    for (i = 0; i < 3; i++) {
        if (!isfinite(t[i]) || (m->clip && !isfinite(t[3 + i]))) return 0;
        out->c[i] = t[i];
        out->u[i] = t[3 + i];
    }
    s = out->c[0] + out->c[1] + out->c[2];
    if (s > 0) {
        out->xy[0] = out->c[0] / s;
        out->xy[1] = out->c[1] / s;
        out->dark = s / m->dark < 1 ? s / m->dark : 1;
    } else {
        /* No chromaticity: the white point's leaves, without the offset. */
        out->xy[0] = m->white[0];
        out->xy[1] = m->white[1];
        out->dark = 0;
    }
    return 1;
}

/* r_b of the rule at band b: the tree walked with its blend weights (a fixed stack: the parser
 * bounded the depth, and a walk holds at most depth + 1 pending nodes), each leaf's affine map
 * weighted, then B·u and the clip. */
static double scs_band_(const scs_model *m, const scs_texel_ *t, int b) {
    long node[SCS_MAX_DEPTH + 2];
    double weight[SCS_MAX_DEPTH + 2];
    int top = 0;
    size_t n = (size_t)m->n;
    double r = 0;
    node[top] = 0;
    weight[top++] = 1;
    while (top > 0) {
        const scs_node_ *nd = &m->nodes[node[--top]];
        double w = weight[top], s;
        if (nd->leaf) {
            const double *map = m->maps + (size_t)nd->k * 4 * n;
            r += w * (map[b] * t->c[0] + map[n + b] * t->c[1] + map[2 * n + b] * t->c[2] +
                      t->dark * map[3 * n + b]);
            continue;
        }
        {
            double p = t->xy[nd->axis];
            if (m->blend > 0 && nd->width > 0) {
                /* Smoothstep over [v − w, v + w]. */
                double x = (p - nd->value + nd->width) / (2 * nd->width);
                x = x < 0 ? 0 : x > 1 ? 1 : x;
                s = x * x * (3 - 2 * x);
            } else {
                s = p >= nd->value ? 1 : 0; /* the paper's hard switch */
            }
        }
        /* Branches of weight 0 are not walked: most colours take one leaf. */
        if (w * (1 - s) > 0) {
            node[top] = nd->below;
            weight[top++] = w * (1 - s);
        }
        if (w * s > 0) {
            node[top] = nd->above;
            weight[top++] = w * s;
        }
    }
    if (m->clip) {
        r += m->b[b] * t->u[0] + m->b[n + b] * t->u[1] + m->b[2 * n + b] * t->u[2];
        /* Written so that a NaN u stays NaN rather than clipping to a number. */
        r = r < 0 ? 0 : r > 1 ? 1 : r;
    }
    return r;
}

/* A value as float: beyond the largest float it saturates there, as the reference's
 * unbounded (clip 0) spectra do; within [0, 1] (clip 1) it never comes near. */
static float scs_float_(double v) {
    return v > FLT_MAX ? FLT_MAX : v < -FLT_MAX ? -FLT_MAX : (float)v;
}

void scs_decode_bands(const scs_model *m, const float texel[6], float *out) {
    scs_texel_ t;
    int b;
    if (!scs_read_texel_(m, texel, &t)) {
        for (b = 0; b < m->n; b++) out[b] = (float)NAN;
        return;
    }
    for (b = 0; b < m->n; b++) out[b] = scs_float_(scs_band_(m, &t, b));
}

float scs_decode_at(const scs_model *m, const float texel[6], double wavelength_nm) {
    scs_texel_ t;
    int lo = 0, hi = m->n - 1;
    double a, b;
    if (!scs_read_texel_(m, texel, &t) || isnan(wavelength_nm)) return (float)NAN;
    /* "Other wavelengths": interpolate the bands' r, not the maps, and hold the ends. */
    if (wavelength_nm <= m->wl[0]) return scs_float_(scs_band_(m, &t, 0));
    if (wavelength_nm >= m->wl[hi]) return scs_float_(scs_band_(m, &t, hi));
    while (hi - lo > 1) { /* wl[lo] < λ < wl[hi] */
        int mid = lo + (hi - lo) / 2;
        if (m->wl[mid] <= wavelength_nm) lo = mid; else hi = mid;
    }
    a = scs_band_(m, &t, lo);
    b = scs_band_(m, &t, hi);
    return scs_float_(a + (b - a) * (wavelength_nm - m->wl[lo]) / (m->wl[hi] - m->wl[lo]));
}

/* ---- ENCODER ------------------------------------------------------------------------------
 * A port of the library's bounded projection (crates/colour/src/solid/, crates/spectral/src/
 * bounded.rs), step for step and in the same order of operations, so that the iterations take
 * the same path: where they do not (a rounding apart at a decision), the spectra still agree
 * within the bound that tests/it/compact.rs states. */


/* Columns of a 3 × n matrix: entry (band i, row k) at cols[i·bs + k·ks]. */
typedef struct {
    const double *cols;
    size_t bs, ks;
    long n;
} scs_cols_;

static double scs_col_(const scs_cols_ *a, long i, int k) { return a->cols[(size_t)i * a->bs + (size_t)k * a->ks]; }

static double scs_dot3_(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double scs_clamp01_(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; } /* NaN stays NaN */

/* v rounded to float as Rust's `as f32` rounds: beyond the largest float, ±∞. */
static double scs_round_f32_(double v) {
    if (v != v) return v;
    if (fabs(v) >= 0x1.ffffffp127) return v > 0 ? (double)INFINITY : -(double)INFINITY;
    return (double)(float)v;
}

static double scs_det3_(const double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* x with j·x = b by Cramer's rule (mat3::solve); 0 when singular or not finite. */
static int scs_solve3_(const double j[3][3], const double b[3], double x[3]) {
    double d = scs_det3_(j);
    int k, row;
    if (!(fabs(d) > 0 && isfinite(d))) return 0;
    for (k = 0; k < 3; k++) {
        double m[3][3];
        memcpy(m, j, sizeof m);
        for (row = 0; row < 3; row++) m[row][k] = b[row];
        x[k] = scs_det3_(m) / d;
    }
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]);
}

/* The dual problem of solid/mod.rs: min Ψ(w) = Σ ψ(pᵢ + bᵢ·w) − s·w + (μ/2)‖w‖². */
typedef struct {
    scs_cols_ b;
    const double *p;
    double s[3], mu, eps;
} scs_dual_;

typedef struct {
    double psi, grad[3], hess[6];
    long free;
} scs_point_;

static void scs_dual_at_(const scs_dual_ *d, const double w[3], double *r, scs_point_ *pt) {
    double psi = 0, f[3] = {0, 0, 0}, h[6] = {0, 0, 0, 0, 0, 0};
    long i, free = 0;
    int k;
    for (i = 0; i < d->b.n; i++) {
        double b0 = scs_col_(&d->b, i, 0), b1 = scs_col_(&d->b, i, 1), b2 = scs_col_(&d->b, i, 2);
        double z = d->p[i] + b0 * w[0] + b1 * w[1] + b2 * w[2];
        /* A band at 0 adds nothing to A·r: skipping its +0 keeps every sum bit for bit (f starts
         * at +0 and never becomes -0) and shortens the sums' chains of additions. */
        if (z <= 0) {
            r[i] = 0;
        } else if (z < 1) {
            psi += 0.5 * z * z;
            h[0] += b0 * b0; h[1] += b0 * b1; h[2] += b0 * b2;
            h[3] += b1 * b1; h[4] += b1 * b2; h[5] += b2 * b2;
            free++;
            r[i] = z;
            f[0] += b0 * z; f[1] += b1 * z; f[2] += b2 * z;
        } else {
            psi += z - 0.5;
            r[i] = 1;
            f[0] += b0; f[1] += b1; f[2] += b2;
        }
    }
    psi += 0.5 * d->mu * scs_dot3_(w, w) - scs_dot3_(d->s, w);
    for (k = 0; k < 3; k++) pt->grad[k] = f[k] - d->s[k] + d->mu * w[k];
    pt->psi = psi;
    memcpy(pt->hess, h, sizeof h);
    pt->free = free;
}

static double scs_maxabs3_(const double v[3], double from) {
    int k;
    for (k = 0; k < 3; k++) from = fabs(v[k]) > from ? fabs(v[k]) : from; /* f64::max: NaN ignored */
    return from;
}

/* The projection's watch (solid/mod.rs): stop when w or the step certifies c is outside. */
typedef struct {
    const scs_cols_ *a;
    double c[3], tol, cert[3];
    int found;
} scs_watch_;

/* Whether u certifies that c is outside the solid: u·c > h(u) + tol, ‖u‖₁ = 1. */
static int scs_certifies_(const scs_cols_ *a, const double c[3], const double u0[3], double tol) {
    double norm = fabs(u0[0]) + fabs(u0[1]) + fabs(u0[2]), u[3], h = 0;
    long i;
    int k;
    if (!(norm > 0 && isfinite(norm))) return 0;
    for (k = 0; k < 3; k++) u[k] = u0[k] / norm;
    for (i = 0; i < a->n; i++) {
        double v = scs_col_(a, i, 0) * u[0] + scs_col_(a, i, 1) * u[1] + scs_col_(a, i, 2) * u[2];
        h += v > 0 ? v : 0;
    }
    return scs_dot3_(u, c) > h + tol;
}

enum { SCS_END_CONVERGED_, SCS_END_WATCHED_, SCS_END_STALLED_ };

/* The Newton step at pt, −(H + reg·I)⁻¹·∇Ψ, reg = μ plus eps where fewer than three bands are
 * free (Dual::newton): 0 where that matrix is singular. */
static int scs_newton_(const scs_dual_ *d, const scs_point_ *pt, double delta[3]) {
    double j[3][3], neg[3], reg = d->mu + (pt->free < 3 ? d->eps : 0);
    const double *h = pt->hess;
    int k;
    j[0][0] = h[0] + reg; j[0][1] = h[1]; j[0][2] = h[2];
    j[1][0] = h[1]; j[1][1] = h[3] + reg; j[1][2] = h[4];
    j[2][0] = h[2]; j[2][1] = h[4]; j[2][2] = h[5] + reg;
    for (k = 0; k < 3; k++) neg[k] = -pt->grad[k];
    return scs_solve3_(j, neg, delta);
}

/* Newton steps with backtracking on Ψ from w (Dual::minimise); r ends as r(w); scratch: n
 * doubles. *residual: the largest gradient component left. At most `iterations` steps, each
 * with at most ~2,100 halvings (t·|δ| > SCS_STEP_FLOOR_·|w| ends within the exponent range). */
static int scs_minimise_(const scs_dual_ *d, double w[3], double *r, double *scratch, double tol,
                         int iterations, scs_watch_ *watch, double *residual) {
    double *cur = r, *other = scratch, *tmp;
    scs_point_ point, next;
    int end = SCS_END_STALLED_, step, k;
    double res = INFINITY;
    scs_dual_at_(d, w, cur, &point);
    for (step = 0; step < iterations; step++) {
        double delta[3], slope, t = 1, size, reach;
        int accepted = 0;
        res = scs_maxabs3_(point.grad, 0);
        if (res <= tol) { end = SCS_END_CONVERGED_; break; }
        end = SCS_END_STALLED_;
        if (!scs_newton_(d, &point, delta)) break;
        if (watch && !(point.free >= 3 && step < 4)) {
            const double *us[2];
            int q;
            us[0] = w; us[1] = delta;
            for (q = 0; q < 2 && !watch->found; q++)
                if (scs_certifies_(watch->a, watch->c, us[q], watch->tol)) {
                    memcpy(watch->cert, us[q], sizeof watch->cert);
                    watch->found = 1;
                }
            if (watch->found) { end = SCS_END_WATCHED_; break; }
        }
        slope = scs_dot3_(point.grad, delta);
        size = scs_maxabs3_(delta, 0);
        reach = scs_maxabs3_(w, 1);
        while (t * size > SCS_STEP_FLOOR_ * reach) {
            double trial[3], slack;
            for (k = 0; k < 3; k++) trial[k] = w[k] + t * delta[k];
            scs_dual_at_(d, trial, other, &next);
            slack = SCS_PSI_ROUNDING_ * (fabs(point.psi) + fabs(next.psi));
            if (next.psi <= point.psi + SCS_ARMIJO_ * t * slope + slack) {
                memcpy(w, trial, sizeof trial);
                point = next;
                tmp = cur; cur = other; other = tmp;
                accepted = 1;
                break;
            }
            t *= 0.5;
        }
        if (!accepted) break;
    }
    if (end != SCS_END_CONVERGED_) {
        res = scs_maxabs3_(point.grad, 0);
        if (res <= tol) end = SCS_END_CONVERGED_;
    }
    if (cur != r) memcpy(r, cur, sizeof(double) * (size_t)d->b.n);
    *residual = res;
    return end;
}

/* The solid {A·r : 0 ≤ r ≤ 1} of the model's A (its `b` rows) and what Solid::new precomputes. */
typedef struct {
    scs_cols_ a;
    double axis[2][3], trace, white[3];
} scs_solid_;

static void scs_solid_init_(const scs_model *m, scs_solid_ *s) {
    long i;
    int k;
    s->a.cols = m->b;
    s->a.bs = 1;
    s->a.ks = (size_t)m->n;
    s->a.n = m->n;
    memset(s->axis, 0, sizeof s->axis);
    s->trace = 0;
    for (i = 0; i < m->n; i++) {
        double col[3];
        for (k = 0; k < 3; k++) {
            col[k] = scs_col_(&s->a, i, k);
            s->axis[0][k] += col[k] > 0 ? col[k] : 0;
            s->axis[1][k] += -col[k] > 0 ? -col[k] : 0;
        }
        s->trace += scs_dot3_(col, col);
    }
    /* The perfect reflector's XYZ, CIELAB's white (Colorimetry::white_xyz). */
    for (k = 0; k < 3; k++) {
        s->white[k] = 0;
        for (i = 0; i < m->n; i++) s->white[k] += m->b[(size_t)k * (size_t)m->n + (size_t)i];
    }
}

/* Bounded::white_tolerance: the rounding, and twice the gap between the RGB spaces' D65 white
 * and A·1 where that gap is below SCS_SAME_WHITE_. */
static double scs_white_tolerance_(const double white[3]) {
    double d65[3], gap = 0;
    int k;
    d65[0] = SCS_D65_X_ / SCS_D65_Y_;
    d65[1] = 1.0;
    d65[2] = (1.0 - SCS_D65_X_ - SCS_D65_Y_) / SCS_D65_Y_;
    for (k = 0; k < 3; k++) {
        double g = fabs(d65[k] / white[k] - 1.0);
        gap = g > gap ? g : gap;
    }
    return SCS_WHITE_ROUNDING_ + (gap < SCS_SAME_WHITE_ ? 2.0 * gap : 0.0);
}

/* Bounded::is_white: q = c ⊘ A·1; the least q at least 1 − τ, their spread at most τ·(largest). */
static int scs_is_white_(const double white[3], const double c[3]) {
    double q[3], lo, hi, tau = scs_white_tolerance_(white);
    int k;
    for (k = 0; k < 3; k++) q[k] = c[k] / white[k];
    lo = q[0] < q[1] ? q[0] : q[1];
    lo = lo < q[2] ? lo : q[2];
    hi = q[0] > q[1] ? q[0] : q[1];
    hi = hi > q[2] ? hi : q[2];
    return lo >= 1.0 - tau && hi - lo <= tau * hi;
}

static void scs_solid_xyz_(const scs_solid_ *s, const double *r, double x[3]) {
    long i;
    int k;
    x[0] = x[1] = x[2] = 0;
    for (i = 0; i < s->a.n; i++)
        for (k = 0; k < 3; k++) x[k] += scs_col_(&s->a, i, k) * r[i];
}

enum { SCS_SOLVED_, SCS_SOLVE_OUTSIDE_, SCS_UNRESOLVED_ };

/* min ½‖r − r0‖² s.t. A·r = c, 0 ≤ r ≤ 1 from w (Solid::project_dual_from): w ends as the dual. */
static int scs_project_(const scs_solid_ *s, const double c[3], const double *r0, double *r,
                        double *scratch, double w[3]) {
    double scale = scs_maxabs3_(c, 0), tol, residual;
    scs_dual_ d;
    scs_watch_ watch;
    int k, end;
    tol = SCS_RESIDUAL_ * (scale > DBL_MIN ? scale : DBL_MIN);
    for (k = 0; k < 3; k++)
        if (c[k] > s->axis[0][k] + tol || -c[k] > s->axis[1][k] + tol) {
            w[0] = w[1] = w[2] = 0;
            return SCS_SOLVE_OUTSIDE_;
        }
    d.b = s->a;
    d.p = r0;
    memcpy(d.s, c, sizeof d.s);
    d.mu = 0;
    d.eps = SCS_HESSIAN_FLOOR_ * s->trace;
    if (!(isfinite(w[0]) && isfinite(w[1]) && isfinite(w[2]))) w[0] = w[1] = w[2] = 0;
    watch.a = &s->a;
    memcpy(watch.c, c, sizeof watch.c);
    watch.tol = tol;
    watch.found = 0;
    end = scs_minimise_(&d, w, r, scratch, tol, SCS_DUAL_STEPS_, &watch, &residual);
    if (end == SCS_END_CONVERGED_) return SCS_SOLVED_;
    if (end == SCS_END_WATCHED_) return SCS_SOLVE_OUTSIDE_;
    return residual <= SCS_STALLED_RESIDUAL_ * (scale > DBL_MIN ? scale : DBL_MIN) ? SCS_SOLVED_ : SCS_UNRESOLVED_;
}

/* Big integers of 32-bit limbs, least significant first: out = a · b (out: na + nb limbs). */
static void scs_big_mul_(const unsigned long *a, int na, const unsigned long *b, int nb, unsigned long *out) {
    int i, j;
    for (i = 0; i < na + nb; i++) out[i] = 0;
    for (i = 0; i < na; i++) {
        unsigned long long carry = 0;
        for (j = 0; j < nb; j++) {
            unsigned long long t = (unsigned long long)a[i] * b[j] + out[i + j] + carry;
            out[i + j] = (unsigned long)(t & 0xffffffffu);
            carry = t >> 32;
        }
        out[i + nb] = (unsigned long)carry;
    }
}

/* The sign of m³ − x for m = M·2^e (M < 2^56) and x > 0 finite, exactly. */
static int scs_cube_cmp_(unsigned long long M, int e, double x) {
    unsigned long m[2], sq[4], cube[6], big[6];
    unsigned long long X;
    int ex, sh, i;
    double f = frexp(x, &ex);
    X = (unsigned long long)ldexp(f, 53);
    ex -= 53;
    m[0] = (unsigned long)(M & 0xffffffffu);
    m[1] = (unsigned long)(M >> 32);
    scs_big_mul_(m, 2, m, 2, sq);
    scs_big_mul_(sq, 4, m, 2, cube);
    /* m³ = cube·2^(3e) against x = X·2^ex: cube against X·2^(ex − 3e). */
    sh = ex - 3 * e;
    if (sh < 0 || sh > 192 - 54) return ldexp((double)M, e) * ldexp((double)M, e) * ldexp((double)M, e) < x ? -1 : 1;
    for (i = 0; i < 6; i++) big[i] = 0;
    for (i = 0; i < 2; i++) {
        unsigned long long part = (X >> (32 * i)) & 0xffffffffu;
        int bit = sh + 32 * i, limb = bit / 32, off = bit % 32;
        unsigned long long v = part << off;
        if (limb < 6) big[limb] |= (unsigned long)(v & 0xffffffffu);
        if (limb + 1 < 6) big[limb + 1] |= (unsigned long)(v >> 32);
    }
    for (i = 5; i >= 0; i--)
        if (cube[i] != big[i]) return cube[i] < big[i] ? -1 : 1;
    return 0;
}

/* (a + b)/2 of two adjacent positive normal doubles a < b, as M·2^e exactly. */
static void scs_mid_(double a, double b, unsigned long long *M, int *e) {
    int ea, eb, e0;
    unsigned long long A = (unsigned long long)ldexp(frexp(a, &ea), 53);
    unsigned long long B = (unsigned long long)ldexp(frexp(b, &eb), 53);
    ea -= 53;
    eb -= 53;
    e0 = ea < eb ? ea : eb;
    *M = (A << (ea - e0)) + (B << (eb - e0));
    *e = e0 - 1;
}

/* The cube root correctly rounded, as Rust's f64::cbrt (the library's CIELAB) computes it:
 * libm's cbrt is within a few ulps, and the candidate whose rounding interval holds x's cube root
 * is chosen by exact integer arithmetic, so that both searches see the same doubles. The
 * intervals do not overlap (the cube of a midpoint, an odd 54-bit number, is no double), so
 * one candidate holds the root: the walk starts at libm's and steps towards the root. */
static double scs_cbrt_(double x) {
    double y = cbrt(x), c = y;
    int k, off = 0;
    if (!(x > DBL_MIN) || !isfinite(x) || !(y > DBL_MIN)) return y; /* CIELAB takes x > 0.0088 */
    /* glibc's cbrt was measured up to 2 ulps off: the 9 candidates within 4 ulps of it. */
    for (k = 0; k < 9 && off >= -4 && off <= 4; k++) {
        unsigned long long M;
        int e;
        scs_mid_(nextafter(c, 0), c, &M, &e);
        if (scs_cube_cmp_(M, e, x) > 0) { /* c's interval is above the root */
            c = nextafter(c, 0);
            off--;
            continue;
        }
        scs_mid_(c, nextafter(c, INFINITY), &M, &e);
        if (scs_cube_cmp_(M, e, x) < 0) { /* below it */
            c = nextafter(c, INFINITY);
            off++;
            continue;
        }
        return c;
    }
    return y;
}

/* CIE's f(t) and CIELAB with its Jacobian (colour::lab), for every XYZ. */
static double scs_lab_f_(double t) { return t > 216.0 / 24389.0 ? scs_cbrt_(t) : t * (841.0 / 108.0) + 4.0 / 29.0; }

static void scs_lab_(const double xyz[3], const double white[3], double lab[3], double jac[3][3]) {
    double f[3], dd[3];
    int k;
    for (k = 0; k < 3; k++) {
        double t = xyz[k] / white[k];
        /* One cube root serves f and its derivative (the same values as scs_lab_f_'s). */
        double q = t > 216.0 / 24389.0 ? scs_cbrt_(t) : 0;
        f[k] = t > 216.0 / 24389.0 ? q : scs_lab_f_(t);
        if (jac) dd[k] = (t > 216.0 / 24389.0 ? 1.0 / (3.0 * (q * q)) : 841.0 / 108.0) / white[k];
    }
    lab[0] = 116.0 * f[1] - 16.0;
    lab[1] = 500.0 * (f[0] - f[1]);
    lab[2] = 200.0 * (f[1] - f[2]);
    if (jac) {
        jac[0][0] = 0; jac[0][1] = 116.0 * dd[1]; jac[0][2] = 0;
        jac[1][0] = 500.0 * dd[0]; jac[1][1] = -500.0 * dd[1]; jac[1][2] = 0;
        jac[2][0] = 0; jac[2][1] = 200.0 * dd[1]; jac[2][2] = -200.0 * dd[2];
    }
}

static double scs_dist2_(const double a[3], const double b[3]) {
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

/* The in-range spectrum nearest to c in CIELAB from r0 (nearest::nearest_lab), into r; its
 * colour into x. bm: 3n doubles, trial and scratch: n each. */
static void scs_nearest_(const scs_solid_ *s, const double c[3], const double *r0, double *r,
                         double *bm, double *trial, double *scratch, double x[3]) {
    long n = s->a.n, i;
    double target[3], lab[3], jac[3][3], phi, mu = NAN;
    int step, k, row;
    scs_lab_(c, s->white, target, NULL);
    for (i = 0; i < n; i++) r[i] = isfinite(r0[i]) ? scs_clamp01_(r0[i]) : 0.5;
    scs_solid_xyz_(s, r, x);
    scs_lab_(x, s->white, lab, jac);
    phi = scs_dist2_(lab, target);
    for (step = 0; step < SCS_NEAREST_STEPS_; step++) {
        double trace = 0, jx[3], sv[3];
        int improved = 0;
        if (phi == 0) break;
        for (i = 0; i < n; i++) {
            double a[3], *bi = bm + 3 * (size_t)i;
            for (k = 0; k < 3; k++) a[k] = scs_col_(&s->a, i, k);
            for (row = 0; row < 3; row++) bi[row] = scs_dot3_(jac[row], a);
            trace += scs_dot3_(bi, bi);
        }
        if (mu != mu) mu = SCS_NEAREST_MU_START_ * trace / (double)n;
        for (k = 0; k < 3; k++) jx[k] = scs_dot3_(jac[k], x);
        for (k = 0; k < 3; k++) sv[k] = jx[k] - (lab[k] - target[k]);
        /* Each failed try multiplies mu by SCS_NEAREST_MU_GROW_ until it passes
         * SCS_NEAREST_MU_CAP_·trace (~30 tries); the count of tries holds where a hostile text's A
         * makes mu NaN (no model of specconv's can). */
        int tries;
        for (tries = 0; !improved && tries < SCS_NEAREST_TRIES_; tries++) {
            scs_dual_ d;
            double w[3] = {0, 0, 0}, tol, residual, xt[3], lab_t[3], jac_t[3][3], phi_t, moved = 0;
            int end, settled;
            d.b.cols = bm; d.b.bs = 3; d.b.ks = 1; d.b.n = n;
            d.p = r;
            memcpy(d.s, sv, sizeof sv);
            d.mu = mu;
            d.eps = 0;
            tol = SCS_NEAREST_SUB_TOLERANCE_ * scs_maxabs3_(sv, 1);
            end = scs_minimise_(&d, w, trial, scratch, tol, SCS_NEAREST_SUB_, NULL, &residual);
            scs_solid_xyz_(s, trial, xt);
            scs_lab_(xt, s->white, lab_t, jac_t);
            phi_t = scs_dist2_(lab_t, target);
            for (i = 0; i < n; i++) {
                double dv = fabs(r[i] - trial[i]);
                moved = dv > moved ? dv : moved;
            }
            settled = fabs(phi - phi_t) <= SCS_NEAREST_SETTLED_PHI_ * phi || moved <= SCS_NEAREST_SETTLED_MOVE_;
            if (end != SCS_END_WATCHED_ && phi_t < phi) {
                double floor_mu = SCS_NEAREST_MU_FLOOR_ * trace / (double)n;
                memcpy(r, trial, sizeof(double) * (size_t)n);
                memcpy(x, xt, sizeof xt);
                memcpy(lab, lab_t, sizeof lab);
                memcpy(jac, jac_t, sizeof jac);
                phi = phi_t;
                mu = mu * SCS_NEAREST_MU_SHRINK_ > floor_mu ? mu * SCS_NEAREST_MU_SHRINK_ : floor_mu;
                improved = 1;
            } else {
                mu *= SCS_NEAREST_MU_GROW_;
            }
            if (settled || mu > SCS_NEAREST_MU_CAP_ * (trace > DBL_MIN ? trace : DBL_MIN)) return;
        }
    }
}

/* Full Newton steps from w while each lowers the largest residual component, the first of
 * t = 1, ½, ¼, … (SCS_POLISH_HALVINGS_ tries) that does, at most `iterations` (Dual::polish); r ends as r(w).
 * scratch: n doubles. Returns the residual left. */
static double scs_polish_(const scs_dual_ *d, double w[3], double *r, double *scratch, double tol,
                          int iterations) {
    scs_point_ point, next;
    double res;
    int it, k, q;
    scs_dual_at_(d, w, r, &point);
    res = scs_maxabs3_(point.grad, 0);
    for (it = 0; it < iterations; it++) {
        double delta[3], trial[3], t = 1, left = 0;
        int found = 0;
        if (res <= tol) break;
        if (!scs_newton_(d, &point, delta)) break;
        for (q = 0; q < SCS_POLISH_HALVINGS_; q++) {
            for (k = 0; k < 3; k++) trial[k] = w[k] + t * delta[k];
            scs_dual_at_(d, trial, scratch, &next);
            left = scs_maxabs3_(next.grad, 0);
            if (left < res) { found = 1; break; }
            t *= 0.5;
        }
        if (!found) break;
        memcpy(w, trial, sizeof trial);
        memcpy(r, scratch, sizeof(double) * (size_t)d->b.n);
        point = next;
        res = left;
    }
    return res;
}

/* One regularised solve at penalty weight mu·trace from w: Newton with backtracking, then the
 * polish where that stops short. Returns the residual left. */
static double scs_regularised_at_(const scs_solid_ *s, const double c[3], const double *r0, double mu,
                                  double tol, double w[3], double *r, double *scratch) {
    scs_dual_ d;
    double residual;
    d.b = s->a;
    d.p = r0;
    memcpy(d.s, c, sizeof d.s);
    d.mu = mu * s->trace;
    d.eps = 0;
    if (scs_minimise_(&d, w, r, scratch, tol, SCS_REGULARISED_STEPS_, NULL, &residual) == SCS_END_CONVERGED_)
        return 0;
    return scs_polish_(&d, w, r, scratch, tol, SCS_REGULARISED_STEPS_);
}

/* min ½‖r − r0‖² + ‖A·r − c‖²/(2μ) over 0 ≤ r ≤ 1, μ = SCS_REGULARISATION_·trace, from w = 0,
 * and from a penalty 10^SCS_STRONGER_PENALTIES_ times as strong weakened tenfold a step where that stalls
 * (Solid::project_regularised): w ends as the dual. */
static int scs_project_regularised_(const scs_solid_ *s, const double c[3], const double *r0, double *r,
                                    double *scratch, double w[3]) {
    double scale = scs_maxabs3_(c, 0), tol, residual;
    int k;
    scale = scale > DBL_MIN ? scale : DBL_MIN;
    tol = SCS_RESIDUAL_ * scale;
    w[0] = w[1] = w[2] = 0;
    residual = scs_regularised_at_(s, c, r0, SCS_REGULARISATION_, tol, w, r, scratch);
    if (residual > SCS_STALLED_RESIDUAL_ * scale) {
        w[0] = w[1] = w[2] = 0;
        /* 10^k, exact for these k, as the library's powi. */
        for (k = SCS_STRONGER_PENALTIES_; k >= 1; k--)
            scs_regularised_at_(s, c, r0, SCS_REGULARISATION_ * pow(10.0, k), tol, w, r, scratch);
        residual = scs_regularised_at_(s, c, r0, SCS_REGULARISATION_, tol, w, r, scratch);
    }
    return residual <= SCS_STALLED_RESIDUAL_ * scale ? SCS_SOLVED_ : SCS_UNRESOLVED_;
}

/* r0 projected onto the reached colour near with the colour a penalty, w rounded to float32 and
 * r made from that w (Bounded::onto_reached): the texel is r to the bit. An unresolved
 * projection keeps its last w. */
static void scs_onto_reached_(const scs_solid_ *s, const double near[3], const double *r0, double *r,
                              double *scratch, double w[3]) {
    scs_dual_ pass;
    scs_point_ point;
    int k;
    scs_project_regularised_(s, near, r0, r, scratch, w);
    if (isfinite(w[0]) && isfinite(w[1]) && isfinite(w[2])) {
        for (k = 0; k < 3; k++) w[k] = scs_round_f32_(w[k]);
    } else {
        w[0] = w[1] = w[2] = 0;
    }
    /* r from that w by the dual's own pass (Solid::texel_form). */
    pass.b = s->a;
    pass.p = r0;
    pass.s[0] = pass.s[1] = pass.s[2] = 0;
    pass.mu = pass.eps = 0;
    scs_dual_at_(&pass, w, r, &point);
}

/* The blend weight of split nd's upper side at coordinate u (Blend::above; the hard switch
 * without blend). */
static double scs_above_(const scs_model *m, const scs_node_ *nd, double u) {
    double w = m->blend > 0 ? nd->width : 0, t;
    if (u >= nd->value + w) return 1;
    if (u <= nd->value - w) return 0;
    t = (u - nd->value + w) / (2.0 * w);
    return t * t * (3.0 - 2.0 * t);
}

/* Each leaf of xy with its blend weight, to f, in the order Blend::weights gives them (each
 * blended split's lower side first, by recursion no deeper than the tree): the one descent of
 * r0's sum and of the blended map. */
typedef void (*scs_leaf_fn_)(const scs_model *m, long k, double weight, void *ctx);

static void scs_leaves_(const scs_model *m, long i, double weight, const double xy[2], scs_leaf_fn_ f,
                        void *ctx) {
    while (!m->nodes[i].leaf) {
        const scs_node_ *nd = &m->nodes[i];
        double s = scs_above_(m, nd, xy[nd->axis]);
        if (s == 1) {
            i = nd->above;
        } else if (s == 0) {
            i = nd->below;
        } else {
            scs_leaves_(m, nd->below, weight * (1.0 - s), xy, f, ctx);
            weight *= s;
            i = nd->above;
        }
    }
    f(m, m->nodes[i].k, weight, ctx);
}

/* r0 of an ordinary colour (X+Y+Z ≥ dark) as the library's uplift computes it, bit for bit:
 * r = Σ w·o + T·(c·w) over the leaves, left to right (runtime.rs kernel_weighted). */
typedef struct {
    const double *c;
    double *r;
    int first; /* no leaf added yet */
} scs_r0_sum_;

static void scs_r0_leaf_(const scs_model *m, long k, double weight, void *ctx) {
    scs_r0_sum_ *a = (scs_r0_sum_ *)ctx;
    size_t n = (size_t)m->n, b;
    const double *t = m->maps + (size_t)k * 4 * n;
    double cw[3];
    cw[0] = a->c[0] * weight; cw[1] = a->c[1] * weight; cw[2] = a->c[2] * weight;
    for (b = 0; b < n; b++) { /* r[b] first */
        if (a->first)
            a->r[b] = t[3 * n + b] * weight + t[b] * cw[0] + t[n + b] * cw[1] + t[2 * n + b] * cw[2];
        else
            a->r[b] = a->r[b] + t[3 * n + b] * weight + t[b] * cw[0] + t[n + b] * cw[1] + t[2 * n + b] * cw[2];
    }
    a->first = 0;
}

/* The blended map of xy (Uplifter::map_xy) added into t (4n, ctx), for colours that are not
 * ordinary. */
static void scs_map_leaf_(const scs_model *m, long k, double weight, void *ctx) {
    double *t = (double *)ctx;
    size_t n4 = 4 * (size_t)m->n, j;
    const double *map = m->maps + (size_t)k * n4;
    for (j = 0; j < n4; j++) t[j] += weight * map[j];
}

/* The model's spectrum r0 of a finite colour c (the rule without B·u and the clip), computed
 * as the library computes it (otsu2018::runtime, hard_inputs), so that the projection starts
 * from the same doubles. t: 4n doubles of scratch. */
static void scs_r0_(const scs_model *m, const double c[3], double *r, double *t) {
    size_t n = (size_t)m->n, b;
    double s = c[0] + c[1] + c[2], mx, u[3], su, xy[2], weight_o;
    int k;
    if (s >= m->dark) { /* ordinary; float colours are far below the overflow guard */
        scs_r0_sum_ sum;
        sum.c = c;
        sum.r = r;
        sum.first = 1;
        xy[0] = c[0] / s;
        xy[1] = c[1] / s;
        scs_leaves_(m, 0, 1.0, xy, scs_r0_leaf_, &sum);
        return;
    }
    mx = fabs(c[0]);
    for (k = 1; k < 3; k++) mx = fabs(c[k]) > mx ? fabs(c[k]) : mx;
    if (mx == 0) {
        for (b = 0; b < n; b++) r[b] = 0;
        return;
    }
    for (k = 0; k < 3; k++) u[k] = c[k] / mx;
    su = u[0] + u[1] + u[2];
    if (su > 0) {
        double sd = su * mx / m->dark;
        xy[0] = u[0] / su;
        xy[1] = u[1] / su;
        weight_o = sd < 1 ? sd : 1;
    } else {
        xy[0] = m->white[0];
        xy[1] = m->white[1];
        weight_o = 0;
    }
    memset(t, 0, sizeof(double) * 4 * n);
    scs_leaves_(m, 0, 1.0, xy, scs_map_leaf_, t);
    for (b = 0; b < n; b++) {
        double lin = t[b] * u[0] + t[n + b] * u[1] + t[2 * n + b] * u[2];
        double v = lin * mx + weight_o * t[3 * n + b];
        r[b] = v > DBL_MAX ? DBL_MAX : v < -DBL_MAX ? -DBL_MAX : v;
    }
}

size_t scs_encode_work_size(const scs_model *m) { return 7 * (size_t)m->n * sizeof(double); }

int scs_encode_xyz(const scs_model *m, const float xyz[3], float texel[6], void *work) {
    double *r = (double *)work, c[3], w[3] = {0, 0, 0};
    double *r0, *scratch, *trial, *bm;
    size_t n = (size_t)m->n;
    scs_solid_ s;
    int k, outcome, in_range, white;
    size_t i;
    for (k = 0; k < 3; k++) {
        texel[k] = xyz[k];
        texel[3 + k] = 0;
        c[k] = xyz[k];
    }
    if (!(isfinite(c[0]) && isfinite(c[1]) && isfinite(c[2]))) return SCS_NOT_FINITE;
    if (!m->clip) return SCS_IN_RANGE; /* unbounded: u = 0, nothing to project */
    scs_r0_(m, c, r, r + 3 * n); /* scratch: the 4n of trial and bm, free until projected */
    for (i = 0; i < n && r[i] >= 0 && r[i] <= 1; i++) {}
    in_range = i == n;
    /* White first (Bounded::bound_dual): its spectrum may be in range and still not r ≡ 1. */
    for (i = 0; i < n && r[i] == 1; i++) {}
    if (i == n) return SCS_IN_RANGE;
    {
        double a1[3] = {0, 0, 0};
        for (k = 0; k < 3; k++)
            for (i = 0; i < n; i++) a1[k] += m->b[(size_t)k * n + i];
        white = scs_is_white_(a1, c);
    }
    if (in_range && !white) return SCS_IN_RANGE;
    r0 = r + n;
    scratch = r + 2 * n;
    trial = r + 3 * n;
    bm = r + 4 * n;
    memcpy(r0, r, sizeof(double) * n);
    scs_solid_init_(m, &s);
    if (white) {
        /* Bounded::white: w = (0, t, 0), t twice what lifts the band of least ȳ weight to 1. */
        double t = 0;
        int lifted = 1;
        for (i = 0; i < n && lifted; i++) {
            if (r0[i] < 1) {
                double y = scs_col_(&s.a, (long)i, 1);
                if (!(y > 0)) lifted = 0;
                else if ((1 - r0[i]) / y > t) t = (1 - r0[i]) / y;
            }
        }
        if (lifted) {
            scs_dual_ pass;
            scs_point_ point;
            double wt[3];
            wt[0] = 0;
            wt[1] = scs_round_f32_(2.0 * t);
            wt[2] = 0;
            pass.b = s.a;
            pass.p = r0;
            pass.s[0] = pass.s[1] = pass.s[2] = 0;
            pass.mu = pass.eps = 0;
            scs_dual_at_(&pass, wt, r, &point);
            for (i = 0; i < n && r[i] == 1; i++) {}
            if (i == n) {
                for (k = 0; k < 3; k++) texel[3 + k] = (float)wt[k];
                return SCS_PROJECTED;
            }
        }
    }
    if (in_range) return SCS_IN_RANGE;
    if (scs_project_(&s, c, r0, r, scratch, w) == SCS_SOLVED_) {
        outcome = SCS_PROJECTED;
    } else {
        double near[3];
        scs_nearest_(&s, c, r0, r, bm, trial, scratch, near);
        scs_onto_reached_(&s, near, r0, r, scratch, w);
        outcome = SCS_OUTSIDE;
    }
    for (k = 0; k < 3; k++) texel[3 + k] = (float)scs_round_f32_(w[k]);
    return outcome;
}

int scs_encode_rgb(const scs_model *m, const double to_xyz[9], const float rgb[3], float texel[6],
                   void *work) {
    float xyz[3];
    int k;
    for (k = 0; k < 3; k++) {
        double v = to_xyz[3 * k] * rgb[0] + to_xyz[3 * k + 1] * rgb[1] + to_xyz[3 * k + 2] * rgb[2];
        xyz[k] = (float)scs_round_f32_(v);
    }
    return scs_encode_xyz(m, xyz, texel, work);
}

#endif /* SPECCONV_SPECTRUM_IMPLEMENTED */
#endif /* SPECCONV_SPECTRUM_IMPLEMENTATION */
