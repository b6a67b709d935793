/* texels_from_exr: a renderer's load step with include/specconv_spectrum.h (docs/compact.md,
 * "Texels from colours in C"). It keeps its RGB texture, makes a compact texel of each pixel
 * at load (as pbrt-v4 and Mitsuba make rgb2spec's coefficients), and decodes them at a
 * wavelength, as a renderer's lookup would.
 *
 *   texels_from_exr MODEL.txt IMAGE.exr NM [M0 .. M8]
 *
 * MODEL.txt: the model's text (a compact file's `specconvCompact` attribute, or the first value
 * of Python's specconv.encode). IMAGE.exr: linear RGB, half or float, scanline or tiled (level
 * 0), read with OpenEXR's C API (OpenEXR 3.1, Debian's libopenexr-dev). M: the working space's
 * matrix to XYZ (row major, white Y = 1); without it, Rec.709 primaries with D65, the space of
 * an EXR without chromaticities. Prints a line per pixel, "x y R G B X Y Z u0 u1 u2 r", r the
 * spectrum at NM, then a summary.
 *
 *   cc -std=c99 -O2 -I include -I /usr/include/OpenEXR examples/c/texels_from_exr.c \
 *      -lOpenEXRCore-3_1 -lm
 */
#define SPECCONV_SPECTRUM_IMPLEMENTATION
#include "specconv_spectrum.h"

#include <openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(const char *what, const char *detail) {
    fprintf(stderr, "texels_from_exr: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    return 1;
}

static char *slurp(const char *path) {
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long len;
    if (!f) return NULL;
    if (!fseek(f, 0, SEEK_END) && (len = ftell(f)) >= 0 && !fseek(f, 0, SEEK_SET) &&
        (buf = (char *)malloc((size_t)len + 1)) && fread(buf, 1, (size_t)len, f) == (size_t)len)
        buf[len] = '\0';
    else {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    return buf;
}

/* Decodes one chunk's R, G and B (any pixel type) as float into rgb (w × h × 3). */
static exr_result_t read_chunk(exr_context_t ctx, const exr_chunk_info_t *ci, int x0, int y0, int w,
                               float *rgb, exr_decode_pipeline_t *dec, int *ready) {
    exr_result_t rv = *ready ? exr_decoding_update(ctx, 0, ci, dec) : exr_decoding_initialize(ctx, 0, ci, dec);
    int c;
    if (rv != EXR_ERR_SUCCESS) return rv;
    for (c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *ch = &dec->channels[c];
        const char *name = ch->channel_name;
        int k = !strcmp(name, "R") ? 0 : !strcmp(name, "G") ? 1 : !strcmp(name, "B") ? 2 : -1;
        ch->decode_to_ptr = NULL; /* other channels (A, ...) are skipped */
        if (k < 0) continue;
        ch->user_data_type = EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = 4;
        ch->user_pixel_stride = 3 * (int32_t)sizeof(float);
        ch->user_line_stride = 3 * (int32_t)sizeof(float) * w;
        ch->decode_to_ptr = (uint8_t *)(rgb + 3 * ((size_t)y0 * (size_t)w + (size_t)x0) + k);
    }
    if (!*ready) {
        rv = exr_decoding_choose_default_routines(ctx, 0, dec);
        if (rv != EXR_ERR_SUCCESS) return rv;
        *ready = 1;
    }
    return exr_decoding_run(ctx, 0, dec);
}

/* Level 0's R, G and B as float, w × h × 3 (NULL and why on failure). */
static float *read_rgb(const char *path, int *w, int *h, const char **why) {
    exr_context_t ctx;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_attr_box2i_t dw;
    exr_storage_t storage;
    const exr_attr_chlist_t *chans;
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    exr_chunk_info_t ci;
    float *rgb = NULL;
    int ready = 0, found = 0, i;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    *why = NULL;
    if (rv != EXR_ERR_SUCCESS) { *why = exr_get_default_error_message(rv); return NULL; }
    if (exr_get_data_window(ctx, 0, &dw) || exr_get_storage(ctx, 0, &storage) || exr_get_channels(ctx, 0, &chans)) {
        *why = "cannot read the header";
        goto done;
    }
    for (i = 0; i < chans->num_channels; i++) {
        const char *n = chans->entries[i].name.str;
        found += !strcmp(n, "R") || !strcmp(n, "G") || !strcmp(n, "B");
    }
    if (found != 3) { *why = "no R, G and B channels"; goto done; }
    *w = dw.max.x - dw.min.x + 1;
    *h = dw.max.y - dw.min.y + 1;
    if (*w <= 0 || *h <= 0 || (double)*w * (double)*h > 1 << 28) { *why = "an empty or huge data window"; goto done; }
    rgb = (float *)calloc((size_t)*w * (size_t)*h * 3, sizeof(float));
    if (!rgb) { *why = "out of memory"; goto done; }
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines;
        int y;
        exr_get_scanlines_per_chunk(ctx, 0, &lines);
        for (y = dw.min.y; y <= dw.max.y; y += lines) {
            if ((rv = exr_read_scanline_chunk_info(ctx, 0, y, &ci)) ||
                (rv = read_chunk(ctx, &ci, 0, y - dw.min.y, *w, rgb, &dec, &ready)))
                break;
        }
    } else if (storage == EXR_STORAGE_TILED) {
        uint32_t tw, th;
        int tx, ty;
        exr_get_tile_descriptor(ctx, 0, &tw, &th, NULL, NULL);
        for (ty = 0; !rv && (uint32_t)ty * th < (uint32_t)*h; ty++)
            for (tx = 0; !rv && (uint32_t)tx * tw < (uint32_t)*w; tx++)
                if (!(rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci)))
                    rv = read_chunk(ctx, &ci, tx * (int)tw, ty * (int)th, *w, rgb, &dec, &ready);
    } else {
        *why = "deep images have no colour to uplift";
    }
    if (rv != EXR_ERR_SUCCESS) *why = exr_get_default_error_message(rv);
done:
    if (ready || dec.channels) exr_decoding_destroy(ctx, &dec);
    exr_finish(&ctx);
    if (*why) { free(rgb); return NULL; }
    return rgb;
}

int main(int argc, char **argv) {
    /* Linear Rec.709 / sRGB primaries, D65, white Y = 1: the OpenEXR default's matrix. */
    double to_xyz[9] = {0.41239079926595948, 0.35758433938387796, 0.18048078840183429,
                        0.21263900587151036, 0.71516867876775593, 0.072192315360733715,
                        0.019330818715591851, 0.11919477979462599, 0.95053215224966058};
    char err[256], *text;
    const char *why;
    scs_model *m;
    float *rgb;
    void *work;
    double nm, sum = 0;
    long counts[4] = {0, 0, 0, 0}, i;
    int w = 0, h = 0, k;
    if (argc != 4 && argc != 13) return fail("usage: texels_from_exr MODEL.txt IMAGE.exr NM [M0 .. M8]", NULL);
    nm = strtod(argv[3], NULL);
    for (k = 0; argc == 13 && k < 9; k++) to_xyz[k] = strtod(argv[4 + k], NULL);
    if (!(text = slurp(argv[1]))) return fail("cannot read the model text", argv[1]);
    if (!(m = scs_model_parse(text, err, sizeof err))) return fail(argv[1], err);
    if (!(rgb = read_rgb(argv[2], &w, &h, &why))) return fail(argv[2], why);
    /* One workspace, reused for every texel: the encoder allocates nothing per call. A
     * renderer's loader keeps one per thread. */
    if (!(work = malloc(scs_encode_work_size(m)))) return fail("out of memory", NULL);
    for (i = 0; i < (long)w * h; i++) {
        float texel[6], r;
        const float *c = rgb + 3 * i;
        counts[scs_encode_rgb(m, to_xyz, c, texel, work)]++;
        r = scs_decode_at(m, texel, nm);
        sum += r == r ? r : 0;
        printf("%ld %ld %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", i % w, i / w, c[0], c[1], c[2],
               texel[0], texel[1], texel[2], texel[3], texel[4], texel[5], r);
    }
    printf("texels=%ld in_range=%ld projected=%ld outside=%ld not_finite=%ld mean_at_nm=%.6f\n", (long)w * h,
           counts[SCS_IN_RANGE], counts[SCS_PROJECTED], counts[SCS_OUTSIDE], counts[SCS_NOT_FINITE],
           sum / ((double)w * h));
    free(work);
    free(rgb);
    free(text);
    scs_model_free(m);
    return 0;
}
