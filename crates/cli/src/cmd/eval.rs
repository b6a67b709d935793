//! `specconv eval`: how well a model reproduces measured spectra from their colours.

use crate::files;
use anyhow::Result;
use spectral::{eval, Uplifter};
use std::path::PathBuf;

/// Measure a model on measured spectra: uplift each from its own XYZ and compare.
///
/// Prints Δe = ‖s − r‖² mean / median / max (as the paper's Table 1), the largest relative
/// round-trip error |XYZ(r) − XYZ(s)| / Y(s), and the fraction of reconstructions inside
/// [0, 1]. The grid, observer and illuminant are the model's.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Measured spectra (CSV, as for train). Repeat for several files.
    #[arg(long, value_name = "CSV", required = true)]
    spectra: Vec<PathBuf>,
    /// Model file from `specconv train`; the built-in model when absent.
    #[arg(long, value_name = "MODEL")]
    model: Option<PathBuf>,
    /// Print one JSON object: count, delta_e.{mean,median,max}, roundtrip_max, in_unit_range.
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
    let model = files::load_model(args.model.as_deref())?;
    let a = model.colorimetry()?;
    let up = Uplifter::new(&model)?;
    let mut spectra = Vec::new();
    let mut labels = Vec::new();
    for path in &args.spectra {
        let table = files::read_spectra(path)?;
        spectra.extend(table.resampled(&model.grid)?);
        labels.extend(
            table
                .names
                .iter()
                .map(|n| (table.source.clone(), n.clone())),
        );
    }
    let outcomes = eval::evaluate(&a, &up, &spectra);
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
        if args.per_spectrum {
            v["spectra"] = serde_json::to_value(&rows)?;
        }
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    if args.per_spectrum {
        println!(
            "{:<12} {:>5} {:>9} {:>7}  name",
            "delta_e", "leaf", "roundtrip", "in_0_1"
        );
        for r in &rows {
            println!(
                "{:<12.6} {:>5} {:>9.1e} {:>7}  {}",
                r.outcome.delta_e,
                r.outcome.leaf.map_or("-".into(), |l| l.to_string()),
                r.outcome.roundtrip,
                r.outcome.in_unit_range,
                r.name
            );
        }
        println!();
    }
    println!(
        "model:      {}",
        files::describe_model(args.model.as_deref(), &model)
    );
    println!("spectra:    {}", summary.count);
    println!(
        "Δe = ‖s − r‖²: mean {:.4}  median {:.4}  max {:.4}",
        summary.delta_e.mean, summary.delta_e.median, summary.delta_e.max
    );
    println!(
        "round trip: max |XYZ(r) − XYZ(s)| / Y(s) = {:.2e}",
        summary.roundtrip_max
    );
    println!(
        "in [0, 1]:  {:.1} % of reconstructions",
        100.0 * summary.in_unit_range
    );
    Ok(())
}
