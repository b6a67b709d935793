// specconv_oiio.cpp - the OpenImageIO side of specconv_oiio.h.
//
// Every entry point runs inside guard(): C++ exceptions become a status code and a
// per-thread message, so nothing unwinds into Rust.

#include "specconv_oiio.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cstring>
#include <exception>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

thread_local std::string last_error;

int32_t fail(int32_t status, std::string message) {
    last_error = std::move(message);
    return status;
}

template <typename F> int32_t guard(F &&body) noexcept {
    try {
        last_error.clear();
        return body();
    } catch (const std::exception &e) {
        return fail(SPECCONV_OIIO_ERR_EXCEPTION, std::string("OpenImageIO raised: ") + e.what());
    } catch (...) {
        return fail(SPECCONV_OIIO_ERR_EXCEPTION, "OpenImageIO raised an unknown C++ exception");
    }
}

// OIIO keeps errors on the ImageInput; fetching them also clears them, which stops OIIO
// from printing "pending error" warnings when the input is destroyed.
std::string input_error(OIIO::ImageInput &in, const char *fallback) {
    std::string msg = in.geterror();
    return msg.empty() ? std::string(fallback) : msg;
}

} // namespace

struct specconv_oiio_input {
    std::unique_ptr<OIIO::ImageInput> in;
    std::string format_name;
    int32_t num_subimages = 1;
    std::vector<std::string> subimage_names;
    // The selected subimage, and the full spec of each of its MIP levels.
    int32_t subimage = 0;
    std::vector<OIIO::ImageSpec> levels;
    std::vector<std::string> channel_formats;
};

namespace {

// Reads the header of every MIP level of `subimage` and makes it the selected one.
int32_t load_subimage(specconv_oiio_input &handle, int32_t subimage) {
    OIIO::ImageInput &in = *handle.in;
    std::vector<OIIO::ImageSpec> levels;
    // spec(0, level) is not a reliable probe (the TIFF plugin answers for any level);
    // seek_subimage fails past the last level. The cap guards against a plugin that
    // never fails: 64 levels would be a 2^63-pixel-wide image.
    for (int level = 0; level < 64 && in.seek_subimage(subimage, level); ++level)
        levels.push_back(in.spec());
    in.geterror(); // seeking past the last level leaves an error behind; it is expected
    if (levels.empty())
        return fail(SPECCONV_OIIO_ERR_OPEN, input_error(in, "the file has no readable image"));
    const OIIO::ImageSpec &top = levels[0];
    if (top.deep)
        return fail(SPECCONV_OIIO_ERR_UNSUPPORTED, "deep images are not supported");
    if (top.depth > 1)
        return fail(SPECCONV_OIIO_ERR_UNSUPPORTED, "volume (3D) images are not supported");
    handle.channel_formats.clear();
    for (int c = 0; c < top.nchannels; ++c)
        handle.channel_formats.emplace_back(top.channelformat(c).c_str());
    handle.levels = std::move(levels);
    handle.subimage = subimage;
    return SPECCONV_OIIO_OK;
}

} // namespace

namespace {

// The three header-attribute calls share their protocol: check the arguments, report -1 (absent)
// unless the first level has the attribute (of `type`, when given), then let `read` fill it.
template <typename F>
int32_t read_attribute(const specconv_oiio_input *input, const char *name, int64_t *len,
                       OIIO::TypeDesc type, F &&read) {
    return guard([&]() -> int32_t {
        if (input == nullptr || name == nullptr || len == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        *len = -1;
        const OIIO::ParamValue *p = input->levels[0].find_attribute(name, type);
        if (p == nullptr)
            return SPECCONV_OIIO_OK;
        return read(*p);
    });
}

// How many scalar values an attribute holds (an aggregate such as a matrix counts each).
size_t value_count(const OIIO::ParamValue &p) {
    OIIO::TypeDesc t = p.type();
    return size_t(p.nvalues()) * t.numelements() * t.aggregate;
}

} // namespace

extern "C" {

const char *specconv_oiio_last_error(void) { return last_error.c_str(); }

int32_t specconv_oiio_version(void) { return OIIO::openimageio_version(); }

int32_t specconv_oiio_open(const char *path, specconv_oiio_input **out) {
    return guard([&]() -> int32_t {
        if (path == nullptr || out == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        *out = nullptr;
        auto handle = std::make_unique<specconv_oiio_input>();
        // Straight alpha stays straight: colour is converted before it is premultiplied.
        OIIO::ImageSpec hints;
        hints.attribute("oiio:UnassociatedAlpha", 1);
        handle->in = OIIO::ImageInput::open(path, &hints);
        if (!handle->in) {
            std::string msg = OIIO::geterror();
            return fail(SPECCONV_OIIO_ERR_OPEN,
                        msg.empty() ? std::string("OpenImageIO could not open the file") : msg);
        }
        OIIO::ImageInput &in = *handle->in;
        // Parallelism comes from one reader per worker; OIIO's own pool would oversubscribe.
        in.threads(1);
        handle->format_name = in.format_name();
        handle->num_subimages = 0;
        while (in.seek_subimage(handle->num_subimages, 0)) {
            handle->subimage_names.push_back(
                in.spec().get_string_attribute("oiio:subimagename"));
            ++handle->num_subimages;
        }
        in.geterror();
        int32_t st = load_subimage(*handle, 0);
        if (st != SPECCONV_OIIO_OK)
            return st;
        *out = handle.release();
        return SPECCONV_OIIO_OK;
    });
}

void specconv_oiio_close(specconv_oiio_input *input) {
    // Destructors of OIIO inputs close files; keep any exception inside the shim.
    try {
        delete input;
    } catch (...) {
    }
}

const char *specconv_oiio_format_name(const specconv_oiio_input *input) {
    return input ? input->format_name.c_str() : "";
}

int32_t specconv_oiio_num_subimages(const specconv_oiio_input *input) {
    return input ? input->num_subimages : 0;
}

int32_t specconv_oiio_subimage_name(const specconv_oiio_input *input, int32_t subimage,
                                    const char **out) {
    return guard([&]() -> int32_t {
        if (input == nullptr || out == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        if (subimage < 0 || subimage >= static_cast<int32_t>(input->subimage_names.size()))
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "no subimage " + std::to_string(subimage));
        *out = input->subimage_names[subimage].c_str();
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_select_subimage(specconv_oiio_input *input, int32_t subimage) {
    return guard([&]() -> int32_t {
        if (input == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        if (subimage < 0 || subimage >= input->num_subimages)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT,
                        "subimage " + std::to_string(subimage) + " does not exist (the file has " +
                            std::to_string(input->num_subimages) + ")");
        return load_subimage(*input, subimage);
    });
}

int32_t specconv_oiio_num_levels(const specconv_oiio_input *input) {
    return input ? static_cast<int32_t>(input->levels.size()) : 0;
}

int32_t specconv_oiio_level_info(const specconv_oiio_input *input, int32_t level,
                                 specconv_oiio_level *out) {
    return guard([&]() -> int32_t {
        if (input == nullptr || out == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        if (level < 0 || level >= static_cast<int32_t>(input->levels.size()))
            return fail(SPECCONV_OIIO_ERR_ARGUMENT,
                        "MIP level " + std::to_string(level) + " does not exist (the file has " +
                            std::to_string(input->levels.size()) + ")");
        const OIIO::ImageSpec &s = input->levels[level];
        out->x = s.x;
        out->y = s.y;
        out->width = s.width;
        out->height = s.height;
        out->full_x = s.full_x;
        out->full_y = s.full_y;
        out->full_width = s.full_width;
        out->full_height = s.full_height;
        out->tile_width = s.tile_width;
        out->tile_height = s.tile_height;
        out->nchannels = s.nchannels;
        out->alpha_channel = s.alpha_channel;
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_channel_name(const specconv_oiio_input *input, int32_t channel,
                                   const char **out) {
    return guard([&]() -> int32_t {
        if (input == nullptr || out == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        const OIIO::ImageSpec &s = input->levels[0];
        if (channel < 0 || channel >= s.nchannels)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "no channel " + std::to_string(channel));
        *out = s.channelnames[channel].c_str();
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_channel_format(const specconv_oiio_input *input, int32_t channel,
                                     const char **out) {
    return guard([&]() -> int32_t {
        if (input == nullptr || out == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        if (channel < 0 || channel >= static_cast<int32_t>(input->channel_formats.size()))
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "no channel " + std::to_string(channel));
        *out = input->channel_formats[channel].c_str();
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_string_attribute(const specconv_oiio_input *input, const char *name,
                                       char *buf, size_t buf_len, int64_t *len) {
    return read_attribute(input, name, len, OIIO::TypeString, [&](const OIIO::ParamValue &p) -> int32_t {
        std::string value = p.get_string();
        *len = static_cast<int64_t>(value.size());
        if (buf != nullptr && buf_len > 0) {
            size_t n = value.size() < buf_len - 1 ? value.size() : buf_len - 1;
            std::memcpy(buf, value.data(), n);
            buf[n] = '\0';
        }
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_string_attribute_names(const specconv_oiio_input *input, char *buf,
                                             size_t buf_len, int64_t *len) {
    return guard([&]() -> int32_t {
        if (input == nullptr || len == nullptr)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        std::string names;
        for (const OIIO::ParamValue &p : input->levels[0].extra_attribs) {
            if (p.type() == OIIO::TypeString) {
                names += p.name().string();
                names += '\0';
            }
        }
        *len = static_cast<int64_t>(names.size());
        if (buf != nullptr)
            std::memcpy(buf, names.data(), names.size() < buf_len ? names.size() : buf_len);
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_numeric_attribute(const specconv_oiio_input *input, const char *name,
                                        double *buf, size_t buf_len, int64_t *len) {
    return read_attribute(input, name, len, OIIO::TypeUnknown, [&](const OIIO::ParamValue &p) -> int32_t {
        size_t n = value_count(p);
        std::vector<double> values(n);
        const void *d = p.data();
        // OIIO 2.4's convert_type and get_float_indexed refuse int to float; convert here.
        for (size_t i = 0; i < n; ++i) {
            switch (p.type().basetype) {
            case OIIO::TypeDesc::UINT8: values[i] = static_cast<const uint8_t *>(d)[i]; break;
            case OIIO::TypeDesc::INT8: values[i] = static_cast<const int8_t *>(d)[i]; break;
            case OIIO::TypeDesc::UINT16: values[i] = static_cast<const uint16_t *>(d)[i]; break;
            case OIIO::TypeDesc::INT16: values[i] = static_cast<const int16_t *>(d)[i]; break;
            case OIIO::TypeDesc::UINT32: values[i] = static_cast<const uint32_t *>(d)[i]; break;
            case OIIO::TypeDesc::INT32: values[i] = static_cast<const int32_t *>(d)[i]; break;
            case OIIO::TypeDesc::UINT64: values[i] = double(static_cast<const uint64_t *>(d)[i]); break;
            case OIIO::TypeDesc::INT64: values[i] = double(static_cast<const int64_t *>(d)[i]); break;
            case OIIO::TypeDesc::FLOAT: values[i] = static_cast<const float *>(d)[i]; break;
            case OIIO::TypeDesc::DOUBLE: values[i] = static_cast<const double *>(d)[i]; break;
            default: return SPECCONV_OIIO_OK; // strings, pointers, half: not read as numbers
            }
        }
        *len = static_cast<int64_t>(n);
        for (size_t i = 0; buf != nullptr && i < n && i < buf_len; ++i)
            buf[i] = values[i];
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_bytes_attribute(const specconv_oiio_input *input, const char *name,
                                      uint8_t *buf, size_t buf_len, int64_t *len) {
    return read_attribute(input, name, len, OIIO::TypeUnknown, [&](const OIIO::ParamValue &p) -> int32_t {
        OIIO::TypeDesc::BASETYPE b = OIIO::TypeDesc::BASETYPE(p.type().basetype);
        if (b != OIIO::TypeDesc::UINT8 && b != OIIO::TypeDesc::INT8)
            return SPECCONV_OIIO_OK;
        size_t n = value_count(p);
        *len = static_cast<int64_t>(n);
        if (buf != nullptr)
            std::memcpy(buf, p.data(), n < buf_len ? n : buf_len);
        return SPECCONV_OIIO_OK;
    });
}

namespace {

// Checks a request against the level and the caller's buffer; returns OK or an error.
int32_t check_region(const specconv_oiio_input *input, int32_t level, int32_t xbegin,
                     int32_t xend, int32_t ybegin, int32_t yend, int32_t chbegin, int32_t chend,
                     const float *out, size_t out_len) {
    if (input == nullptr || out == nullptr)
        return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
    if (level < 0 || level >= static_cast<int32_t>(input->levels.size()))
        return fail(SPECCONV_OIIO_ERR_ARGUMENT, "MIP level " + std::to_string(level) +
                                                    " does not exist");
    const OIIO::ImageSpec &s = input->levels[level];
    if (xbegin < 0 || xend > s.width || xbegin >= xend || ybegin < 0 || yend > s.height ||
        ybegin >= yend)
        return fail(SPECCONV_OIIO_ERR_ARGUMENT, "region outside MIP level " +
                                                    std::to_string(level));
    if (chbegin < 0 || chend > s.nchannels || chbegin >= chend)
        return fail(SPECCONV_OIIO_ERR_ARGUMENT, "channel range outside the image");
    uint64_t need = uint64_t(xend - xbegin) * uint64_t(yend - ybegin) * uint64_t(chend - chbegin);
    if (need > out_len)
        return fail(SPECCONV_OIIO_ERR_ARGUMENT, "output buffer too small");
    return SPECCONV_OIIO_OK;
}

} // namespace

int32_t specconv_oiio_read_tiles(specconv_oiio_input *input, int32_t level, int32_t xbegin,
                                 int32_t xend, int32_t ybegin, int32_t yend, int32_t chbegin,
                                 int32_t chend, float *out, size_t out_len) {
    return guard([&]() -> int32_t {
        int32_t st = check_region(input, level, xbegin, xend, ybegin, yend, chbegin, chend, out,
                                  out_len);
        if (st != SPECCONV_OIIO_OK)
            return st;
        const OIIO::ImageSpec &s = input->levels[level];
        if (s.tile_width == 0)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "the image is stored as scanlines, not tiles");
        if (!input->in->read_tiles(input->subimage, level, s.x + xbegin, s.x + xend,
                                   s.y + ybegin, s.y + yend, s.z, s.z + 1, chbegin, chend,
                                   OIIO::TypeFloat, out))
            return fail(SPECCONV_OIIO_ERR_READ, input_error(*input->in, "reading tiles failed"));
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_read_scanlines(specconv_oiio_input *input, int32_t level, int32_t ybegin,
                                     int32_t yend, int32_t chbegin, int32_t chend, float *out,
                                     size_t out_len) {
    return guard([&]() -> int32_t {
        if (input == nullptr || level < 0 || level >= static_cast<int32_t>(input->levels.size()))
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "MIP level " + std::to_string(level) +
                                                        " does not exist");
        const OIIO::ImageSpec &s = input->levels[level];
        int32_t st = check_region(input, level, 0, s.width, ybegin, yend, chbegin, chend, out,
                                  out_len);
        if (st != SPECCONV_OIIO_OK)
            return st;
        // OIIO 2.4.7's read_scanlines on a tiled TIFF dies with SIGFPE for row ranges that
        // do not cover whole tile rows, so tiled levels are read through read_tiles only.
        if (s.tile_width != 0)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT,
                        "the image is tiled; read it by tiles (scanline reads are refused)");
        if (!input->in->read_scanlines(input->subimage, level, s.y + ybegin, s.y + yend, s.z,
                                       chbegin, chend, OIIO::TypeFloat, out))
            return fail(SPECCONV_OIIO_ERR_READ,
                        input_error(*input->in, "reading scanlines failed"));
        return SPECCONV_OIIO_OK;
    });
}

int32_t specconv_oiio_make_texture(const char *input, int32_t subimage, const char *output,
                                   int32_t tile_width, int32_t tile_height,
                                   const char *compression, const char *const *names,
                                   const char *const *values, size_t count) {
    return guard([&]() -> int32_t {
        if (input == nullptr || output == nullptr || compression == nullptr ||
            (count > 0 && (names == nullptr || values == nullptr)))
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null argument");
        if (tile_width <= 0 || tile_height <= 0 || subimage < 0)
            return fail(SPECCONV_OIIO_ERR_ARGUMENT, "tiles need a size and subimages count from 0");
        OIIO::ImageBuf source(input, subimage, 0);
        if (!source.read(subimage, 0, true))
            return fail(SPECCONV_OIIO_ERR_READ, source.geterror());
        OIIO::ImageSpec config;
        config.tile_width = tile_width;
        config.tile_height = tile_height;
        config.tile_depth = 1;
        config.attribute("compression", compression);
        // The output's name need not end in .exr (a temporary): say the format.
        config.attribute("maketx:fileformatname", "openexr");
        // make_texture writes "black,black" unless told: keep the input's.
        std::string wrap = source.spec().get_string_attribute("wrapmodes");
        if (!wrap.empty())
            config.attribute("wrapmodes", wrap);
        for (size_t i = 0; i < count; ++i) {
            if (names[i] == nullptr || values[i] == nullptr)
                return fail(SPECCONV_OIIO_ERR_ARGUMENT, "null attribute");
            // Not a setting: the input's attributes (a name a line) the texture leaves out,
            // since make_texture copies the input's header.
            if (std::string(names[i]) == "specconv:erase") {
                std::istringstream lines(values[i]);
                for (std::string name; std::getline(lines, name);)
                    if (!name.empty())
                        source.specmod().erase_attribute(name);
                continue;
            }
            config.attribute(names[i], values[i]);
        }
        if (!OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, source, output,
                                              config)) {
            std::string msg = OIIO::geterror();
            return fail(SPECCONV_OIIO_ERR_READ, msg.empty() ? "make_texture failed" : msg);
        }
        return SPECCONV_OIIO_OK;
    });
}

} // extern "C"
