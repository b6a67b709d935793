/*
 * specconv_oiio.h - the C interface specconv uses to read images through OpenImageIO.
 *
 * Every function returns a status (0 = success). On failure the message is kept per
 * thread and read with specconv_oiio_last_error() on the same thread. No C++ exception
 * leaves the shim. A handle is used by one thread at a time; open one per worker.
 * Pixel coordinates are relative to the data window origin of the MIP level. Everything
 * describes and reads the selected subimage (part), subimage 0 unless one is selected.
 */
#ifndef SPECCONV_OIIO_H
#define SPECCONV_OIIO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum specconv_oiio_status {
    SPECCONV_OIIO_OK = 0,
    /* The file could not be opened or its header could not be read. */
    SPECCONV_OIIO_ERR_OPEN = 1,
    /* Pixel data could not be read (corrupt or truncated file, I/O error). */
    SPECCONV_OIIO_ERR_READ = 2,
    /* The caller passed an invalid argument (level, region, buffer size, NULL). */
    SPECCONV_OIIO_ERR_ARGUMENT = 3,
    /* The image is valid but of a kind specconv does not handle (deep, volume). */
    SPECCONV_OIIO_ERR_UNSUPPORTED = 4,
    /* A C++ exception was caught; the message says which. */
    SPECCONV_OIIO_ERR_EXCEPTION = 5
} specconv_oiio_status;

typedef struct specconv_oiio_input specconv_oiio_input;

/* Geometry and storage of one MIP level of the selected subimage. */
typedef struct specconv_oiio_level {
    int32_t x, y;            /* data window origin */
    int32_t width, height;   /* data window size */
    int32_t full_x, full_y;  /* display window origin */
    int32_t full_width, full_height;
    int32_t tile_width, tile_height; /* 0 when stored as scanlines */
    int32_t nchannels;
    int32_t alpha_channel;   /* -1 when none */
} specconv_oiio_level;

/* The message of the last failure on this thread ("" if none). Valid until the next call. */
const char *specconv_oiio_last_error(void);

/* The OpenImageIO version the program runs against, e.g. 20407 for 2.4.7. */
int32_t specconv_oiio_version(void);

/* Opens `path` (UTF-8) with whichever format plugin reads it. Unassociated (straight)
 * alpha is kept as stored, not premultiplied (OIIO's oiio:UnassociatedAlpha hint); such
 * files say so with the attribute oiio:UnassociatedAlpha = 1. */
int32_t specconv_oiio_open(const char *path, specconv_oiio_input **out);
void specconv_oiio_close(specconv_oiio_input *input);

/* The plugin's format name ("openexr", "tiff", ...). Valid while the input is open. */
const char *specconv_oiio_format_name(const specconv_oiio_input *input);
int32_t specconv_oiio_num_subimages(const specconv_oiio_input *input);
/* The name of subimage `subimage` (an OpenEXR part's `name`), "" when it has none. Valid
 * while the input is open. */
int32_t specconv_oiio_subimage_name(const specconv_oiio_input *input, int32_t subimage,
                                    const char **out);
/* Selects the subimage that every other call describes and reads; reads its header. */
int32_t specconv_oiio_select_subimage(specconv_oiio_input *input, int32_t subimage);
int32_t specconv_oiio_num_levels(const specconv_oiio_input *input);
int32_t specconv_oiio_level_info(const specconv_oiio_input *input, int32_t level,
                                 specconv_oiio_level *out);

/* Name and stored data type ("uint8", "half", ...) of channel `channel` of level 0.
 * Valid while the input is open. */
int32_t specconv_oiio_channel_name(const specconv_oiio_input *input, int32_t channel,
                                   const char **out);
int32_t specconv_oiio_channel_format(const specconv_oiio_input *input, int32_t channel,
                                     const char **out);

/* Copies string attribute `name` of level 0 into buf (NUL-terminated, truncated to
 * buf_len). *len receives the full length without the NUL, or -1 when the attribute is
 * absent or not a string. buf may be NULL to ask for the length. */
int32_t specconv_oiio_string_attribute(const specconv_oiio_input *input, const char *name,
                                       char *buf, size_t buf_len, int64_t *len);

/* Copies the names of level 0's string attributes into buf, each followed by a NUL, in the
 * header's order (truncated to buf_len). *len receives the full length of the list. buf may
 * be NULL to ask for the length. */
int32_t specconv_oiio_string_attribute_names(const specconv_oiio_input *input, char *buf,
                                             size_t buf_len, int64_t *len);

/* Copies numeric attribute `name` of level 0 (integer, float or double; scalar, array or
 * aggregate such as OpenEXR's chromaticities) into buf as doubles, at most buf_len of them.
 * *len receives the number of values, or -1 when the attribute is absent or not numeric.
 * buf may be NULL to ask for the count. */
int32_t specconv_oiio_numeric_attribute(const specconv_oiio_input *input, const char *name,
                                        double *buf, size_t buf_len, int64_t *len);

/* Copies byte-array attribute `name` of level 0 (e.g. "ICCProfile") into buf, at most
 * buf_len bytes. *len receives its size, or -1 when absent or not an array of bytes. buf may
 * be NULL to ask for the size. */
int32_t specconv_oiio_bytes_attribute(const specconv_oiio_input *input, const char *name,
                                      uint8_t *buf, size_t buf_len, int64_t *len);

/* Reads channels [chbegin, chend) of the pixels [xbegin, xend) x [ybegin, yend) of
 * `level` as f32, interleaved, rows top to bottom, into out (out_len floats at least).
 * read_tiles needs a tiled level and a region on tile boundaries (or the image edge);
 * read_scanlines reads whole rows of a scanline level (tiled levels are refused). */
int32_t specconv_oiio_read_tiles(specconv_oiio_input *input, int32_t level, int32_t xbegin,
                                 int32_t xend, int32_t ybegin, int32_t yend, int32_t chbegin,
                                 int32_t chend, float *out, size_t out_len);
int32_t specconv_oiio_read_scanlines(specconv_oiio_input *input, int32_t level, int32_t ybegin,
                                     int32_t yend, int32_t chbegin, int32_t chend, float *out,
                                     size_t out_len);

/* Writes subimage `subimage` of the image at `input` through, unconverted, as a tiled,
 * MIP-mapped OpenEXR texture at `output` with ImageBufAlgo::make_texture (what maketx does:
 * box-filtered levels, the input's metadata kept, its wrapmodes when it has them), tiles of
 * tile_width x tile_height, OpenEXR compression `compression` ("zip", ...), and the `count`
 * string attributes names[i] = values[i] added, except "specconv:erase", whose value names
 * (a line each) the input's attributes to leave out. OpenImageIO writes a temporary beside
 * `output` and renames it into place. */
int32_t specconv_oiio_make_texture(const char *input, int32_t subimage, const char *output,
                                   int32_t tile_width, int32_t tile_height,
                                   const char *compression, const char *const *names,
                                   const char *const *values, size_t count);

#ifdef __cplusplus
}
#endif

#endif
