/*
 * specconv_ocio.h - the C interface specconv uses for colour management through
 * OpenColorIO.
 *
 * Every function that can fail returns a status (0 = success); the message is kept per
 * thread and read with specconv_ocio_last_error() on the same thread. No C++ exception
 * leaves the shim. Configs and processors are immutable once made and may be shared
 * between threads. Strings returned by a config stay valid while the config lives.
 */
#ifndef SPECCONV_OCIO_H
#define SPECCONV_OCIO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum specconv_ocio_status {
    SPECCONV_OCIO_OK = 0,
    /* The config could not be read, parsed or validated. */
    SPECCONV_OCIO_ERR_CONFIG = 1,
    /* A colour space, role or transform name is unknown to the config. */
    SPECCONV_OCIO_ERR_NOT_FOUND = 2,
    /* OpenColorIO could not build or apply a processor. */
    SPECCONV_OCIO_ERR_PROCESSOR = 3,
    /* The caller passed an invalid argument. */
    SPECCONV_OCIO_ERR_ARGUMENT = 4,
    /* A C++ exception was caught; the message says which. */
    SPECCONV_OCIO_ERR_EXCEPTION = 5
} specconv_ocio_status;

typedef struct specconv_ocio_config specconv_ocio_config;
typedef struct specconv_ocio_processor specconv_ocio_processor;

/* One colour space of a config. Strings belong to the config. */
typedef struct specconv_ocio_color_space {
    const char *name;
    const char *family;
    const char *encoding;
    const char *description;
    int32_t num_aliases;
    int32_t is_data;
    /* 0: scene-referred, 1: display-referred */
    int32_t is_display;
} specconv_ocio_color_space;

/* The message of the last failure on this thread ("" if none). Valid until the next call. */
const char *specconv_ocio_last_error(void);

/* OpenColorIO's log: from the first call into this shim on, its messages are kept here
 * instead of being printed on standard error. Returns the messages kept since the last call
 * ("" if none), each ending with a newline, and forgets them. Valid until the next call on
 * the same thread. */
const char *specconv_ocio_take_log(void);

/* Loads a config from a file, or from YAML text whose relative paths resolve against
 * working_dir (may be NULL). Either is validated before it is returned. */
int32_t specconv_ocio_config_from_file(const char *path, specconv_ocio_config **out);
int32_t specconv_ocio_config_from_yaml(const char *yaml, const char *working_dir,
                                       specconv_ocio_config **out);
void specconv_ocio_config_free(specconv_ocio_config *config);

/* Active colour spaces, scene- and display-referred, in config order. */
int32_t specconv_ocio_num_color_spaces(const specconv_ocio_config *config);
int32_t specconv_ocio_color_space_at(const specconv_ocio_config *config, int32_t index,
                                     specconv_ocio_color_space *out);
/* Looks a colour space up by name, alias or role (as OCIO does: case-insensitive). */
int32_t specconv_ocio_color_space_named(const specconv_ocio_config *config, const char *name,
                                        specconv_ocio_color_space *out);
int32_t specconv_ocio_color_space_alias(const specconv_ocio_config *config, const char *name,
                                        int32_t index, const char **out);

/* The colour space a role points to, or NULL (status OK) when the config lacks it. */
int32_t specconv_ocio_role(const specconv_ocio_config *config, const char *role,
                           const char **out);

/* What specconv_ocio_list_len and specconv_ocio_list_item enumerate, in config order.
 * Items are tab-separated fields. */
typedef enum specconv_ocio_list_kind {
    /* Every colour space, active or inactive: name. */
    SPECCONV_OCIO_LIST_COLOR_SPACES = 0,
    /* role, colour space */
    SPECCONV_OCIO_LIST_ROLES = 1,
    /* Every display: name. */
    SPECCONV_OCIO_LIST_DISPLAYS = 2,
    /* The views of display `parent`: view, view transform, colour space, looks. */
    SPECCONV_OCIO_LIST_VIEWS = 3,
    /* name, the reference space it converts from (scene or display) */
    SPECCONV_OCIO_LIST_VIEW_TRANSFORMS = 4,
    /* name, process space */
    SPECCONV_OCIO_LIST_LOOKS = 5,
    /* name, then its aliases */
    SPECCONV_OCIO_LIST_NAMED_TRANSFORMS = 6,
    /* name, colour space, pattern, extension, regex */
    SPECCONV_OCIO_LIST_FILE_RULES = 7
} specconv_ocio_list_kind;

/* How many items of `kind` the config has; `parent` is the display for views, else NULL. */
int32_t specconv_ocio_list_len(const specconv_ocio_config *config, int32_t kind,
                               const char *parent, int32_t *out);
/* Item `index` of `kind`. The string is valid until the next call of this function on the
 * same thread. */
int32_t specconv_ocio_list_item(const specconv_ocio_config *config, int32_t kind,
                                const char *parent, int32_t index, const char **out);

/* The colour space the config's file_rules give `path` and the name of the rule that gave
 * it; both NULL (status OK) when no rule but the default one matches the path. */
int32_t specconv_ocio_file_rule(const specconv_ocio_config *config, const char *path,
                                const char **colorspace, const char **rule);

/* A processor from colour space src to colour space dst of the config, followed, when
 * post_builtin is not NULL, by the OCIO built-in transform of that style. */
int32_t specconv_ocio_processor_new(const specconv_ocio_config *config, const char *src,
                                    const char *dst, const char *post_builtin,
                                    specconv_ocio_processor **out);
/* A processor from colour space src of the config to view `view` of display `display`
 * (the view's look and view transform, then the display colour space). */
int32_t specconv_ocio_display_view_processor_new(const specconv_ocio_config *config,
                                                 const char *src, const char *display,
                                                 const char *view,
                                                 specconv_ocio_processor **out);
void specconv_ocio_processor_free(specconv_ocio_processor *processor);

/* Converts npixels interleaved pixels of nchannels (3: RGB, 4: RGBA, alpha untouched)
 * f32 values in place. */
int32_t specconv_ocio_processor_apply(const specconv_ocio_processor *processor, float *data,
                                      size_t npixels, int32_t nchannels);

#ifdef __cplusplus
}
#endif

#endif
