//! Our ZIP and ZIPS blocks (specconv_exr::zip, on libdeflate) read back by OpenEXR itself:
//! edge cases written with the library's writer, opened with exrheader and decoded sample by
//! sample through OpenImageIO's Python bindings (OpenEXR's decoder), bit for bit.

use crate::runner::*;
use specconv_exr::{Blocks, Compression, Kind, Sample, Spec, SpectralFile};
use std::path::{Path, PathBuf};

/// Every sample of every channel of level 0 of each file, as OpenImageIO decodes it: one JSON
/// object per file, channel name → bit patterns (u16 for half, u32 for float), row by row.
fn oiio_bits(paths: &[PathBuf]) -> Vec<serde_json::Value> {
    const SCRIPT: &str = r#"
import json, sys
import OpenImageIO as oiio
out = []
for path in sys.argv[1:]:
    i = oiio.ImageInput.open(path)
    assert i is not None, oiio.geterror()
    spec = i.spec()
    half = spec.format == oiio.HALF
    pixels = i.read_image(spec.format)
    assert pixels is not None, oiio.geterror()
    bits = pixels.view("uint16" if half else "uint32").reshape(-1, spec.nchannels)
    out.append({n: [int(v) for v in bits[:, c]] for c, n in enumerate(spec.channelnames)})
print(json.dumps(out))
"#;
    let mut args = vec![std::ffi::OsString::from("-c"), SCRIPT.into()];
    args.extend(paths.iter().map(|p| p.clone().into_os_string()));
    serde_json::from_slice(&python_output(args)).unwrap()
}

/// A pseudo-random stream (xorshift), so that noise is the same on every run.
fn noise(n: usize, seed: u32) -> impl Iterator<Item = u32> {
    let mut s = seed;
    (0..n).map(move |_| {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s
    })
}

/// One edge case: a size and band values per pixel (3 bands).
struct Case {
    name: &'static str,
    width: usize,
    height: usize,
    values: Vec<f32>,
}

/// The value of a half given by its bits.
fn half_bits(bits: u16) -> f32 {
    half::f16::from_bits(bits).to_f32()
}

fn cases(sample: Sample) -> Vec<Case> {
    let specials: Vec<f32> = vec![
        65504.0,
        -65504.0,
        half_bits(0x0001), // the least subnormal half, 2⁻²⁴
        half_bits(0x03ff), // the greatest subnormal half, 1023 × 2⁻²⁴
        half_bits(0x0400), // the least normal half, 2⁻¹⁴
        half_bits(0x8001),
        -0.0,
        0.0,
        1.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MIN_POSITIVE, // a float subnormal's neighbour; 0 in half
        1.0e-40,           // a float subnormal
        f32::MAX,
    ];
    let random = |w: usize, h: usize| -> Vec<f32> {
        noise(w * h * 3, 99)
            .map(|r| match sample {
                // Any finite half: its 16 bits are noise.
                Sample::Half => {
                    let bits = (r >> 8) as u16;
                    let h = half::f16::from_bits(if bits & 0x7c00 == 0x7c00 {
                        bits & 0xbfff
                    } else {
                        bits
                    });
                    h.to_f32()
                }
                Sample::Float => f32::from_bits(r & 0xbfff_ffff),
            })
            .collect()
    };
    vec![
        Case {
            name: "empty (all zero) tile",
            width: 64,
            height: 64,
            values: vec![0.0; 64 * 64 * 3],
        },
        Case {
            name: "one pixel",
            width: 1,
            height: 1,
            values: vec![0.25, 65504.0, half_bits(0x0001)],
        },
        Case {
            name: "65504, subnormals and other special values",
            width: 13,
            height: 7,
            values: specials.iter().copied().cycle().take(13 * 7 * 3).collect(),
        },
        Case {
            name: "incompressible noise",
            width: 64,
            height: 64,
            values: random(64, 64),
        },
        Case {
            name: "noise beside flat areas, partial tiles and blocks",
            width: 97,
            height: 35,
            values: random(97, 35)
                .into_iter()
                .enumerate()
                .map(|(i, v)| if (i / 3) % 97 < 40 { 0.5 } else { v })
                .collect(),
        },
    ]
}

/// Writes `case` with our encoder; returns the written bytes' path.
fn write(
    dir: &Scratch,
    case: &Case,
    sample: Sample,
    compression: Compression,
    blocks: Blocks,
    level: u8,
) -> std::path::PathBuf {
    let file = SpectralFile::new(Spec {
        width: case.width,
        height: case.height,
        windows: None,
        wavelengths: vec![400.0, 550.0, 700.0],
        kind: Kind::Reflective,
        alpha: false,
        sample,
        compression,
        zip_level: level,
        blocks,
        attributes: vec![],
        float_attributes: vec![],
    })
    .unwrap();
    let path = dir.path(&format!(
        "{}-{sample:?}-{compression:?}-{}-{level}.exr",
        case.name.replace(' ', "_"),
        matches!(blocks, Blocks::Scanlines)
    ));
    let mut out = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    file.write(&mut out, |sink| {
        for b in file.blocks() {
            let px: Vec<f32> = (b.y..b.y + b.height)
                .flat_map(|y| {
                    let row = &case.values[(y * case.width + b.x) * 3..];
                    row[..b.width * 3].to_vec()
                })
                .collect();
            sink(b.chunk, file.encode(&b, &px, None)?)?;
        }
        Ok(())
    })
    .unwrap();
    drop(out);
    path
}

/// The bits a sample is stored with, as our encoder documents it: half rounds to nearest.
fn stored(v: f32, sample: Sample) -> u64 {
    match sample {
        Sample::Half => u64::from(half::f16::from_f32(v).to_bits()),
        Sample::Float => u64::from(v.to_bits()),
    }
}

#[test]
fn zip_edge_cases_decode_bit_for_bit_in_openexr_and_the_exr_crate() {
    let dir = Scratch::new("compression-edges");
    let layouts = [
        (Compression::ZIP16, Blocks::Scanlines),
        (Compression::ZIP1, Blocks::Scanlines),
        (
            Compression::ZIP16,
            Blocks::Tiles {
                width: 64,
                height: 64,
                mip_levels: false,
            },
        ),
        (
            Compression::ZIP1,
            Blocks::Tiles {
                width: 16,
                height: 8,
                mip_levels: false,
            },
        ),
    ];
    // Every layout at the default level; the extreme levels (0 stores, 9 searches hardest) on one.
    let mut files = Vec::new();
    for sample in [Sample::Half, Sample::Float] {
        for (k, case) in cases(sample).into_iter().enumerate() {
            for (l, (compression, blocks)) in layouts.into_iter().enumerate() {
                let levels: &[u8] = if l == 2 {
                    &[0, specconv_exr::zip::DEFAULT_LEVEL, 9]
                } else {
                    &[specconv_exr::zip::DEFAULT_LEVEL]
                };
                for &level in levels {
                    let what = format!(
                        "{} {sample:?} {compression:?} {blocks:?} level {level}",
                        case.name
                    );
                    let path = write(&dir, &case, sample, compression, blocks, level);
                    let header = tool("exrheader", &[path.to_str().unwrap()]);
                    let expected = if compression == Compression::ZIP1 {
                        "zip, individual scanlines"
                    } else {
                        "zip, multi-scanline blocks"
                    };
                    assert!(header.contains(expected), "{what}: {header}");
                    files.push((what, sample, k, path));
                }
            }
        }
    }
    let paths: Vec<PathBuf> = files.iter().map(|f| f.3.clone()).collect();
    let decoded_files = oiio_bits(&paths);
    assert_eq!(decoded_files.len(), files.len());
    for ((what, sample, k, path), oiio) in files.iter().zip(&decoded_files) {
        let case = &cases(*sample)[*k];
        let ours = specconv_exr::read(path).unwrap();
        for (band, name) in ["T.400,000000nm", "T.550,000000nm", "T.700,000000nm"]
            .iter()
            .enumerate()
        {
            let decoded = oiio[name]
                .as_array()
                .unwrap_or_else(|| panic!("{what}: no {name}"));
            assert_eq!(decoded.len(), case.width * case.height, "{what}");
            for (i, d) in decoded.iter().enumerate() {
                let want = stored(case.values[i * 3 + band], *sample);
                assert_eq!(
                    d.as_u64().unwrap(),
                    want,
                    "{what}: {name} sample {i} in OpenEXR"
                );
                assert_eq!(
                    stored(ours.bands[band][i], *sample),
                    want,
                    "{what}: {name} sample {i} in the exr crate"
                );
            }
        }
    }
}

#[test]
fn zip_levels_trade_size_and_incompressible_blocks_are_stored_raw() {
    let dir = Scratch::new("compression-levels");
    let tiles = Blocks::Tiles {
        width: 64,
        height: 64,
        mip_levels: false,
    };
    let case = &cases(Sample::Half)[4];
    let len = |level| {
        std::fs::metadata(write(
            &dir,
            case,
            Sample::Half,
            Compression::ZIP16,
            tiles,
            level,
        ))
        .unwrap()
        .len()
    };
    let (stored_raw, fast, small) = (len(0), len(1), len(9));
    assert!(
        fast < stored_raw && small <= fast,
        "{stored_raw} {fast} {small}"
    );
    // Noise cannot shrink: its chunks hold the raw bytes, so the file is the uncompressed one.
    let noisy = &cases(Sample::Half)[3];
    let zip = write(&dir, noisy, Sample::Half, Compression::ZIP16, tiles, 9);
    let raw = write(
        &dir,
        noisy,
        Sample::Half,
        Compression::Uncompressed,
        tiles,
        9,
    );
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert_eq!(size(&zip), size(&raw));
}

#[test]
fn zip_level_with_a_method_that_has_none_is_a_usage_error() {
    let dir = Scratch::new("compression-zip-level-usage");
    let input = crate::convert::testdata("photo.jpg");
    let out = dir.path("out.exr");
    let convert = |method: &str| {
        Cmd::convert(&input, &out)
            .args(["--compression", method, "--zip-level", "9", "--force"])
            .run()
    };
    for method in ["none", "piz", "b44a"] {
        convert(method).fails(2, &["--zip-level", &format!("--compression {method}")]);
        assert!(!out.exists(), "no output after a usage error");
    }
    // The same level with zip and zips is taken.
    for method in ["zip", "zips"] {
        convert(method).ok();
        assert!(out.exists());
    }
}
