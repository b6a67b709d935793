//! `specconv train`: fit a clustered-PCA model to measured spectra.

use crate::files;
use anyhow::Result;
use specconv_atomic_file::Replace;
use specconv_convert_cmd::errors::{explain, usage};
use specconv_flags::defs;
use specconv_spectral::TrainOptions;
use std::path::{Path, PathBuf};

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv train --spectra munsell.csv --clusters 8 -o munsell8.json
  specconv train --spectra a.csv --spectra b.csv --bands 380:780:5 --illuminant E -o model.json
  specconv train --spectra big.csv --spectra small.csv --balance 1 --licence CC0 --licence MIT -o m.json
  specconv train --spectra swatches.csv --weights 4 --licence \"ours\" --commercial yes \
      --with open --with-data ../shared/spectra -o studio.json
";

specconv_flags::args! {
    /// Train a clustered-PCA model on measured reflectance spectra.
    ///
    /// Builds the kd-tree on CIE xy of the paper (Eq. 10–13): every split is placed where the summed
    /// reconstruction error ‖s − r‖² of both sides is least, and the leaf whose split gains most is
    /// split next, until --clusters leaves exist or no split helps. Same data, same model, bit for bit.
    #[derive(Debug)]
    pub struct Args {
        spectra: Vec<PathBuf> = (defs::TRAIN_SPECTRA),
        clusters: Option<usize> = (defs::TRAIN_CLUSTERS),
        min_cluster_size: Option<usize> = (defs::TRAIN_MIN_CLUSTER_SIZE),
        max_condition: Option<f64> = (defs::TRAIN_MAX_CONDITION),
        with: Option<PathBuf> = (defs::TRAIN_WITH),
        with_data: Option<PathBuf> = (defs::TRAIN_WITH_DATA),
        weights: crate::methods::WeightArgs = flatten,
        colorimetry: crate::methods::ColorimetryArgs = flatten,
        output: PathBuf = (defs::TRAIN_OUTPUT),
        /// --force, as the library defines it.
        force: specconv_flags::ForceArg = flatten,
    }
}

pub fn run(args: Args) -> Result<()> {
    use specconv_conversion::models;
    files::check_output(&args.output, models::EXTENSIONS, "a model file is JSON")?;
    let base = match &args.with {
        Some(with) => Some(models::load(Some(with))?),
        None => None,
    };
    // Every file this command reads, which --force never replaces: the spectra, the --with
    // model's file and its recorded sets. Checked before training, and again as the model is
    // written (models::save).
    let mut read: Vec<PathBuf> = args.spectra.clone();
    if let (Some(with), Some(base), Some(dir)) = (&args.with, &base, &args.with_data) {
        read.extend(models::file_read(Some(with)));
        read.extend(models::recorded_files(with, base, dir)?);
    }
    let inputs: Vec<&Path> = read.iter().map(PathBuf::as_path).collect();
    let replace = Replace::when(args.force.on());
    files::check_writable(&args.output, &inputs, replace)?;
    let (a, set, base) = match (&args.with, base, &args.with_data) {
        (Some(with), Some(base), Some(dir)) => {
            let a = base.colorimetry()?;
            let c = &args.colorimetry;
            if (c.bands, c.observer, c.illuminant) != (a.grid, a.observer, a.illuminant) {
                return Err(usage(anyhow::anyhow!(
                    "--with trains in its model's setting ({}, {}, {} nm): drop --observer, --illuminant and --bands, or give them as the model has them",
                    a.observer,
                    a.illuminant,
                    a.grid
                )));
            }
            let own = crate::methods::weighted_parts(&args.spectra, &a.grid, &args.weights)?;
            let recorded = models::recorded_parts(with, &base, dir)?;
            for why in &recorded.unverified {
                errln!("specconv: warning: {why}");
            }
            let set =
                specconv_spectral::TrainingSet::on_top(recorded.parts, own, args.weights.balance)
                    .map_err(usage)?;
            (a, set, models::recorded_options(&base))
        }
        _ => {
            let a = args.colorimetry.on(args.colorimetry.bands)?;
            let set = crate::methods::weighted_set(&args.spectra, &a.grid, &args.weights)?;
            (a, set, TrainOptions::default())
        }
    };
    let opts = TrainOptions {
        clusters: args.clusters.unwrap_or(base.clusters),
        min_cluster_size: args.min_cluster_size.unwrap_or(base.min_cluster_size),
        max_condition: args.max_condition.unwrap_or(base.max_condition),
    };
    let start = std::time::Instant::now();
    let model = specconv_spectral::train(&set, &a, &opts)?;
    let seconds = start.elapsed().as_secs_f64();
    models::save(&model, &args.output, &inputs, replace)
        .map_err(|e| anyhow::anyhow!(explain(&e.into())))?;

    errln!(
        "trained {} clusters on {} spectra in {seconds:.3} s; total error Σ‖s − r‖² = {:.6}",
        model.leaves.len(),
        set.spectra.len(),
        model.training.total_error
    );
    for (k, leaf) in model.leaves.iter().enumerate() {
        errln!(
            "  cluster {k}: {:5} spectra, error {:10.6}, condition of M {:8.2}",
            leaf.count,
            leaf.error,
            leaf.condition
        );
    }
    if let Some(why) = files::fewer_clusters(&model) {
        errln!("specconv: warning: {why}");
    }
    errln!("data: {}", specconv_conversion::models::sources(&model));
    let commercial = model.training.commercial();
    let unstated = if commercial == specconv_spectral::otsu2018::terms::Commercial::Unstated {
        "; a set's terms are not stated: --commercial yes for your own measurements"
    } else {
        ""
    };
    errln!("commercial use: {commercial} (yes only when every set's data allow it{unstated})");
    errln!("wrote {}", args.output.display());
    Ok(())
}
