//! The conversion job on its own (no CLI): blocks written in the file order OpenEXR defines,
//! the input's data and display windows kept (an origin that is not 0, partial tiles), a
//! cancelled job leaving neither output nor temporary, and the same bytes on 1, 2 and 4
//! threads. The files are read back with the `exr` crate, an OpenEXR reader that is not ours;
//! the inputs are written by oiiotool.

use exr::block::chunk::CompressedBlock;
use exr::meta::attribute::IntegerBounds;
use exr::meta::BlockDescription;
use specconv_atomic_file::leftovers as leftover_temporaries;
use specconv_conversion::{Blocks, Compression, Converter, Error, Mip, Options, Report};
use specconv_testkit::cmd::{tool, Scratch};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// The input: noise of 520×330 pixels whose data window starts at (13, 7) inside a display
/// window of 560×360 at (−5, −4), so that 64×64 tiles end in partial ones (520 = 8·64 + 8,
/// 330 = 5·64 + 10) and a window of strips is less than the image on every thread count.
fn noise_input(dir: &Scratch) -> std::path::PathBuf {
    let input = dir.path("noise.exr");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "noise:type=uniform:min=0:max=1",
            "520x330",
            "3",
            "--origin",
            "+13+7",
            "--fullsize",
            "560x360-5-4",
            "-d",
            "half",
            "-o",
            input.to_str().unwrap(),
        ],
    );
    input
}

fn settings(tile: Option<(usize, usize)>, compression: Compression) -> Options {
    let mut o = Options::default();
    o.ocio = Some("aces".into());
    o.compression = compression;
    o.blocks = match tile {
        Some((w, h)) => Blocks::Tiles(w, h),
        None => Blocks::Scanlines,
    };
    o.mip = Mip::Base;
    o.overwrite = true;
    o
}

/// Converts `input` to `output` on a pool of `threads` threads with the CLI's default stack
/// (blended clusters, bounded reflectances); `progress` hears every window.
fn run(
    input: &Path,
    output: &Path,
    settings: &Options,
    threads: usize,
    cancel: &AtomicBool,
    progress: &mut (dyn FnMut(u64, u64) + Send),
) -> Result<Report, Error> {
    let mut options = settings.clone();
    options.threads = Some(threads);
    let converter = Converter::new(options).unwrap();
    converter.convert_with(input, output, cancel, progress)
}

fn converted(input: &Path, output: &Path, settings: &Options, threads: usize) -> Vec<(u64, u64)> {
    let mut heard = Vec::new();
    run(
        input,
        output,
        settings,
        threads,
        &AtomicBool::new(false),
        &mut |d, t| heard.push((d, t)),
    )
    .unwrap();
    heard
}

/// The chunks of a file in the order they stand in it, as the `exr` crate reads them (with
/// its checks of the offset table), each as (tile x, tile y, level x, level y): scanline
/// blocks as tile (0, block index), which is what OpenEXR's increasing-y order numbers.
fn chunks_in_file_order(path: &Path) -> (exr::meta::header::Header, Vec<[usize; 4]>) {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let reader = exr::block::read(file, true).unwrap();
    let header = reader.headers()[0].clone();
    let chunks = reader
        .all_chunks(true)
        .unwrap()
        .map(|c| match c.unwrap().compressed_block {
            CompressedBlock::ScanLine(b) => {
                let at = header
                    .get_scan_line_block_tile_coordinates(b.y_coordinate)
                    .unwrap();
                [at.tile_index.x(), at.tile_index.y(), 0, 0]
            }
            CompressedBlock::Tile(b) => {
                let (t, l) = (b.coordinates.tile_index, b.coordinates.level_index);
                [t.x(), t.y(), l.x(), l.y()]
            }
            other => panic!("a deep block: {other:?}"),
        })
        .collect();
    (header, chunks)
}

/// Chunks stand in the file in OpenEXR's increasing-y order (the order of the offset table,
/// level by level, row by row), every block once, and the progress grows to the total.
#[test]
fn blocks_are_written_in_file_order() {
    let dir = Scratch::new("pipeline-order");
    let input = noise_input(&dir);
    for (name, tile, compression) in [
        ("tiles.exr", Some((64, 64)), Compression::Zip),
        ("zip16.exr", None, Compression::Zip),
        ("zips.exr", None, Compression::Zips),
    ] {
        let output = dir.path(name);
        let heard = converted(&input, &output, &settings(tile, compression), 1);
        let (header, got) = chunks_in_file_order(&output);
        assert_eq!(
            header.line_order,
            exr::meta::attribute::LineOrder::Increasing
        );
        let want: Vec<[usize; 4]> = header
            .blocks_increasing_y_order()
            .map(|b| {
                let (t, l) = (b.location.tile_index, b.location.level_index);
                [t.x(), t.y(), l.x(), l.y()]
            })
            .collect();
        assert_eq!(got.len(), header.chunk_count, "{name}");
        assert_eq!(
            got, want,
            "{name}: the chunks are not in increasing-y order"
        );
        // Several windows, each reported once, in order, ending at every pixel.
        assert!(heard.len() > 2, "{name}: {heard:?}");
        assert!(heard.windows(2).all(|w| w[0].0 < w[1].0), "{heard:?}");
        assert_eq!(heard.last(), Some(&(520 * 330, 520 * 330)));
    }
}

/// The output keeps the input's data window (origin (13, 7), not 0) and display window, with
/// the last tiles of each row and column partial; the pixels are the same whatever the
/// blocks: 64×64 tiles, 24×20 tiles and scanlines agree sample for sample.
#[test]
fn windows_and_partial_tiles_are_kept() {
    let dir = Scratch::new("pipeline-window");
    let input = noise_input(&dir);
    let read = |path: &Path| exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    let source = read(&input);
    let display = source.attributes.display_window;
    assert_eq!(display, IntegerBounds::new((-5, -4), (560, 360)));
    let mut samples = Vec::new();
    for (name, tile) in [
        ("t64.exr", Some((64, 64))),
        ("t24x20.exr", Some((24, 20))),
        ("scan.exr", None),
    ] {
        let output = dir.path(name);
        converted(&input, &output, &settings(tile, Compression::Zip), 2);
        let image = read(&output);
        assert_eq!(image.layer_data.len(), 1);
        let layer = &image.layer_data[0];
        assert_eq!(image.attributes.display_window, display, "{name}");
        assert_eq!(
            layer.attributes.layer_position,
            exr::math::Vec2(13, 7),
            "{name}"
        );
        assert_eq!(layer.size, exr::math::Vec2(520, 330), "{name}");
        if let Some((w, h)) = tile {
            let header = chunks_in_file_order(&output).0;
            let BlockDescription::Tiles(t) = header.blocks else {
                panic!("{name} is not tiled")
            };
            assert_eq!(t.tile_size, exr::math::Vec2(w, h));
            assert_eq!(
                header.chunk_count,
                520usize.div_ceil(w) * 330usize.div_ceil(h)
            );
        }
        let channels: Vec<(String, Vec<f32>)> = layer
            .channel_data
            .list
            .iter()
            .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
            .collect();
        assert_eq!(channels.len(), 36, "{name}");
        assert!(channels.iter().all(|(_, v)| v.len() == 520 * 330));
        samples.push(channels);
    }
    assert!(
        samples[1] == samples[0],
        "24×20 tiles differ from 64×64 tiles"
    );
    assert!(
        samples[2] == samples[0],
        "scanlines differ from 64×64 tiles"
    );
}

/// A job cancelled before its first window or between windows returns `Cancelled` and leaves
/// neither the output nor a temporary file.
#[test]
fn cancelled_jobs_leave_nothing() {
    let dir = Scratch::new("pipeline-cancel");
    let input = noise_input(&dir);
    let output = dir.path("out.exr");
    for tile in [Some((64, 64)), None] {
        let s = settings(tile, Compression::Zip);
        let before = AtomicBool::new(true);
        let r = run(&input, &output, &s, 1, &before, &mut |_, _| {});
        assert!(r.as_ref().is_err_and(Error::is_cancelled), "{:?}", r.err());
        // Cancelled from the progress callback after the first window.
        let midway = AtomicBool::new(false);
        let mut windows = 0;
        let r = run(&input, &output, &s, 1, &midway, &mut |done, total| {
            windows += 1;
            assert!(done < total, "the job finished before it was cancelled");
            midway.store(true, Ordering::Relaxed);
        });
        assert!(r.as_ref().is_err_and(Error::is_cancelled), "{:?}", r.err());
        assert_eq!(windows, 1);
        assert!(!output.exists());
        assert!(leftover_temporaries(&output).is_empty());
        assert_eq!(dir.files(), vec!["noise.exr"]);
    }
}

/// The bytes written do not depend on the number of threads (the windows of strips do: their
/// size grows with it).
#[test]
fn the_bytes_do_not_depend_on_the_thread_count() {
    let dir = Scratch::new("pipeline-threads");
    let input = noise_input(&dir);
    for (tile, compression) in [
        (Some((64, 64)), Compression::Zip),
        (None, Compression::Zip),
        (None, Compression::Zips),
    ] {
        let s = settings(tile, compression);
        let bytes: Vec<Vec<u8>> = [1, 2, 4]
            .iter()
            .map(|&threads| {
                let output = dir.path(&format!("{threads}.exr"));
                converted(&input, &output, &s, threads);
                std::fs::read(&output).unwrap()
            })
            .collect();
        assert!(bytes[0].len() > 100_000);
        assert!(
            bytes[1] == bytes[0],
            "{tile:?} {compression:?}: 2 threads differ from 1"
        );
        assert!(
            bytes[2] == bytes[0],
            "{tile:?} {compression:?}: 4 threads differ from 1"
        );
    }
}
