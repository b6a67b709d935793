//! Deflate compressors and levels on real spectral tiles: which makes OpenEXR ZIP chunks no
//! larger than the `exr` crate's own (miniz_oxide, level 4) fastest.
//!
//! Reads the tiles of an uncompressed spectral EXR (by default the convert bench's
//! target/bench-data/out-none.exr: the photograph, 36-band half, level 0; or the path given),
//! applies OpenEXR's byte split and predictor to each (as `specconv_exr::zip` does), and
//! compresses the first half of the tiles with each compressor on one thread. Prints the size
//! as a fraction of the raw bytes (a chunk never larger than raw, as the format stores raw
//! bytes then) and MB/s of raw bytes. Run with `cargo bench -p specconv-exr --bench deflate`.

use std::time::Instant;

/// OpenEXR's ZIP preparation, written plainly (the reference for `specconv_exr::zip`).
fn predicted(raw: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(raw.len());
    let half = raw.len().div_ceil(2);
    let mut split = vec![0u8; raw.len()];
    for (i, &b) in raw.iter().enumerate() {
        if i % 2 == 0 {
            split[i / 2] = b
        } else {
            split[half + i / 2] = b
        }
    }
    let mut prev = split[0];
    out.push(prev);
    for &b in &split[1..] {
        out.push(b.wrapping_sub(prev).wrapping_add(128));
        prev = b;
    }
    out
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .filter(|a| !a.starts_with('-'))
        .unwrap_or_else(|| {
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../target/bench-data/out-none.exr"
            )
            .into()
        });
    let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    let reader = exr::block::read(file, false).unwrap();
    let tiles: Vec<Vec<u8>> = reader
        .all_chunks(false)
        .unwrap()
        .map(|c| match c.unwrap().compressed_block {
            exr::block::chunk::CompressedBlock::Tile(t) => t.compressed_pixels_le,
            exr::block::chunk::CompressedBlock::ScanLine(s) => s.compressed_pixels_le,
            _ => unreachable!(),
        })
        .collect();
    let tiles = &tiles[..tiles.len() / 2];
    let raw: usize = tiles.iter().map(Vec::len).sum();
    let pre: Vec<Vec<u8>> = tiles.iter().map(|t| predicted(t)).collect();
    let report = |name: &str, f: &mut dyn FnMut(&[u8]) -> usize| {
        let s = Instant::now();
        let size: usize = pre.iter().zip(tiles).map(|(p, t)| f(p).min(t.len())).sum();
        let secs = s.elapsed().as_secs_f64();
        println!(
            "{name:24} {:.4} {:7.1} MB/s",
            size as f64 / raw as f64,
            raw as f64 / secs / 1e6
        );
    };
    println!("{} tiles, {:.1} MB raw", tiles.len(), raw as f64 / 1e6);
    let mut out = vec![0u8; 1 << 20];
    for level in [1, 2, 3, 4, 5, 6, 9] {
        let mut c = libdeflater::Compressor::new(libdeflater::CompressionLvl::new(level).unwrap());
        report(&format!("libdeflate {level}"), &mut |p| {
            c.zlib_compress(p, &mut out).unwrap()
        });
    }
    use zlib_rs::{compress_slice, DeflateConfig, Strategy};
    for (level, strategy) in [
        (1, Strategy::Default),
        (2, Strategy::Default),
        (3, Strategy::Default),
        (4, Strategy::Default),
        (6, Strategy::Default),
        (4, Strategy::Rle),
        (4, Strategy::HuffmanOnly),
        (4, Strategy::Filtered),
    ] {
        let mut config = DeflateConfig::new(level);
        config.strategy = strategy;
        report(&format!("zlib-rs {level} {strategy:?}"), &mut |p| {
            compress_slice(&mut out, p, config).0.len()
        });
    }
    report("miniz_oxide 4", &mut |p| {
        miniz_oxide::deflate::compress_to_vec_zlib(p, 4).len()
    });
    let s = Instant::now();
    let ours: usize = tiles
        .iter()
        .map(|t| specconv_exr::zip::compress(t, specconv_exr::zip::DEFAULT_LEVEL).len())
        .sum();
    println!(
        "{:24} {:.4} {:7.1} MB/s (split, predictor and libdeflate {})",
        "specconv_exr::zip",
        ours as f64 / raw as f64,
        raw as f64 / s.elapsed().as_secs_f64() / 1e6,
        specconv_exr::zip::DEFAULT_LEVEL
    );
    println!(
        "(load {})",
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim()
    );
}
