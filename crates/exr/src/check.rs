//! Whether an OpenEXR file can hold what its header promises, checked before any pixel is read:
//! a damaged header (a data window of 262661×15105 in a 1.4 KB file) or a truncated file then
//! fails at once, instead of after seconds of decoding into gigabytes of buffers.
//!
//! By the OpenEXR file layout (openexr.com, "OpenEXR File Layout"): the header(s) come first,
//! then one offset table per part (a u64 per chunk), then the chunks; each chunk starts with its
//! part number (multi-part files), its y coordinate (scanline blocks) or four tile coordinates,
//! and its data size. So a file holds at least the headers, 8 bytes per chunk of offset table
//! and 8 (scanlines) or 20 (tiles) bytes per chunk, and every offset (but zeros: a table never
//! filled in) points past the tables and inside the file. A chunk's data is never larger than its pixels (OpenEXR stores a chunk
//! uncompressed when compression would not pay), so an uncompressed part holds all its pixel
//! bytes; deflate (ZIP, ZIPS) shrinks at most 1032:1 (RFC 1951: a 258-byte match in at least
//! 2 bits), so a ZIP part holds at least 1/1032 of them.

use exr::compression::Compression;
use exr::meta::{BlockDescription, MetaData};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// What is wrong with a file, or that it could not be read.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    /// The file cannot hold what its header promises (too short for its chunks, or an offset
    /// outside it): damaged or truncated.
    #[error("{}: {message}", path.display())]
    Damaged {
        /// The file checked.
        path: std::path::PathBuf,
        /// What the header promises and what the file holds.
        message: String,
    },
    /// The file could not be opened or read.
    #[error("cannot read {}", path.display())]
    Io {
        /// The file that could not be read.
        path: std::path::PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// The deflate bound: at most 1032 bytes out per byte in.
const DEFLATE_MAX_RATIO: u128 = 1032;

/// Checks that `path`, if it is an OpenEXR file, is large enough for its header's promises and
/// that its offset tables point inside it. Other files, and headers this reader cannot parse
/// (OpenImageIO reports those), pass. Reads the headers and the offset tables only, streaming.
pub fn check_input(path: &Path) -> Result<(), Problem> {
    let io = |source| Problem::Io {
        path: path.to_path_buf(),
        source,
    };
    let damaged = |message: String| Problem::Damaged {
        path: path.to_path_buf(),
        message,
    };
    // A file that cannot be opened (or is no regular file) is the image reader's to report.
    let Ok(mut file) = specconv_atomic_file::open_file(path) else {
        return Ok(());
    };
    let len = u128::from(file.metadata().map_err(io)?.len());
    let mut magic = [0u8; 4];
    if file.read_exact(&mut magic).is_err() || magic != [0x76, 0x2f, 0x31, 0x01] {
        return Ok(());
    }
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    let mut counted = Counted {
        inner: BufReader::new(file),
        position: 0,
        ended: false,
    };
    let meta = match MetaData::read_from_buffered(&mut counted, false) {
        Ok(meta) => meta,
        Err(_) if counted.ended => {
            return Err(damaged(format!(
                "the file ends inside its OpenEXR header ({len} bytes): it is truncated"
            )))
        }
        Err(_) => return Ok(()),
    };
    let headers_end = u128::from(counted.position);
    let multipart = meta.headers.len() > 1;

    let mut chunks: u128 = 0;
    let mut least: u128 = headers_end;
    for h in &meta.headers {
        let n = h.chunk_count as u128;
        chunks += n;
        let chunk_header = match h.blocks {
            BlockDescription::ScanLines => 8,
            BlockDescription::Tiles(_) => 20,
        } + if multipart { 4 } else { 0 };
        least += n * (8 + chunk_header);
        if h.deep
            || h.channels
                .list
                .iter()
                .any(|c| c.sampling.x() == 0 || c.sampling.y() == 0)
        {
            continue;
        }
        // Level 0's pixel bytes: a lower bound of the part's (MIP levels add more).
        let pixels: u128 = h
            .channels
            .list
            .iter()
            .map(|c| {
                let size = c.subsampled_resolution(h.layer_size);
                size.x() as u128 * size.y() as u128 * c.sample_type.bytes_per_sample() as u128
            })
            .sum();
        least += match h.compression {
            Compression::Uncompressed => pixels,
            Compression::ZIP1 | Compression::ZIP16 => pixels / DEFLATE_MAX_RATIO,
            _ => 0,
        };
    }
    if least > len {
        let size = meta.headers.first().map_or_else(String::new, |h| {
            format!("{}×{} pixels in ", h.layer_size.x(), h.layer_size.y())
        });
        return Err(damaged(format!(
            "its header promises {size}{chunks} chunks, which need at least {least} bytes, but the \
             file has {len}: the header is damaged or the file truncated"
        )));
    }

    // The tables fit in the file (checked above); stream through them.
    let tables_end = headers_end + 8 * chunks;
    let mut table = counted.inner;
    let mut entry = [0u8; 8];
    for index in 0..chunks {
        table.read_exact(&mut entry).map_err(io)?;
        let offset = u128::from(u64::from_le_bytes(entry));
        // A zero is a table never filled in (OpenImageIO's MIP-map writer leaves them); the
        // OpenEXR library then finds the chunks by reading them in order.
        if offset != 0 && (offset < tables_end || offset + 8 > len) {
            return Err(damaged(format!(
                "chunk {index} of {chunks} is said to start at byte {offset}, outside the file's \
                 chunks (bytes {tables_end} to {len}): the file is truncated or damaged"
            )));
        }
    }
    Ok(())
}

/// As [`check_input`], and the file is whole: every chunk ends inside it. A file cut short
/// inside its last chunk passes [`check_input`] (its offsets still point inside it); here the
/// chunk that starts last is read and must end within the file, or, where offset tables were
/// left unfilled (OpenImageIO's MIP-map writer), every chunk is walked in order. What `-u`
/// asks of an output before it counts as up to date.
pub fn check_complete(path: &Path) -> Result<(), Problem> {
    check_input(path)?;
    let io = |source| Problem::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = specconv_atomic_file::open_file(path).map_err(|e| io(e.into_io()))?;
    let len = file.metadata().map_err(io)?.len();
    let mut counted = Counted {
        inner: BufReader::new(&mut file),
        position: 0,
        ended: false,
    };
    let Ok(meta) = MetaData::read_from_buffered(&mut counted, false) else {
        return Ok(());
    };
    let (tables_start, mut table) = (counted.position, counted.inner);
    let mut offsets = Vec::new();
    for (part, h) in meta.headers.iter().enumerate() {
        for _ in 0..h.chunk_count {
            let mut entry = [0u8; 8];
            table.read_exact(&mut entry).map_err(io)?;
            offsets.push((u64::from_le_bytes(entry), part));
        }
    }
    drop(table);
    let tables_end = tables_start + 8 * offsets.len() as u64;
    let mut chunk = Chunks {
        file: &mut file,
        meta: &meta,
    };
    let end = if offsets.iter().any(|&(o, _)| o == 0) {
        chunk.walk(tables_end, offsets.len())
    } else {
        match offsets.iter().max() {
            Some(&(offset, part)) => chunk.end_of(offset, Some(part)),
            None => Ok(Some(tables_end)),
        }
    };
    match end.map_err(io)? {
        Some(end) if end > len => Err(Problem::Damaged {
            path: path.to_path_buf(),
            message: format!(
                "its chunks end at byte {end}, but the file has {len}: it is truncated"
            ),
        }),
        _ => Ok(()),
    }
}

/// The chunks of an OpenEXR file, read by their headers (not their pixels).
struct Chunks<'a> {
    file: &'a mut File,
    meta: &'a MetaData,
}

impl Chunks<'_> {
    /// Where the chunk at `offset` ends (its header says how many bytes it holds); `None` for
    /// a deep part, whose chunks this does not measure. `part` is known from the offset table,
    /// else read from the chunk (multi-part files).
    fn end_of(&mut self, offset: u64, part: Option<usize>) -> std::io::Result<Option<u64>> {
        let multipart = self.meta.headers.len() > 1;
        self.file.seek(SeekFrom::Start(offset))?;
        let mut word = [0u8; 4];
        let mut header = 0u64;
        let mut part = part.unwrap_or(0);
        if multipart {
            self.file.read_exact(&mut word)?;
            part = u32::from_le_bytes(word) as usize;
            header += 4;
        }
        let Some(h) = self.meta.headers.get(part).filter(|h| !h.deep) else {
            return Ok(None);
        };
        // Scanlines: y, then the size; tiles: four coordinates, then the size.
        let before = match h.blocks {
            BlockDescription::ScanLines => 4,
            BlockDescription::Tiles(_) => 16,
        };
        self.file.seek(SeekFrom::Current(before))?;
        header += before as u64 + 4;
        if self.file.read_exact(&mut word).is_err() {
            // The size itself is cut off: the chunk ends past the file.
            return Ok(Some(u64::MAX));
        }
        Ok(Some(offset + header + u64::from(u32::from_le_bytes(word))))
    }

    /// Where the last of `count` chunks stored one after another from `start` ends.
    fn walk(mut self, start: u64, count: usize) -> std::io::Result<Option<u64>> {
        let mut at = start;
        for _ in 0..count {
            match self.end_of(at, None)? {
                Some(u64::MAX) => return Ok(Some(u64::MAX)),
                Some(end) => at = end,
                None => return Ok(None),
            }
        }
        Ok(Some(at))
    }
}

/// Counts the bytes the header parser takes, to know where the offset tables begin.
struct Counted<R> {
    inner: R,
    position: u64,
    ended: bool,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.ended |= n == 0 && !buf.is_empty();
        self.position += n as u64;
        Ok(n)
    }
}
