//! Spectral OpenEXR in the layout of Fichet, Pacanowski and Wilkie, "An OpenEXR Layout for
//! Spectral Images" (JCGT 10(3), 2021), on the `exr` crate.
//!
//! Reflective bands are channels `T.<wavelength>nm`, emissive bands `S0.<wavelength>nm` with an
//! `emissiveUnits` attribute; the wavelength is written with a comma as decimal separator and
//! six decimals (`T.380,000000nm`), and the header carries `spectralLayoutVersion` = "1.0".
//! Alpha passes through as `A`. OpenEXR sorts channels by name, so `T.1000,…` comes before
//! `T.380,…`: this crate maps bands to channels by name, never by position, in both directions.
//!
//! Writing streams: [`SpectralFile::blocks`] lists the file's tiles (or scanline blocks) of
//! every level; callers fill any block from any thread, [`SpectralFile::encode`] turns it into a
//! compressed chunk, and [`SpectralFile::write`] writes chunks as they come. Nothing holds the
//! whole image.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod blocks;
pub mod check;
pub mod quantize;
pub mod rgb;
pub mod zip;

use exr::block::chunk::{
    CompressedBlock, CompressedScanLineBlock, CompressedTileBlock, TileCoordinates,
};
use exr::block::{BlockIndex, UncompressedBlock};
use exr::math::{RoundingMode, Vec2};
use exr::meta::attribute::{
    AttributeValue, ChannelDescription, IntegerBounds, LevelMode, LineOrder, SampleType, Text,
    TileDescription,
};
use exr::meta::header::Header;
use exr::meta::BlockDescription;
use std::io::{Seek, Write};

pub use exr::block::chunk::Chunk;
pub use exr::compression::Compression;

/// What can go wrong writing or reading a spectral file.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Something the layout or this crate does not allow, named in the text: an empty image, no
    /// bands, two bands with one channel name, bad tile size, windows beyond 32-bit coordinates, a
    /// non-text attribute name, a file without spectral channels, or re-radiation without its
    /// bands.
    #[error("{0}")]
    Invalid(String),
    /// A block larger than OpenEXR's readers accept.
    #[error(transparent)]
    BlockTooLarge(#[from] BlockTooLarge),
    /// More channels than OpenEXR's readers accept.
    #[error(transparent)]
    TooManyChannels(#[from] TooManyChannels),
    /// An error of the `exr` crate: I/O, or a file it cannot read or write.
    #[error("OpenEXR: {0}")]
    Exr(#[from] exr::error::Error),
    /// A path to read that is no regular file (a FIFO, a device, a directory) or is missing:
    /// refused by kind, without blocking.
    #[error(transparent)]
    File(#[from] specconv_atomic_file::ReadError),
}

impl Error {
    /// The I/O error of the file system underneath (a full disk, a file size limit), if that is
    /// what this is; else the error itself.
    pub fn into_io(self) -> std::result::Result<std::io::Error, Error> {
        match self {
            Error::Exr(exr::error::Error::Io(e)) => Ok(e),
            e => Err(e),
        }
    }
}

/// The extensions of an OpenEXR file's name (without the dot): what every writer of spectral
/// files checks its output's name against.
pub const EXTENSIONS: &[&str] = &["exr"];

/// The largest uncompressed block (a tile, or a block of scanlines) OpenEXR's readers accept:
/// its size in bytes is a signed 32-bit integer. Measured with oiiotool 2.4 on 36 half
/// channels: 5000×5000 tiles (1.8 GB) open, 6000×6000 (2.6 GB) fail with "Tile size too large
/// for OpenEXR format".
pub const MAX_BLOCK_BYTES: u64 = i32::MAX as u64;

/// A tile or scanline block over [`MAX_BLOCK_BYTES`]: a file no reader would open.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "a block of {width}×{height} pixels with {channels} channels of {bytes_per_sample} bytes is {bytes} bytes; OpenEXR readers accept at most {} bytes per block: use smaller tiles or fewer bands",
    MAX_BLOCK_BYTES
)]
pub struct BlockTooLarge {
    /// Block width in pixels.
    pub width: u64,
    /// Block height in pixels.
    pub height: u64,
    /// Channels per pixel.
    pub channels: u64,
    /// Bytes per sample.
    pub bytes_per_sample: u64,
    /// The block's size.
    pub bytes: u128,
}

/// Refuses a block of `width`×`height` pixels of `channels` samples of `sample` over
/// [`MAX_BLOCK_BYTES`] (as the file declares it: tiles at their full size, even where the image
/// is smaller).
pub fn check_block(
    width: usize,
    height: usize,
    channels: usize,
    sample: Sample,
) -> std::result::Result<(), BlockTooLarge> {
    let bytes_per_sample = match sample {
        Sample::Half => 2,
        Sample::Float => 4,
    };
    let bytes = width as u128 * height as u128 * channels as u128 * bytes_per_sample as u128;
    if bytes <= MAX_BLOCK_BYTES as u128 {
        return Ok(());
    }
    Err(BlockTooLarge {
        width: width as u64,
        height: height as u64,
        channels: channels as u64,
        bytes_per_sample,
        bytes,
    })
}

/// The most channels (bands and alpha) a spectral file may have for readers to read it:
/// OpenImageIO 2.4 reads 32,767 channels and aborts on 32,768 (`std::bad_alloc`; measured with
/// oiiotool 2.4.7 reading files of 16×16 tiles, whose blocks are small, and of 64×64 tiles).
/// OpenImageIO's `limits:channels` attribute (1024 by default) is checked by its TIFF reader
/// only, not by its OpenEXR reader, in 2.4.
pub const MAX_CHANNELS: usize = 32_767;

/// A file of more than [`MAX_CHANNELS`] channels: one OpenImageIO would not read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{bands} bands{} would be {} channels; OpenEXR readers (OpenImageIO) read at most {MAX_CHANNELS} ({} bands and alpha): use fewer bands, with a coarser step or a shorter range",
    if *alpha { " and alpha" } else { "" },
    bands + usize::from(*alpha),
    MAX_CHANNELS - 1
)]
pub struct TooManyChannels {
    /// The bands.
    pub bands: usize,
    /// Whether alpha is one more channel.
    pub alpha: bool,
}

/// Refuses a file of `bands` bands (and alpha, when `alpha`) over [`MAX_CHANNELS`] channels.
pub fn check_channels(bands: usize, alpha: bool) -> std::result::Result<(), TooManyChannels> {
    if bands + usize::from(alpha) <= MAX_CHANNELS {
        Ok(())
    } else {
        Err(TooManyChannels { bands, alpha })
    }
}

/// This crate's result, with [`enum@Error`].
pub type Result<T> = std::result::Result<T, Error>;

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

/// Values rounded to half all at once (F16C where the CPU has it, as `half` does value by
/// value).
fn halves(values: &[f32]) -> Vec<half::f16> {
    use half::slice::HalfFloatSliceExt;
    let mut h = vec![half::f16::ZERO; values.len()];
    h.convert_from_f32_slice(values);
    h
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
    /// Whether the file has an `A` channel; [`SpectralFile::encode`] then takes one alpha
    /// value per pixel beside the bands.
    pub alpha: bool,
    /// Half or float storage for every channel, alpha included.
    pub sample: Sample,
    /// The OpenEXR compression of every block (ZIP and ZIPS through [`zip`], others through the
    /// `exr` crate).
    pub compression: Compression,
    /// Deflate level of ZIP and ZIPS blocks, 0–9 ([`zip::DEFAULT_LEVEL`] unless asked).
    pub zip_level: u8,
    /// Scanlines or tiles, and whether tiles have MIP levels.
    pub blocks: Blocks,
    /// Extra string attributes (names prefixed `specconv` by convention).
    pub attributes: Vec<(String, String)>,
    /// Extra float attributes (a texture's `fovcot`).
    pub float_attributes: Vec<(String, f32)>,
}

/// The channel name of a band: `T.550,000000nm` or `S0.550,000000nm`.
pub fn channel_name(kind: &Kind, wavelength_nm: f64) -> String {
    let prefix = match kind {
        Kind::Reflective => "T",
        Kind::Emissive { .. } => "S0",
        // The value's number, from 1 (`Kind::Named`).
        Kind::Named(names) => {
            let i = (wavelength_nm as usize).wrapping_sub(1);
            return names.get(i).map(|n| n.0.clone()).unwrap_or_default();
        }
    };
    format!(
        "{prefix}.{}nm",
        format!("{wavelength_nm:.6}").replace('.', ",")
    )
}

/// What a channel of the layout holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Channel {
    /// `T.<λ>`: reflectance (the diagonal of a bispectral file).
    Reflective {
        /// The wavelength, nm.
        nm: f64,
    },
    /// `S<k>.<λ>`: the Stokes component k of emission (S0 the radiance, S1–S3 polarisation).
    Stokes {
        /// The component, 0–3.
        k: u8,
        /// The wavelength, nm.
        nm: f64,
    },
    /// `T.<λi>.<λo>`: light re-radiated at λo from light received at λi (fluorescence).
    Reradiation {
        /// λi, the wavelength received, nm.
        from_nm: f64,
        /// λo, the wavelength re-radiated, nm.
        to_nm: f64,
    },
}

/// The channel a name denotes, by the reference reader's grammar: a wavelength with a comma
/// (or point) as decimal separator and an optional exponent, an SI prefix on the unit (`nm`,
/// `um`, `m`, …, `da`) and `m` or `Hz` (a frequency, turned into its wavelength in vacuum).
pub fn parse_channel(name: &str) -> Option<Channel> {
    let (prefix, rest) = name.split_once('.')?;
    match prefix {
        "T" => match rest.find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E') {
            Some(i) => {
                // Either `λ<unit>` or `λi<unit>.λo<unit>`.
                let (first, second) = match rest[i..].split_once('.') {
                    Some((unit, second)) => (&rest[..i + unit.len()], Some(second)),
                    None => (rest, None),
                };
                let from_nm = wavelength(first)?;
                match second {
                    None => Some(Channel::Reflective { nm: from_nm }),
                    Some(second) => Some(Channel::Reradiation {
                        from_nm,
                        to_nm: wavelength(second)?,
                    }),
                }
            }
            None => None,
        },
        "S0" | "S1" | "S2" | "S3" => Some(Channel::Stokes {
            k: prefix.as_bytes()[1] - b'0',
            nm: wavelength(rest)?,
        }),
        _ => None,
    }
}

/// A wavelength with its unit (`550,5nm`, `0,55um`, `545,077196THz`) in nm.
fn wavelength(text: &str) -> Option<f64> {
    let split = text.find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')?;
    let (number, unit) = text.split_at(split);
    if number.is_empty() || number.starts_with(['+', '-']) {
        return None;
    }
    let value: f64 = number.replace(',', ".").parse().ok()?;
    let (prefix, hz) = if let Some(p) = unit.strip_suffix("Hz") {
        (p, true)
    } else {
        (unit.strip_suffix('m')?, false)
    };
    // The SI prefixes the reference reader accepts, as powers of ten (exact in f64).
    let power = match prefix {
        "Y" => 24,
        "Z" => 21,
        "E" => 18,
        "P" => 15,
        "T" => 12,
        "G" => 9,
        "M" => 6,
        "k" => 3,
        "h" => 2,
        "da" => 1,
        "" => 0,
        "d" => -1,
        "c" => -2,
        "m" => -3,
        "u" => -6,
        "n" => -9,
        "p" => -12,
        _ => return None,
    };
    let nm = if hz {
        // λ = c / ν, in nm: c·10⁹⁻ᵖ / value.
        299_792_458.0 * 10f64.powi(9 - power) / value
    } else {
        value * 10f64.powi(power + 9)
    };
    (nm.is_finite() && nm > 0.0).then_some(nm)
}

/// The band a channel name denotes: (emissive?, wavelength in nm), for reflective `T.` and
/// emissive `S0.` channels only (see [`parse_channel`] for the others).
pub fn parse_channel_name(name: &str) -> Option<(bool, f64)> {
    match parse_channel(name)? {
        Channel::Reflective { nm } => Some((false, nm)),
        Channel::Stokes { k: 0, nm } => Some((true, nm)),
        _ => None,
    }
}

/// The spectral content of a list of channel names: what [`read`] reads, and what `info`
/// reports without reading pixels.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Layout {
    /// Wavelengths (nm, increasing) of `T.` channels.
    pub reflective: Vec<f64>,
    /// Wavelengths of S0, S1, S2, S3 channels.
    pub stokes: [Vec<f64>; 4],
    /// (λi, λo) pairs of re-radiation channels, sorted.
    pub reradiation: Vec<(f64, f64)>,
    /// Channels outside the layout, `A` excepted (e.g. an RGB preview stored beside spectra), in
    /// the order given (a file's, alphabetical).
    pub other: Vec<String>,
    /// Whether there is an `A` channel.
    pub alpha: bool,
}

impl Layout {
    /// Sorts channel names into the layout by [`parse_channel`]: wavelengths in nm, each list
    /// increasing, whatever the order or the units of the names.
    ///
    /// ```
    /// use specconv_exr::{channel_name, parse_channel_name, Kind, Layout};
    ///
    /// // OpenEXR lists channels by name, so 1000 nm comes before 380 nm.
    /// let names = ["A", "RGB.R", "T.1000,000000nm", "T.380,000000nm", "T.0,55um"];
    /// let layout = Layout::of(names);
    /// assert_eq!(layout.reflective, [380.0, 550.0, 1000.0]);
    /// assert!(layout.alpha && layout.is_spectral() && !layout.polarised());
    /// assert_eq!(layout.other, ["RGB.R"]);
    ///
    /// // The writer's names, and back.
    /// let name = channel_name(&Kind::Reflective, 380.0);
    /// assert_eq!(name, "T.380,000000nm");
    /// assert_eq!(parse_channel_name(&name), Some((false, 380.0)));
    /// ```
    pub fn of<'a>(names: impl IntoIterator<Item = &'a str>) -> Layout {
        let mut l = Layout::default();
        for name in names {
            match parse_channel(name) {
                Some(Channel::Reflective { nm }) => l.reflective.push(nm),
                Some(Channel::Stokes { k, nm }) => l.stokes[k as usize].push(nm),
                Some(Channel::Reradiation { from_nm, to_nm }) => {
                    l.reradiation.push((from_nm, to_nm))
                }
                None if name == "A" => l.alpha = true,
                None => l.other.push(name.to_string()),
            }
        }
        l.reflective.sort_by(f64::total_cmp);
        l.stokes.iter_mut().for_each(|s| s.sort_by(f64::total_cmp));
        l.reradiation
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        l
    }

    /// Whether the names hold a spectrum [`read`] can read: any `T.` or `S0.` channel.
    pub fn is_spectral(&self) -> bool {
        !self.reflective.is_empty() || !self.stokes[0].is_empty()
    }

    /// Whether any Stokes component beyond S0 (polarisation) is present.
    pub fn polarised(&self) -> bool {
        self.stokes[1..].iter().any(|s| !s.is_empty())
    }
}

/// One block of the file: a tile or scanline block of one MIP level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Block {
    /// Index of the chunk in the file, in increasing-y order within the header.
    pub chunk: usize,
    /// MIP level, 0 the full-size image.
    pub level: usize,
    /// Position and size in pixels, within the level.
    pub x: usize,
    /// Top row of the block within the level; (`x`, `y`) is its top-left pixel.
    pub y: usize,
    /// Width of the block in pixels; tiles at the right edge are narrower.
    pub width: usize,
    /// Height of the block in pixels; blocks at the bottom edge are shorter.
    pub height: usize,
}

/// A spectral file being written: its header and how to encode blocks.
#[derive(Debug)]
pub struct SpectralFile {
    spec: Spec,
    header: Header,
    /// For each header channel (sorted by name), where its value sits among a pixel's inputs:
    /// band index, or `bands` for alpha.
    source: Vec<usize>,
    /// For each header channel, how it is stored: [`Spec::sample`] but for named channels.
    types: Vec<Sample>,
}

impl SpectralFile {
    /// The header of `spec`: channels named by [`channel_name`] (and `A`), `spectralLayoutVersion`
    /// = "1.0", `emissiveUnits` for emission, the extra attributes (as UTF-8, [`text`]).
    /// Refuses an empty image, no bands, wavelengths that are not finite, positive and
    /// increasing ([`check_wavelengths`]), two wavelengths equal to six decimals, tiles of zero
    /// size, windows beyond OpenEXR's 32-bit coordinates and attribute names OpenEXR cannot
    /// take as free text ([`standard_attribute`], [`MAX_NAME_BYTES`]).
    pub fn new(spec: Spec) -> Result<SpectralFile> {
        check_not_empty(&spec)?;
        let named = named_channels(&spec)?;
        let types: Vec<Sample> = named
            .iter()
            .map(|&(_, i)| match &spec.kind {
                Kind::Named(names) if i < names.len() => names[i].1,
                _ => spec.sample,
            })
            .collect();
        let channels = named
            .iter()
            .zip(&types)
            .map(|((name, _), t)| {
                let sample_type = match t {
                    Sample::Half => SampleType::F16,
                    Sample::Float => SampleType::F32,
                };
                ChannelDescription::new(Text::new_or_panic(name), sample_type, name == "A")
            })
            .collect();
        let blocks = block_description(&spec, named.len())?;
        let mut header = Header::new(
            Text::new_or_panic("spectral"),
            Vec2(spec.width, spec.height),
            channels,
        )
        .with_encoding(spec.compression, blocks, LineOrder::Increasing);
        header.own_attributes.layer_name = None;
        if let Some(w) = spec.windows {
            set_windows(&mut header, &spec, w)?;
        }
        set_attributes(&mut header, &spec)?;
        let source = named.into_iter().map(|(_, i)| i).collect();
        Ok(SpectralFile {
            spec,
            header,
            source,
            types,
        })
    }

    /// What the file was made from.
    pub fn spec(&self) -> &Spec {
        &self.spec
    }

    /// The file's OpenEXR header, as the `exr` crate's block functions take it.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Values stored per pixel: the bands, and alpha if any.
    pub fn values_per_pixel(&self) -> usize {
        self.spec.wavelengths.len() + usize::from(self.spec.alpha)
    }

    /// `values` given per band (in the order of `Spec::wavelengths`), then alpha, put in the
    /// order of the file's channels (sorted by name).
    pub fn in_channel_order<T: Copy>(&self, values: &[T]) -> Vec<T> {
        self.source.iter().map(|&i| values[i]).collect()
    }

    /// Number of MIP levels the file has (1 unless MIP-mapped): ⌊log₂ max(w, h)⌋ + 1.
    pub fn levels(&self) -> usize {
        match self.spec.blocks {
            Blocks::Tiles {
                mip_levels: true, ..
            } => (usize::BITS - self.spec.width.max(self.spec.height).leading_zeros()) as usize,
            _ => 1,
        }
    }

    /// Size of a MIP level (rounding down, as OpenImageIO's maketx does).
    pub fn level_size(&self, level: usize) -> (usize, usize) {
        (
            (self.spec.width >> level).max(1),
            (self.spec.height >> level).max(1),
        )
    }

    /// The rows of the blocks of one strip of the file: its tile height, or its scanline
    /// blocks' (which the compression decides).
    pub fn block_height(&self) -> usize {
        match self.spec.blocks {
            Blocks::Tiles { height, .. } => height,
            Blocks::Scanlines => self.blocks().first().map_or(1, |b| b.height),
        }
    }

    /// Every block of the file, in the order of chunk indices.
    pub fn blocks(&self) -> Vec<Block> {
        exr::block::enumerate_ordered_header_block_indices(std::slice::from_ref(&self.header))
            .map(|(chunk, b)| Block {
                chunk,
                level: b.level.x(),
                x: b.pixel_position.x(),
                y: b.pixel_position.y(),
                width: b.pixel_size.x(),
                height: b.pixel_size.y(),
            })
            .collect()
    }

    /// Encodes and compresses one block. `bands` holds the block's pixels row by row, one
    /// spectrum (in the order of `Spec::wavelengths`) per pixel; `alpha` one value per pixel,
    /// when the file has alpha. Values are stored as given (half rounds to nearest; beyond
    /// ±65504 becomes ±infinity, NaN stays NaN).
    pub fn encode(&self, block: &Block, bands: &[f32], alpha: Option<&[f32]>) -> Result<Chunk> {
        let n = self.spec.wavelengths.len();
        let pixels = block.width * block.height;
        if bands.len() != pixels * n || alpha.map(<[f32]>::len) != self.spec.alpha.then_some(pixels)
        {
            return Err(Error::Invalid(format!(
                "block {}×{} needs {} band values{}, got {}{}",
                block.width,
                block.height,
                pixels * n,
                if self.spec.alpha {
                    format!(" and {pixels} alpha values")
                } else {
                    String::new()
                },
                bands.len(),
                alpha.map_or(String::new(), |a| format!(" and {} alpha values", a.len()))
            )));
        }
        // ZIP blocks are compressed here (module `zip`), from the little-endian bytes the file
        // stores; the exr crate compresses the others from native-endian bytes.
        let zip = matches!(
            self.spec.compression,
            Compression::ZIP1 | Compression::ZIP16
        );
        if zip {
            let compressed_pixels_le = self.zip_chunk(block, bands, alpha);
            let compressed_block = match self.spec.blocks {
                // A scanline block is addressed by its y in pixel space: the data window's
                // origin plus the block's row.
                Blocks::Scanlines => CompressedBlock::ScanLine(CompressedScanLineBlock {
                    y_coordinate: i32::try_from(block.y)
                        .ok()
                        .and_then(|y| y.checked_add(self.header.own_attributes.layer_position.y()))
                        .ok_or_else(|| Error::Invalid("image taller than OpenEXR allows".into()))?,
                    compressed_pixels_le,
                }),
                Blocks::Tiles { width, height, .. } => CompressedBlock::Tile(CompressedTileBlock {
                    coordinates: TileCoordinates {
                        tile_index: Vec2(block.x / width, block.y / height),
                        level_index: Vec2(block.level, block.level),
                    },
                    compressed_pixels_le,
                }),
            };
            return Ok(Chunk {
                layer_index: 0,
                compressed_block,
            });
        }
        let data = self.sample_bytes(block, bands, alpha);
        let block = UncompressedBlock {
            index: BlockIndex {
                layer: 0,
                pixel_position: Vec2(block.x, block.y),
                pixel_size: Vec2(block.width, block.height),
                level: Vec2(block.level, block.level),
            },
            data,
        };
        Ok(block.compress_to_chunk(std::slice::from_ref(&self.header))?)
    }

    /// Calls `row` for each row of samples in the order the file stores them (pixel row by
    /// pixel row, and within a pixel row channel by channel, sorted by name) with the row's
    /// index, its samples (sample x at `x · stride`) and the stride.
    fn for_each_row<T: Copy>(
        &self,
        block: &Block,
        bands: &[T],
        alpha: Option<&[T]>,
        mut row: impl FnMut(usize, &[T], usize),
    ) {
        let (n, width) = (self.spec.wavelengths.len(), block.width);
        if width == 0 {
            return;
        }
        let mut index = 0;
        for y in 0..block.height {
            let first = y * width;
            for &src in &self.source {
                if src == n {
                    let a = alpha.expect("checked by encode");
                    row(index, &a[first..first + width], 1);
                } else {
                    let start = first * n + src;
                    row(index, &bands[start..start + (width - 1) * n + 1], n);
                }
                index += 1;
            }
        }
    }

    /// The block's samples as the file stores them, native-endian, for the exr crate's
    /// compressors.
    fn sample_bytes(&self, block: &Block, bands: &[f32], alpha: Option<&[f32]>) -> Vec<u8> {
        fn place<T: Copy, const B: usize>(
            v: &[T],
            stride: usize,
            out: &mut Vec<u8>,
            to: fn(T) -> [u8; B],
        ) {
            out.extend(v.iter().step_by(stride).flat_map(|&x| to(x)));
        }
        if self.mixed() {
            return self.mixed_bytes(block, bands, alpha, false);
        }
        let mut data = Vec::with_capacity(bands.len() * self.spec.sample.bytes());
        match self.spec.sample {
            Sample::Half => {
                let (bands, alpha) = (halves(bands), alpha.map(halves));
                self.for_each_row(block, &bands, alpha.as_deref(), |_, v, stride| {
                    place(v, stride, &mut data, half::f16::to_ne_bytes)
                });
            }
            Sample::Float => self.for_each_row(block, bands, alpha, |_, v, stride| {
                place(v, stride, &mut data, f32::to_ne_bytes)
            }),
        }
        data
    }

    /// Whether some channel is stored otherwise than [`Spec::sample`] says.
    fn mixed(&self) -> bool {
        self.types.iter().any(|&t| t != self.spec.sample)
    }

    /// The block's samples, each channel as its type stores it, little-endian when `le`, else
    /// native-endian: the path of files whose channels differ in type (slower, by value).
    fn mixed_bytes(
        &self,
        block: &Block,
        bands: &[f32],
        alpha: Option<&[f32]>,
        le: bool,
    ) -> Vec<u8> {
        let mut out = Vec::new();
        let channels = self.source.len();
        self.for_each_row(block, bands, alpha, |r, v, stride| {
            let ty = self.types[r % channels];
            for &x in v.iter().step_by(stride) {
                match (ty, le) {
                    (Sample::Half, true) => out.extend(half::f16::from_f32(x).to_le_bytes()),
                    (Sample::Half, false) => out.extend(half::f16::from_f32(x).to_ne_bytes()),
                    (Sample::Float, true) => out.extend(x.to_le_bytes()),
                    (Sample::Float, false) => out.extend(x.to_ne_bytes()),
                }
            }
        });
        out
    }

    /// The block as a ZIP chunk ([`zip`]): its little-endian sample bytes are placed straight
    /// into the format's two halves (even-indexed bytes, odd-indexed bytes), not placed and
    /// then split.
    fn zip_chunk(&self, block: &Block, bands: &[f32], alpha: Option<&[f32]>) -> Vec<u8> {
        let width = block.width;
        let samples = width * block.height * self.source.len();
        let level = self.spec.zip_level;
        if self.mixed() {
            let bytes = self.mixed_bytes(block, bands, alpha, true);
            return zip::compress_split(bytes.len(), level, |evens, odds| {
                for (i, &b) in bytes.iter().enumerate() {
                    if i % 2 == 0 {
                        evens[i / 2] = b;
                    } else {
                        odds[i / 2] = b;
                    }
                }
            });
        }
        match self.spec.sample {
            // A half's low byte is even-indexed, its high byte odd-indexed.
            Sample::Half => {
                let (bands, alpha) = (halves(bands), alpha.map(halves));
                zip::compress_split(samples * 2, level, |evens, odds| {
                    self.for_each_row(block, &bands, alpha.as_deref(), |r, v, stride| {
                        let row = r * width..(r + 1) * width;
                        let (lo, hi) = (&mut evens[row.clone()], &mut odds[row]);
                        for ((l, h), x) in lo.iter_mut().zip(hi).zip(v.iter().step_by(stride)) {
                            [*l, *h] = x.to_le_bytes();
                        }
                    });
                })
            }
            // A float's bytes 0 and 2 are even-indexed, 1 and 3 odd-indexed.
            Sample::Float => zip::compress_split(samples * 4, level, |evens, odds| {
                self.for_each_row(block, bands, alpha, |r, v, stride| {
                    let row = 2 * r * width..2 * (r + 1) * width;
                    let (lo, hi) = (&mut evens[row.clone()], &mut odds[row]);
                    let pairs = lo.chunks_exact_mut(2).zip(hi.chunks_exact_mut(2));
                    for ((l, h), x) in pairs.zip(v.iter().step_by(stride)) {
                        let b = x.to_le_bytes();
                        l.copy_from_slice(&[b[0], b[2]]);
                        h.copy_from_slice(&[b[1], b[3]]);
                    }
                });
            }),
        }
    }

    /// Writes the header, then every chunk that `produce` hands to its callback (any order,
    /// each exactly once), then completes the offset table. `out` should be buffered. The
    /// callback may be sent to another thread, so that chunks are written while others are made.
    pub fn write<W, F>(&self, out: W, produce: F) -> Result<()>
    where
        W: Write + Seek + Send,
        F: FnOnce(&mut (dyn FnMut(usize, Chunk) -> Result<()> + Send)) -> Result<()>,
    {
        self.write_then(out, produce, Vec::new)
    }

    /// As [`SpectralFile::write`], then gives string attributes the values `late` returns
    /// once every chunk is written (what is known only then, such as an average): each must
    /// already be in the header with a value of the same length in bytes, which nothing after
    /// the header moves for.
    ///
    /// `produce` speaks its caller's error type `E`: an error it returns (a cancellation, a
    /// failed read) aborts the file and comes back unchanged; the writer's own errors, the
    /// sink's included, become `E` through `From`.
    pub fn write_then<W, F, E>(
        &self,
        mut out: W,
        produce: F,
        late: impl FnOnce() -> Vec<(String, String)>,
    ) -> std::result::Result<(), E>
    where
        W: Write + Seek + Send,
        F: FnOnce(
            &mut (dyn FnMut(usize, Chunk) -> Result<()> + Send),
        ) -> std::result::Result<(), E>,
        E: From<Error>,
    {
        self.write_chunks(&mut out, produce)?;
        let header = self.header_with(late())?;
        Ok(sort_attributes(&header, &mut out)?)
    }

    /// Writes the header and the chunks `produce` hands to its sink, then the offset table;
    /// an error of `produce` aborts the file and is returned as it is.
    fn write_chunks<W, F, E>(&self, out: &mut W, produce: F) -> std::result::Result<(), E>
    where
        W: Write + Seek + Send,
        F: FnOnce(
            &mut (dyn FnMut(usize, Chunk) -> Result<()> + Send),
        ) -> std::result::Result<(), E>,
        E: From<Error>,
    {
        use exr::block::writer::ChunksWriter;
        // The exr crate's callback may return only its own error, which carries nothing: the
        // producer's result is kept as it is and the exr crate is told to abort.
        let mut produced = Ok(());
        let written = exr::block::write(
            out,
            smallvec::smallvec![self.header.clone()],
            true,
            |_meta, writer| {
                let mut sink = |index: usize, chunk: Chunk| -> Result<()> {
                    Ok(writer.write_chunk(index, chunk)?)
                };
                produced = produce(&mut sink);
                match produced {
                    Ok(()) => Ok(()),
                    Err(_) => Err(exr::error::Error::Aborted),
                }
            },
        );
        produced?;
        Ok(written.map_err(Error::from)?)
    }

    /// The header with the `late` values of attributes it reserved (same name, same length).
    fn header_with(&self, late: Vec<(String, String)>) -> Result<Header> {
        let mut header = self.header.clone();
        for (name, value) in late {
            let key = text(&name);
            let same = match header.own_attributes.other.get(&key) {
                Some(AttributeValue::Text(t)) => t.as_slice().len() == value.len(),
                _ => false,
            };
            if !same {
                return Err(Error::Invalid(format!(
                    "attribute {name} was not reserved with {} bytes of text",
                    value.len()
                )));
            }
            header
                .own_attributes
                .other
                .insert(key, AttributeValue::Text(text(&value)));
        }
        Ok(header)
    }
}

/// Refuses an image without pixels or without bands.
fn check_not_empty(spec: &Spec) -> Result<()> {
    if spec.width == 0 || spec.height == 0 {
        return Err(Error::Invalid(format!(
            "an image of {}×{} pixels has nothing to write",
            spec.width, spec.height
        )));
    }
    if spec.wavelengths.is_empty() {
        return Err(Error::Invalid(
            "a spectral image needs at least one band".into(),
        ));
    }
    check_wavelengths(&spec.wavelengths)
}

/// Refuses wavelengths that name no band: each finite and positive (a channel `T.NaNnm` is
/// one the layout's readers drop), and in increasing order, each band once. The rule of every
/// writer of the layout, whichever front-end passes them.
pub fn check_wavelengths(wavelengths: &[f64]) -> Result<()> {
    if let Some((i, w)) = wavelengths
        .iter()
        .enumerate()
        .find(|(_, w)| !(w.is_finite() && **w > 0.0))
    {
        return Err(Error::Invalid(format!(
            "wavelength {i} is {w} nm; every wavelength must be a finite number of nanometres above 0"
        )));
    }
    if let Some(i) = wavelengths.windows(2).position(|p| p[1] <= p[0]) {
        return Err(Error::Invalid(format!(
            "wavelengths must increase, band by band: {} nm (wavelength {}) is followed by {} nm",
            wavelengths[i],
            i,
            wavelengths[i + 1]
        )));
    }
    Ok(())
}

/// The channels' names, sorted as OpenEXR stores them, each with where its value sits among a
/// pixel's inputs (band index, or `bands` for alpha); refuses two bands of one name.
fn named_channels(spec: &Spec) -> Result<Vec<(String, usize)>> {
    check_channels(spec.wavelengths.len(), spec.alpha)?;
    let mut named: Vec<(String, usize)> = spec
        .wavelengths
        .iter()
        .enumerate()
        .map(|(i, &w)| (channel_name(&spec.kind, w), i))
        .collect();
    if spec.alpha {
        named.push(("A".into(), spec.wavelengths.len()));
    }
    named.sort();
    if let Kind::Named(names) = &spec.kind {
        if names.len() != spec.wavelengths.len()
            || names.iter().any(|(n, _)| n.is_empty() || n == "A")
        {
            return Err(Error::Invalid(format!(
                "{} channel names for {} values",
                names.len(),
                spec.wavelengths.len()
            )));
        }
    }
    if named.windows(2).any(|w| w[0].0 == w[1].0) {
        return Err(Error::Invalid(
            "two bands have the same wavelength to six decimals".into(),
        ));
    }
    Ok(named)
}

/// The widest type of `spec`'s channels: a block's size is checked as if all were so stored.
fn widest(spec: &Spec) -> Sample {
    match &spec.kind {
        Kind::Named(names) if names.iter().any(|n| n.1 == Sample::Float) => Sample::Float,
        _ => spec.sample,
    }
}

/// Scanlines or tiles (a MIP map or one level) of `channels` channels; refuses tiles of zero
/// size and blocks over [`MAX_BLOCK_BYTES`].
fn block_description(spec: &Spec, channels: usize) -> Result<BlockDescription> {
    match spec.blocks {
        Blocks::Scanlines => {
            let lines = spec.compression.scan_lines_per_block();
            check_block(spec.width, lines, channels, widest(spec))?;
            Ok(BlockDescription::ScanLines)
        }
        Blocks::Tiles {
            width,
            height,
            mip_levels,
        } => {
            if width == 0 || height == 0 {
                return Err(Error::Invalid("tiles must be at least 1×1".into()));
            }
            check_block(width, height, channels, widest(spec))?;
            Ok(BlockDescription::Tiles(TileDescription {
                tile_size: Vec2(width, height),
                level_mode: if mip_levels {
                    LevelMode::MipMap
                } else {
                    LevelMode::Singular
                },
                rounding_mode: RoundingMode::Down,
            }))
        }
    }
}

/// Gives `header` the data window's origin and the display window of `w`; refuses windows
/// beyond OpenEXR's 32-bit coordinates.
fn set_windows(header: &mut Header, spec: &Spec, w: Windows) -> Result<()> {
    let (x, y, width, height) = w.display;
    let bounds = |x: i32, y: i32, width: usize, height: usize| {
        let fits = |origin: i32, size: usize| {
            size > 0 && i64::from(origin) + size as i64 - 1 <= i64::from(i32::MAX)
        };
        (fits(x, width) && fits(y, height))
            .then(|| IntegerBounds::new(Vec2(x, y), Vec2(width, height)))
    };
    let (Some(data), Some(display)) = (
        bounds(w.data_origin.0, w.data_origin.1, spec.width, spec.height),
        bounds(x, y, width, height),
    ) else {
        return Err(Error::Invalid(format!(
            "the data window at {:?} of {}×{} or the display window {:?} does not fit OpenEXR's 32-bit coordinates",
            w.data_origin, spec.width, spec.height, w.display
        )));
    };
    header.own_attributes.layer_position = data.position;
    header.shared_attributes.display_window = display;
    Ok(())
}

/// Gives `header` the layout's attributes and `spec`'s own, text (UTF-8, [`text`]) and float;
/// refuses attribute names that are empty, longer than [`MAX_NAME_BYTES`] or OpenEXR's own
/// ([`standard_attribute`]): the callers' rules keep such names out.
fn set_attributes(header: &mut Header, spec: &Spec) -> Result<()> {
    let put = |header: &mut Header, name: &str, value: &str| {
        header
            .own_attributes
            .other
            .insert(text(name), AttributeValue::Text(text(value)));
    };
    match &spec.kind {
        Kind::Named(_) => {}
        Kind::Reflective => put(header, "spectralLayoutVersion", "1.0"),
        Kind::Emissive { units } => {
            put(header, "spectralLayoutVersion", "1.0");
            put(header, "emissiveUnits", units);
        }
    }
    for (k, v) in &spec.attributes {
        // The exr crate keeps `wrapmodes` (a texture's, OpenImageIO's name) in a field of its
        // own.
        if k == "wrapmodes" {
            header.own_attributes.wrap_mode_name = Some(text(v));
            continue;
        }
        check_name(k)?;
        put(header, k, v);
    }
    for (k, v) in &spec.float_attributes {
        check_name(k)?;
        header
            .own_attributes
            .other
            .insert(text(k), AttributeValue::F32(*v));
    }
    Ok(())
}

/// The longest attribute name OpenEXR writes (its long-name limit), in bytes.
pub const MAX_NAME_BYTES: usize = 255;

/// Whether `name` is one of OpenEXR's own attribute names (its required and standard
/// attributes, as the `exr` crate lists them): each has a type and a meaning of its own in
/// the file (`tiles`, `channels`, `view`, `owner`, …), so no free text may take it.
pub fn standard_attribute(name: &str) -> bool {
    exr::meta::header::standard_names::ALL.contains(&name.as_bytes())
}

/// Text for a header, as UTF-8 bytes: OpenEXR's strings are bytes, which OpenImageIO and
/// OpenEXR's own tools read as UTF-8 (the `exr` crate's `Text::new_or_none` writes Latin-1
/// and refuses anything past U+00FF).
pub fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

/// A header's text as a string: UTF-8, or Latin-1 where the bytes are not UTF-8 (as specconv
/// wrote text before it wrote UTF-8, and as the `exr` crate writes it).
pub fn text_string(t: &Text) -> String {
    match std::str::from_utf8(t.as_slice()) {
        Ok(s) => s.to_owned(),
        Err(_) => t.as_slice().iter().map(|&b| char::from(b)).collect(),
    }
}

/// Refuses an attribute name OpenEXR cannot take as free text: empty, past
/// [`MAX_NAME_BYTES`], or OpenEXR's own ([`standard_attribute`]).
fn check_name(name: &str) -> Result<()> {
    if name.is_empty() || name.len() > MAX_NAME_BYTES || standard_attribute(name) {
        return Err(Error::Invalid(format!(
            "attribute name '{}' cannot be written: OpenEXR takes names of 1 to \
             {MAX_NAME_BYTES} bytes that are not its own attributes'",
            name.escape_debug()
        )));
    }
    Ok(())
}

/// Writes `header`'s attributes again over the header written, in name order: the `exr` crate
/// writes them in the order of a `HashMap`, which changes from run to run, and the same image
/// must give the same bytes. `header` has the length of the one written, so nothing moves.
fn sort_attributes(header: &Header, out: &mut (impl Write + Seek)) -> Result<()> {
    let mut written = Vec::new();
    header.write(&mut written)?;
    let mut attributes: Vec<_> = header.all_named_attributes().collect();
    attributes.sort_by(|a, b| a.0.cmp(b.0));
    let mut sorted = Vec::with_capacity(written.len());
    for (name, value) in &attributes {
        exr::meta::attribute::write(name, value, &mut sorted)?;
    }
    exr::meta::sequence_end::write(&mut sorted)?;
    if sorted.len() != written.len() {
        // Not the header the exr crate wrote: leave it as it is (a valid file, only its
        // attribute order unsorted) rather than write over what follows it.
        return Ok(());
    }
    // After the magic number and the version field.
    let mut rewrite = || -> std::io::Result<()> {
        out.seek(std::io::SeekFrom::Start(8))?;
        out.write_all(&sorted)?;
        out.seek(std::io::SeekFrom::End(0))?;
        out.flush()
    };
    Ok(rewrite().map_err(exr::error::Error::from)?)
}

/// A spectral image read whole (for previews, conversion back to colour and tests).
#[derive(Debug, Clone)]
pub struct SpectralImage {
    /// Width of the image in pixels (of its data window, largest level).
    pub width: usize,
    /// Height of the image in pixels.
    pub height: usize,
    /// Band wavelengths in nm, increasing; `bands[i]` is the plane of `wavelengths[i]`.
    pub wavelengths: Vec<f64>,
    /// Reflective when the file has `T.` bands (those are read), else emissive with the file's
    /// `emissiveUnits` (empty when it has none).
    pub kind: Kind,
    /// One plane per band, row-major: `T.` channels, else `S0.` channels.
    pub bands: Vec<Vec<f32>>,
    /// Re-radiation planes of a bispectral file: (from band, to band, plane), indices into
    /// `wavelengths`; empty otherwise.
    pub reradiation: Vec<(usize, usize, Vec<f32>)>,
    /// The `A` plane, row-major like the bands; `None` when the file has no `A` channel.
    pub alpha: Option<Vec<f32>>,
    /// Every channel by kind, as [`Layout::of`] sees the names (also what was not read).
    pub layout: Layout,
    /// Text attributes of the header.
    pub attributes: Vec<(String, String)>,
    /// Number of MIP levels in the file (1 when it has none).
    pub levels: usize,
}

/// Reads the largest level of a spectral EXR: its `T.` bands (with re-radiation, if any), else
/// its `S0.` bands. Polarisation (S1–S3), emission beside reflectance and channels outside
/// the layout are listed in [`SpectralImage::layout`], not read.
pub fn read(path: &std::path::Path) -> Result<SpectralImage> {
    read_level(path, 0)
}

/// As [`read`], MIP level `level` of the file (0 is the largest; [`blocks::Header::levels`]
/// says how many there are).
pub fn read_level(path: &std::path::Path, level: usize) -> Result<SpectralImage> {
    let mut reader = blocks::BlockReader::open_level(path, level)?;
    let header = reader.header().clone();
    let plane = || vec![0.0f32; header.width * header.height];
    let mut bands = vec![plane(); header.wavelengths.len()];
    let mut rerad = vec![plane(); header.reradiation.len()];
    let mut alpha = header.alpha.then(plane);
    while let Some(b) = reader.next_block() {
        let b = b?;
        if b.x + b.width > header.width || b.y + b.height > header.height || b.width == 0 {
            return Err(Error::Invalid(format!(
                "{}: a block at ({}, {}) of {}×{} lies outside the {}×{} image",
                path.display(),
                b.x,
                b.y,
                b.width,
                b.height,
                header.width,
                header.height
            )));
        }
        let place = |to: &mut Vec<f32>, from: &[f32]| {
            for (row, values) in from.chunks_exact(b.width).enumerate() {
                let start = (b.y + row) * header.width + b.x;
                to[start..start + b.width].copy_from_slice(values);
            }
        };
        for (to, from) in bands.iter_mut().zip(&b.bands) {
            place(to, from);
        }
        for (to, from) in rerad.iter_mut().zip(&b.reradiation) {
            place(to, from);
        }
        if let (Some(to), Some(from)) = (alpha.as_mut(), &b.alpha) {
            place(to, from);
        }
    }
    Ok(SpectralImage {
        width: header.width,
        height: header.height,
        wavelengths: header.wavelengths,
        kind: header.kind,
        bands,
        reradiation: header
            .reradiation
            .into_iter()
            .zip(rerad)
            .map(|((from, to), p)| (from, to, p))
            .collect(),
        alpha,
        layout: header.layout,
        attributes: header.attributes,
        levels: header.levels,
    })
}

/// What an OpenEXR file's first header says of its colour, read without its pixels: the
/// evidence a conversion weighs (docs/colour.md), as OpenImageIO reports it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ColourAttributes {
    /// `chromaticities`: red, green, blue and white x, y.
    pub chromaticities: Option<[f32; 8]>,
    /// `acesImageContainerFlag`, where it is a number.
    pub aces_container: Option<f64>,
    /// `colorInteropID`.
    pub interop_id: Option<String>,
    /// `oiio:ColorSpace`, a name a tool wrote.
    pub colour_space: Option<String>,
}

/// The first bytes of every OpenEXR file.
const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// The colour attributes of an OpenEXR file's first header, without reading its pixels;
/// `None` for a file that is not OpenEXR (its first bytes are not OpenEXR's magic number).
pub fn colour_attributes(path: &std::path::Path) -> Result<Option<ColourAttributes>> {
    use std::io::{Read, Seek};
    let mut file = std::io::BufReader::new(specconv_atomic_file::open_file(path)?);
    let mut magic = [0u8; 4];
    if file.read_exact(&mut magic).is_err() || magic != MAGIC {
        return Ok(None);
    }
    file.rewind().map_err(exr::error::Error::from)?;
    let meta = exr::meta::MetaData::read_from_buffered(file, false)?;
    let Some(h) = meta.headers.first() else {
        return Ok(Some(ColourAttributes::default()));
    };
    let c = h.shared_attributes.chromaticities;
    let string = |name: &str| match h.own_attributes.other.get(&text(name)) {
        Some(AttributeValue::Text(t)) => Some(text_string(t)),
        _ => None,
    };
    let aces = match h.own_attributes.other.get(&text("acesImageContainerFlag")) {
        Some(AttributeValue::I32(v)) => Some(f64::from(*v)),
        Some(AttributeValue::F32(v)) => Some(f64::from(*v)),
        Some(AttributeValue::F64(v)) => Some(*v),
        _ => None,
    };
    Ok(Some(ColourAttributes {
        chromaticities: c.map(|c| {
            let xy = |v: Vec2<f32>| [v.x(), v.y()];
            let [r, g, b, w] = [c.red, c.green, c.blue, c.white].map(xy);
            [r[0], r[1], g[0], g[1], b[0], b[1], w[0], w[1]]
        }),
        aces_container: aces,
        interop_id: string("colorInteropID"),
        colour_space: string("oiio:ColorSpace"),
    }))
}

/// An OpenEXR file's R, G, B (and A) samples as stored, widened to float32 (half widens
/// exactly): no colour conversion, whatever its header declares.
#[derive(Debug, Clone)]
pub struct RgbaSamples {
    /// Width and height.
    pub size: (usize, usize),
    /// 3 (R, G, B) or 4 (and A).
    pub channels: usize,
    /// Row-major, `channels` a pixel.
    pub samples: Vec<f32>,
}

/// The R, G, B and A channels of the first layer of an OpenEXR file that has them, full
/// resolution, as stored.
pub fn read_rgba(path: &std::path::Path) -> Result<RgbaSamples> {
    use exr::image::read::image::ReadLayers as _;
    use exr::image::read::layers::ReadChannels as _;
    let file = std::io::BufReader::new(specconv_atomic_file::open_file(path)?);
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, channels: &exr::image::RgbaChannels| {
                let c = if channels.3.is_some() { 4 } else { 3 };
                RgbaSamples {
                    size: (size.width(), size.height()),
                    channels: c,
                    samples: vec![0.0; size.area() * c],
                }
            },
            |out: &mut RgbaSamples, at, (r, g, b, a): (f32, f32, f32, f32)| {
                let c = out.channels;
                let i = (at.y() * out.size.0 + at.x()) * c;
                out.samples[i..i + 3].copy_from_slice(&[r, g, b]);
                if c == 4 {
                    out.samples[i + 3] = a;
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(file)?;
    Ok(image.layer_data.channel_data.pixels)
}

/// The text attributes of a file's first header, without reading its pixels.
pub fn read_attributes(path: &std::path::Path) -> Result<Vec<(String, String)>> {
    let file = std::io::BufReader::new(specconv_atomic_file::open_file(path)?);
    let meta = exr::meta::MetaData::read_from_buffered(file, false)?;
    Ok(meta.headers.first().map_or_else(Vec::new, |h| {
        h.own_attributes
            .other
            .iter()
            .filter_map(|(k, v)| match v {
                AttributeValue::Text(t) => Some((text_string(k), text_string(t))),
                _ => None,
            })
            .collect()
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wavelengths_that_name_no_band_are_refused() {
        for (bad, says) in [
            (vec![400.0, f64::NAN, 600.0], "wavelength 1 is NaN nm"),
            (vec![f64::INFINITY], "wavelength 0 is inf nm"),
            (vec![0.0, 500.0], "wavelength 0 is 0 nm"),
            (vec![-400.0], "wavelength 0 is -400 nm"),
            (
                vec![500.0, 400.0],
                "500 nm (wavelength 0) is followed by 400 nm",
            ),
            (vec![500.0, 500.0], "is followed by 500 nm"),
        ] {
            let mut spec = spec(Blocks::Scanlines, false);
            spec.wavelengths = bad.clone();
            let e = SpectralFile::new(spec).map(|_| ()).unwrap_err();
            assert!(e.to_string().contains(says), "{bad:?}: {e}");
        }
        assert!(check_wavelengths(&[0.5, 380.0, 1e6]).is_ok());
    }

    #[test]
    fn channel_names_follow_the_layout() {
        assert_eq!(channel_name(&Kind::Reflective, 380.0), "T.380,000000nm");
        assert_eq!(
            channel_name(
                &Kind::Emissive {
                    units: "W.m^-2.sr^-1".into()
                },
                552.5
            ),
            "S0.552,500000nm"
        );
        assert_eq!(parse_channel_name("T.380,000000nm"), Some((false, 380.0)));
        assert_eq!(parse_channel_name("S0.552,5nm"), Some((true, 552.5)));
        assert_eq!(parse_channel_name("T.0,55um"), Some((false, 550.0)));
        assert_eq!(parse_channel_name("T.5.5e2nm"), Some((false, 550.0)));
        let (_, nm) = parse_channel_name("T.545,077196THz").unwrap();
        assert!((nm - 550.0).abs() < 1e-3, "{nm}");
        for bad in [
            "R", "A", "T.nm", "T.-5nm", "S1.500nm", "T.500", "T.500xm", "S4.500nm",
        ] {
            assert_eq!(parse_channel_name(bad), None, "{bad}");
        }
        assert_eq!(parse_channel("T.5daHz").map(|_| ()), Some(()));
        assert_eq!(
            parse_channel("S2.550,000000nm"),
            Some(Channel::Stokes { k: 2, nm: 550.0 })
        );
        assert_eq!(
            parse_channel("T.380,000000nm.450,5nm"),
            Some(Channel::Reradiation {
                from_nm: 380.0,
                to_nm: 450.5
            })
        );
        assert_eq!(
            parse_channel("T.0,38um.4,505e2nm"),
            Some(Channel::Reradiation {
                from_nm: 380.0,
                to_nm: 450.5
            })
        );
        let l = Layout::of(["R", "G", "B", "A", "S0.500nm", "S1.500nm", "T.400nm.500nm"]);
        assert_eq!(l.other, ["R", "G", "B"]);
        assert!(l.alpha && l.polarised());
        assert_eq!(l.reradiation, [(400.0, 500.0)]);
    }

    fn spec(blocks: Blocks, alpha: bool) -> Spec {
        Spec {
            width: 37,
            height: 21,
            windows: None,
            wavelengths: vec![380.0, 550.0, 1000.0],
            kind: Kind::Reflective,
            alpha,
            sample: Sample::Float,
            compression: Compression::ZIP16,
            zip_level: zip::DEFAULT_LEVEL,
            blocks,
            attributes: vec![("specconvMethod".into(), "otsu2018".into())],
            float_attributes: vec![],
        }
    }

    #[test]
    fn files_of_more_channels_than_readers_read_are_refused() {
        // Issue 31: `--bands 380:730:0.01` wrote 35,001 channels, which OpenImageIO cannot read.
        let tiles = Blocks::Tiles {
            width: 1,
            height: 1,
            mip_levels: false,
        };
        let with = |bands: usize, alpha: bool| {
            let mut s = spec(tiles, alpha);
            s.width = 1;
            s.height = 1;
            s.wavelengths = (0..bands).map(|i| 380.0 + 0.01 * i as f64).collect();
            SpectralFile::new(s).map(|_| ())
        };
        assert!(with(MAX_CHANNELS, false).is_ok());
        assert!(with(MAX_CHANNELS - 1, true).is_ok());
        for (bands, alpha) in [
            (MAX_CHANNELS, true),
            (MAX_CHANNELS + 1, false),
            (35_001, true),
        ] {
            let e = with(bands, alpha).unwrap_err();
            assert!(
                matches!(&e, Error::TooManyChannels(t) if *t == TooManyChannels { bands, alpha }),
                "{e}"
            );
        }
        assert_eq!(
            check_channels(35_001, true).unwrap_err().to_string(),
            "35001 bands and alpha would be 35002 channels; OpenEXR readers (OpenImageIO) read \
             at most 32767 (32766 bands and alpha): use fewer bands, with a coarser step or a \
             shorter range"
        );
    }

    #[test]
    fn blocks_cover_every_level_once() {
        let f = SpectralFile::new(spec(
            Blocks::Tiles {
                width: 8,
                height: 8,
                mip_levels: true,
            },
            false,
        ))
        .unwrap();
        assert_eq!(f.levels(), 6);
        for level in 0..f.levels() {
            let (w, h) = f.level_size(level);
            let area: usize = f
                .blocks()
                .iter()
                .filter(|b| b.level == level)
                .map(|b| b.width * b.height)
                .sum();
            assert_eq!(area, w * h, "level {level}");
        }
        let chunks: Vec<usize> = f.blocks().iter().map(|b| b.chunk).collect();
        assert_eq!(chunks, (0..chunks.len()).collect::<Vec<_>>());
    }

    #[test]
    fn written_files_read_back_band_by_band_whatever_the_channel_order() {
        for (blocks, alpha) in [
            (Blocks::Scanlines, true),
            (
                Blocks::Tiles {
                    width: 16,
                    height: 8,
                    mip_levels: false,
                },
                false,
            ),
        ] {
            let f = SpectralFile::new(spec(blocks, alpha)).unwrap();
            // Band b of pixel (x, y) holds b + x/100 + y/10000; alpha is 0.5.
            let value =
                |x: usize, y: usize, b: usize| b as f32 + x as f32 / 100.0 + y as f32 / 10000.0;
            let mut buf = std::io::Cursor::new(Vec::new());
            f.write(&mut buf, |sink| {
                for b in f.blocks() {
                    let px: Vec<f32> = (0..b.height)
                        .flat_map(|y| {
                            (0..b.width)
                                .flat_map(move |x| (0..3).map(move |c| value(b.x + x, b.y + y, c)))
                        })
                        .collect();
                    let a = vec![0.5; b.width * b.height];
                    sink(b.chunk, f.encode(&b, &px, alpha.then_some(a.as_slice()))?)?;
                }
                Ok(())
            })
            .unwrap();
            let path = std::env::temp_dir()
                .join(format!("specconv-exr-{}-{alpha}.exr", std::process::id()));
            std::fs::write(&path, buf.into_inner()).unwrap();
            let img = read(&path).unwrap();
            std::fs::remove_file(&path).unwrap();
            assert_eq!((img.width, img.height), (37, 21));
            assert_eq!(img.wavelengths, vec![380.0, 550.0, 1000.0]);
            for (b, plane) in img.bands.iter().enumerate() {
                assert_eq!(plane[5 * 37 + 7], value(7, 5, b));
            }
            assert_eq!(img.alpha.map(|a| a[100]), alpha.then_some(0.5));
            assert!(img
                .attributes
                .contains(&("spectralLayoutVersion".into(), "1.0".into())));
            assert!(img
                .attributes
                .contains(&("specconvMethod".into(), "otsu2018".into())));
        }
    }

    #[test]
    fn a_failing_producer_aborts_the_write_with_its_error() {
        let f = SpectralFile::new(spec(Blocks::Scanlines, false)).unwrap();
        let mut buf = std::io::Cursor::new(Vec::new());
        let err = f
            .write(&mut buf, |_| Err(Error::Invalid("input went away".into())))
            .unwrap_err();
        assert_eq!(err.to_string(), "input went away");
        let bad = f.encode(&f.blocks()[0], &[0.0; 3], None).unwrap_err();
        assert!(bad.to_string().contains("needs"), "{bad}");
    }

    /// A caller's own error, as `write_then` hands it back.
    #[derive(Debug)]
    enum Caller {
        Stopped,
        Writer(Error),
    }

    impl From<Error> for Caller {
        fn from(e: Error) -> Caller {
            Caller::Writer(e)
        }
    }

    #[test]
    fn a_producers_own_error_comes_back_unchanged_and_the_writers_become_it() {
        let f = SpectralFile::new(spec(Blocks::Scanlines, false)).unwrap();
        let mut buf = std::io::Cursor::new(Vec::new());
        let stopped = f.write_then(&mut buf, |_| Err(Caller::Stopped), Vec::new);
        assert!(matches!(stopped, Err(Caller::Stopped)), "{stopped:?}");
        // A chunk the file has no place for: the sink's error, through `From`.
        let b = &f.blocks()[0];
        let chunk = f
            .encode(b, &vec![0.0; b.width * b.height * 3], None)
            .unwrap();
        let mut buf = std::io::Cursor::new(Vec::new());
        let sunk = f.write_then(&mut buf, |sink| Ok(sink(usize::MAX, chunk)?), Vec::new);
        assert!(
            matches!(sunk, Err(Caller::Writer(Error::Exr(_)))),
            "{sunk:?}"
        );
    }
}
