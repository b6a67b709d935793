//! The conversion's cost against the `exr` crate alone, measured in the same run.
//!
//! Converts a 2048×2048 8-bit .tx (made here with oiiotool and maketx) to a 36-band half ZIP
//! EXR with every MIP level, at 1 and 2 threads (and all cores), and times the reference: the
//! exr crate encoding and writing the very same spectra (computed beforehand and held in
//! memory) in the same file layout with the same threads. Prints end-to-end time, reference
//! time, their ratio and the thread speed-up. Run with `cargo bench -p specconv-pipeline`.

use rayon::prelude::*;
use specconv_exr::{Blocks, Compression, Kind, Sample, Spec, SpectralFile};
use specconv_pipeline::{convert, Job, Mip, Settings};
use specconv_spectral::{Method, Model, Uplifter};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn texture(dir: &Path) -> PathBuf {
    let tx = dir.join("noise2048.tx");
    if !tx.exists() {
        let tif = dir.join("noise2048.tif");
        let ok =
            |c: &mut Command| assert!(c.status().expect("oiiotool and maketx installed").success());
        ok(Command::new("oiiotool")
            .args([
                "--pattern",
                "noise:type=uniform:min=0:max=1",
                "2048x2048",
                "3",
                "-d",
                "uint8",
                "-o",
            ])
            .arg(&tif));
        ok(Command::new("maketx")
            .arg(&tif)
            .args(["--colorconvert", "sRGB", "sRGB", "-o"])
            .arg(&tx));
    }
    tx
}

fn median(mut f: impl FnMut() -> f64) -> f64 {
    let mut t: Vec<f64> = (0..3).map(|_| f()).collect();
    t.sort_by(f64::total_cmp);
    t[1]
}

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/bench-data");
    std::fs::create_dir_all(&dir).unwrap();
    let input = texture(&dir);
    let output = dir.join("out.exr");
    let config = specconv_ocio::Config::resolve(Some("aces")).unwrap();
    let model = Model::builtin();
    let method = Uplifter::new(model).unwrap();
    let settings = Settings {
        kind: Kind::Reflective,
        xyz_weights: None,
        colorspace: None,
        input: Default::default(),
        sample: Sample::Half,
        compression: Compression::ZIP16,
        tile: Some((64, 64)),
        mip: Mip::All,
        overwrite: true,
        attributes: vec![],
    };
    let cancel = AtomicBool::new(false);

    // The reference's pixels: every block's spectra, as the conversion computes them.
    let mut reader = specconv_oiio::ImageReader::open(&input).unwrap();
    let processor = config.processor_to_xyz("sRGB - Texture").unwrap();
    let file = SpectralFile::new(Spec {
        width: 2048,
        height: 2048,
        windows: None,
        wavelengths: method.grid().wavelengths(),
        kind: Kind::Reflective,
        alpha: false,
        sample: Sample::Half,
        compression: Compression::ZIP16,
        blocks: Blocks::Tiles {
            width: 64,
            height: 64,
            mip_levels: true,
        },
        attributes: vec![],
    })
    .unwrap();
    let levels: Vec<specconv_oiio::Pixels> = (0..file.levels())
        .map(|l| reader.read_level(l).unwrap())
        .collect();
    let blocks = file.blocks();
    let spectra: Vec<Vec<f32>> = blocks
        .par_iter()
        .map(|b| {
            let px = &levels[b.level];
            let mut rgb: Vec<f32> = (b.y..b.y + b.height)
                .flat_map(|y| {
                    (b.x..b.x + b.width)
                        .flat_map(move |x| px.pixel(x as u32, y as u32)[..3].to_vec())
                })
                .collect();
            processor.apply_rgb(&mut rgb).unwrap();
            let mut out = vec![0.0; b.width * b.height * 36];
            method.uplift_f32(&rgb, &mut out);
            out
        })
        .collect();
    drop(levels);

    let mut results = Vec::new();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut threads = vec![1, 2];
    if cores > 2 {
        threads.push(cores);
    }
    for &n in &threads {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap();
        let end_to_end = median(|| {
            pool.install(|| {
                let s = Instant::now();
                let job = Job {
                    input: &input,
                    output: &output,
                    config: &config,
                    method: &method,
                    settings: &settings,
                    cancel: &cancel,
                };
                convert(&job, &mut |_, _| {}).unwrap();
                s.elapsed().as_secs_f64()
            })
        });
        let reference = median(|| {
            pool.install(|| {
                let s = Instant::now();
                let out = std::io::BufWriter::with_capacity(
                    1 << 20,
                    std::fs::File::create(dir.join("ref.exr")).unwrap(),
                );
                file.write(out, |sink| {
                    // Same window size as the pipeline: compress a window in parallel, write in order.
                    for (window, data) in blocks.chunks(n * 8).zip(spectra.chunks(n * 8)) {
                        let chunks: Vec<_> = window
                            .par_iter()
                            .zip(data)
                            .map(|(b, d)| file.encode(b, d, None))
                            .collect();
                        for (b, c) in window.iter().zip(chunks) {
                            sink(b.chunk, c?)?;
                        }
                    }
                    Ok(())
                })
                .unwrap();
                s.elapsed().as_secs_f64()
            })
        });
        println!(
            "threads {n}: convert 2048×2048 8-bit .tx → 36-band half ZIP EXR with MIP levels {:.3} s; exr crate alone {:.3} s; ratio {:.2}",
            end_to_end,
            reference,
            end_to_end / reference
        );
        results.push((n, end_to_end));
    }
    println!(
        "speed-up from 1 to 2 threads: {:.2}×",
        results[0].1 / results[1].1
    );
    if let Some(&(n, t)) = results.get(2) {
        println!("speed-up from 1 to {n} threads: {:.2}×", results[0].1 / t);
    }
}
