//! Tiles and row bands read by several readers on several threads equal a whole-level read,
//! and arbitrary regions equal the same crop of the whole level.

use std::path::{Path, PathBuf};

use specconv_oiio::{ImageReader, Pixels, Region};

fn image(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testdata/images")
        .join(name)
}

/// Pastes `block` into `whole` at `(x0, y0)`.
fn paste(whole: &mut Pixels, block: &Pixels, x0: u32, y0: u32) {
    for y in 0..block.height {
        for x in 0..block.width {
            let dst =
                ((y0 + y) as usize * whole.width as usize + (x0 + x) as usize) * whole.channels;
            whole.data[dst..dst + whole.channels].copy_from_slice(block.pixel(x, y));
        }
    }
}

const WORKERS: u32 = 4;

#[test]
fn tiles_read_in_parallel_equal_a_whole_read() {
    for name in [
        "srgba8.tx",
        "float_alpha.tx",
        "half_tiled_alpha.exr",
        "float_tiled_alpha.exr",
    ] {
        let mut first = ImageReader::open(image(name)).unwrap();
        for (level, l) in first.info().levels.clone().into_iter().enumerate() {
            let whole = first.read_level(level).unwrap();
            let (nx, ny) = l.tile_count().expect("tiled");
            let (tw, th) = l.tile.unwrap();
            let tiles: Vec<(u32, u32)> = (0..ny)
                .flat_map(|ty| (0..nx).map(move |tx| (tx, ty)))
                .collect();
            let mut assembled = Pixels {
                data: vec![f32::NAN; whole.data.len()],
                ..whole.clone()
            };
            let blocks: Vec<_> = std::thread::scope(|s| {
                let handles: Vec<_> = (0..WORKERS)
                    .map(|w| {
                        let mut reader = first.reopen().unwrap();
                        let tiles = &tiles;
                        s.spawn(move || {
                            tiles
                                .iter()
                                .skip(w as usize)
                                .step_by(WORKERS as usize)
                                .map(|&(tx, ty)| (tx, ty, reader.read_tile(level, tx, ty).unwrap()))
                                .collect::<Vec<_>>()
                        })
                    })
                    .collect();
                handles
                    .into_iter()
                    .flat_map(|h| h.join().unwrap())
                    .collect()
            });
            assert_eq!(blocks.len(), tiles.len());
            for (tx, ty, block) in &blocks {
                paste(&mut assembled, block, tx * tw, ty * th);
            }
            // Bitwise, so NaN left unfilled would also fail.
            let same = assembled
                .data
                .iter()
                .zip(&whole.data)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(
                same,
                "{name} level {level}: tiles differ from the whole read"
            );
        }
    }
}

#[test]
fn row_bands_read_in_parallel_equal_a_whole_read() {
    for name in [
        "half_scanline.exr",
        "float_scanline.exr",
        "srgb8.png",
        "rgb16.tif",
        "photo.jpg",
        "sky.hdr",
        "srgba8.tx",
    ] {
        let mut first = ImageReader::open(image(name)).unwrap();
        let whole = first.read_level(0).unwrap();
        let h = whole.height;
        let band = h.div_ceil(WORKERS);
        let bands: Vec<Pixels> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..WORKERS)
                .map(|w| {
                    let mut reader = first.reopen().unwrap();
                    s.spawn(move || {
                        reader
                            .read_scanlines(0, w * band..((w + 1) * band).min(h))
                            .unwrap()
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        let joined: Vec<f32> = bands.iter().flat_map(|b| b.data.iter().copied()).collect();
        assert!(
            joined
                .iter()
                .zip(&whole.data)
                .all(|(a, b)| a.to_bits() == b.to_bits())
                && joined.len() == whole.data.len(),
            "{name}: row bands differ from the whole read"
        );
    }
}

#[test]
fn unaligned_regions_equal_the_crop_of_a_whole_read() {
    for name in ["float_tiled_alpha.exr", "half_scanline.exr", "srgba8.tx"] {
        let mut reader = ImageReader::open(image(name)).unwrap();
        let whole = reader.read_level(0).unwrap();
        for region in [
            Region {
                x0: 5,
                y0: 3,
                x1: 38,
                y1: 20,
            },
            Region {
                x0: 60,
                y0: 46,
                x1: 61,
                y1: 47,
            },
            Region {
                x0: 0,
                y0: 0,
                x1: 61,
                y1: 1,
            },
            Region {
                x0: 16,
                y0: 16,
                x1: 32,
                y1: 32,
            },
        ] {
            let got = reader.read_region(0, region).unwrap();
            assert_eq!(got, whole.crop(region), "{name} {region:?}");
        }
    }
}
