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

/* The grammar's limits (docs/compact.md, "The header text"), the library's own: at most
 * SCS_MAX_DEPTH splits from the root to a leaf (decoding walks the tree with a fixed stack, no
 * allocation, no recursion; specconv's models are 3 to 6 deep), at most SCS_MAX_BANDS bands,
 * the dark level SCS_DARK, blend widths up to SCS_MAX_WIDTH. */
#define SCS_MAX_DEPTH 64
#define SCS_MAX_BANDS 100000
#define SCS_DARK 0.01
#define SCS_MAX_WIDTH 0.5

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
 * START a whole number of steps to 1e-9 relative, at most SCS_MAX_BANDS bands) whose bands are
 * the n wavelengths wl exactly: START + i × STEP, the product rounded, then the sum. */
static int scs_grid_is_(const double grid[3], const double *wl, long n) {
    double intervals, whole;
    long i;
    if (!(grid[0] > 0 && grid[2] > 0 && grid[1] >= grid[0])) return 0;
    intervals = (grid[1] - grid[0]) / grid[2];
    whole = floor(intervals + 0.5);
    if (fabs(intervals - whole) > 1e-9 * (intervals > 1 ? intervals : 1)) return 0;
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

#endif /* SPECCONV_SPECTRUM_IMPLEMENTED */
#endif /* SPECCONV_SPECTRUM_IMPLEMENTATION */
