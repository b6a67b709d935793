//! `specconv eval`: how well a method reproduces measured spectra from their colours.

use crate::{files, methods};
use anyhow::Result;
use specconv_spectral::method::MethodName;
use specconv_spectral::{Model, TrainOptions};
use specconv_study::eval;
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv eval --spectra colorchecker.csv
  specconv eval --spectra colorchecker.csv --method jakob2019
  specconv eval --spectra colorchecker.csv --train munsell.csv --clusters 16
";

/// Measure a method on measured spectra: uplift each from its own XYZ and compare.
///
/// Prints Δe = ‖s − r‖² mean / median / max (as the paper's Table 1), the largest relative
/// round-trip error |XYZ(r) − XYZ(s)| / Y(s) and CIEDE2000, and the fraction of
/// reconstructions inside [0, 1]. The clustered methods (otsu2018, pca) use --model, a model
/// trained here on --train, or the built-in model; their grid, observer and illuminant are the
/// model's. The baselines use --observer, --illuminant and --bands, by default those of the
/// model.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Measured spectra (CSV, as for train). Repeat for several files.
    #[arg(long, value_name = "CSV", required = true)]
    spectra: Vec<PathBuf>,
    /// Uplift method: otsu2018 (clustered PCA), pca (one cluster), smits1999, meng2015,
    /// meng2015-bounded (values kept in [0, 1] where possible) or jakob2019.
    #[arg(long, value_name = "NAME", default_value = "otsu2018")]
    method: MethodName,
    /// Model file from `specconv train`; the built-in model when absent.
    #[arg(long, value_name = "MODEL", conflicts_with = "train")]
    model: Option<PathBuf>,
    /// Train the clustered model here on these spectra (CSV) instead of reading one.
    #[arg(long, value_name = "CSV")]
    train: Vec<PathBuf>,
    /// Clusters of the model trained with --train (pca: always 1).
    #[arg(long, value_name = "K", default_value_t = 8)]
    clusters: usize,
    /// Smallest cluster of the model trained with --train.
    #[arg(long, value_name = "N", default_value_t = TrainOptions::default().min_cluster_size)]
    min_cluster_size: usize,
    #[command(flatten)]
    setting: methods::SettingArgs,
    #[command(flatten)]
    blend: methods::BlendArg,
    /// Evaluate the method bounded, as `convert` writes it by default: spectra kept in [0, 1]
    /// with their XYZ (reported as METHOD-bounded). Without it, the method as named.
    #[arg(long)]
    bounded: bool,
    /// Print one JSON object: method, count, delta_e.{mean,median,max}, roundtrip_max,
    /// roundtrip_de2000_max, in_unit_range.
    #[arg(long)]
    json: bool,
    /// Also list every spectrum's error (with --json, under "spectra").
    #[arg(long)]
    per_spectrum: bool,
}

#[derive(serde::Serialize)]
struct Row<'a> {
    source: &'a str,
    name: &'a str,
    #[serde(flatten)]
    outcome: &'a eval::Outcome,
}

pub fn run(args: Args) -> Result<()> {
    let (model, described) = model(&args)?;
    let stack = methods::build(&args.description(), &model).map_err(|e| match args.method {
        // The one setting a user can fix here: a many-cluster model for pca.
        MethodName::Pca => crate::usage(anyhow::anyhow!(
            "{}; or pass --train CSV to train one here",
            crate::one_line(e.as_ref())
        )),
        _ => e,
    })?;
    let (method, a) = (stack.method(), stack.colorimetry());
    let described = if args.method.is_clustered() {
        described
    } else {
        format!("{}, {}, {} nm", a.observer, a.illuminant, a.grid)
    };
    let name = if args.bounded {
        format!("{}-bounded", args.method)
    } else {
        args.method.to_string()
    };
    let mut spectra = Vec::new();
    let mut labels = Vec::new();
    for path in &args.spectra {
        let table = files::read_spectra(path)?;
        spectra.extend(table.resampled(&a.grid)?);
        labels.extend(
            table
                .names
                .iter()
                .map(|n| (table.source.clone(), n.clone())),
        );
    }
    let outcomes = eval::evaluate(a, method, &spectra);
    let summary = eval::summarise(&outcomes);
    let rows: Vec<Row> = labels
        .iter()
        .zip(&outcomes)
        .map(|((source, name), outcome)| Row {
            source,
            name,
            outcome,
        })
        .collect();

    if args.json {
        let mut v = serde_json::to_value(&summary)?;
        v["method"] = name.as_str().into();
        if args.per_spectrum {
            v["spectra"] = serde_json::to_value(&rows)?;
        }
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
        return Ok(());
    }
    Ok(print_text(&args, &name, &described, &summary, &rows)?)
}

/// The text report: every spectrum's row with --per-spectrum, then the summary.
fn print_text(
    args: &Args,
    name: &str,
    described: &str,
    summary: &eval::Summary,
    rows: &[Row],
) -> Result<(), crate::stdio::StdoutFailed> {
    if args.per_spectrum {
        outln!(
            "{:<12} {:>5} {:>9} {:>9} {:>7}  name",
            "delta_e",
            "leaf",
            "roundtrip",
            "ΔE00",
            "in_0_1"
        )?;
        for r in rows {
            outln!(
                "{:<12.6} {:>5} {:>9.1e} {:>9.1e} {:>7}  {}",
                r.outcome.delta_e,
                r.outcome.leaf.map_or("-".into(), |l| l.to_string()),
                r.outcome.roundtrip,
                r.outcome.roundtrip_de2000,
                r.outcome.in_unit_range,
                r.name
            )?;
        }
        outln!()?;
    }
    outln!("method:     {name}")?;
    let what = if args.method.is_clustered() {
        "model"
    } else {
        "setting"
    };
    outln!("{what:<11} {described}", what = format!("{what}:"))?;
    outln!("spectra:    {}", summary.count)?;
    outln!(
        "Δe = ‖s − r‖²: mean {:.4}  median {:.4}  max {:.4}",
        summary.delta_e.mean,
        summary.delta_e.median,
        summary.delta_e.max
    )?;
    outln!(
        "round trip: max |XYZ(r) − XYZ(s)| / Y(s) = {:.2e}, max CIEDE2000 = {:.2e}",
        summary.roundtrip_max,
        summary.roundtrip_de2000_max
    )?;
    outln!(
        "in [0, 1]:  {:.1} % of reconstructions",
        100.0 * summary.in_unit_range
    )
}

impl Args {
    /// The method stack these options describe.
    pub(crate) fn description(&self) -> specconv_spectral::stack::Description {
        self.setting
            .describe(self.method, self.blend.width, self.bounded)
    }
}

/// The clustered methods' model: read (or built in), or trained here on --train; and how
/// the report names it.
fn model(args: &Args) -> Result<(Model, String)> {
    let base = files::load_model(args.model.as_deref())?;
    if args.train.is_empty() || !args.method.is_clustered() {
        let described = specconv_conversion::models::describe(args.model.as_deref(), &base);
        return Ok((base, described));
    }
    let a = args.setting.colorimetry(&base)?;
    let set = methods::training_set(&args.train, &a.grid)?;
    let opts = TrainOptions {
        clusters: if args.method == MethodName::Pca {
            1
        } else {
            args.clusters
        },
        min_cluster_size: args.min_cluster_size,
        ..TrainOptions::default()
    };
    let model = specconv_spectral::train(&set, &a, &opts)?;
    let described =
        specconv_conversion::models::describe(None, &model).replacen("built-in", "trained here", 1);
    Ok((model, described))
}
