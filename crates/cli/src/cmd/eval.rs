//! `specconv eval`: how well a method reproduces measured spectra from their colours.

use crate::{files, methods};
use anyhow::Result;
use specconv_convert_cmd::errors::{one_line, usage};
use specconv_evaluation::eval;
use specconv_flags::defs;
use specconv_spectral::method::MethodName;
use specconv_spectral::{Model, TrainOptions};
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv eval --spectra colorchecker.csv
  specconv eval --spectra colorchecker.csv --method jakob2019
  specconv eval --spectra colorchecker.csv --train munsell.csv --clusters 16
  specconv eval --by-set --model broad --spectra munsell.csv --spectra cc.csv --spectra usgs.csv
  specconv eval --by-set --train a.csv --train b.csv --balance 1 --spectra a.csv --spectra b.csv --spectra c.csv
";

specconv_flags::args! {
    /// Measure a method on measured spectra: uplift each from its own XYZ and compare.
    ///
    /// Prints Δe = ‖s − r‖² mean / median / max (as the paper's Table 1), the colour shift under
    /// other lights (CIEDE2000 between measured and uplifted spectra under each --shift-under
    /// illuminant: mean, 95th percentile, max), the largest relative round-trip error
    /// |XYZ(r) − XYZ(s)| / Y(s) and CIEDE2000, and the fraction of reconstructions inside [0, 1]. The clustered methods (otsu2018, pca) use --model, a model
    /// trained here on --train, or the built-in model; their grid, observer and illuminant are the
    /// model's. The baselines use --observer, --illuminant and --bands, by default those of the
    /// model.
    ///
    /// With --by-set, each --spectra file is scored on spectra the model was not trained on, and
    /// the report gives every file's figures, their mean and the worst file: a file that is not
    /// in the training recipe is uplifted by the recipe's model; one that is, by the model trained
    /// on the recipe's other files (leave one set out; --folds K: on the other files and the
    /// file's other K − 1 folds; a recipe of that one file alone: 10-fold within it). The recipe
    /// is --train with --weights, --balance, --clusters and --min-cluster-size, or else the
    /// model's own: its recorded sets, weights and options (each recorded set's file among
    /// --spectra).
    #[derive(Debug)]
    pub struct Args {
        spectra: Vec<PathBuf> = (defs::EVAL_SPECTRA),
        method: MethodName = (defs::EVAL_METHOD),
        model: Option<PathBuf> = (defs::EVAL_MODEL),
        train: Vec<PathBuf> = (defs::EVAL_TRAIN),
        clusters: usize = (defs::EVAL_CLUSTERS),
        min_cluster_size: usize = (defs::EVAL_MIN_CLUSTER_SIZE),
        weights: methods::WeightArgs = flatten,
        by_set: bool = (defs::EVAL_BY_SET),
        folds: Option<u32> = (defs::EVAL_FOLDS),
        against: Option<PathBuf> = (defs::EVAL_AGAINST),
        setting: methods::SettingArgs = flatten,
        blend: methods::BlendArg = flatten,
        shift: methods::ShiftArg = flatten,
        bounded: bool = (defs::EVAL_BOUNDED),
        json: bool = (defs::EVAL_JSON),
        per_spectrum: bool = (defs::EVAL_PER_SPECTRUM),
    }
}

#[derive(serde::Serialize)]
struct Row<'a> {
    source: &'a str,
    name: &'a str,
    #[serde(flatten)]
    outcome: &'a eval::Outcome,
}

pub fn run(args: Args) -> Result<()> {
    if args.by_set {
        return by_set::run(&args);
    }
    let (model, described) = model(&args)?;
    let stack = methods::build(&args.stack_spec(), &model).map_err(|e| match args.method {
        // The one setting a user can fix here: a many-cluster model for pca.
        MethodName::Pca => usage(anyhow::anyhow!(
            "{}; or pass --train CSV to train one here",
            one_line(e.as_ref())
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
    let outcomes = eval::evaluate(a, method, &spectra, &args.shift.viewing(a)?);
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
        v["model"] = described.as_str().into();
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
    summary: &eval::Statistics,
    rows: &[Row],
) -> Result<(), specconv_convert_cmd::stdio::StdoutFailed> {
    if args.per_spectrum {
        let lights: String = summary
            .colour_shift
            .iter()
            .map(|s| format!(" {:>8}", format!("ΔE00 {}", s.illuminant)))
            .collect();
        outln!(
            "{:<12} {:>5} {:>9} {:>9} {:>7}{lights}  name",
            "delta_e",
            "leaf",
            "roundtrip",
            "ΔE00",
            "in_0_1"
        )?;
        for r in rows {
            let shifts: String = r
                .outcome
                .colour_shift
                .iter()
                .map(|s| format!(" {:>8.3}", s.ciede2000))
                .collect();
            outln!(
                "{:<12.6} {:>5} {:>9.1e} {:>9.1e} {:>7}{shifts}  {}",
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
    for s in &summary.colour_shift {
        outln!(
            "colour shift under {}: CIEDE2000 mean {:.3}  95th percentile {:.3}  max {:.3}",
            s.illuminant,
            s.mean,
            s.p95,
            s.max
        )?;
    }
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
    pub(crate) fn stack_spec(&self) -> specconv_spectral::stack::StackSpec {
        self.setting
            .describe(self.method, self.blend.options.blend, self.bounded)
    }
}

fn model(args: &Args) -> Result<(Model, String)> {
    let base = files::load_model(args.model.as_deref())?;
    if args.train.is_empty() || !args.method.is_clustered() {
        let described = specconv_conversion::models::describe(args.model.as_deref(), &base);
        return Ok((base, described));
    }
    let a = args.setting.colorimetry(&base)?;
    let set = methods::weighted_set(&args.train, &a.grid, &args.weights)?;
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
    let described = specconv_conversion::models::describe(Some("trained here".as_ref()), &model);
    Ok((model, described))
}

/// `eval --by-set`: cross-validation across the --spectra files.
mod by_set {
    use super::Args;
    use crate::methods;
    use anyhow::{anyhow, Result};
    use specconv_convert_cmd::errors::usage;
    use specconv_evaluation::eval;
    use specconv_evaluation::sets::{held_out_by_set, Holdout, Recipe, Scores};
    use specconv_spectral::method::MethodName;
    use specconv_spectral::{Model, Part, TrainOptions, TrainingSet};

    pub(super) fn run(args: &Args) -> Result<()> {
        if !args.method.is_clustered() {
            return Err(usage(anyhow!(
                "--by-set measures trained models: use --method otsu2018 or pca ({} is not trained)",
                args.method
            )));
        }
        let base = crate::files::load_model(args.model.as_deref())?;
        let a = args.setting.colorimetry(&base)?;
        let mut tests = Vec::with_capacity(args.spectra.len());
        for path in &args.spectra {
            let table = crate::files::read_spectra(path)?;
            tests.push(TrainingSet::from_table_holding(
                &table,
                &a.grid,
                args.weights.hold_ends,
            )?);
        }
        let recipe = recipe(args, &base, &tests, &a.grid)?;
        let d = args.stack_spec();
        let viewing = args.shift.viewing(&a)?;
        let holdout = args
            .folds
            .map_or(Holdout::Set, |k| Holdout::Folds(k as usize));
        let score = |recipe: &Recipe| {
            held_out_by_set(recipe, &tests, &a, holdout, |m, held| {
                let stack = methods::build(&d, m)?;
                Ok::<_, anyhow::Error>(eval::evaluate(
                    stack.colorimetry(),
                    stack.method(),
                    held,
                    &viewing,
                ))
            })
        };
        let scores = score(&recipe)?;
        let against = match &args.against {
            None => None,
            Some(path) => {
                let other = crate::files::load_model(Some(path))?;
                if (other.grid, other.observer, other.illuminant)
                    != (a.grid, a.observer, a.illuminant)
                {
                    return Err(usage(anyhow!(
                        "--against {} is trained in another setting than the model measured: compare models of one grid, observer and illuminant",
                        path.display()
                    )));
                }
                let pca = args.method == MethodName::Pca;
                Some(score(&recorded(&other, &tests, pca)?)?)
            }
        };
        print(args, &recipe, &scores, against.as_ref())
    }

    /// --train's recipe, or the model's recorded one.
    fn recipe(
        args: &Args,
        model: &Model,
        tests: &[TrainingSet],
        grid: &specconv_colour::Grid,
    ) -> Result<Recipe> {
        let pca = args.method == MethodName::Pca;
        if !args.train.is_empty() {
            return Ok(Recipe {
                parts: methods::weighted_parts(&args.train, grid, &args.weights)?,
                balance: args.weights.balance,
                options: TrainOptions {
                    clusters: if pca { 1 } else { args.clusters },
                    min_cluster_size: args.min_cluster_size,
                    ..TrainOptions::default()
                },
            });
        }
        recorded(model, tests, pca)
    }

    /// The model's recorded recipe, its sets found among `tests` by file name.
    fn recorded(model: &Model, tests: &[TrainingSet], pca: bool) -> Result<Recipe> {
        let t = &model.training;
        if t.sets.is_empty() {
            return Err(usage(anyhow!(
                "the model does not record its training sets: give them with --train"
            )));
        }
        let mut parts = Vec::with_capacity(t.sets.len());
        for record in &t.sets {
            let Some(set) = tests.iter().find(|s| s.sources == [record.source.clone()]) else {
                return Err(usage(anyhow!(
                    "the model was trained on {}, which is not among --spectra: give that file with --spectra",
                    record.source
                )));
            };
            parts.push(Part {
                set: set.clone(),
                weight: record.weight,
                terms: record.terms(),
            });
        }
        Ok(Recipe {
            parts,
            balance: 0.0,
            options: TrainOptions {
                clusters: if pca { 1 } else { t.clusters_requested },
                min_cluster_size: t.min_cluster_size,
                max_condition: t.max_condition,
            },
        })
    }

    fn print(
        args: &Args,
        recipe: &Recipe,
        scores: &Scores,
        against: Option<&Scores>,
    ) -> Result<()> {
        let trained: Vec<String> = recipe
            .parts
            .iter()
            .map(|p| {
                let name = p.set.sources.join(", ");
                if p.weight == 1.0 {
                    name
                } else {
                    format!("{name} ×{:.3}", p.weight)
                }
            })
            .collect();
        if args.json {
            let mut v = serde_json::to_value(scores)?;
            v["method"] = args.method.as_str().into();
            v["trained_on"] = trained.into();
            if let Some(other) = against {
                v["against"] = serde_json::to_value(other)?;
            }
            outln!("{}", serde_json::to_string_pretty(&v)?)?;
            return Ok(());
        }
        outln!("method:     {}", args.method)?;
        outln!(
            "recipe:     {} clusters, min {}, condition ≤ {}, trained on {}",
            recipe.options.clusters,
            recipe.options.min_cluster_size,
            recipe.options.max_condition,
            trained.join(", ")
        )?;
        table(args, scores, against)?;
        let other = |f: &dyn Fn(&Scores) -> f64| {
            against.map_or(String::new(), |o| format!(" (against {:.4})", f(o)))
        };
        outln!(
            "mean over sets: Δe {:.4}{}",
            scores.mean_of_sets,
            other(&|s| s.mean_of_sets)
        )?;
        outln!(
            "worst set:      Δe {:.4} ({}){}",
            scores.worst,
            scores.worst_set,
            other(&|s| s.worst)
        )?;
        for (k, x) in scores.colour_shift.iter().enumerate() {
            outln!(
                "colour shift under {}: mean over sets CIEDE2000 {:.4}{}, worst set {:.4} ({}){}",
                x.illuminant,
                x.mean_of_sets,
                other(&|s| s.colour_shift[k].mean_of_sets),
                x.worst,
                x.worst_set,
                other(&|s| s.colour_shift[k].worst)
            )?;
        }
        Ok(())
    }

    /// The per-set table: Δe and, per illuminant, the shift's mean / 95th percentile / max;
    /// against the other model, its mean and this model's ratio to it.
    fn table(args: &Args, scores: &Scores, against: Option<&Scores>) -> Result<()> {
        let lights: Vec<_> = scores.colour_shift.iter().map(|s| s.illuminant).collect();
        let mut head = String::new();
        let mut rule = String::new();
        for l in &lights {
            head.push_str(&format!(" ΔE00 {l} mean / p95 / max |"));
            rule.push_str("---|");
        }
        if let Some(path) = &args.against {
            head.push_str(&format!(" {} Δe mean | ratio |", path.display()));
            rule.push_str("---|---|");
            for l in &lights {
                head.push_str(&format!(" {} ΔE00 {l} mean | ratio |", path.display()));
                rule.push_str("---|---|");
            }
        }
        outln!("| set | held out | spectra | Δe mean | Δe median | Δe max | in [0,1] |{head}")?;
        outln!("|---|---|---|---|---|---|---|{rule}")?;
        // A ratio below 1: this model does better on the set than the other.
        let vs = |mine: f64, theirs: f64| format!(" {theirs:.4} | {:.2} |", mine / theirs);
        for (k, s) in scores.sets.iter().enumerate() {
            let mut cells: String = s
                .summary
                .colour_shift
                .iter()
                .map(|x| format!(" {:.3} / {:.3} / {:.3} |", x.mean, x.p95, x.max))
                .collect();
            if let Some(o) = against {
                let theirs = &o.sets[k].summary;
                cells.push_str(&vs(s.summary.delta_e.mean, theirs.delta_e.mean));
                for (mine, theirs) in s.summary.colour_shift.iter().zip(&theirs.colour_shift) {
                    cells.push_str(&vs(mine.mean, theirs.mean));
                }
            }
            outln!(
                "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.3} |{cells}",
                s.source,
                s.how,
                s.summary.count,
                s.summary.delta_e.mean,
                s.summary.delta_e.median,
                s.summary.delta_e.max,
                s.summary.in_unit_range
            )?;
        }
        Ok(())
    }
}
