//! What a conversion is asked to do: [`Options`], every choice typed, each with its name as
//! the command line and the `specconvSettings` attribute spell it.

use specconv_colour::{EmissionUnits, Grid};
use specconv_spectral::method::MethodName;
use std::path::PathBuf;

pub use specconv_exr::Sample;
pub use specconv_pipeline::survey::NonFinite;
pub use specconv_pipeline::texture::{Wrap, WrapModes, WRAP_NAMES};
pub use specconv_pipeline::{Alpha, Filter, Mip};

/// Everything that makes a conversion what it is. Start from [`Options::default`] (the
/// command line's defaults) and set what differs; [`crate::Converter::new`] checks it all once.
///
/// ```
/// use specconv_conversion::{Compression, Options};
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
    /// Where the Jakob 2019 tables are kept (`None`: [`crate::tables::cache_dir`]).
    pub table_dir: Option<PathBuf>,
    /// What becomes of a data texture (a roughness or normal map): never uplifted.
    pub data: DataPolicy,
}

/// What a conversion does with a texture that holds data, not colour
/// ([`specconv_pipeline::DataTexture`]): it is never uplifted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DataPolicy {
    /// Write nothing; the report says it is data ([`crate::DataOutcome::Skipped`]). Not a
    /// failure.
    #[default]
    Skip,
    /// Write it through as a tiled, MIP-mapped data texture, its values unconverted.
    Copy,
    /// Fail, saying it is data.
    Fail,
}

impl DataPolicy {
    /// The name the command line and `specconvSettings` give it.
    pub fn name(self) -> &'static str {
        match self {
            DataPolicy::Skip => "skip",
            DataPolicy::Copy => "copy",
            DataPolicy::Fail => "fail",
        }
    }
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
        }
    }
}

/// How half samples are rounded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rounding {
    /// Each band on its own.
    Nearest,
    /// Band by band, the half below or above that moves the spectrum's XYZ least.
    Colour,
}

/// Tiles of a size, or scanlines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocks {
    /// Tiles of this width and height.
    Tiles(usize, usize),
    /// Scanlines (no MIP levels).
    Scanlines,
}

/// The output compressions of OpenEXR.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Compression {
    None,
    Rle,
    Zips,
    Zip,
    Piz,
    Pxr24,
    B44,
    B44a,
    Dwaa,
    Dwab,
}

impl Compression {
    /// Every compression, in the order the help lists them.
    pub const ALL: [Compression; 10] = [
        Compression::None,
        Compression::Rle,
        Compression::Zips,
        Compression::Zip,
        Compression::Piz,
        Compression::Pxr24,
        Compression::B44,
        Compression::B44a,
        Compression::Dwaa,
        Compression::Dwab,
    ];

    /// The name the command line and `specconvSettings` give it.
    pub fn name(self) -> &'static str {
        match self {
            Compression::None => "none",
            Compression::Rle => "rle",
            Compression::Zips => "zips",
            Compression::Zip => "zip",
            Compression::Piz => "piz",
            Compression::Pxr24 => "pxr24",
            Compression::B44 => "b44",
            Compression::B44a => "b44a",
            Compression::Dwaa => "dwaa",
            Compression::Dwab => "dwab",
        }
    }

    /// Whether it deflates (and so takes a level).
    pub fn deflates(self) -> bool {
        matches!(self, Compression::Zip | Compression::Zips)
    }

    /// The `exr` crate's name for it.
    pub fn exr(self) -> specconv_exr::Compression {
        use specconv_exr::Compression as C;
        match self {
            Compression::None => C::Uncompressed,
            Compression::Rle => C::RLE,
            Compression::Zips => C::ZIP1,
            Compression::Zip => C::ZIP16,
            Compression::Piz => C::PIZ,
            Compression::Pxr24 => C::PXR24,
            Compression::B44 => C::B44,
            Compression::B44a => C::B44A,
            Compression::Dwaa => C::DWAA(None),
            Compression::Dwab => C::DWAB(None),
        }
    }
}

impl std::fmt::Display for Compression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not one of a choice's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} '{name}'; choose one of {}", choices.join(", "))]
pub struct UnknownName {
    /// What was named.
    pub what: &'static str,
    /// The name given.
    pub name: String,
    /// The names there are.
    pub choices: Vec<&'static str>,
}

impl std::str::FromStr for Compression {
    type Err = UnknownName;

    fn from_str(s: &str) -> Result<Compression, UnknownName> {
        Compression::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| UnknownName {
                what: "compression",
                name: s.to_string(),
                choices: Compression::ALL.map(Compression::name).to_vec(),
            })
    }
}

/// The name of a sample type, as `specconvSettings` and the front-ends spell it.
pub fn sample_name(s: Sample) -> &'static str {
    match s {
        Sample::Half => "half",
        Sample::Float => "float",
    }
}

/// The name of a MIP choice (`all` or `0`).
pub fn mip_name(m: Mip) -> &'static str {
    match m {
        Mip::All => "all",
        Mip::Base => "0",
    }
}

/// The name of a NaN policy (`refuse`, `black`, `box3`, `keep`).
pub fn non_finite_name(n: NonFinite) -> &'static str {
    match n {
        NonFinite::Refuse => "refuse",
        NonFinite::Black => "black",
        NonFinite::Box3 => "box3",
        NonFinite::Keep => "keep",
    }
}

/// The name of an alpha reading (`auto`, `straight`, `premultiplied`).
pub fn alpha_name(a: Alpha) -> &'static str {
    match a {
        Alpha::Auto => "auto",
        Alpha::Straight => "straight",
        Alpha::Premultiplied => "premultiplied",
    }
}
