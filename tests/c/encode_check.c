/* include/specconv_spectrum.h's encoder against the library (tests/it/compact.rs builds and
 * runs this; crates/spectral/examples/c_texels.rs times it):
 *
 *   encode_check TEXT COLOURS OUT M0 .. M8   COLOURS: records of four float32 (native order),
 *                                            a colour and its kind (0: XYZ, 1: RGB through the
 *                                            row-major matrix M to XYZ); OUT: per record the
 *                                            outcome, the six texel values and the texel's
 *                                            spectrum at the bands (scs_decode_bands), float32
 *   encode_check --bench TEXT COLOURS REPEAT M0 .. M8
 *                                            encodes every record REPEAT times; prints
 *                                            "texels=N seconds=S" (CPU time, clock())
 */
#define SPECCONV_SPECTRUM_IMPLEMENTATION
#include "specconv_spectrum.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void die(const char *what, const char *path) {
    fprintf(stderr, "encode_check: %s: %s\n", path, what);
    exit(2);
}

static void *slurp(const char *path, long *len) {
    FILE *f = fopen(path, "rb");
    char *buf;
    if (!f) die("cannot open", path);
    if (fseek(f, 0, SEEK_END) || (*len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) die("cannot seek", path);
    buf = (char *)malloc((size_t)*len + 1);
    if (!buf) die("out of memory", path);
    if (fread(buf, 1, (size_t)*len, f) != (size_t)*len) die("cannot read", path);
    buf[*len] = '\0';
    fclose(f);
    return buf;
}

static int encode(const scs_model *m, const double to_xyz[9], const float *rec, float texel[6], void *work) {
    return rec[3] == 1 ? scs_encode_rgb(m, to_xyz, rec, texel, work) : scs_encode_xyz(m, rec, texel, work);
}

int main(int argc, char **argv) {
    int bench = argc > 1 && !strcmp(argv[1], "--bench");
    int first = bench ? 2 : 1;
    long len, records, i, k, repeat = 1;
    char err[256], *text;
    float *colours;
    double to_xyz[9];
    scs_model *m;
    void *work;
    if (argc != first + 3 + 9) {
        fprintf(stderr, "usage: encode_check [--bench] TEXT COLOURS (OUT|REPEAT) M0 .. M8\n");
        return 2;
    }
    text = (char *)slurp(argv[first], &len);
    colours = (float *)slurp(argv[first + 1], &len);
    records = len / (long)(4 * sizeof(float));
    for (k = 0; k < 9; k++) to_xyz[k] = strtod(argv[first + 3 + k], NULL);
    m = scs_model_parse(text, err, sizeof err);
    if (!m) die(err, argv[first]);
    /* One workspace for every call: the encoder allocates nothing. */
    work = malloc(scs_encode_work_size(m));
    if (!work) die("out of memory", "workspace");
    if (bench) {
        float texel[6];
        clock_t t0;
        double sink = 0;
        repeat = strtol(argv[first + 2], NULL, 10);
        t0 = clock();
        for (k = 0; k < repeat; k++)
            for (i = 0; i < records; i++) {
                encode(m, to_xyz, colours + 4 * i, texel, work);
                sink += texel[3];
            }
        printf("texels=%ld seconds=%.6f sink=%g\n", records * repeat,
               (double)(clock() - t0) / CLOCKS_PER_SEC, sink);
    } else {
        FILE *out = fopen(argv[first + 2], "wb");
        int n = scs_bands(m);
        float *row = (float *)malloc(sizeof(float) * (size_t)(7 + n));
        if (!out || !row) die("cannot write", argv[first + 2]);
        for (i = 0; i < records; i++) {
            row[0] = (float)encode(m, to_xyz, colours + 4 * i, row + 1, work);
            scs_decode_bands(m, row + 1, row + 7);
            if (fwrite(row, sizeof(float), (size_t)(7 + n), out) != (size_t)(7 + n)) die("cannot write", argv[first + 2]);
        }
        if (fclose(out)) die("cannot write", argv[first + 2]);
        free(row);
        printf("records=%ld bands=%d\n", records, n);
    }
    free(work);
    free(colours);
    free(text);
    scs_model_free(m);
    return 0;
}
