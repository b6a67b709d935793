//! Building any uplift method by name, for `eval`, `report` (and `convert`): the clustered
//! models from a model file or trained in place, the baselines from a colorimetry. The Jakob
//! 2019 table is solved in parallel here and kept in the user's cache directory, keyed by
//! everything it depends on, so it is built once per setting.

use anyhow::{Context, Result};
use rayon::prelude::*;
use specconv_colour::Colorimetry;
use specconv_spectral::baselines::jakob;
use specconv_spectral::baselines::jakob::{Fitter, Table};
use specconv_spectral::baselines::{Jakob2019, Meng2015, Smits1999};
use specconv_spectral::method::MethodName;
use specconv_spectral::{Method, Model, Uplifter};
use std::path::PathBuf;

/// The baseline `name` in colorimetry `a`. Clustered methods come from [`clustered`].
pub fn baseline(name: MethodName, a: &Colorimetry, jakob_res: usize) -> Result<Box<dyn Method>> {
    Ok(match name {
        MethodName::Smits1999 => Box::new(Smits1999::new(a)?),
        MethodName::Meng2015 => Box::new(Meng2015::new(a, false)?),
        MethodName::Meng2015Bounded => Box::new(Meng2015::new(a, true)?),
        MethodName::Jakob2019 => Box::new(Jakob2019::new(a, jakob_table(a, jakob_res)?)?),
        MethodName::Pca | MethodName::Otsu2018 => {
            unreachable!("clustered methods are built from a model")
        }
    })
}

/// A clustered method from its model, named `pca` when it has one cluster, with the paper's
/// hard switch between clusters.
pub fn clustered(model: &Model) -> Result<Box<dyn Method>> {
    blended(model, 0.0)
}

/// A clustered method whose clusters blend within `width` of their boundaries (`--blend`).
pub fn blended(model: &Model, width: f64) -> Result<Box<dyn Method>> {
    Ok(Box::new(Uplifter::new(model)?.with_blend(width)?))
}

/// `m` with its spectra kept in [0, 1] and their XYZ (`specconv_spectral::bounded`); `a` is the
/// colorimetry `m` uplifts for.
pub fn bounded(m: Box<dyn Method>, a: &Colorimetry) -> Result<Box<dyn Method>> {
    Ok(Box::new(specconv_spectral::bounded::Bounded::new(
        m,
        a.clone(),
    )?))
}

/// `--blend WIDTH` of the commands that uplift with a clustered model.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct BlendArg {
    /// Blend the spectra of neighbouring clusters within WIDTH of their boundary (in CIE xy),
    /// so that spectra change continuously across it; XYZ stays exact. WIDTH is the least
    /// width: a boundary whose two sides differ a lot is widened so that no spectrum jumps by
    /// more than 1e-3 between colours 1e-5 apart. 0 is the paper's hard switch. The default
    /// keeps the paper's Table 1 (Munsell mean Δe 0.01378 against 0.01379).
    #[arg(long = "blend", value_name = "WIDTH", default_value_t = specconv_spectral::otsu2018::blend::DEFAULT_WIDTH)]
    pub width: f64,
}

impl BlendArg {
    /// The width that applies to `method`: 0 for the baselines, which have no clusters.
    pub fn of(&self, method: MethodName) -> f64 {
        if method.is_clustered() {
            self.width
        } else {
            0.0
        }
    }
}

/// Where cached tables live: $SPECCONV_CACHE_DIR, else $XDG_CACHE_HOME/specconv, else
/// ~/.cache/specconv.
pub fn cache_dir() -> Option<PathBuf> {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("SPECCONV_CACHE_DIR")
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("specconv")))
        .or_else(|| env("HOME").map(|d| d.join(".cache").join("specconv")))
}

/// The Jakob 2019 table for `a` at resolution `res`: read from the cache when an intact file
/// for the same key is there, else solved (in parallel) and written to the cache. A cache that
/// cannot be written is not an error: the table is used anyway, with a warning.
pub fn jakob_table(a: &Colorimetry, res: usize) -> Result<Table> {
    jakob::check_resolution(res)?;
    let fitter = Fitter::new(a)?;
    let key = fitter.key(a, res);
    let mut h = jakob::Fnv::new();
    h.write(key.as_bytes());
    let file = cache_dir().map(|d| d.join(format!("jakob2019-{:016x}.bin", h.finish())));
    if let Some(file) = &file {
        if let Ok(bytes) = std::fs::read(file) {
            if let Some(t) = Table::from_bytes(&bytes, &key, res) {
                return Ok(t);
            }
            eprintln!(
                "specconv: note: {} is damaged or stale; rebuilding it",
                file.display()
            );
        }
    }
    let start = std::time::Instant::now();
    let columns: Vec<Vec<[f32; 3]>> = (0..3 * res)
        .into_par_iter()
        .map(|c| fitter.solve_column(res, c / res, c % res))
        .collect();
    let table = Table::from_columns(res, key, columns);
    eprintln!(
        "specconv: built the jakob2019 table ({res}³ × 3 cells, {}) in {:.1} s",
        a.grid,
        start.elapsed().as_secs_f64()
    );
    if let Some(file) = &file {
        let written = file
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .context("cannot create the cache directory")
            .and_then(|()| crate::files::write_atomically(file, &table.to_bytes(), &[]));
        if let Err(e) = written {
            eprintln!(
                "specconv: warning: cannot cache the jakob2019 table in {}: {e:#}",
                file.display()
            );
        }
    }
    Ok(table)
}

/// Colorimetry flags shared by `eval` and `report`.
#[derive(Debug, Clone, clap::Args)]
pub struct SettingArgs {
    /// Colour-matching functions for baselines and in-place training: cie1931, cie1964 or
    /// wyman2013 (default: the model's, cie1931 for the built-in one).
    #[arg(long)]
    pub observer: Option<specconv_colour::Observer>,
    /// Illuminant for baselines and in-place training: D65, E, A, D50, FL2, FL11 or
    /// blackbody:KELVIN (default: the model's, D65 for the built-in one).
    #[arg(long)]
    pub illuminant: Option<specconv_colour::Illuminant>,
    /// Wavelength grid START:END:STEP in nm (default: the model's, 380:730:10 for the built-in).
    #[arg(long, value_name = "START:END:STEP")]
    pub bands: Option<specconv_colour::Grid>,
    /// Resolution of the jakob2019 coefficient table (cells per axis; the paper's 64).
    #[arg(long, value_name = "N", default_value_t = jakob::DEFAULT_RESOLUTION)]
    pub jakob_resolution: usize,
}

impl SettingArgs {
    /// The colorimetry: the flags, falling back to `model`'s setting.
    pub fn colorimetry(&self, model: &Model) -> Result<Colorimetry> {
        Ok(Colorimetry::new(
            self.bands.unwrap_or(model.grid),
            self.observer.unwrap_or(model.observer),
            self.illuminant.unwrap_or(model.illuminant),
        )?)
    }
}

/// Reads spectra files into one training set on `grid`.
pub fn training_set(
    paths: &[PathBuf],
    grid: &specconv_colour::Grid,
) -> Result<specconv_spectral::TrainingSet> {
    let mut set = specconv_spectral::TrainingSet::default();
    for path in paths {
        let table = crate::files::read_spectra(path)?;
        set.spectra.extend(table.resampled(grid)?);
        set.names.extend(table.names.iter().cloned());
        set.sources.push(table.source);
    }
    Ok(set)
}
