//! `specconv train`: fit a clustered-PCA model to measured spectra.

use crate::files;
use anyhow::Result;
use specconv_atomic_file::Replace;
use specconv_spectral::otsu2018::train::SMALLEST_CLUSTER;
use specconv_spectral::TrainOptions;
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv train --spectra munsell.csv --clusters 8 -o munsell8.json
  specconv train --spectra a.csv --spectra b.csv --bands 380:780:5 --illuminant E -o model.json
  specconv train --spectra big.csv --spectra small.csv --balance 1 --licence CC0 --licence MIT -o m.json
";

/// Train a clustered-PCA model on measured reflectance spectra.
///
/// Builds the kd-tree on CIE xy of the paper (Eq. 10–13): every split is placed where the summed
/// reconstruction error ‖s − r‖² of both sides is least, and the leaf whose split gains most is
/// split next, until --clusters leaves exist or no split helps. Same data, same model, bit for bit.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Measured spectra: CSV with a wavelength column, then one column per named sample.
    /// Repeat to train on several files.
    #[arg(long, value_name = "CSV", required = true)]
    spectra: Vec<PathBuf>,
    /// Number of clusters (leaves of the tree).
    #[arg(long, value_name = "K", default_value_t = TrainOptions::default().clusters)]
    clusters: usize,
    /// Smallest number of spectra in a cluster. Small clusters fit their training spectra
    /// closely but generalise badly; the paper's Table 1 used 4.
    #[arg(long, value_name = "N", default_value_t = TrainOptions::default().min_cluster_size,
          value_parser = min_cluster_size)]
    min_cluster_size: usize,
    /// Largest condition number of a cluster's 3×3 matrix M that a split may create. Near-singular
    /// M turn colours the cluster was not trained on into wild spectra.
    #[arg(long, value_name = "BOUND", default_value_t = TrainOptions::default().max_condition)]
    max_condition: f64,
    #[command(flatten)]
    weights: crate::methods::WeightArgs,
    #[command(flatten)]
    colorimetry: crate::methods::ColorimetryArgs,
    /// Where to write the model (JSON).
    #[arg(short, long, value_name = "MODEL")]
    output: PathBuf,
    /// Replace an existing output.
    #[arg(long)]
    force: bool,
}

fn min_cluster_size(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if n >= SMALLEST_CLUSTER => Ok(n),
        _ => Err(format!("must be a whole number ≥ {SMALLEST_CLUSTER}: three principal components need four spectra")),
    }
}

pub fn run(args: Args) -> Result<()> {
    use specconv_conversion::models;
    files::check_output(&args.output, models::EXTENSIONS, "a model file is JSON")?;
    let inputs: Vec<&std::path::Path> = args.spectra.iter().map(PathBuf::as_path).collect();
    // Checked before training, and again as the model is written (models::save).
    let replace = Replace::when(args.force);
    files::check_writable(&args.output, &inputs, replace)?;
    let a = args.colorimetry.on(args.colorimetry.bands)?;
    let set = crate::methods::weighted_set(&args.spectra, &a.grid, &args.weights)?;
    let opts = TrainOptions {
        clusters: args.clusters,
        min_cluster_size: args.min_cluster_size,
        max_condition: args.max_condition,
    };
    let start = std::time::Instant::now();
    let model = specconv_spectral::train(&set, &a, &opts)?;
    let seconds = start.elapsed().as_secs_f64();
    models::save(&model, &args.output, &inputs, replace)
        .map_err(|e| anyhow::anyhow!(crate::explain(&e.into())))?;

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
    errln!("wrote {}", args.output.display());
    Ok(())
}
