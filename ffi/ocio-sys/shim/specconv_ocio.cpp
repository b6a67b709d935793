// specconv_ocio.cpp - the OpenColorIO side of specconv_ocio.h.
//
// Every entry point runs inside guard(): OCIO reports nearly everything by throwing
// OCIO::Exception, which here becomes a status code and a per-thread message.

#include "specconv_ocio.h"

#include <OpenColorIO/OpenColorIO.h>

#include <exception>
#include <mutex>
#include <sstream>
#include <string>

namespace OCIO = OCIO_NAMESPACE;

namespace {

thread_local std::string last_error;

// OpenColorIO's log, kept for the caller to read (specconv_ocio_take_log) rather than
// printed: OCIO's default logging function writes to standard error.
std::mutex log_mutex;
std::string log_kept;
thread_local std::string log_taken;

void keep_log(const char *message) {
    std::lock_guard<std::mutex> lock(log_mutex);
    log_kept += message;
    if (log_kept.empty() || log_kept.back() != '\n')
        log_kept += '\n';
}

void route_log() {
    static std::once_flag routed;
    std::call_once(routed, [] { OCIO::SetLoggingFunction(&keep_log); });
}

int32_t fail(int32_t status, std::string message) {
    last_error = std::move(message);
    return status;
}

template <typename F> int32_t guard(int32_t on_exception, F &&body) noexcept {
    try {
        route_log();
        last_error.clear();
        return body();
    } catch (const std::exception &e) {
        return fail(on_exception, e.what());
    } catch (...) {
        return fail(SPECCONV_OCIO_ERR_EXCEPTION, "OpenColorIO raised an unknown C++ exception");
    }
}

} // namespace

struct specconv_ocio_config {
    OCIO::ConstConfigRcPtr config;
};

struct specconv_ocio_processor {
    OCIO::ConstProcessorRcPtr processor;
    OCIO::ConstCPUProcessorRcPtr cpu;
};

namespace {

int32_t adopt_config(OCIO::ConstConfigRcPtr config, specconv_ocio_config **out) {
    // Catch dangling references (roles to missing spaces, bad transforms) now rather
    // than halfway through a batch.
    config->validate();
    *out = new specconv_ocio_config{std::move(config)};
    return SPECCONV_OCIO_OK;
}

void describe(const OCIO::ColorSpace &cs, specconv_ocio_color_space *out) {
    out->name = cs.getName();
    out->family = cs.getFamily();
    out->encoding = cs.getEncoding();
    out->description = cs.getDescription();
    out->num_aliases = static_cast<int32_t>(cs.getNumAliases());
    out->is_data = cs.isData() ? 1 : 0;
    out->is_display = cs.getReferenceSpaceType() == OCIO::REFERENCE_SPACE_DISPLAY ? 1 : 0;
}

} // namespace

namespace {

// The calls that take a colour space by name: the arguments checked, the space found, or an
// error naming it.
template <typename F>
int32_t with_space_named(const specconv_ocio_config *config, const char *name, const void *out,
                         F &&body) {
    return guard(SPECCONV_OCIO_ERR_EXCEPTION, [&]() -> int32_t {
        if (config == nullptr || name == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        OCIO::ConstColorSpaceRcPtr cs = config->config->getColorSpace(name);
        if (!cs)
            return fail(SPECCONV_OCIO_ERR_NOT_FOUND,
                        std::string("no colour space named '") + name + "'");
        return body(*cs);
    });
}

} // namespace

extern "C" {

const char *specconv_ocio_last_error(void) { return last_error.c_str(); }

const char *specconv_ocio_take_log(void) {
    try {
        route_log();
        std::lock_guard<std::mutex> lock(log_mutex);
        log_taken.swap(log_kept);
        log_kept.clear();
    } catch (...) {
        log_taken.clear();
    }
    return log_taken.c_str();
}

int32_t specconv_ocio_config_from_file(const char *path, specconv_ocio_config **out) {
    return guard(SPECCONV_OCIO_ERR_CONFIG, [&]() -> int32_t {
        if (path == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        *out = nullptr;
        return adopt_config(OCIO::Config::CreateFromFile(path), out);
    });
}

int32_t specconv_ocio_config_from_yaml(const char *yaml, const char *working_dir,
                                       specconv_ocio_config **out) {
    return guard(SPECCONV_OCIO_ERR_CONFIG, [&]() -> int32_t {
        if (yaml == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        *out = nullptr;
        std::istringstream stream{std::string(yaml)};
        OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromStream(stream);
        if (working_dir != nullptr) {
            OCIO::ConfigRcPtr editable = config->createEditableCopy();
            editable->setWorkingDir(working_dir);
            config = editable;
        }
        return adopt_config(std::move(config), out);
    });
}

void specconv_ocio_config_free(specconv_ocio_config *config) {
    try {
        delete config;
    } catch (...) {
    }
}

int32_t specconv_ocio_num_color_spaces(const specconv_ocio_config *config) {
    if (config == nullptr)
        return 0;
    try {
        return config->config->getNumColorSpaces(OCIO::SEARCH_REFERENCE_SPACE_ALL,
                                                 OCIO::COLORSPACE_ACTIVE);
    } catch (...) {
        return 0;
    }
}

int32_t specconv_ocio_color_space_at(const specconv_ocio_config *config, int32_t index,
                                     specconv_ocio_color_space *out) {
    return guard(SPECCONV_OCIO_ERR_EXCEPTION, [&]() -> int32_t {
        if (config == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        const char *name = config->config->getColorSpaceNameByIndex(
            OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ACTIVE, index);
        OCIO::ConstColorSpaceRcPtr cs =
            (name && *name) ? config->config->getColorSpace(name) : nullptr;
        if (!cs)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "no colour space at index " +
                                                        std::to_string(index));
        describe(*cs, out);
        return SPECCONV_OCIO_OK;
    });
}

int32_t specconv_ocio_color_space_named(const specconv_ocio_config *config, const char *name,
                                        specconv_ocio_color_space *out) {
    return with_space_named(config, name, out, [&](const OCIO::ColorSpace &cs) -> int32_t {
        describe(cs, out);
        return SPECCONV_OCIO_OK;
    });
}

int32_t specconv_ocio_color_space_alias(const specconv_ocio_config *config, const char *name,
                                        int32_t index, const char **out) {
    return with_space_named(config, name, out, [&](const OCIO::ColorSpace &cs) -> int32_t {
        if (index < 0 || static_cast<size_t>(index) >= cs.getNumAliases())
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "no alias " + std::to_string(index));
        *out = cs.getAlias(static_cast<size_t>(index));
        return SPECCONV_OCIO_OK;
    });
}

int32_t specconv_ocio_role(const specconv_ocio_config *config, const char *role,
                           const char **out) {
    return guard(SPECCONV_OCIO_ERR_EXCEPTION, [&]() -> int32_t {
        if (config == nullptr || role == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        *out = nullptr;
        if (!config->config->hasRole(role))
            return SPECCONV_OCIO_OK;
        OCIO::ConstColorSpaceRcPtr cs = config->config->getColorSpace(role);
        if (!cs)
            return fail(SPECCONV_OCIO_ERR_NOT_FOUND, std::string("role '") + role +
                                                         "' names a missing colour space");
        *out = cs->getName();
        return SPECCONV_OCIO_OK;
    });
}

int32_t specconv_ocio_list_len(const specconv_ocio_config *config, int32_t kind,
                               const char *parent, int32_t *out) {
    return guard(SPECCONV_OCIO_ERR_EXCEPTION, [&]() -> int32_t {
        if (config == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        const OCIO::Config &cfg = *config->config;
        switch (kind) {
        case SPECCONV_OCIO_LIST_COLOR_SPACES:
            *out = cfg.getNumColorSpaces(OCIO::SEARCH_REFERENCE_SPACE_ALL,
                                         OCIO::COLORSPACE_ALL);
            break;
        case SPECCONV_OCIO_LIST_ROLES:
            *out = cfg.getNumRoles();
            break;
        case SPECCONV_OCIO_LIST_DISPLAYS:
            *out = cfg.getNumDisplaysAll();
            break;
        case SPECCONV_OCIO_LIST_VIEWS:
            if (parent == nullptr)
                return fail(SPECCONV_OCIO_ERR_ARGUMENT, "views need a display");
            *out = cfg.getNumViews(OCIO::VIEW_DISPLAY_DEFINED, parent) +
                   cfg.getNumViews(OCIO::VIEW_SHARED, parent);
            break;
        case SPECCONV_OCIO_LIST_VIEW_TRANSFORMS:
            *out = cfg.getNumViewTransforms();
            break;
        case SPECCONV_OCIO_LIST_LOOKS:
            *out = cfg.getNumLooks();
            break;
        case SPECCONV_OCIO_LIST_NAMED_TRANSFORMS:
            *out = cfg.getNumNamedTransforms(OCIO::NAMEDTRANSFORM_ALL);
            break;
        case SPECCONV_OCIO_LIST_FILE_RULES:
            *out = static_cast<int32_t>(cfg.getFileRules()->getNumEntries());
            break;
        default:
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "unknown list kind " + std::to_string(kind));
        }
        return SPECCONV_OCIO_OK;
    });
}

namespace {

thread_local std::string list_item;

std::string or_empty(const char *s) { return s ? s : ""; }

std::string view_transform_item(const OCIO::ViewTransform &vt) {
    const bool display = vt.getReferenceSpaceType() == OCIO::REFERENCE_SPACE_DISPLAY;
    return or_empty(vt.getName()) + (display ? "\tdisplay" : "\tscene");
}

} // namespace

int32_t specconv_ocio_list_item(const specconv_ocio_config *config, int32_t kind,
                                const char *parent, int32_t index, const char **out) {
    return guard(SPECCONV_OCIO_ERR_EXCEPTION, [&]() -> int32_t {
        if (config == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        int32_t len = 0;
        int32_t status = specconv_ocio_list_len(config, kind, parent, &len);
        if (status != SPECCONV_OCIO_OK)
            return status;
        if (index < 0 || index >= len)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "no item " + std::to_string(index));
        const OCIO::Config &cfg = *config->config;
        std::string item;
        switch (kind) {
        case SPECCONV_OCIO_LIST_COLOR_SPACES:
            item = or_empty(cfg.getColorSpaceNameByIndex(OCIO::SEARCH_REFERENCE_SPACE_ALL,
                                                         OCIO::COLORSPACE_ALL, index));
            break;
        case SPECCONV_OCIO_LIST_ROLES: {
            const char *role = cfg.getRoleName(index);
            OCIO::ConstColorSpaceRcPtr cs = cfg.getColorSpace(role);
            item = or_empty(role) + "\t" + (cs ? cs->getName() : "");
            break;
        }
        case SPECCONV_OCIO_LIST_DISPLAYS:
            item = or_empty(cfg.getDisplayAll(index));
            break;
        case SPECCONV_OCIO_LIST_VIEWS: {
            int32_t own = cfg.getNumViews(OCIO::VIEW_DISPLAY_DEFINED, parent);
            const char *view = index < own
                                   ? cfg.getView(OCIO::VIEW_DISPLAY_DEFINED, parent, index)
                                   : cfg.getView(OCIO::VIEW_SHARED, parent, index - own);
            item = or_empty(view) + "\t" +
                   or_empty(cfg.getDisplayViewTransformName(parent, view)) + "\t" +
                   or_empty(cfg.getDisplayViewColorSpaceName(parent, view)) + "\t" +
                   or_empty(cfg.getDisplayViewLooks(parent, view));
            break;
        }
        case SPECCONV_OCIO_LIST_VIEW_TRANSFORMS:
            item = view_transform_item(
                *cfg.getViewTransform(cfg.getViewTransformNameByIndex(index)));
            break;
        case SPECCONV_OCIO_LIST_LOOKS: {
            OCIO::ConstLookRcPtr look = cfg.getLook(cfg.getLookNameByIndex(index));
            item = or_empty(look->getName()) + "\t" + or_empty(look->getProcessSpace());
            break;
        }
        case SPECCONV_OCIO_LIST_NAMED_TRANSFORMS: {
            OCIO::ConstNamedTransformRcPtr nt = cfg.getNamedTransform(
                cfg.getNamedTransformNameByIndex(OCIO::NAMEDTRANSFORM_ALL, index));
            item = or_empty(nt->getName());
            for (size_t i = 0; i < nt->getNumAliases(); ++i)
                item += std::string("\t") + nt->getAlias(i);
            break;
        }
        case SPECCONV_OCIO_LIST_FILE_RULES: {
            OCIO::ConstFileRulesRcPtr rules = cfg.getFileRules();
            size_t i = static_cast<size_t>(index);
            item = or_empty(rules->getName(i)) + "\t" + or_empty(rules->getColorSpace(i)) +
                   "\t" + or_empty(rules->getPattern(i)) + "\t" +
                   or_empty(rules->getExtension(i)) + "\t" + or_empty(rules->getRegex(i));
            break;
        }
        }
        list_item = std::move(item);
        *out = list_item.c_str();
        return SPECCONV_OCIO_OK;
    });
}

int32_t specconv_ocio_file_rule(const specconv_ocio_config *config, const char *path,
                                const char **colorspace, const char **rule) {
    return guard(SPECCONV_OCIO_ERR_EXCEPTION, [&]() -> int32_t {
        if (config == nullptr || path == nullptr || colorspace == nullptr || rule == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        *colorspace = nullptr;
        *rule = nullptr;
        // The default rule always matches; it is the format's default, not a rule of the
        // config's author for this path.
        if (config->config->filepathOnlyMatchesDefaultRule(path))
            return SPECCONV_OCIO_OK;
        size_t index = 0;
        *colorspace = config->config->getColorSpaceFromFilepath(path, index);
        *rule = config->config->getFileRules()->getName(index);
        return SPECCONV_OCIO_OK;
    });
}

int32_t specconv_ocio_processor_new(const specconv_ocio_config *config, const char *src,
                                    const char *dst, const char *post_builtin,
                                    specconv_ocio_processor **out) {
    return guard(SPECCONV_OCIO_ERR_PROCESSOR, [&]() -> int32_t {
        if (config == nullptr || src == nullptr || dst == nullptr || out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        *out = nullptr;
        const OCIO::Config &cfg = *config->config;
        if (!cfg.getColorSpace(src))
            return fail(SPECCONV_OCIO_ERR_NOT_FOUND,
                        std::string("no colour space named '") + src + "'");
        if (!cfg.getColorSpace(dst))
            return fail(SPECCONV_OCIO_ERR_NOT_FOUND,
                        std::string("no colour space named '") + dst + "'");
        OCIO::ConstProcessorRcPtr processor;
        if (post_builtin == nullptr) {
            processor = cfg.getProcessor(src, dst);
        } else {
            OCIO::GroupTransformRcPtr group = OCIO::GroupTransform::Create();
            OCIO::ColorSpaceTransformRcPtr cst = OCIO::ColorSpaceTransform::Create();
            cst->setSrc(src);
            cst->setDst(dst);
            group->appendTransform(cst);
            OCIO::BuiltinTransformRcPtr builtin = OCIO::BuiltinTransform::Create();
            builtin->setStyle(post_builtin); // throws on an unknown style
            group->appendTransform(builtin);
            processor = cfg.getProcessor(group);
        }
        OCIO::ConstCPUProcessorRcPtr cpu = processor->getDefaultCPUProcessor();
        *out = new specconv_ocio_processor{std::move(processor), std::move(cpu)};
        return SPECCONV_OCIO_OK;
    });
}

int32_t specconv_ocio_display_view_processor_new(const specconv_ocio_config *config,
                                                 const char *src, const char *display,
                                                 const char *view,
                                                 specconv_ocio_processor **out) {
    return guard(SPECCONV_OCIO_ERR_PROCESSOR, [&]() -> int32_t {
        if (config == nullptr || src == nullptr || display == nullptr || view == nullptr ||
            out == nullptr)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        *out = nullptr;
        const OCIO::Config &cfg = *config->config;
        if (!cfg.getColorSpace(src))
            return fail(SPECCONV_OCIO_ERR_NOT_FOUND,
                        std::string("no colour space named '") + src + "'");
        OCIO::DisplayViewTransformRcPtr dvt = OCIO::DisplayViewTransform::Create();
        dvt->setSrc(src);
        dvt->setDisplay(display);
        dvt->setView(view);
        OCIO::ConstProcessorRcPtr processor = cfg.getProcessor(dvt);
        OCIO::ConstCPUProcessorRcPtr cpu = processor->getDefaultCPUProcessor();
        *out = new specconv_ocio_processor{std::move(processor), std::move(cpu)};
        return SPECCONV_OCIO_OK;
    });
}

void specconv_ocio_processor_free(specconv_ocio_processor *processor) {
    try {
        delete processor;
    } catch (...) {
    }
}

int32_t specconv_ocio_processor_apply(const specconv_ocio_processor *processor, float *data,
                                      size_t npixels, int32_t nchannels) {
    return guard(SPECCONV_OCIO_ERR_PROCESSOR, [&]() -> int32_t {
        if (processor == nullptr || (data == nullptr && npixels > 0))
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "null argument");
        if (nchannels != 3 && nchannels != 4)
            return fail(SPECCONV_OCIO_ERR_ARGUMENT, "pixels must have 3 or 4 channels");
        if (npixels == 0)
            return SPECCONV_OCIO_OK;
        OCIO::PackedImageDesc desc(data, static_cast<long>(npixels), 1, nchannels);
        processor->cpu->apply(desc);
        return SPECCONV_OCIO_OK;
    });
}

} // extern "C"
