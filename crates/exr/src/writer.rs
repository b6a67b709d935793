//! A spectral file written block by block ([`SpectralFile`]): its header made and checked
//! from a [`Spec`], each block encoded and compressed, the chunks written as they come.

use crate::attributes::{set_attributes, sort_attributes, text};
use crate::channels::channel_name;
use crate::error::{Error, Result};
use crate::limits::{check_block, check_channels};
use crate::spec::{Blocks, Kind, Sample, Spec, Windows};
use crate::zip;
use exr::block::chunk::{
    Chunk, CompressedBlock, CompressedScanLineBlock, CompressedTileBlock, TileCoordinates,
};
use exr::block::{BlockIndex, UncompressedBlock};
use exr::compression::Compression;
use exr::math::{RoundingMode, Vec2};
use exr::meta::attribute::{
    AttributeValue, ChannelDescription, IntegerBounds, LevelMode, LineOrder, SampleType, Text,
    TileDescription,
};
use exr::meta::header::Header;
use exr::meta::BlockDescription;
use std::io::{Seek, Write};

/// Values rounded to half all at once (F16C where the CPU has it, as `half` does value by
/// value).
fn halves(values: &[f32]) -> Vec<half::f16> {
    use half::slice::HalfFloatSliceExt;
    let mut h = vec![half::f16::ZERO; values.len()];
    h.convert_from_f32_slice(values);
    h
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
    /// take as free text ([`standard_attribute`](crate::standard_attribute),
    /// [`MAX_NAME_BYTES`](crate::MAX_NAME_BYTES)).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{check_channels, read, zip, Compression, TooManyChannels, MAX_CHANNELS};

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
