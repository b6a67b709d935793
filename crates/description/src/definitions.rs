//! Every option of a conversion, defined once: its name (the Python keyword, the key of a farm
//! manifest and of the `-u` tag), what its value is, what it means when unset, the command
//! line's flags and the one help text of each. The command line's arguments, Python's keywords
//! and stub, the guide's and README's tables and the man pages are made from these
//! (`cargo run -p specconv-dev -- generate`; its `--check`, run by CI, fails when a generated
//! file is stale).

use crate::key::Key;

/// What an option's value is: how every front-end takes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Value {
    /// Text (a name, a list, a grid).
    Text,
    /// A path: any bytes on Unix.
    Path,
    /// Yes or no (`true`, `false`).
    Switch,
    /// A real number.
    Number,
    /// A whole number from 0.
    Count,
    /// One of a choice's names ([`crate::Named`]).
    Choice,
    /// Tiles `WxH` (Python: a pair of whole numbers), or `scanline`.
    Size,
}

/// How one command-line flag sets its option.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Takes {
    /// `--flag VALUE`, the value named so in help: the option's text.
    Value(&'static str),
    /// `--flag A B`, the two values named so: the text `AxB`.
    Pair(&'static str, &'static str),
    /// `--flag` alone: the option's text becomes this.
    Sets(&'static str),
    /// `--flag` (true) or `--flag=BOOL`.
    MaybeBool,
}

/// A command-line flag of an option.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Flag {
    /// Its long name, without `--`.
    pub long: &'static str,
    /// Its one-letter name, if any.
    pub short: Option<char>,
    /// Other long names it answers to (shown in help).
    pub aliases: &'static [&'static str],
    /// What follows it.
    pub takes: Takes,
    /// Another flag of the same option that must be given with it.
    pub requires: Option<&'static str>,
    /// Its help; `None` for an option's first flag, whose help is the option's.
    pub help: Option<&'static str>,
}

impl Flag {
    const fn new(long: &'static str, takes: Takes) -> Flag {
        Flag {
            long,
            short: None,
            aliases: &[],
            takes,
            requires: None,
            help: None,
        }
    }

    const fn short(self, short: char) -> Flag {
        Flag {
            short: Some(short),
            ..self
        }
    }

    const fn help(self, help: &'static str) -> Flag {
        Flag {
            help: Some(help),
            ..self
        }
    }
}

/// `--long VALUE`.
const fn value(long: &'static str, name: &'static str) -> Flag {
    Flag::new(long, Takes::Value(name))
}

/// `--long` alone, setting the text `sets`.
const fn sets(long: &'static str, sets: &'static str) -> Flag {
    Flag::new(long, Takes::Sets(sets))
}

/// One option, as every front-end shows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Definition {
    /// The option.
    pub key: Key,
    /// Its name: the Python keyword, the key of a farm manifest and of the `-u` tag.
    pub name: &'static str,
    /// What its value is.
    pub value: Value,
    /// What it means unset, for an option with no default text (decided by the input, the
    /// model, the machine, or another option).
    pub unset: Option<&'static str>,
    /// The command line's flags, the first the option's own; none where it has none.
    pub flags: &'static [Flag],
    /// What it does: the one help text of every front-end.
    pub help: &'static str,
    /// Whether it changes the bytes written (the `-u` tag must tell two values apart).
    pub changes_output: bool,
}

/// The definition of `key`.
pub fn definition(key: Key) -> Definition {
    DEFINITIONS[key as usize]
}

/// Every option's definition, in the order of [`Key::ALL`] (a test checks it).
const DEFINITIONS: [Definition; 30] = [
    d(
        Key::Ocio,
        "ocio",
        Value::Text,
        // maketx's --colorconfig.
        const {
            &[Flag {
                aliases: &["colorconfig"],
                ..value("ocio", "CONFIG")
            }]
        },
        OCIO,
    )
    .unset("$OCIO, else aces"),
    d(
        Key::Colorspace,
        "colorspace",
        Value::Text,
        const {
            &[Flag {
                aliases: &["iscolorspace"],
                ..value("colorspace", "NAME")
            }]
        },
        COLORSPACE,
    )
    .unset("the evidence's rule (docs/colour.md)"),
    d(
        Key::Alpha,
        "alpha",
        Value::Choice,
        const {
            &[
                value("alpha", "HOW"),
                sets("ignore-unassoc", "premultiplied").help(IGNORE_UNASSOC),
            ]
        },
        ALPHA,
    ),
    d(
        Key::Subimage,
        "subimage",
        Value::Text,
        const { &[value("subimage", "N|NAME")] },
        SUBIMAGE,
    )
    .unset("the first"),
    d(
        Key::Channels,
        "channels",
        Value::Text,
        const { &[value("channels", "LIST|LAYER")] },
        CHANNELS,
    )
    .unset("chosen by the input's names"),
    d(
        Key::Method,
        "method",
        Value::Choice,
        const { &[value("method", "NAME")] },
        METHOD,
    ),
    d(
        Key::Model,
        "model",
        Value::Path,
        const { &[value("model", "NAME|MODEL")] },
        MODEL,
    )
    .unset("$SPECCONV_MODEL, else open"),
    d(
        Key::Blend,
        "blend",
        Value::Number,
        const { &[value("blend", "WIDTH")] },
        BLEND,
    ),
    d(
        Key::Bounded,
        "bounded",
        Value::Switch,
        const {
            &[
                sets("bounded", "true"),
                sets("unbounded", "false").help(UNBOUNDED),
            ]
        },
        BOUNDED,
    ),
    d(
        Key::Bands,
        "bands",
        Value::Text,
        const { &[value("bands", "START:END:STEP")] },
        BANDS,
    )
    .unset("the model's"),
    d(
        Key::Emission,
        "emission",
        Value::Choice,
        const {
            &[
                sets("emissive", "reference"),
                Flag {
                    requires: Some("emissive"),
                    ..value("emission-units", "UNITS").help(EMISSION_UNITS)
                },
            ]
        },
        EMISSIVE,
    )
    .unset("reflectance"),
    d(
        Key::Layout,
        "layout",
        Value::Choice,
        const { &[value("layout", "LAYOUT")] },
        LAYOUT,
    ),
    d(
        Key::Sample,
        "sample",
        Value::Choice,
        const { &[value("data-type", "TYPE").short('d')] },
        SAMPLE,
    ),
    d(
        Key::Rounding,
        "rounding",
        Value::Choice,
        const { &[value("half-rounding", "HOW")] },
        ROUNDING,
    )
    .unset("nearest for reflectance, colour for emission"),
    d(
        Key::Compression,
        "compression",
        Value::Choice,
        const { &[value("compression", "NAME")] },
        COMPRESSION,
    ),
    d(
        Key::ZipLevel,
        "zip_level",
        Value::Count,
        const { &[value("zip-level", "LEVEL")] },
        ZIP_LEVEL,
    )
    .unset("the measured default (docs/compression.md)"),
    d(
        Key::Tile,
        "tile",
        Value::Size,
        const {
            &[
                Flag::new("tile", Takes::Pair("W", "H")),
                sets("scanline", "scanline").help(SCANLINE),
            ]
        },
        TILE,
    ),
    d(
        Key::Mip,
        "mip",
        Value::Choice,
        const { &[value("mip", "LEVELS"), sets("nomipmap", "0").help(NOMIPMAP)] },
        MIP,
    ),
    d(
        Key::Filter,
        "filter",
        Value::Choice,
        const { &[value("filter", "NAME")] },
        FILTER,
    ),
    d(
        Key::Resize,
        "resize",
        Value::Switch,
        const {
            &[
                sets("resize", "true"),
                sets("noresize", "false").help(NORESIZE),
            ]
        },
        RESIZE,
    ),
    d(
        Key::Wrap,
        "wrap",
        Value::Text,
        const { &[value("wrap", "MODE[,MODE]")] },
        WRAP,
    )
    .unset("the input's, else black"),
    d(
        Key::NonFinite,
        "non_finite",
        Value::Choice,
        const {
            &[
                value("fixnan", "HOW"),
                sets("checknan", "refuse").help(CHECKNAN),
            ]
        },
        NON_FINITE,
    ),
    d(
        Key::ConstantDetect,
        "constant_detect",
        Value::Switch,
        const { &[Flag::new("constant-color-detect", Takes::MaybeBool)] },
        CONSTANT_DETECT,
    ),
    d(
        Key::OpaqueDetect,
        "opaque_detect",
        Value::Switch,
        const { &[Flag::new("opaque-detect", Takes::MaybeBool)] },
        OPAQUE_DETECT,
    ),
    d(
        Key::Threads,
        "threads",
        Value::Count,
        const { &[value("threads", "N").short('j')] },
        THREADS,
    )
    .unset("one per core")
    .no_bytes(),
    d(
        Key::Overwrite,
        "overwrite",
        Value::Switch,
        const { &[sets("force", "true")] },
        OVERWRITE,
    )
    .no_bytes(),
    d(
        Key::TableDir,
        "table_dir",
        Value::Path,
        const { &[] },
        TABLE_DIR,
    )
    .unset("the cache directory")
    .no_bytes(),
    d(
        Key::Data,
        "data",
        Value::Choice,
        const { &[value("data", "HOW")] },
        DATA,
    ),
    d(
        Key::StripMetadata,
        "strip_metadata",
        Value::Switch,
        const { &[sets("strip-metadata", "true")] },
        STRIP_METADATA,
    ),
    d(
        Key::Strict,
        "strict",
        Value::Switch,
        const { &[sets("strict", "true")] },
        STRICT,
    )
    .no_bytes(),
];

/// An option that changes the output and has a default.
const fn d(
    key: Key,
    name: &'static str,
    value: Value,
    flags: &'static [Flag],
    help: &'static str,
) -> Definition {
    Definition {
        key,
        name,
        value,
        unset: None,
        flags,
        help,
        changes_output: true,
    }
}

impl Definition {
    /// With no default text: what unset means.
    const fn unset(self, unset: &'static str) -> Definition {
        Definition {
            unset: Some(unset),
            ..self
        }
    }

    /// Changing no byte of the output.
    const fn no_bytes(self) -> Definition {
        Definition {
            changes_output: false,
            ..self
        }
    }
}

const OCIO: &str = "OCIO config: a file, `aces`, or an OCIO 2.2 built-in name (ocio://default, \
ocio://cg-config-latest, ocio://studio-config-latest, or versioned). Unset: $OCIO, else aces";

const COLORSPACE: &str = "The input's colour space, overriding all other evidence. Without it, \
the first of: the config's explicit file rules; strong declarations in the file (ICC profile, EXR \
chromaticities, a colour-space name); weak ones (PNG sRGB/cHRM/gAMA); the Default rule of a \
config given by --ocio or $OCIO; linear Rec.709 for float and sRGB texture for integer pixels \
(docs/colour.md)";

const ALPHA: &str = "Whether the input's colour is straight (unassociated) or premultiplied by \
alpha: `auto` as the file says (PNG straight, OpenEXR premultiplied), or force either for files \
that say it wrong (as oiiotool's --no-autopremult). Straight colour is converted, then \
premultiplied: OpenEXR stores premultiplied colour";

const SUBIMAGE: &str = "The subimage (OpenEXR part) to read: its index or name. Default: the \
first; the report names the one read when the file has several";

const CHANNELS: &str = "The channels that carry the colour: names R,G,B or R,G,B,A (Y or Y,A for \
grey), or a layer such as `diffuse` (diffuse.R, .G, .B and .A if present). Default: the channels \
named R, G, B (and A); else, without layers, the channels in order; else the only layer with R, G \
and B. Other layered files are refused with the list of their layers";

const METHOD: &str = "Uplift method: otsu2018 (the clustered PCA of the model), pca (a \
one-cluster model), smits1999, meng2015, meng2015-bounded or jakob2019";

const MODEL: &str = "A built-in model by name (open, the default; extended; paper; broad: \
`specconv models` lists them with their data and licences) or a model file from `specconv \
train`; when absent, the site default $SPECCONV_MODEL, else open. Its grid, observer and \
illuminant are those of the output, whatever the method. extended, paper and broad are trained \
partly on data for non-commercial use only (docs/licences.md); every output says whether it may \
be used commercially (specconvCommercialUse, and specconvModel's last words)";

const BLEND: &str = "Blend the spectra of neighbouring clusters within WIDTH of their boundary \
(in CIE xy), so that spectra change continuously across it; XYZ stays exact. WIDTH is the least \
width: a boundary whose two sides differ a lot is widened so that no spectrum jumps by more than \
1e-3 between colours 1e-5 apart. 0 is the paper's hard switch. The default keeps the paper's \
Table 1 (Munsell mean Δe 0.01378 against 0.01379)";

const BOUNDED: &str = "Keep every reflectance inside [0, 1] with its XYZ unchanged (the \
default): where the method's spectrum leaves [0, 1], the nearest spectrum (least squares) that \
stays inside with exactly the input's XYZ. Colours no reflectance can have (outside the \
object-colour solid: too saturated, negative, or brighter than white) get the in-range spectrum \
whose colour is nearest in CIELAB. The summary counts both. About 1 µs per pixel that needs the \
projection (≈30 % of an sRGB cube), ≈25 µs per pixel outside the solid";

const UNBOUNDED: &str =
    "The method's spectra as they are, values outside [0, 1] included (the paper's output)";

const BANDS: &str = "Output wavelength grid START:END:STEP in nm (default: the model's). The \
method's spectra are interpolated onto it and corrected so that their XYZ stays exact";

const EMISSIVE: &str = "Write emission (`S0.` channels, `emissiveUnits` W.m^-2.sr^-1) instead of \
reflectance: the colour is that of emitted radiance, of any brightness, and each spectrum L has \
it under the observer alone, in the convention of --emission-units. Each colour is scaled into \
half the range of reflectances, uplifted by the method and scaled back, so the shape does not \
depend on brightness; with a bounded method L ≥ 0. `to-rgb` turns it back into the input \
colours";

const EMISSION_UNITS: &str = "What S0 values mean (recorded as specconvEmissionUnits): \
`reference`, the layout's reference implementation, ∫ S0·x̄ dλ (1 nm steps) = the input's XYZ; \
`normalised`, ∫ S0·ȳ dλ / ∫ ȳ dλ = Y, a flat S0 = 1 has Y = 1 (pbrt-v4, Mitsuba 3), ≈106.8× the \
reference's values; `photometric`, the input's Y is luminance in cd/m² and S0 is radiance in \
W·m⁻²·sr⁻¹·nm⁻¹, Y = 683·∫ S0·ȳ dλ, 1/683 of the reference's values";

const LAYOUT: &str = "How the spectra are stored: `spectral`, a band a channel in the layout of \
Fichet et al. 2021; `compact`, a texel's colour `R G B` as an RGB texture stores it (linear Rec.709, half unless \
--data-type float) and the bounded projection's dual unknowns solved for that colour (`U.*` \
half, or `UF.*` float32 where half is not exact enough) with the model's maps and the decoding \
rule in the header: the model's spectra of the stored colour at the size of RGB, for renderers \
that decode per lookup (docs/compact.md); `specconv expand` writes the spectral layout from it. \
The clustered methods' reflectance only; its smaller MIP levels hold the filtered colour, \
rounded, their dual unknowns solved again";

const SAMPLE: &str = "Sample type of the output (with --layout compact, of the texel's colour and \
dual unknowns)";

const ROUNDING: &str = "How half samples are rounded: `nearest` rounds each band on its own (the \
colour moves by up to ≈3e-4 relative, below what half can resolve per band); `colour` picks, \
band by band, the half below or above so that the spectrum's XYZ moves as little as possible \
(≈5× smaller colour error, ≈1.5× the conversion time of a 36-band ZIP file). Default: `nearest` \
for reflectances, `colour` for --emissive, whose dark pixels' S0 values (∫ S0·x̄ dλ = XYZ: \
≈1/107 of Y per band) fall where half has few digits";

const COMPRESSION: &str = "Output compression. The lossless ones: none, rle, zips, zip, piz, \
pxr24 (for half; float loses 8 bits); b44, b44a, dwaa and dwab lose precision \
(docs/compression.md compares them all)";

const ZIP_LEVEL: &str = "Deflate level of zip and zips, 0 (stored) to 9 (smallest), as \
OpenEXR's zipCompressionLevel; the default is the measured best trade (docs/compression.md)";

const TILE: &str = "Tile width and height of the output";

const SCANLINE: &str = "Write scanlines instead of tiles (no MIP levels)";

const MIP: &str = "`all`: a MIP map (tiled outputs), each level filtered from the spectra of the \
level above as maketx filters (the input's own smaller levels are not read); `0`: the full \
resolution only";

const FILTER: &str = "The filter each MIP level is made with from the spectra of the level above, \
as maketx's `--filter`: `box` (its default: the 2×2 average, bilinear at odd sizes) or one of \
OpenImageIO's. Filters with negative lobes (lanczos3, catmull-rom, mitchell, sinc, the cubics) \
clamp what they push out of range: bands into [0, 1] (bounded reflectance) or above 0, alpha into \
[0, 1]";

const NOMIPMAP: &str = "maketx's spelling of --mip 0: the full resolution only";

const NORESIZE: &str = "maketx's spelling of the default: level 0 keeps the input's size";

const IGNORE_UNASSOC: &str = "maketx's spelling of --alpha premultiplied: the colour is taken as \
premultiplied whatever the file says";

const RESIZE: &str = "Resize level 0 up to the next power of two in each direction, as maketx's \
`--resize`: the input is uplifted at its own size and its spectra resampled with --filter (box \
and triangle: bilinearly, as maketx)";

const WRAP: &str = "Wrap modes the texture records, `MODE` or `S,T` (black, clamp, periodic, \
mirror); default: the input's (a maketx texture's), else black, as maketx";

const NON_FINITE: &str = "Repair NaN and infinite input values: `box3` (the average of the finite \
3×3 neighbours), `black` (0), or `keep` (maketx's `none`) to write them as they are. Without it such an input is \
refused (as maketx --checknan)";

const CHECKNAN: &str = "Refuse inputs with NaN or infinite values (the default; for maketx \
habits)";

const CONSTANT_DETECT: &str = "Write a texture whose pixels are all the same as one tile, \
recording oiio:ConstantColor (default true, as maketx --constant-color-detect)";

const OPAQUE_DETECT: &str =
    "Leave out an alpha that is 1 everywhere (default true, as maketx --opaque-detect)";

const THREADS: &str = "Worker threads (default: one per core)";

const OVERWRITE: &str = "Replace existing outputs";

const TABLE_DIR: &str =
    "Where the Jakob 2019 tables are kept (unset: the cache directory, $SPECCONV_CACHE_DIR)";

const DATA: &str = "What to do with a data texture (roughness, normal map, mask), which is never \
uplifted: one whose colour space is data (OCIO isdata, such as Raw: by --colorspace, the file, \
or the config's file rules, ahead of PNG chunks), or one channel that neither --colorspace, a \
file rule nor a strong declaration in the file calls colour. `skip` writes nothing (status \
`data`, not a failure); `copy` writes it through as a tiled, MIP-mapped data texture, values and \
metadata kept (OpenImageIO's make_texture, as maketx); `fail` counts it as a failure";

const STRIP_METADATA: &str = "Leave out the input's texture metadata. Without it the output \
carries, as maketx does, the input's Copyright, DocumentName, ImageDescription, Artist and custom \
string attributes (such as studio:assetId), and `to-rgb` carries them back";

const STRICT: &str = "Fail an input on any warning (a declaration of the file not followed, \
pixels above 1 clipped in a reflectance conversion, 1 % of the image or more): nothing is \
written for it and the exit status is 1, for farms that gate on warnings";

#[cfg(test)]
mod tests {
    use super::*;

    /// The help names the built-in models as they are listed, the first as the default
    /// (issue 58: a help text once named a model that does not exist).
    #[test]
    fn the_model_help_names_every_built_in_model() {
        use specconv_spectral::otsu2018::model::BUILTIN;
        let help = definition(Key::Model).help;
        for b in BUILTIN {
            assert!(help.contains(b.name), "{}: {help}", b.name);
        }
        assert!(
            help.contains(&format!("{}, the default", BUILTIN[0].name)),
            "{help}"
        );
        // The models it says are partly non-commercial are those whose summary says so.
        let (_, after) = help.split_once("open. ").expect("the default named");
        for b in BUILTIN {
            let restricted = b.summary.contains("non-commercial");
            assert_eq!(after.contains(b.name), restricted, "{}: {help}", b.name);
        }
    }

    #[test]
    fn each_option_has_its_definition_in_order() {
        for (i, key) in Key::ALL.into_iter().enumerate() {
            assert_eq!(key as usize, i, "{key:?}: Key::ALL is in declaration order");
            assert_eq!(DEFINITIONS[i].key, key);
        }
    }

    /// `--emissive` alone writes the library's default units.
    #[test]
    fn emissive_sets_the_default_units() {
        let units = specconv_colour::EmissionUnits::default();
        assert_eq!(
            definition(Key::Emission).flags[0].takes,
            Takes::Sets(crate::Named::name(units))
        );
    }
}
