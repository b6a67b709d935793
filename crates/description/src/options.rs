//! What a conversion is asked to do: [`Options`], the one description of a conversion. Each
//! option is one [`Key`]: its name, the command line's flags, its choices ([`Named`]), one line
//! of help and whether it changes what is written ([`Key::about`]); its value as text is
//! [`Options::text`] and [`Options::set`] reads it back. Front-ends derive their arguments
//! from it (tests in each fail when one accepts what is not defined here), and the `-u` tag
//! ([`settings_tag`]) names every option that changes the output by its name.

use crate::definitions::{definition, Definition, Flag, Value};
pub use crate::key::Key;
use crate::named::Named;
use specconv_colour::{EmissionUnits, Grid};
use specconv_spectral::method::MethodName;
use std::path::PathBuf;

pub use crate::choices::{
    Alpha, Compression, DataPolicy, Filter, Layout, Mip, NonFinite, Rounding,
};
pub use crate::wrap::{Wrap, WrapModes, WRAP_NAMES};
pub use specconv_exr::Sample;

/// Everything that makes a conversion what it is. Start from [`Options::default`] (the
/// command line's defaults) and set what differs; the facade's `Converter::new` checks it all once.
///
/// ```
/// use specconv_description::{Compression, Options};
/// let mut options = Options::default();
/// options.compression = Compression::Piz;
/// options.emission = Some(specconv_colour::EmissionUnits::Normalised);
/// assert_eq!(options.compression.to_string(), "piz");
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Options {
    /// The OCIO config: a file, `aces`, an `ocio://` name; `None`: `$OCIO`, else the built-in
    /// ACES config.
    pub ocio: Option<String>,
    /// The input's colour space, overriding what the file declares.
    pub colorspace: Option<String>,
    /// Whether the input's colour is straight or premultiplied.
    pub alpha: Alpha,
    /// The subimage to read: its index or name (`None`: the first).
    pub subimage: Option<String>,
    /// The channels that carry the colour: `R,G,B[,A]`, `Y[,A]` or a layer (`None`: chosen
    /// by the input's names).
    pub channels: Option<String>,
    /// The uplift method.
    pub method: MethodName,
    /// A model file from `specconv train` (`None`: the built-in model).
    pub model: Option<PathBuf>,
    /// Blend width of the clustered methods in CIE xy; 0 is the paper's hard switch.
    pub blend: f64,
    /// Keep reflectances in [0, 1] with their XYZ.
    pub bounded: bool,
    /// The output's wavelength grid (`None`: the model's).
    pub bands: Option<Grid>,
    /// Emission in these units instead of reflectance.
    pub emission: Option<EmissionUnits>,
    /// A band a channel, or the compact texel (its samples float32 whatever `sample` says).
    pub layout: Layout,
    /// Half or float samples.
    pub sample: Sample,
    /// How half samples are rounded (`None`: [`Rounding::Nearest`] for reflectance,
    /// [`Rounding::Colour`] for emission).
    pub rounding: Option<Rounding>,
    /// Output compression.
    pub compression: Compression,
    /// Deflate level of zip and zips, 0–9 (`None`: the measured default).
    pub zip_level: Option<u8>,
    /// Tiles of this size, or scanlines.
    pub blocks: Blocks,
    /// Whether a tiled output is a MIP map (its levels filtered from the spectra).
    pub mip: Mip,
    /// The filter MIP levels are made with (maketx's `--filter`; box by default).
    pub filter: Filter,
    /// Resize level 0 to the next power of two in each direction, filtering the spectra
    /// (maketx's `--resize`).
    pub resize: bool,
    /// Wrap modes a tiled output records (`None`: the input's, else black as maketx's).
    pub wrap: Option<WrapModes>,
    /// NaN and infinite input values: refused (the default), repaired, or kept.
    pub non_finite: NonFinite,
    /// Write a texture whose pixels are all the same as one tile (default: yes).
    pub constant_detect: bool,
    /// Leave out an alpha that is 1 everywhere (default: yes).
    pub opaque_detect: bool,
    /// Worker threads (`None`: one per core).
    pub threads: Option<usize>,
    /// Replace an existing output.
    pub overwrite: bool,
    /// Where the Jakob 2019 tables are kept (`None`: the facade's `tables::cache_dir`).
    pub table_dir: Option<PathBuf>,
    /// What becomes of a data texture (a roughness or normal map): never uplifted.
    pub data: DataPolicy,
    /// Leave out the input's texture metadata (Copyright, DocumentName, ImageDescription,
    /// Artist, custom string attributes), which outputs otherwise carry as maketx does.
    pub strip_metadata: bool,
    /// Fail an input on any warning (a declaration ignored or disagreeing, pixels clipped):
    /// nothing is written for it, and the batch counts it failed.
    pub strict: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            ocio: None,
            colorspace: None,
            alpha: Alpha::Auto,
            subimage: None,
            channels: None,
            method: MethodName::Otsu2018,
            model: None,
            blend: specconv_spectral::otsu2018::blend::DEFAULT_WIDTH,
            bounded: true,
            bands: None,
            emission: None,
            layout: Layout::Spectral,
            sample: Sample::Half,
            rounding: None,
            compression: Compression::Zip,
            zip_level: None,
            blocks: Blocks::Tiles(64, 64),
            mip: Mip::All,
            filter: Filter::Box,
            resize: false,
            wrap: None,
            non_finite: NonFinite::Refuse,
            constant_detect: true,
            opaque_detect: true,
            threads: None,
            overwrite: false,
            table_dir: None,
            data: DataPolicy::Skip,
            strip_metadata: false,
            strict: false,
        }
    }
}

/// Tiles of a size, or scanlines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocks {
    /// Tiles of this width and height.
    Tiles(usize, usize),
    /// Scanlines (no MIP levels).
    Scanlines,
}

/// How front-ends name an option, and what it does: its [`Definition`], with a choice's names.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct About {
    /// Its name: the Python keyword, the key of a farm manifest and of the `-u` tag.
    pub name: &'static str,
    /// The command line's flags, the first the option's own; none where it has none.
    pub flags: &'static [Flag],
    /// What its value is.
    pub value: Value,
    /// What it means unset, for an option with no default text.
    pub unset: Option<&'static str>,
    /// For a choice, its names ([`Named::names`]) and the other spellings it accepts.
    pub choices: Option<(Vec<&'static str>, Vec<&'static str>)>,
    /// For a choice, each name with its other spellings.
    pub spellings: Option<Spellings>,
    /// What it does: the one help text of every front-end.
    pub help: &'static str,
    /// Whether it changes the bytes written (the `-u` tag must tell two values apart).
    pub changes_output: bool,
}

/// Each name of a choice with its other spellings.
type Spellings = Vec<(&'static str, &'static [&'static str])>;

/// The names of a choice, each with its other spellings.
fn spellings<T: Named>() -> Option<Spellings> {
    Some(T::ALL.iter().map(|v| (v.name(), v.aliases())).collect())
}

impl Key {
    /// How front-ends name it, its choices and help ([`definition`]).
    pub fn about(self) -> About {
        let Definition {
            key: _,
            name,
            value,
            unset,
            flags,
            help,
            changes_output,
        } = definition(self);
        let spellings = match self {
            Key::Alpha => spellings::<Alpha>(),
            Key::Method => spellings::<MethodName>(),
            Key::Emission => spellings::<EmissionUnits>(),
            Key::Layout => spellings::<Layout>(),
            Key::Sample => spellings::<Sample>(),
            Key::Rounding => spellings::<Rounding>(),
            Key::Compression => spellings::<Compression>(),
            Key::Mip => spellings::<Mip>(),
            Key::Filter => spellings::<Filter>(),
            Key::NonFinite => spellings::<NonFinite>(),
            Key::Data => spellings::<DataPolicy>(),
            _ => None,
        };
        let choices = spellings.as_ref().map(|s| {
            let aliases = s.iter().flat_map(|(_, a)| a.iter().copied());
            (s.iter().map(|(n, _)| *n).collect(), aliases.collect())
        });
        About {
            name,
            flags,
            value,
            unset,
            choices,
            spellings,
            help,
            changes_output,
        }
    }

    /// The option of this name ([`About::name`]).
    pub fn from_name(name: &str) -> Option<Key> {
        Key::ALL.into_iter().find(|k| definition(*k).name == name)
    }
}

/// An option's text that does not read as its value.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("option {key}: {why}")]
pub struct BadValue {
    /// The option's name.
    pub key: &'static str,
    /// Why.
    pub why: String,
}

impl Options {
    /// Every option's value as text ([`Options::set`] reads it back); `None` where it is
    /// unset (decided by the input, the model or the machine).
    pub fn text(&self, key: Key) -> Option<String> {
        let word = |b: bool| Some(b.to_string());
        let name = |n: &str| Some(n.to_string());
        match key {
            Key::Ocio => self.ocio.clone(),
            Key::Colorspace => self.colorspace.clone(),
            Key::Alpha => name(self.alpha.name()),
            Key::Subimage => self.subimage.clone(),
            Key::Channels => self.channels.clone(),
            Key::Method => name(Named::name(self.method)),
            Key::Model => self.model.as_ref().map(|p| p.display().to_string()),
            Key::Blend => Some(self.blend.to_string()),
            Key::Bounded => word(self.bounded),
            Key::Bands => self.bands.map(|g| g.to_string()),
            Key::Emission => self.emission.map(|u| Named::name(u).to_string()),
            Key::Layout => name(Named::name(self.layout)),
            Key::Sample => name(self.sample.name()),
            Key::Rounding => self.rounding.map(|r| r.name().to_string()),
            Key::Compression => name(self.compression.name()),
            Key::ZipLevel => self.zip_level.map(|l| l.to_string()),
            Key::Tile => Some(match self.blocks {
                Blocks::Tiles(w, h) => format!("{w}x{h}"),
                Blocks::Scanlines => "scanline".into(),
            }),
            Key::Mip => name(self.mip.name()),
            Key::Filter => name(Named::name(self.filter)),
            Key::Resize => word(self.resize),
            Key::Wrap => self.wrap.map(|(s, t)| format!("{s},{t}")),
            Key::NonFinite => name(self.non_finite.name()),
            Key::ConstantDetect => word(self.constant_detect),
            Key::OpaqueDetect => word(self.opaque_detect),
            Key::Threads => self.threads.map(|n| n.to_string()),
            Key::Overwrite => word(self.overwrite),
            Key::TableDir => self.table_dir.as_ref().map(|p| p.display().to_string()),
            Key::Data => name(self.data.name()),
            Key::StripMetadata => word(self.strip_metadata),
            Key::Strict => word(self.strict),
        }
    }

    /// Sets an option from its text as the system gives it (a command-line word, a Python
    /// path): a path option takes any bytes, the others UTF-8 ([`Options::set`]).
    pub fn set_os(&mut self, key: Key, text: &std::ffi::OsStr) -> Result<(), BadValue> {
        match key {
            Key::Model => self.model = Some(PathBuf::from(text)),
            Key::TableDir => self.table_dir = Some(PathBuf::from(text)),
            _ => return self.set_utf8(key, text),
        }
        Ok(())
    }

    /// Sets an option that is not a path from its text, which must be UTF-8.
    fn set_utf8(&mut self, key: Key, text: &std::ffi::OsStr) -> Result<(), BadValue> {
        let text = text.to_str().ok_or_else(|| BadValue {
            key: key.about().name,
            why: format!("{} is not UTF-8", text.to_string_lossy()),
        })?;
        self.set(key, Some(text))
    }

    /// Sets an option from its text ([`Options::text`]'s form); `None` unsets it (the default
    /// for an option that cannot be unset).
    pub fn set(&mut self, key: Key, text: Option<&str>) -> Result<(), BadValue> {
        let bad = |why: String| BadValue {
            key: key.about().name,
            why,
        };
        let Some(text) = text else {
            self.unset(key);
            return Ok(());
        };
        fn named<T: Named>(text: &str) -> Result<T, String> {
            T::from_name(text).map_err(|e| e.to_string())
        }
        fn number<T: std::str::FromStr>(text: &str, what: &str) -> Result<T, String> {
            text.trim()
                .parse()
                .map_err(|_| format!("'{text}' is not {what}"))
        }
        let boolean = |text: &str| match text.to_ascii_lowercase().as_str() {
            "true" | "1" | "yes" | "on" => Ok(true),
            "false" | "0" | "no" | "off" => Ok(false),
            _ => Err(format!("'{text}' is neither true nor false")),
        };
        let owned = || Some(text.to_string());
        match key {
            Key::Ocio => self.ocio = owned(),
            Key::Colorspace => self.colorspace = owned(),
            Key::Alpha => self.alpha = named(text).map_err(bad)?,
            Key::Subimage => self.subimage = owned(),
            Key::Channels => self.channels = owned(),
            Key::Method => self.method = named(text).map_err(bad)?,
            Key::Model => self.model = Some(PathBuf::from(text)),
            Key::Blend => self.blend = number(text, "a width in CIE xy").map_err(bad)?,
            Key::Bounded => self.bounded = boolean(text).map_err(bad)?,
            Key::Bands => {
                self.bands = Some(
                    text.parse()
                        .map_err(|e: specconv_colour::Error| bad(e.to_string()))?,
                )
            }
            Key::Emission => self.emission = Some(named(text).map_err(bad)?),
            Key::Layout => self.layout = named(text).map_err(bad)?,
            Key::Sample => self.sample = named(text).map_err(bad)?,
            Key::Rounding => self.rounding = Some(named(text).map_err(bad)?),
            Key::Compression => self.compression = named(text).map_err(bad)?,
            Key::ZipLevel => {
                self.zip_level = Some(number(text, "a deflate level 0–9").map_err(bad)?)
            }
            Key::Tile => self.blocks = parse_blocks(text).map_err(bad)?,
            Key::Mip => self.mip = named(text).map_err(bad)?,
            Key::Filter => self.filter = named(text).map_err(bad)?,
            Key::Resize => self.resize = boolean(text).map_err(bad)?,
            Key::Wrap => self.wrap = Some(crate::wrap::parse_wrapmodes(text).map_err(bad)?),
            Key::NonFinite => self.non_finite = named(text).map_err(bad)?,
            Key::ConstantDetect => self.constant_detect = boolean(text).map_err(bad)?,
            Key::OpaqueDetect => self.opaque_detect = boolean(text).map_err(bad)?,
            Key::Threads => self.threads = Some(number(text, "a number of threads").map_err(bad)?),
            Key::Overwrite => self.overwrite = boolean(text).map_err(bad)?,
            Key::TableDir => self.table_dir = Some(PathBuf::from(text)),
            Key::Data => self.data = named(text).map_err(bad)?,
            Key::StripMetadata => self.strip_metadata = boolean(text).map_err(bad)?,
            Key::Strict => self.strict = boolean(text).map_err(bad)?,
        }
        Ok(())
    }
}

impl Options {
    /// Sets an option back to its default.
    pub fn unset(&mut self, key: Key) {
        let d = Options::default();
        match key {
            Key::Ocio => self.ocio = d.ocio,
            Key::Colorspace => self.colorspace = d.colorspace,
            Key::Alpha => self.alpha = d.alpha,
            Key::Subimage => self.subimage = d.subimage,
            Key::Channels => self.channels = d.channels,
            Key::Method => self.method = d.method,
            Key::Model => self.model = d.model,
            Key::Blend => self.blend = d.blend,
            Key::Bounded => self.bounded = d.bounded,
            Key::Bands => self.bands = d.bands,
            Key::Emission => self.emission = d.emission,
            Key::Layout => self.layout = d.layout,
            Key::Sample => self.sample = d.sample,
            Key::Rounding => self.rounding = d.rounding,
            Key::Compression => self.compression = d.compression,
            Key::ZipLevel => self.zip_level = d.zip_level,
            Key::Tile => self.blocks = d.blocks,
            Key::Mip => self.mip = d.mip,
            Key::Filter => self.filter = d.filter,
            Key::Resize => self.resize = d.resize,
            Key::Wrap => self.wrap = d.wrap,
            Key::NonFinite => self.non_finite = d.non_finite,
            Key::ConstantDetect => self.constant_detect = d.constant_detect,
            Key::OpaqueDetect => self.opaque_detect = d.opaque_detect,
            Key::Threads => self.threads = d.threads,
            Key::Overwrite => self.overwrite = d.overwrite,
            Key::TableDir => self.table_dir = d.table_dir,
            Key::Data => self.data = d.data,
            Key::StripMetadata => self.strip_metadata = d.strip_metadata,
            Key::Strict => self.strict = d.strict,
        }
    }
}

impl Options {
    /// The method stack these options describe.
    pub fn stack_spec(&self) -> specconv_spectral::stack::StackSpec {
        specconv_spectral::stack::StackSpec {
            blend: self.blend,
            grid: self.bands,
            bounded: self.bounded,
            emissive: self.emission,
            ..specconv_spectral::stack::StackSpec::convert_default(self.method)
        }
    }

    /// How half samples are rounded unless asked: to keep the colour for emission, whose dark
    /// pixels' S0 values fall where half has few digits; each band to nearest for reflectance.
    pub fn default_rounding(&self) -> Rounding {
        if self.emission.is_some() {
            Rounding::Colour
        } else {
            Rounding::Nearest
        }
    }

    /// How half samples are rounded: as asked, else [`Options::default_rounding`].
    pub fn rounding_in_effect(&self) -> Rounding {
        self.rounding.unwrap_or_else(|| self.default_rounding())
    }
}

/// `WxH` (or `W H`, `W,H`) tiles, or `scanline`.
fn parse_blocks(text: &str) -> Result<Blocks, String> {
    if text.eq_ignore_ascii_case("scanline") || text.eq_ignore_ascii_case("scanlines") {
        return Ok(Blocks::Scanlines);
    }
    let parts: Vec<&str> = text
        .split(['x', 'X', ',', ' '])
        .filter(|p| !p.is_empty())
        .collect();
    match parts.as_slice() {
        [w, h] => match (w.parse(), h.parse()) {
            (Ok(w), Ok(h)) => Ok(Blocks::Tiles(w, h)),
            _ => Err(format!("'{text}' is not a tile size WxH")),
        },
        _ => Err(format!(
            "'{text}' is neither a tile size WxH nor `scanline`"
        )),
    }
}

/// What the options leave to the model, the method stack and the config, as outputs record it.
#[derive(Debug, Clone, Copy)]
pub struct Resolved<'a> {
    /// The model, described (the facade's `models::describe`).
    pub model: &'a str,
    /// The method stack's name (bounded, resampled and emission adapters included).
    pub method: &'a str,
    /// The blend width the stack uses.
    pub blend: f64,
    /// The OCIO config's source.
    pub config: &'a str,
}

/// The version of the library's numerical rules, first in every settings tag as `rules=N`
/// (DESIGN: "up to date means same bytes"): bumped by any change that moves a written sample,
/// so that `-u` rebuilds what this version would write differently. 1: the perfect white's
/// rule (r ≡ 1) and compact u stored to the texel's scale (issue 55, 2026-12-07); files
/// written before have no `rules=` and are rebuilt.
pub const RULES: u32 = 1;

/// `specconvSettings`: [`RULES`], then every option that changes what is written ([`About::changes_output`]),
/// for `-u`, as `NAME=VALUE` by the option's name in the order of [`Key::ALL`]: what the
/// options leave to the model, the method stack and the config as they resolved, a value that
/// makes no difference (the rounding of float samples, the filter of an output without
/// filtered levels) left out, an unset one too. A value with a space, a quote or `=` is quoted
/// (Rust's `{:?}`), so that no two settings give one tag.
pub fn settings_tag(o: &Options, r: Resolved) -> String {
    let filtered = (o.mip == Mip::All && o.blocks != Blocks::Scanlines) || o.resize;
    let words = Key::ALL.into_iter().filter_map(|key| {
        let about = key.about();
        let value = match key {
            _ if !about.changes_output => None,
            Key::Ocio => Some(r.config.to_string()),
            Key::Model => Some(r.model.to_string()),
            Key::Method => Some(r.method.to_string()),
            Key::Blend => Some(r.blend.to_string()),
            Key::Rounding if o.sample == Sample::Half => Some(o.rounding_in_effect().to_string()),
            Key::Rounding => None,
            Key::Filter if !filtered => None,
            _ => o.text(key),
        }?;
        let plain = !value.contains([' ', '"', '=', '\\']) && !value.is_empty();
        Some(match plain {
            true => format!("{}={value}", about.name),
            false => format!("{}={value:?}", about.name),
        })
    });
    std::iter::once(format!("rules={RULES}"))
        .chain(words)
        .collect::<Vec<_>>()
        .join(" ")
}

/// The tag ([`settings_tag`]) of the conversion that wrote `tag` in the compact layout, had
/// it written the spectral layout instead (what `specconv expand` makes of it).
pub fn as_spectral(tag: &str) -> String {
    let (compact, spectral) = (Layout::Compact, Layout::Spectral);
    let from = format!("layout={}", Named::name(compact));
    let to = format!("layout={}", Named::name(spectral));
    tag.split(' ')
        .map(|word| if word == from { to.as_str() } else { word })
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resolved() -> Resolved<'static> {
        Resolved {
            model: "open (built-in)",
            method: "otsu2018",
            blend: 0.02,
            config: "aces",
        }
    }

    /// Path options keep their bytes; every other option's text is read by `set`.
    #[test]
    fn set_os_keeps_the_bytes_of_path_options_only() {
        use std::os::unix::ffi::OsStrExt;
        let bytes = std::ffi::OsStr::from_bytes(b"/tmp/\xff.json");
        for key in Key::ALL {
            let mut o = Options::default();
            let kept = o.set_os(key, bytes).is_ok();
            assert_eq!(kept, key.about().value == Value::Path, "{key:?}");
        }
    }

    /// Each flag that sets a word sets one its option reads.
    #[test]
    fn every_flag_word_is_read_by_its_option() {
        for key in Key::ALL {
            for flag in key.about().flags {
                if let crate::Takes::Sets(word) = flag.takes {
                    let mut o = Options::default();
                    assert!(o.set(key, Some(word)).is_ok(), "--{}", flag.long);
                }
            }
        }
    }

    /// The tag names options as every front-end does, and quotes what would run together.
    #[test]
    fn the_tag_uses_the_option_names() {
        let mut o = Options::default();
        assert_eq!(
            settings_tag(&o, resolved()),
            "rules=1 ocio=aces alpha=auto method=otsu2018 model=\"open (built-in)\" blend=0.02 \
             bounded=true layout=spectral sample=half rounding=nearest compression=zip \
             tile=64x64 mip=all filter=box resize=false non_finite=refuse \
             constant_detect=true opaque_detect=true data=skip strip_metadata=false"
        );
        o.colorspace = Some("sRGB - Texture".into());
        o.sample = Sample::Float;
        o.blocks = Blocks::Scanlines;
        let tag = settings_tag(&o, resolved());
        assert!(tag.contains(" colorspace=\"sRGB - Texture\" "), "{tag}");
        assert!(
            !tag.contains("rounding=") && !tag.contains("filter="),
            "{tag}"
        );
        assert_eq!(
            as_spectral("sample=half layout=compact mip=all"),
            "sample=half layout=spectral mip=all"
        );
    }
}
