//! The default conversion's cost, against references measured in the same run.
//!
//! Converts a 2048×2048 8-bit .tx of a real photograph (scripts/bench_textures.sh makes it
//! from a photo shipped with the `image` crate) with the CLI's default stack (otsu2018, blended,
//! bounded) to a 36-band half ZIP EXR of level 0, on 1 and 2 threads, and times in the same run:
//! - the same conversion with `--compression none`;
//! - the encode alone: the same spectra, computed beforehand and held in memory, encoded and
//!   written in the same layout, with our ZIP (libdeflate) and with the `exr` crate's own ZIP
//!   (miniz_oxide), which is what the conversion used before;
//! - `oiiotool OUT.exr --compression zip -o …`: OpenImageIO re-encoding the same output;
//! - the whole default conversion with every MIP level (filtered from level 0's spectra).
//!
//! Prints medians of three, the ratios the project tracks and the file sizes. Run with
//! `cargo bench -p specconv-conversion --bench convert`; the machine's load is the reader's to
//! report (ratios are what carries over).

use exr::block::{BlockIndex, UncompressedBlock};
use exr::math::Vec2;
use rayon::prelude::*;
use specconv_conversion::{Converter, Mip, Options};
use specconv_exr::{Block, Blocks, Chunk, Compression, Kind, Sample, Spec, SpectralFile};
use specconv_spectral::baselines::jakob_cache::TableCache;
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::{Stack, StackSpec};
use specconv_spectral::Model;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

fn texture(dir: &Path) -> PathBuf {
    let tx = dir.join("photo.tx");
    if !tx.exists() {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/bench_textures.sh");
        let ok = Command::new(script)
            .arg(dir)
            .status()
            .expect("scripts/bench_textures.sh runs (oiiotool and maketx installed)");
        assert!(ok.success(), "scripts/bench_textures.sh failed");
    }
    tx
}

fn median(mut f: impl FnMut() -> f64) -> f64 {
    let mut t: Vec<f64> = (0..3).map(|_| f()).collect();
    t.sort_by(f64::total_cmp);
    t[1]
}

/// Seconds that `f` takes to write `out`, which is removed first (untimed): replacing a large
/// file costs the writer the freeing of the old one (0.8 s for oiiotool over 150 MB here).
fn timed(out: &Path, f: impl FnOnce()) -> f64 {
    let _ = std::fs::remove_file(out);
    let s = Instant::now();
    f();
    s.elapsed().as_secs_f64()
}

fn size(p: &Path) -> f64 {
    std::fs::metadata(p).unwrap().len() as f64 / (1 << 20) as f64
}

/// Writes `chunks` (one per block, in chunk order) as `file` to `path`, compressing a window
/// of blocks in parallel and writing in order, as the pipeline does.
fn write_all(
    file: &SpectralFile,
    path: &Path,
    blocks: &[Block],
    encode: &(dyn Fn(usize) -> Chunk + Sync),
) {
    let out = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path).unwrap());
    let window = rayon::current_num_threads() * 8;
    file.write(out, |sink| {
        for start in (0..blocks.len()).step_by(window) {
            let end = (start + window).min(blocks.len());
            let chunks: Vec<Chunk> = (start..end).into_par_iter().map(encode).collect();
            for (i, c) in (start..end).zip(chunks) {
                sink(blocks[i].chunk, c)?;
            }
        }
        Ok(())
    })
    .unwrap();
}

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/bench-data");
    std::fs::create_dir_all(&dir).unwrap();
    let input = texture(&dir);
    let config = specconv_ocio::Config::resolve(Some("aces")).unwrap();
    let model = Model::builtin();
    // The CLI's default stack, built as convert builds it (blended, corrected onto the
    // readers' integration, bounded).
    let default = StackSpec::convert_default(MethodName::Otsu2018);
    let stack = Stack::build(&default, model, &TableCache::none()).unwrap();
    let method = stack.method();
    // The conversion as every front-end runs it, on the pool the caller installs.
    let converter = |compression, mip| {
        let mut o = Options::default();
        o.ocio = Some("aces".into());
        o.compression = compression;
        o.mip = mip;
        o.overwrite = true;
        Converter::new(o).unwrap()
    };
    let zip = converter(specconv_conversion::Compression::Zip, Mip::Base);
    let none = converter(specconv_conversion::Compression::None, Mip::Base);
    let zip_mip = converter(specconv_conversion::Compression::Zip, Mip::All);
    let run = |converter: &Converter, output: &Path| {
        converter.convert(&input, output).unwrap();
    };

    // The encode's input: every block's spectra, as the conversion computes them.
    let spec = |compression| Spec {
        width: 2048,
        height: 2048,
        windows: None,
        wavelengths: method.grid().wavelengths(),
        kind: Kind::Reflective,
        alpha: false,
        sample: Sample::Half,
        compression,
        zip_level: specconv_exr::zip::DEFAULT_LEVEL,
        blocks: Blocks::Tiles {
            width: 64,
            height: 64,
            mip_levels: false,
        },
        attributes: vec![],
        float_attributes: vec![],
    };
    let ours = SpectralFile::new(spec(Compression::ZIP16)).unwrap();
    let raw = SpectralFile::new(spec(Compression::Uncompressed)).unwrap();
    let blocks = ours.blocks();
    let spectra: Vec<Vec<f32>> = {
        let mut reader = specconv_oiio::ImageReader::open(&input).unwrap();
        let processor = config.processor_to_xyz("sRGB - Texture").unwrap();
        let px = reader.read_level(0).unwrap();
        blocks
            .par_iter()
            .map(|b| {
                let mut rgb: Vec<f32> = (b.y..b.y + b.height)
                    .flat_map(|y| {
                        (b.x..b.x + b.width)
                            .flat_map(|x| px.pixel(x as u32, y as u32)[..3].to_vec())
                            .collect::<Vec<_>>()
                    })
                    .collect();
                processor.apply_rgb(&mut rgb).unwrap();
                let mut out = vec![0.0; b.width * b.height * 36];
                method.uplift_f32(&rgb, &mut out);
                out
            })
            .collect()
    };
    // The exr crate's own ZIP of the same bytes: the uncompressed block, compressed by it.
    let exr_zip = |i: usize| -> Chunk {
        let b = &blocks[i];
        let data = match raw.encode(b, &spectra[i], None).unwrap().compressed_block {
            exr::block::chunk::CompressedBlock::Tile(t) => t.compressed_pixels_le,
            _ => unreachable!("tiled file"),
        };
        let block = UncompressedBlock {
            index: BlockIndex {
                layer: 0,
                pixel_position: Vec2(b.x, b.y),
                pixel_size: Vec2(b.width, b.height),
                level: Vec2(0, 0),
            },
            data,
        };
        block
            .compress_to_chunk(std::slice::from_ref(ours.header()))
            .unwrap()
    };

    let path = |name: &str| dir.join(name);
    let mut zip_times = Vec::new();
    for n in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap();
        pool.install(|| {
            let t_zip = median(|| timed(&path("out.exr"), || run(&zip, &path("out.exr"))));
            let t_none = median(|| {
                timed(&path("out-none.exr"), || {
                    run(&none, &path("out-none.exr"))
                })
            });
            let t_encode = median(|| {
                timed(&path("encode.exr"), || {
                    write_all(&ours, &path("encode.exr"), &blocks, &|i| {
                        ours.encode(&blocks[i], &spectra[i], None).unwrap()
                    })
                })
            });
            let t_exr = median(|| {
                timed(&path("exr.exr"), || {
                    write_all(&ours, &path("exr.exr"), &blocks, &exr_zip)
                })
            });
            let t_oiio = median(|| {
                timed(&path("oiio.exr"), || {
                    let ok = Command::new("oiiotool")
                        .args(["--threads", &n.to_string()])
                        .arg(path("out.exr"))
                        .args(["--compression", "zip", "-o"])
                        .arg(path("oiio.exr"))
                        .status()
                        .expect("oiiotool installed");
                    assert!(ok.success());
                })
            });
            let t_mip = median(|| {
                timed(&path("out-mip.exr"), || {
                    run(&zip_mip, &path("out-mip.exr"))
                })
            });
            println!(
                "threads {n}: default conversion of photo.tx (2048², level 0, ZIP) {t_zip:.3} s; \
                 --compression none {t_none:.3} s ({:.2}×); encode alone {t_encode:.3} s, with the exr crate's ZIP {t_exr:.3} s ({:.2}× ours); \
                 oiiotool's ZIP re-encode of the output {t_oiio:.3} s (conversion {:.2}× it); every MIP level {t_mip:.3} s ({:.2}× level 0 alone)",
                t_zip / t_none,
                t_exr / t_encode,
                t_zip / t_oiio,
                t_mip / t_zip,
            );
            zip_times.push((t_zip, t_none, t_mip));
        });
    }
    println!(
        "speed-up from 1 to 2 threads: {:.2}× (none {:.2}×, every MIP level {:.2}×)",
        zip_times[0].0 / zip_times[1].0,
        zip_times[0].1 / zip_times[1].1,
        zip_times[0].2 / zip_times[1].2
    );
    println!(
        "sizes (MiB): ours {:.1} (encode alone {:.1}), exr crate's ZIP {:.1}, oiiotool's ZIP {:.1}, none {:.1}",
        size(&path("out.exr")),
        size(&path("encode.exr")),
        size(&path("exr.exr")),
        size(&path("oiio.exr")),
        size(&path("out-none.exr"))
    );
}
