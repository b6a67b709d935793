//! `simulate --image`: the per-patch report as swatches, so the drift is seen at a glance.

use super::Report;
use crate::files;
use crate::picture::Format;
use anyhow::{bail, Result};
use serde::Serialize;
use specconv_atomic_file::Replace;
use specconv_convert_cmd::stdio::serialize_path;
use specconv_figures::picture;
use specconv_figures::swatches::{self, Block, Cell, Row};
use std::path::{Path, PathBuf};

/// More blocks than this make a picture nobody reads; --patch chooses.
pub const MAX_PATCHES: usize = 16;

/// What `--image` wrote, for --json: the file and each swatch's rectangle in it.
#[derive(Serialize)]
pub struct Written {
    #[serde(serialize_with = "serialize_path")]
    path: PathBuf,
    width: u32,
    height: u32,
    swatches: Vec<Swatch>,
}

#[derive(Serialize)]
struct Swatch {
    patch: String,
    method: String,
    /// Index into the report's `counts`.
    count: usize,
    x: u32,
    y: u32,
    width: u32,
    height: u32,
}

/// Refuses, before any work, what would fail at the end.
pub fn check(path: &Path, (inputs, replace): (&[&Path], Replace), patches: usize) -> Result<()> {
    Format::of(path, "--image", &[Format::Png])?;
    files::check_writable(path, inputs, replace)?;
    if patches > MAX_PATCHES {
        bail!(
            "--image draws one block per patch and the scene has {patches}; choose at most \
             {MAX_PATCHES} with --patch NAME (repeatable)"
        );
    }
    Ok(specconv_figures::font::ensure()?)
}

/// Draws the report's patches and writes the PNG atomically.
pub fn write(path: &Path, r: &Report, (inputs, replace): (&[&Path], Replace)) -> Result<Written> {
    let reference = if r.mean_delta_e.is_some() {
        "measured"
    } else {
        "rgb"
    };
    let columns: Vec<String> = r
        .counts
        .iter()
        .map(|c| match c.parse::<usize>() {
            Ok(k) => format!("K = {k}"),
            Err(_) => c.clone(),
        })
        .collect();
    let blocks: Vec<Block> = r
        .per_patch
        .iter()
        .map(|p| Block {
            title: format!(
                "patch {}: CIEDE2000 from {}",
                p.name,
                if reference == "measured" {
                    "the measured reference"
                } else {
                    "RGB multiplication (no measured spectrum)"
                }
            ),
            columns: columns.clone(),
            rows: r
                .methods
                .iter()
                .map(|m| Row {
                    label: m.clone(),
                    cells: p.colours[m]
                        .iter()
                        .map(|c| Cell {
                            srgb: c.srgb,
                            text: if m == reference {
                                "reference".into()
                            } else {
                                let d = if reference == "measured" {
                                    c.delta_e.unwrap_or(f64::NAN)
                                } else {
                                    c.delta_e_rgb
                                };
                                format!("ΔE {d:.2}")
                            },
                        })
                        .collect(),
                })
                .collect(),
        })
        .collect();
    let (size, placed) = swatches::layout(&blocks);
    let png = picture::render_png(size, |root| swatches::draw(root, &blocks))?;
    files::write_atomically(path, &png, inputs, replace)?;
    Ok(Written {
        path: path.to_path_buf(),
        width: size.0,
        height: size.1,
        swatches: placed
            .iter()
            .map(|s| Swatch {
                patch: r.per_patch[s.block].name.clone(),
                method: r.methods[s.row].clone(),
                count: s.column,
                x: s.x,
                y: s.y,
                width: s.width,
                height: s.height,
            })
            .collect(),
    })
}
