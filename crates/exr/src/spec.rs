//! What a spectral file is made of, but its pixels ([`Spec`]): its size and windows, its
//! bands' kind and sample type, its blocks and levels, its extra attributes.

use exr::compression::Compression;

/// The extensions of an OpenEXR file's name (without the dot): what every writer of spectral
/// files checks its output's name against.
pub const EXTENSIONS: &[&str] = &["exr"];

/// Reflectance (`T.` channels) or emission (`S0.` channels with their units).
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// Reflectance in `T.<λ>nm` channels (a ratio, 1 = all light reflected).
    Reflective,
    /// Emitted radiance in `S0.<λ>nm` channels.
    Emissive {
        /// The `emissiveUnits` attribute as written or read (specconv writes `W.m^-2.sr^-1`);
        /// empty when a file read has none.
        units: String,
    },
    /// Values that are not bands, one channel of each of these names, stored as each says
    /// (a compact texture's `R` …, `specconv_spectral::compact`; alpha as [`Spec::sample`]):
    /// [`Spec::wavelengths`] then numbers them 1, 2, … and the header has no
    /// `spectralLayoutVersion`. Written only.
    Named(Vec<(String, Sample)>),
}

/// How each sample is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sample {
    /// 16-bit half floats (largest finite value 65504).
    Half,
    /// 32-bit floats.
    Float,
}

impl Sample {
    /// Bytes per stored sample.
    pub fn bytes(self) -> usize {
        match self {
            Sample::Half => 2,
            Sample::Float => 4,
        }
    }
}

/// Scanline blocks, or tiles with or without MIP levels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocks {
    /// Scanline blocks (as many lines per block as the compression takes, e.g. 16 for ZIP); no MIP
    /// levels.
    Scanlines,
    /// Tiles of `width × height` pixels, optionally with MIP levels (their sizes round down, as
    /// OpenImageIO's maketx does).
    Tiles {
        /// Tile width in pixels (at least 1).
        width: usize,
        /// Tile height in pixels (at least 1).
        height: usize,
        /// Whether the file holds a MIP map, every level down to 1×1, rather than one level.
        mip_levels: bool,
    },
}

/// Where the pixels sit in the image's pixel space: OpenEXR's data and display windows.
/// The data window is `width × height` of the [`Spec`] from `data_origin`; OpenEXR gives every
/// MIP level that same origin and its own (rounded-down) size, and one display window per file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Windows {
    /// Position (x, y) of the data window's top-left pixel.
    pub data_origin: (i32, i32),
    /// Origin and size of the display window.
    pub display: (i32, i32, usize, usize),
}

/// Everything about a spectral file but its pixels.
#[derive(Debug, Clone)]
pub struct Spec {
    /// Size of the data window (the stored pixels).
    pub width: usize,
    /// Height of the data window in pixels (width above).
    pub height: usize,
    /// `None`: the data window starts at (0, 0) and the display window is the data window.
    pub windows: Option<Windows>,
    /// Band wavelengths in nm, in the order callers pass band values.
    pub wavelengths: Vec<f64>,
    /// Reflective (`T.`) or emissive (`S0.`) bands; emissive writes the `emissiveUnits` attribute.
    pub kind: Kind,
    /// Whether the file has an `A` channel; [`SpectralFile::encode`](crate::SpectralFile::encode)
    /// then takes one alpha value per pixel beside the bands.
    pub alpha: bool,
    /// Half or float storage for every channel, alpha included.
    pub sample: Sample,
    /// The OpenEXR compression of every block (ZIP and ZIPS through [`zip`](crate::zip), others
    /// through the `exr` crate).
    pub compression: Compression,
    /// Deflate level of ZIP and ZIPS blocks, 0–9
    /// ([`zip::DEFAULT_LEVEL`](crate::zip::DEFAULT_LEVEL) unless asked).
    pub zip_level: u8,
    /// Scanlines or tiles, and whether tiles have MIP levels.
    pub blocks: Blocks,
    /// Extra string attributes (names prefixed `specconv` by convention).
    pub attributes: Vec<(String, String)>,
    /// Extra float attributes (a texture's `fovcot`).
    pub float_attributes: Vec<(String, f32)>,
}
