//! A spectral EXR read block by block (the largest level of its first part, in file order), so
//! that a reader of a 16K texture holds one block of bands at a time. [`crate::read`] is this
//! reader with every block gathered into planes.

use crate::attributes::text_attributes;
use crate::channels::{parse_channel, Channel, ChannelKinds};
use crate::error::{Error, Result};
use crate::spec::Kind;
use exr::block::reader::ChunksReader;
use exr::meta::attribute::SampleType;
use std::path::Path;

/// What a spectral EXR holds, from its header: everything but the pixels.
#[derive(Debug, Clone)]
pub struct Header {
    /// Width of the data window, in pixels.
    pub width: usize,
    /// Height of the data window, in pixels.
    pub height: usize,
    /// Number of MIP levels in the file (1 when it has none); `width` and `height` are those
    /// of the level being read.
    pub levels: usize,
    /// Band wavelengths in nm, increasing; a [`Block`]'s `bands[i]` is `wavelengths[i]`'s.
    pub wavelengths: Vec<f64>,
    /// Reflectance (`T.` channels read) or emission (`S0.` channels read).
    pub kind: Kind,
    /// Re-radiation channels of a bispectral file: (from band, to band), indices into
    /// `wavelengths`, in the order of a [`Block`]'s `reradiation`.
    pub reradiation: Vec<(usize, usize)>,
    /// Whether the file has an `A` channel.
    pub alpha: bool,
    /// Every channel by kind, as [`ChannelKinds::of`] sees the names (also what is not read).
    pub channel_kinds: ChannelKinds,
    /// Text attributes of the header.
    pub attributes: Vec<(String, String)>,
    /// What each of the file's channels (in the file's order) is read as.
    roles: Vec<Role>,
}

/// What a channel of the file is read as.
#[derive(Debug, Clone, Copy)]
enum Role {
    Band(usize),
    Reradiation(usize),
    Alpha,
    Unused,
}

/// One block of pixels: planes of `width × height` values, row-major.
#[derive(Debug, Clone)]
pub struct Block {
    /// Column of its top-left pixel in the data window.
    pub x: usize,
    /// Row of its top-left pixel in the data window.
    pub y: usize,
    /// Its width in pixels.
    pub width: usize,
    /// Its height in pixels.
    pub height: usize,
    /// One plane per band of [`Header::wavelengths`].
    pub bands: Vec<Vec<f32>>,
    /// One plane per pair of [`Header::reradiation`].
    pub reradiation: Vec<Vec<f32>>,
    /// The alpha plane, when the file has alpha.
    pub alpha: Option<Vec<f32>>,
}

/// A spectral EXR open for reading block by block.
pub struct BlockReader {
    header: Header,
    channels: exr::meta::attribute::ChannelList,
    blocks: exr::block::reader::SequentialBlockDecompressor<
        exr::block::reader::FilteredChunksReader<std::io::BufReader<std::fs::File>>,
    >,
}

impl BlockReader {
    /// Opens `path` and reads its header: the pixels are read by [`BlockReader::next_block`].
    pub fn open(path: &Path) -> Result<BlockReader> {
        BlockReader::open_level(path, 0)
    }

    /// As [`BlockReader::open`], for MIP level `level` (0 is the largest).
    pub fn open_level(path: &Path, level: usize) -> Result<BlockReader> {
        let (reader, levels, size) = open_first_part(path, level)?;
        let first = &reader.headers()[0];
        let mut header = header_of(path, first)?;
        (header.width, header.height) = size;
        header.levels = levels;
        let channels = first.channels.clone();
        let blocks = reader
            .filter_chunks(false, |_, _, block| {
                block.layer == 0 && block.level == exr::math::Vec2(level, level)
            })?
            .sequential_decompressor(false);
        Ok(BlockReader {
            header,
            channels,
            blocks,
        })
    }

    /// The file's spectral header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The next block of the largest level, in the order the file stores them; `None` after
    /// the last.
    pub fn next_block(&mut self) -> Option<Result<Block>> {
        let block = match self.blocks.decompress_next_block()? {
            Ok(b) => b,
            Err(e) => return Some(Err(e.into())),
        };
        Some(self.planes(block))
    }

    /// A decompressed block's lines placed into planes by the channels' roles.
    fn planes(&self, block: exr::block::UncompressedBlock) -> Result<Block> {
        let header = &self.header;
        let (width, height) = (block.index.pixel_size.x(), block.index.pixel_size.y());
        let plane = || vec![0.0f32; width * height];
        let mut out = Block {
            x: block.index.pixel_position.x(),
            y: block.index.pixel_position.y(),
            width,
            height,
            bands: vec![plane(); header.wavelengths.len()],
            reradiation: vec![plane(); header.reradiation.len()],
            alpha: header.alpha.then(plane),
        };
        for line in block.lines(&self.channels) {
            let target = match header.roles[line.location.channel] {
                Role::Band(i) => &mut out.bands[i],
                Role::Reradiation(i) => &mut out.reradiation[i],
                Role::Alpha => out.alpha.as_mut().expect("alpha has a plane"),
                Role::Unused => continue,
            };
            let row = line.location.position.y() - out.y;
            let start = row * width + line.location.position.x() - out.x;
            let row = &mut target[start..start + line.location.sample_count];
            match self.channels.list[line.location.channel].sample_type {
                SampleType::F32 => line.read_samples_into_slice(row)?,
                SampleType::F16 => {
                    for (o, v) in row.iter_mut().zip(line.read_samples::<half::f16>()) {
                        *o = v?.to_f32();
                    }
                }
                SampleType::U32 => {
                    for (o, v) in row.iter_mut().zip(line.read_samples::<u32>()) {
                        *o = v? as f32;
                    }
                }
            }
        }
        Ok(out)
    }
}

/// A file's block reader, as the `exr` crate opens it.
type FileReader = exr::block::reader::Reader<std::io::BufReader<std::fs::File>>;

/// `path` opened for its blocks, once its first part is there and has MIP level `level`: the
/// reader, the part's number of levels and the level's size. Both block readers start here.
fn open_first_part(path: &Path, level: usize) -> Result<(FileReader, usize, (usize, usize))> {
    let file = std::io::BufReader::new(specconv_atomic_file::open_file(path)?);
    let reader = exr::block::read(file, false)?;
    let first = reader
        .headers()
        .first()
        .ok_or_else(|| Error::Invalid(format!("{} has no image part", path.display())))?;
    let (levels, size) = levels_of(first, level);
    if level >= levels {
        return Err(Error::Invalid(format!(
            "{}: MIP level {level} does not exist; the file has {levels} (0 to {})",
            path.display(),
            levels - 1
        )));
    }
    Ok((reader, levels, size))
}

/// The number of MIP levels of a part (RIP maps: their levels along the diagonal) and the size
/// of `level`.
fn levels_of(h: &exr::meta::header::Header, level: usize) -> (usize, (usize, usize)) {
    use exr::meta::attribute::LevelMode;
    use exr::meta::BlockDescription;
    let (width, height) = (h.layer_size.x(), h.layer_size.y());
    match h.blocks {
        BlockDescription::Tiles(t) if t.level_mode != LevelMode::Singular => {
            let r = t.rounding_mode;
            let count = |full| exr::meta::compute_level_count(r, full);
            let levels = match t.level_mode {
                LevelMode::RipMap => count(width).min(count(height)),
                _ => count(width.max(height)),
            };
            let size = |full| exr::meta::compute_level_size(r, full, level.min(levels - 1));
            (levels, (size(width), size(height)))
        }
        _ => (1, (width, height)),
    }
}

/// The spectral header of the first part of `path`: which channels are bands (`T.`, else
/// `S0.`), re-radiation and alpha.
fn header_of(path: &Path, h: &exr::meta::header::Header) -> Result<Header> {
    let attributes = text_attributes(h);
    let names: Vec<String> = h.channels.list.iter().map(|c| c.name.to_string()).collect();
    full_resolution(path, &h.channels)?;
    let channel_kinds = ChannelKinds::of(names.iter().map(String::as_str));
    if !channel_kinds.is_spectral() {
        return Err(Error::Invalid(format!(
            "{} is not a spectral EXR: it has no T.<wavelength>nm or S0.<wavelength>nm channels",
            path.display()
        )));
    }
    let reflective = !channel_kinds.reflective.is_empty();
    // (wavelength, channel index) of the bands; (from, to, channel) of re-radiation.
    let mut bands: Vec<(f64, usize)> = Vec::new();
    let mut rerad: Vec<(f64, f64, usize)> = Vec::new();
    let mut roles = vec![Role::Unused; names.len()];
    for (c, name) in names.iter().enumerate() {
        match parse_channel(name) {
            Some(Channel::Reflective { nm }) if reflective => bands.push((nm, c)),
            Some(Channel::Stokes { k: 0, nm }) if !reflective => bands.push((nm, c)),
            Some(Channel::Reradiation { from_nm, to_nm }) if reflective => {
                rerad.push((from_nm, to_nm, c))
            }
            None if name == "A" => roles[c] = Role::Alpha,
            _ => {}
        }
    }
    bands.sort_by(|a, b| a.0.total_cmp(&b.0));
    let wavelengths: Vec<f64> = bands.iter().map(|b| b.0).collect();
    if wavelengths.windows(2).any(|w| w[0] == w[1]) {
        return Err(Error::Invalid(format!(
            "{} names one wavelength twice (in two units?)",
            path.display()
        )));
    }
    for (i, &(_, c)) in bands.iter().enumerate() {
        roles[c] = Role::Band(i);
    }
    let index = |nm: f64, what: &str| {
        wavelengths
            .iter()
            .position(|w| (w - nm).abs() <= 1e-6 * nm)
            .ok_or_else(|| {
                Error::Invalid(format!(
                    "{}: a re-radiation channel's {what} wavelength {nm} nm has no T.{nm}nm \
                     band; the layout pairs re-radiation with the bands of the diagonal",
                    path.display()
                ))
            })
    };
    let mut reradiation = Vec::with_capacity(rerad.len());
    for (i, (from, to, c)) in rerad.into_iter().enumerate() {
        reradiation.push((index(from, "incident")?, index(to, "re-radiated")?));
        roles[c] = Role::Reradiation(i);
    }
    let kind = if reflective {
        Kind::Reflective
    } else {
        let units = attributes
            .iter()
            .find(|(k, _)| k == "emissiveUnits")
            .map_or("", |(_, v)| v.as_str());
        Kind::Emissive {
            units: units.to_string(),
        }
    };
    let size = h.layer_size;
    Ok(Header {
        width: size.x(),
        height: size.y(),
        levels: 1,
        wavelengths,
        kind,
        reradiation,
        alpha: roles.iter().any(|r| matches!(r, Role::Alpha)),
        channel_kinds,
        attributes,
        roles,
    })
}

/// One MIP level of an OpenEXR file's first part, any channels, read block by block with the
/// blocks decompressed in parallel: for a reader that keeps only what it makes of each block
/// (a compact texture's texels), not the file's channels.
pub struct ChannelBlocks {
    /// Width and height of the level.
    pub size: (usize, usize),
    /// MIP levels of the file (1 without).
    pub levels: usize,
    /// Channel names, in the file's (a block's planes') order.
    pub channels: Vec<String>,
    /// Text attributes of the header.
    pub attributes: Vec<(String, String)>,
    level: usize,
    reader: exr::block::reader::Reader<std::io::BufReader<std::fs::File>>,
}

/// A block of [`ChannelBlocks`]: one plane (`width × height`, row-major) per channel.
#[derive(Debug)]
pub struct PlaneBlock {
    /// Column and row of its top-left pixel in the level.
    pub at: (usize, usize),
    /// Its width and height.
    pub size: (usize, usize),
    /// One plane per channel of [`ChannelBlocks::channels`], widened to float32.
    pub planes: Vec<Vec<f32>>,
}

impl ChannelBlocks {
    /// Opens MIP level `level` of `path` and reads its header.
    pub fn open(path: &Path, level: usize) -> Result<ChannelBlocks> {
        let (reader, levels, size) = open_first_part(path, level)?;
        let first = &reader.headers()[0];
        full_resolution(path, &first.channels)?;
        let attributes = text_attributes(first);
        Ok(ChannelBlocks {
            size,
            levels,
            channels: first
                .channels
                .list
                .iter()
                .map(|c| c.name.to_string())
                .collect(),
            attributes,
            level,
            reader,
        })
    }

    /// Every block of the level, decompressed in parallel, handed to `each` in turn (in
    /// whatever order they finish).
    pub fn read(self, mut each: impl FnMut(PlaneBlock)) -> Result<()> {
        let level = exr::math::Vec2(self.level, self.level);
        let channels = self.reader.headers()[0].channels.clone();
        let chunks = self.reader.filter_chunks(false, |_, _, block| {
            block.layer == 0 && block.level == level
        })?;
        let mut failed = None;
        chunks.decompress_parallel(false, |_, block| {
            match planes(&channels, block) {
                Ok(b) => each(b),
                Err(e) => failed = Some(e),
            }
            Ok(())
        })?;
        failed.map_or(Ok(()), Err)
    }
}

/// A decompressed block's lines as one plane per channel.
fn planes(
    channels: &exr::meta::attribute::ChannelList,
    block: exr::block::UncompressedBlock,
) -> Result<PlaneBlock> {
    let (width, height) = (block.index.pixel_size.x(), block.index.pixel_size.y());
    let (x0, y0) = (
        block.index.pixel_position.x(),
        block.index.pixel_position.y(),
    );
    let mut planes = vec![vec![0.0f32; width * height]; channels.list.len()];
    for line in block.lines(channels) {
        let (c, p) = (line.location.channel, line.location.position);
        let start = (p.y() - y0) * width + p.x() - x0;
        let row = &mut planes[c][start..start + line.location.sample_count];
        match channels.list[c].sample_type {
            SampleType::F32 => line.read_samples_into_slice(row)?,
            SampleType::F16 => {
                for (o, v) in row.iter_mut().zip(line.read_samples::<half::f16>()) {
                    *o = v?.to_f32();
                }
            }
            SampleType::U32 => {
                for (o, v) in row.iter_mut().zip(line.read_samples::<u32>()) {
                    *o = v? as f32;
                }
            }
        }
    }
    Ok(PlaneBlock {
        at: (x0, y0),
        size: (width, height),
        planes,
    })
}

/// Refuses a part with a subsampled channel (4:2:0 chroma and the like): a texture's channels,
/// spectral or compact, are all at full resolution.
fn full_resolution(path: &Path, channels: &exr::meta::attribute::ChannelList) -> Result<()> {
    match channels
        .list
        .iter()
        .find(|c| c.sampling != exr::math::Vec2(1, 1))
    {
        Some(c) => Err(Error::Invalid(format!(
            "{}: channel {} is subsampled; a texture's channels are all at full resolution",
            path.display(),
            c.name
        ))),
        None => Ok(()),
    }
}
