//! OpenEXR's ZIP and ZIPS block compression, on libdeflate.
//!
//! The format is OpenEXR's (ImfZip.cpp; the `exr` crate's `compression::zip` writes the same):
//! the block's little-endian bytes are split into the even-indexed bytes followed by the
//! odd-indexed ones, every byte but the first becomes its difference to the previous one plus
//! 128, and the result is one zlib stream. A chunk whose stream would not be smaller than the
//! raw bytes stores the raw bytes, which readers recognise by their size.
//!
//! The `exr` crate compresses with miniz_oxide at level 4; libdeflate at the same level makes
//! slightly smaller chunks of spectral photographs at 2–3× the speed (docs/compression.md), so
//! blocks are compressed here and handed to the crate's block writer as finished chunks.

use std::cell::RefCell;

/// The deflate level used unless asked otherwise, chosen by measurement (docs/compression.md):
/// the fastest level whose files of the real textures are no larger than the `exr` crate's own
/// ZIP (level 2 is larger on the flower photograph; 3 is 15–18 % faster than 4 on both
/// photographs and the painted texture, for 0.4–1.3 % more bytes).
pub const DEFAULT_LEVEL: u8 = 3;

/// Levels run from 0 (stored, no compression) to 9 (smallest), as OpenEXR's
/// `zipCompressionLevel` (zlib's range).
pub const MAX_LEVEL: u8 = 9;

thread_local! {
    /// One compressor per level per thread: libdeflate's state is a few hundred KB, too much
    /// to allocate for every block.
    static COMPRESSORS: RefCell<Vec<Option<libdeflater::Compressor>>> =
        const { RefCell::new(Vec::new()) };
    /// The split and predicted bytes of the block being compressed and room for its stream,
    /// reused block after block.
    static SCRATCH: RefCell<(Vec<u8>, Vec<u8>, Vec<u8>)> =
        const { RefCell::new((Vec::new(), Vec::new(), Vec::new())) };
}

/// The bytes of a ZIP chunk holding `raw_le`, the block's uncompressed little-endian bytes:
/// the zlib stream of its predicted bytes, or `raw_le` itself when that is not smaller.
/// `level` above [`MAX_LEVEL`] is taken as [`MAX_LEVEL`].
pub fn compress(raw_le: &[u8], level: u8) -> Vec<u8> {
    compress_split(raw_le.len(), level, |evens, odds| {
        for (pair, (e, o)) in raw_le.chunks_exact(2).zip(evens.iter_mut().zip(odds)) {
            (*e, *o) = (pair[0], pair[1]);
        }
        if raw_le.len() % 2 == 1 {
            evens[evens.len() - 1] = raw_le[raw_le.len() - 1];
        }
    })
}

/// As [`compress`], for a block of `len` bytes that `split` writes already split: the
/// even-indexed bytes of its little-endian form into the first slice (⌈len/2⌉ bytes), the
/// odd-indexed ones into the second. Writers that place samples anyway place their bytes
/// straight into the halves, which saves a pass over the block.
pub fn compress_split(len: usize, level: u8, split: impl FnOnce(&mut [u8], &mut [u8])) -> Vec<u8> {
    if len == 0 {
        return Vec::new();
    }
    let level = level.min(MAX_LEVEL);
    SCRATCH.with(|scratch| {
        let (halves, predicted, out) = &mut *scratch.borrow_mut();
        halves.resize(len, 0);
        let (evens, odds) = halves.split_at_mut(len.div_ceil(2));
        split(evens, odds);
        // Each byte but the first minus the one before it, plus 128: a plain pass, which the
        // compiler vectorises.
        predicted.resize(len, 0);
        predicted[0] = halves[0];
        for ((p, &b), &a) in predicted[1..].iter_mut().zip(&halves[1..]).zip(&halves[..]) {
            *p = b.wrapping_sub(a).wrapping_add(128);
        }
        COMPRESSORS.with(|cell| {
            let mut compressors = cell.borrow_mut();
            if compressors.len() <= usize::from(level) {
                compressors.resize_with(usize::from(level) + 1, || None);
            }
            let compressor = compressors[usize::from(level)].get_or_insert_with(|| {
                libdeflater::Compressor::new(
                    libdeflater::CompressionLvl::new(i32::from(level)).expect("levels 0–9 exist"),
                )
            });
            // Room for the worst case, kept from block to block (zeroing it anew for every
            // block cost more than copying out the stream).
            let bound = compressor.zlib_compress_bound(len);
            if out.len() < bound {
                out.resize(bound, 0);
            }
            // The bound is what libdeflate promises to fit, so this cannot run out of space.
            let stream = compressor
                .zlib_compress(predicted, &mut out[..bound])
                .expect("output sized by zlib_compress_bound");
            if stream < len {
                return out[..stream].to_vec();
            }
            // Not smaller: the raw little-endian bytes, interleaved back.
            let (evens, odds) = halves.split_at(len.div_ceil(2));
            let mut raw = Vec::with_capacity(len);
            for (e, o) in evens.iter().zip(odds) {
                raw.extend_from_slice(&[*e, *o]);
            }
            if len % 2 == 1 {
                raw.push(evens[evens.len() - 1]);
            }
            raw
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Undoes the format with an independent inflater (miniz_oxide, which the `exr` crate
    /// reads with too): zlib, then the predictor, then the byte split.
    fn decompress(chunk: &[u8], len: usize) -> Vec<u8> {
        if chunk.len() == len {
            return chunk.to_vec();
        }
        let mut p = miniz_oxide::inflate::decompress_to_vec_zlib(chunk).unwrap();
        for i in 1..p.len() {
            p[i] = p[i - 1].wrapping_add(p[i]).wrapping_sub(128);
        }
        let half = p.len().div_ceil(2);
        (0..len)
            .map(|i| {
                if i % 2 == 0 {
                    p[i / 2]
                } else {
                    p[half + i / 2]
                }
            })
            .collect()
    }

    #[test]
    fn chunks_inflate_to_the_raw_bytes_at_every_level() {
        let smooth: Vec<u8> = (0..3001u32).map(|i| (i / 7) as u8).collect();
        let mut state = 12345u32;
        let noise: Vec<u8> = (0..3000)
            .map(|_| {
                state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
                (state >> 16) as u8
            })
            .collect();
        for raw in [vec![7u8], vec![1, 2], vec![0; 4096], smooth, noise.clone()] {
            for level in 0..=MAX_LEVEL + 1 {
                let chunk = compress(&raw, level);
                assert!(chunk.len() <= raw.len());
                assert_eq!(decompress(&chunk, raw.len()), raw, "level {level}");
            }
        }
        // Incompressible bytes are stored as they are; compressible ones are not.
        assert_eq!(compress(&noise, DEFAULT_LEVEL), noise);
        assert!(compress(&[0; 4096], DEFAULT_LEVEL).len() < 100);
        assert!(compress(&[], DEFAULT_LEVEL).is_empty());
    }
}
