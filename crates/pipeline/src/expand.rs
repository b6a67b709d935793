//! `specconv expand`: a compact texture ([`specconv_spectral::compact`]) written out in the
//! spectral layout, as `convert` writes it from the same input and settings.
//!
//! Level 0's texels are decoded by the compact text's own rule ([`Compact::decode_f32`]);
//! the smaller levels are filtered from those spectra, as a conversion filters its own
//! (module `mip`), not decoded from the compact file's smaller levels, which hold filtered
//! colours. The samples are rounded and compressed as the compact file records a conversion
//! would have (`specconvExpand`), with its tiles, levels, windows and attributes; its
//! `specconvSettings` says `layout=spectral` where the compact file's says `layout=compact`
//! ([`specconv_description::as_spectral`]), so an expanded file is as up to date as a
//! converted one. The values are the conversion's to float32 rounding of
//! the dual unknowns: within one half step, and mostly the same half (docs/compact.md).
//!
//! The file is read a strip of blocks at a time; memory is bounded by a strip.

use super::survey::{self, Repair};
use crate::attributes::{average_attributes, average_text, windows_of, AVERAGE, CONSTANT};
use crate::blocks::{clamp_made, finish, level_sums};
use crate::error::{Error, Result};
use crate::job::refuse_overwrites;
use crate::mip;
use crate::options::{Key, Options};
use crate::storage::{COMPACT_ATTRIBUTE, COMPACT_CHANNELS, EXPAND_ATTRIBUTE, LAYOUT_ATTRIBUTE};
use crate::strips::{strips, Strip};
use crate::Rounding;
use rayon::prelude::*;
use specconv_atomic_file::{Pending, Replace};
use specconv_exr::{Block, Blocks, Chunk, Kind, Spec, SpectralFile};
use specconv_oiio::{ImageReader, Pixels};
use specconv_spectral::compact::{Compact, STORED, TEXEL, VERSION};
use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// The options that say how a conversion stores the spectra, which a compact file records
/// for its expansion.
const STORAGE_KEYS: [Key; 5] = [
    Key::Sample,
    Key::Rounding,
    Key::Compression,
    Key::ZipLevel,
    Key::Filter,
];

/// `specconvExpand`: how the spectral layout would have been stored, `name=value` a word.
pub fn settings(options: &Options) -> String {
    STORAGE_KEYS
        .iter()
        .filter_map(|&k| {
            let value = match k {
                Key::Rounding => Some(options.rounding_in_effect().to_string()),
                k => options.text(k),
            };
            value.map(|v| format!("{}={v}", k.about().name))
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// What an expansion wrote.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Expanded {
    /// Level 0's size.
    pub width: usize,
    /// Level 0's height.
    pub height: usize,
    /// MIP levels written.
    pub levels: usize,
    /// Wavelengths of the bands, nm.
    pub wavelengths: Vec<f64>,
    /// Texels of level 0 whose spectrum the projection changed (u ≠ 0).
    pub projected: u64,
}

/// The rule: a file is compact when its layout attribute says so (`compact …`, any version),
/// or when it has every channel of a compact texel.
pub fn is_compact(layout: Option<&str>, channels: &[&str]) -> bool {
    layout.is_some_and(|l| l.trim_start().starts_with("compact"))
        || COMPACT_CHANNELS.iter().all(|c| channels.contains(c))
}

/// What makes a file compact, from its header, however it was read: its layout attribute
/// (`compact 2`), its decoding text (`specconvCompact`, checked line by line) and the texel's
/// channels among `channels` (their columns, in the order of a texel's values).
pub fn header(
    path: &Path,
    layout: Option<&str>,
    text: Option<&str>,
    channels: &[&str],
) -> Result<(Compact, [usize; STORED])> {
    let not = |why: String| Error::NotCompact {
        path: path.to_path_buf(),
        why,
    };
    if layout != Some(VERSION) {
        return Err(not(match layout {
            Some(l) => format!(
                "its {LAYOUT_ATTRIBUTE} is '{l}'; this specconv reads '{VERSION}': convert the texture again, or expand it with the specconv that wrote it"
            ),
            None => format!("no {LAYOUT_ATTRIBUTE} attribute"),
        }));
    }
    let text = text.ok_or_else(|| not(format!("no {COMPACT_ATTRIBUTE} attribute")))?;
    let compact = Compact::from_text(text).map_err(|e| not(format!("{COMPACT_ATTRIBUTE}: {e}")))?;
    let mut columns = [0; STORED];
    for (c, name) in columns.iter_mut().zip(COMPACT_CHANNELS) {
        *c = channels
            .iter()
            .position(|n| *n == name)
            .ok_or_else(|| not(format!("no channel {name}")))?;
    }
    Ok((compact, columns))
}

/// The layout and decoding-text attributes of `input` as its header holds them, every byte,
/// read by the OpenEXR reader of `specconv_exr` as [`read_texels`] reads them: OpenImageIO ends
/// a string attribute at a NUL, and a text cut there can read as a shorter valid one (issue
/// 57, item 7). Every reader of a compact file in this library takes the text from here.
pub fn text_attributes(input: &Path) -> Result<(Option<String>, Option<String>)> {
    let blocks =
        specconv_exr::blocks::ChannelBlocks::open(input, 0).map_err(|e| Error::NotCompact {
            path: input.to_path_buf(),
            why: format!("it cannot be read as OpenEXR ({e})"),
        })?;
    let (layout, text) = layout_and_text(&blocks.attributes);
    Ok((layout.map(str::to_string), text.map(str::to_string)))
}

/// The layout and decoding-text attributes among a header's text attributes.
fn layout_and_text(attributes: &[(String, String)]) -> (Option<&str>, Option<&str>) {
    let attribute = |name: &str| {
        let found = attributes.iter().find(|(k, _)| k == name);
        found.map(|(_, v)| v.as_str())
    };
    (attribute(LAYOUT_ATTRIBUTE), attribute(COMPACT_ATTRIBUTE))
}

/// One MIP level of a compact texture in memory: what a renderer holds to decode spectra at
/// each lookup (docs/compact.md), six float32 values a texel instead of one a band.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CompactTexels {
    /// The decoding text (`specconvCompact`): the model and the rule.
    pub text: String,
    /// The level's width.
    pub width: usize,
    /// The level's height.
    pub height: usize,
    /// The file's MIP levels.
    pub levels: usize,
    /// X Y Z u₀ u₁ u₂ of each texel (the rule's six values, [`Compact::unstore`] of what the
    /// file stores), rows from the top as the file stores them.
    pub texels: Vec<f32>,
    /// Alpha (premultiplied, as the file's colour) per texel, when the file has `A`.
    pub alpha: Option<Vec<f32>>,
}

/// Reads MIP level `level` of the compact texture `input` into the texels alone (memory: the
/// texels, and the blocks being decompressed), its blocks decompressed in parallel by the
/// OpenEXR reader of `specconv_exr` (not OpenImageIO: a renderer's process need not load it).
pub fn read_texels(input: &Path, level: usize) -> Result<CompactTexels> {
    specconv_atomic_file::readable_file(input)?;
    specconv_exr::check::check_input(input)?;
    let unreadable = |e: specconv_exr::Error| Error::NotCompact {
        path: input.to_path_buf(),
        why: format!("it cannot be read as OpenEXR ({e})"),
    };
    let blocks = specconv_exr::blocks::ChannelBlocks::open(input, level).map_err(unreadable)?;
    let names: Vec<&str> = blocks.channels.iter().map(String::as_str).collect();
    let (layout, text) = layout_and_text(&blocks.attributes);
    let (compact, columns) = header(input, layout, text, &names)?;
    let alpha_column = names.iter().position(|n| *n == "A");
    let ((width, height), levels) = (blocks.size, blocks.levels);
    let mut texels = vec![0.0f32; width * height * TEXEL];
    let mut alpha = alpha_column.map(|_| vec![0.0f32; width * height]);
    let mut outside = false;
    blocks
        .read(|b| {
            let (bw, bh) = b.size;
            if b.at.0 + bw > width || b.at.1 + bh > height {
                outside = true; // a damaged file's block: refused below, never written past
                return;
            }
            for y in 0..bh {
                for x in 0..bw {
                    let (i, at) = (y * bw + x, (b.at.1 + y) * width + b.at.0 + x);
                    let stored = columns.map(|c| b.planes[c][i]);
                    compact.unstore(&stored, &mut texels[at * TEXEL..(at + 1) * TEXEL]);
                    if let (Some(a), Some(c)) = (alpha.as_mut(), alpha_column) {
                        a[at] = b.planes[c][i];
                    }
                }
            }
        })
        .map_err(unreadable)?;
    if outside {
        return Err(Error::NotCompact {
            path: input.to_path_buf(),
            why: format!("a block lies outside its {width}×{height} level: the file is damaged"),
        });
    }
    Ok(CompactTexels {
        text: compact.to_text(),
        width,
        height,
        levels,
        texels,
        alpha,
    })
}

/// A compact file opened: its reader and what decodes it.
struct Source {
    reader: ImageReader,
    d: Decoding,
}

/// A compact file's decoder, texel channels and settings.
struct Decoding {
    compact: Compact,
    /// Where R … UF.2 and alpha are among a pixel's channels.
    columns: [usize; STORED],
    alpha: Option<usize>,
    /// The storage settings (`specconvExpand`) and the rule on NaN and infinities the
    /// conversion recorded (`specconvSettings`' `non_finite`; refuse when none).
    options: Options,
}

/// Opens `input` as a compact texture.
fn open(input: &Path) -> Result<Source> {
    specconv_exr::check::check_input(input)?;
    let reader = ImageReader::open(input)?;
    let not = |why: String| Error::NotCompact {
        path: input.to_path_buf(),
        why,
    };
    let names: Vec<&str> = reader
        .info()
        .channels
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    let (layout, text) = text_attributes(input)?;
    let (compact, columns) = header(input, layout.as_deref(), text.as_deref(), &names)?;
    let mut options = Options::default();
    let recorded = reader
        .string_attribute(EXPAND_ATTRIBUTE)?
        .unwrap_or_default();
    for word in recorded.split_whitespace() {
        let (name, value) = word.split_once('=').unwrap_or((word, ""));
        if let Some(key) = Key::from_name(name).filter(|k| STORAGE_KEYS.contains(k)) {
            options
                .set(key, Some(value))
                .map_err(|e| not(e.to_string()))?;
        }
    }
    // The conversion's rule on NaN and infinities, applied to the texels as `convert` applies
    // it to its input's pixels (module `survey`).
    let tag = reader
        .string_attribute("specconvSettings")?
        .unwrap_or_default();
    let key = Key::NonFinite;
    if let Some(value) = setting(&tag, key.about().name) {
        options
            .set(key, Some(value))
            .map_err(|e| not(format!("specconvSettings: {e}")))?;
    }
    let d = Decoding {
        alpha: names.iter().position(|n| *n == "A"),
        compact,
        columns,
        options,
    };
    Ok(Source { reader, d })
}

/// The value of `name=` in a settings tag (`specconvSettings`): words separated by spaces, a
/// quoted value (Rust's `{:?}`, as the tag quotes one) read past its spaces and quotes, so
/// that no other value can pose as the word.
fn setting<'t>(tag: &'t str, name: &str) -> Option<&'t str> {
    let mut rest = tag.trim_start_matches(' ');
    while !rest.is_empty() {
        let (mut quoted, mut escaped, mut end) = (false, false, rest.len());
        for (i, c) in rest.char_indices() {
            match c {
                _ if escaped => escaped = false,
                '\\' if quoted => escaped = true,
                '"' => quoted = !quoted,
                ' ' if !quoted => {
                    end = i;
                    break;
                }
                _ => {}
            }
        }
        let value = rest[..end]
            .strip_prefix(name)
            .and_then(|w| w.strip_prefix('='));
        if value.is_some() {
            return value;
        }
        rest = rest[end..].trim_start_matches(' ');
    }
    None
}

/// The spectral file `source` expands to.
fn spec(source: &Source) -> Result<Spec> {
    let info = source.reader.info();
    let top = info.levels[0];
    let blocks = match top.tile {
        Some((width, height)) => Blocks::Tiles {
            width: width as usize,
            height: height as usize,
            mip_levels: info.levels.len() > 1,
        },
        None => Blocks::Scanlines,
    };
    let o = &source.d.options;
    Ok(Spec {
        width: top.width as usize,
        height: top.height as usize,
        windows: Some(windows_of(&top)),
        wavelengths: source.d.compact.grid().wavelengths(),
        kind: Kind::Reflective,
        alpha: source.d.alpha.is_some(),
        sample: o.sample,
        compression: o.compression.exr(),
        zip_level: o.zip_level.unwrap_or(specconv_exr::zip::DEFAULT_LEVEL),
        blocks,
        attributes: attributes(
            &source.reader,
            source.d.compact.grid().len() + usize::from(source.d.alpha.is_some()),
        )?,
        float_attributes: match (blocks, source.reader.numeric_attribute("fovcot")?) {
            (Blocks::Tiles { .. }, Some(v)) if !v.is_empty() => {
                vec![("fovcot".into(), v[0] as f32)]
            }
            _ => Vec::new(),
        },
    })
}

/// The attributes a conversion would have written: the compact file's own (provenance, the
/// texture's, the input's metadata) but the compact layout's, the tag without
/// `layout=compact`, and the average (and constant) colours' places, `values` long.
fn attributes(reader: &ImageReader, values: usize) -> Result<Vec<(String, String)>> {
    let placeholder = average_text(&vec![0.0; values]);
    let mut out = vec![(AVERAGE.to_string(), placeholder.clone())];
    // The input's metadata by a conversion's rule and bounds, each length before its value.
    let mut metadata = crate::metadata::Carry::default();
    for name in reader.string_attribute_names()? {
        let ours = name.starts_with("specconv")
            && ![LAYOUT_ATTRIBUTE, COMPACT_ATTRIBUTE, EXPAND_ATTRIBUTE].contains(&name.as_str());
        let texture = ["textureformat", "wrapmodes"].contains(&name.as_str());
        if !(ours || texture || name == CONSTANT) {
            let len = reader.string_attribute_len(name.as_bytes())?;
            if len.is_some_and(|len| metadata.admit(&name, len)) {
                if let Some(value) = reader.string_attribute_bytes(name.as_bytes())? {
                    metadata.push(name, &value, crate::metadata::Encoding::Utf8);
                }
            }
            continue;
        }
        let Some(value) = reader.string_attribute(&name)? else {
            continue;
        };
        if name == CONSTANT {
            out.push((name, placeholder.clone()));
        } else if name == "specconvSettings" {
            out.push((name, specconv_description::as_spectral(&value)));
        } else {
            out.push((name, value));
        }
    }
    out.extend(metadata.kept);
    Ok(out)
}

/// Expands the compact texture `input` into the spectral file `output` (see the module): NaN
/// and infinite texels by `fixnan`, else by the rule the conversion recorded (refuse when it
/// recorded none); `cancel` stops it between strips, leaving nothing.
pub fn expand(
    input: &Path,
    output: &Path,
    overwrite: bool,
    fixnan: Option<crate::NonFinite>,
    cancel: &AtomicBool,
) -> Result<Expanded> {
    refuse_overwrites(input, output, overwrite)?;
    let mut source = open(input)?;
    let file = SpectralFile::new(spec(&source)?)?;
    // One strip of the file's spectra at a time, refused with the figure when out of reach.
    let decoded = super::memory::Source::DecodedStrips {
        threads: rayon::current_num_threads(),
    };
    super::memory::check(super::memory::needed(&file, file.level_size(0).0, decoded))?;
    // NaN and infinities in the texels: refused, repaired or kept by the conversion's rule
    // (`--fixnan`, recorded), as `convert` treats its input's pixels, before anything is written.
    let asked = survey::Asked {
        non_finite: fixnan.unwrap_or(source.d.options.non_finite),
        input,
        cancel,
    };
    let read = (&source.d.columns[..], source.d.alpha);
    let repair = survey::survey(asked, &mut source.reader, read)?.repair;
    let pending = Pending::beside(output).map_err(|e| io(output, e))?;
    let n = file.spec().wavelengths.len();
    let level0 = file.level_size(0);
    let sums = Mutex::new(vec![0.0f64; file.values_per_pixel()]);
    let late = || {
        let pixels = (level0.0 * level0.1) as u64;
        average_attributes(&file, &sums.lock().expect("no panic holds it"), pixels)
    };
    let mut projected = 0;
    let out = std::io::BufWriter::with_capacity(1 << 20, pending.file());
    file.write_then(
        out,
        |sink| {
            let mut strips = Strips::new(&file, &source.d.options);
            for strip in std::mem::take(&mut strips.level0) {
                if cancel.load(Ordering::Relaxed) {
                    return Err(Error::Cancelled);
                }
                let rows = (strip.y as u32)..(strip.y + strip.height) as u32;
                let px = source.reader.read_scanlines(0, rows)?;
                let (values, u) = decode(&source.d, (&px, strip.y), &repair, n);
                projected += u;
                for (i, chunk, block_sums) in strips.level0_blocks(&source.d, &strip, &values)? {
                    let mut s = sums.lock().expect("no panic holds it");
                    s.iter_mut().zip(block_sums).for_each(|(s, b)| *s += b);
                    sink(i, chunk)?;
                }
                for (i, chunk) in strips.smaller(&source.d, &values, level0.0)? {
                    sink(i, chunk)?;
                }
            }
            Ok(())
        },
        late,
    )
    .map_err(|e| match e {
        Error::Output(e) => match e.into_io() {
            Ok(source) => io(output, specconv_atomic_file::explained(source)),
            Err(e) => Error::Output(e),
        },
        e => e,
    })?;
    if cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    pending
        .publish(Replace::when(overwrite))
        .map_err(|e| io(output, e))?;
    Ok(Expanded {
        width: level0.0,
        height: level0.1,
        levels: file.levels(),
        wavelengths: file.spec().wavelengths.clone(),
        projected,
    })
}

fn io(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The spectra (then alpha, per pixel) of the texels of a strip (`px`, from row `y0`),
/// repaired by `repair` where it repairs, row after row, and how many texels had u ≠ 0.
fn decode(
    source: &Decoding,
    (px, y0): (&Pixels, usize),
    repair: &Repair,
    n: usize,
) -> (Vec<f32>, u64) {
    let width = px.width as usize;
    let m = n + usize::from(source.alpha.is_some());
    let mut values = vec![0.0f32; width * px.height as usize * m];
    let read = (&source.columns[..], source.alpha);
    let projected = values
        .par_chunks_mut(width * m)
        .enumerate()
        .map(|(y, row)| {
            let mut stored = Vec::with_capacity(width * STORED);
            let mut alpha = Vec::with_capacity(width);
            for x in 0..width {
                let mut p = px.pixel(x as u32, y as u32);
                let fixed;
                if repair.fixes(p, read.0, read.1) {
                    fixed = repair.fixed(p, read, (x, y0 + y));
                    p = &fixed;
                }
                stored.extend(source.columns.map(|c| p[c]));
                alpha.extend(source.alpha.map(|a| p[a]));
            }
            let mut texels = vec![0.0f32; width * TEXEL];
            source.compact.unstore(&stored, &mut texels);
            let mut spectra = vec![0.0f32; width * n];
            source.compact.decode_f32(&texels, &mut spectra);
            for (x, (v, s)) in row
                .chunks_exact_mut(m)
                .zip(spectra.chunks_exact(n))
                .enumerate()
            {
                v[..n].copy_from_slice(s);
                if let Some(&a) = alpha.get(x) {
                    v[n] = a;
                }
            }
            texels
                .chunks_exact(TEXEL)
                .filter(|t| t[3..] != [0.0; 3])
                .count() as u64
        })
        .sum();
    (values, projected)
}

/// The file's blocks by strip, and what makes the smaller levels.
struct Strips<'f> {
    file: &'f SpectralFile,
    level0: Vec<Strip>,
    smaller: HashMap<(usize, usize), Vec<Block>>,
    cascade: Option<mip::Cascade>,
    filter: crate::Filter,
}

impl<'f> Strips<'f> {
    fn new(file: &'f SpectralFile, options: &Options) -> Strips<'f> {
        let (level0, smaller): (Vec<_>, Vec<_>) =
            strips(file).into_iter().partition(|s| s.level == 0);
        let sizes: Vec<_> = (0..file.levels()).map(|l| file.level_size(l)).collect();
        Strips {
            file,
            level0,
            smaller: smaller
                .into_iter()
                .map(|s| ((s.level, s.y), s.blocks))
                .collect(),
            cascade: (file.levels() > 1).then(|| {
                mip::Cascade::new(
                    &sizes,
                    file.block_height(),
                    file.values_per_pixel(),
                    options.filter,
                    false,
                )
            }),
            filter: options.filter,
        }
    }

    /// The chunks of a strip of level 0 (`values`: its rows) with their sums for the average.
    fn level0_blocks(
        &self,
        source: &Decoding,
        strip: &Strip,
        values: &[f32],
    ) -> Result<Vec<(usize, Chunk, Vec<f64>)>> {
        let width = self.file.level_size(0).0;
        strip
            .blocks
            .par_iter()
            .map(|b| {
                let (bands, alpha) = self.block_values(b, values, width);
                let n = self.file.spec().wavelengths.len();
                let sums = level_sums(&bands, alpha.as_deref(), n);
                let weights = self.weights(source);
                let (chunk, _) = finish(self.file, weights, n, b, bands, alpha.as_deref())?;
                Ok((b.chunk, chunk, sums))
            })
            .collect()
    }

    /// The chunks of the smaller levels' strips that level 0's next rows complete.
    fn smaller(
        &mut self,
        source: &Decoding,
        values: &[f32],
        width: usize,
    ) -> Result<Vec<(usize, Chunk)>> {
        let Some(cascade) = self.cascade.as_mut() else {
            return Ok(Vec::new());
        };
        let made = cascade.push(values, width);
        let n = self.file.spec().wavelengths.len();
        let range = if source.compact.clips() {
            (0.0, 1.0)
        } else {
            (0.0, f32::INFINITY)
        };
        made.par_iter()
            .flat_map(|strip| {
                self.smaller[&(strip.level, strip.y)]
                    .par_iter()
                    .map(move |b| (strip, b))
            })
            .map(|(strip, b)| {
                let (mut bands, mut alpha) = self.block_values(b, &strip.rows, strip.width);
                clamp_made(self.filter, range, &mut bands, alpha.as_deref_mut(), n);
                let weights = self.weights(source);
                let (chunk, _) = finish(self.file, weights, n, b, bands, alpha.as_deref())?;
                Ok((b.chunk, chunk))
            })
            .collect()
    }

    /// The weights half rounding keeps the colour under, when it does.
    fn weights<'s>(&self, source: &'s Decoding) -> Option<&'s [Vec<f64>; 3]> {
        (source.options.rounding_in_effect() == Rounding::Colour).then(|| source.compact.weights())
    }

    /// A block's bands and alpha from rows of `width` pixels (bands then alpha each) that
    /// start at the block's strip.
    fn block_values(&self, b: &Block, rows: &[f32], width: usize) -> (Vec<f32>, Option<Vec<f32>>) {
        let n = self.file.spec().wavelengths.len();
        let m = self.file.values_per_pixel();
        let mut bands = Vec::with_capacity(b.width * b.height * n);
        let mut alpha = self.file.spec().alpha.then(Vec::new);
        for y in 0..b.height {
            let row = (y * width + b.x) * m;
            for px in rows[row..row + b.width * m].chunks_exact(m) {
                bands.extend_from_slice(&px[..n]);
                if let Some(a) = alpha.as_mut() {
                    a.push(px[n]);
                }
            }
        }
        (bands, alpha)
    }
}
