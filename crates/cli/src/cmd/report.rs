//! `specconv report`: every method on the same spectra, accuracy and cost in one table.

use crate::picture::Format;
use crate::{files, methods};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use specconv_atomic_file::Replace;
use specconv_colour::{Colorimetry, Grid};
use specconv_convert_cmd::errors::usage;
use specconv_convert_cmd::stdio::StdoutFailed;
use specconv_evaluation::{cost, eval};
use specconv_figures::plot;
use specconv_flags::defs;
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::{Setting, Stack, StackSpec};
use specconv_spectral::{Method, Model, TrainOptions};
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv report --spectra colorchecker.csv --train munsell.csv --plot cost.svg
  specconv report --spectra munsell.csv --holdout 5 --csv > table.csv
  specconv report --by-set --spectra munsell.csv --spectra usgs_soils.csv --spectra leaves.csv
";

specconv_flags::args! {
    /// Measure every uplift method on the same measured spectra: accuracy against cost.
    ///
    /// Rows: smits1999, meng2015, meng2015-bounded, jakob2019, pca, otsu2018 at each --clusters
    /// count (with 8, also otsu2018-bounded: its spectra kept in [0, 1] with their XYZ, as
    /// `convert` writes them by default), and otsu2018 with 8 clusters at each --steps band
    /// width. Columns: Δe = ‖s − r‖² mean,
    /// median and max; the colour shift under each --shift-under illuminant (CIEDE2000 between
    /// measured and uplifted spectra lit by it: mean, 95th percentile, max); the round trip (max |XYZ(r) − XYZ(s)| / Y(s) and max CIEDE2000); the
    /// fraction of spectra inside [0, 1]; the model's size in bytes (the data the f32 uplift
    /// reads); and the cost of the f32 uplift alone, in nanoseconds per colour and Mpixel/s, on one
    /// thread and on all, measured in this run over --colours random linear sRGB colours, 4096 per
    /// tile. The clustered models are trained on --train (default: --spectra itself, the paper's
    /// Table 1 setting) or, with --holdout K, K-fold on --spectra: trained on K−1 parts, evaluated
    /// on the held-out one; or, with --by-set, leave one set out: each --spectra file evaluated by
    /// the model trained on the other files (weighted by --weights and --balance), the row's
    /// figures over all files, and its note the mean over files and the worst file.
    #[derive(Debug)]
    pub struct Args {
        spectra: Vec<PathBuf> = (defs::REPORT_SPECTRA),
        train: Vec<PathBuf> = (defs::REPORT_TRAIN),
        by_set: bool = (defs::REPORT_BY_SET),
        weights: methods::WeightArgs = flatten,
        holdout: Option<u32> = (defs::REPORT_HOLDOUT),
        clusters: Vec<usize> = (defs::REPORT_CLUSTERS),
        steps: Vec<f64> = (defs::REPORT_STEPS),
        min_cluster_size: usize = (defs::REPORT_MIN_CLUSTER_SIZE),
        colorimetry: methods::ColorimetryArgs = flatten,
        blend: methods::BlendArg = flatten,
        shift: methods::ShiftArg = flatten,
        jakob: methods::JakobArg = flatten,
        colours: usize = (defs::REPORT_COLOURS),
        threads: Option<usize> = (defs::REPORT_THREADS),
        json: bool = (defs::REPORT_JSON),
        csv: bool = (defs::REPORT_CSV),
        plot: Option<PathBuf> = (defs::REPORT_PLOT),
    }
}

#[derive(Debug, Serialize)]
struct Row {
    method: String,
    setting: String,
    bands: usize,
    count: usize,
    delta_e_mean: f64,
    delta_e_median: f64,
    delta_e_max: f64,
    colour_shift: Vec<eval::ShiftStats>,
    roundtrip_max: f64,
    roundtrip_de2000_max: f64,
    in_unit_range: f64,
    model_bytes: usize,
    ns_per_colour_1_thread: f64,
    mpixel_per_s_1_thread: f64,
    ns_per_colour_all_threads: f64,
    mpixel_per_s_all_threads: f64,
    threads: usize,
    /// Why a clustered row has fewer clusters than --clusters asked for; null otherwise.
    note: Option<String>,
}

pub fn run(args: Args) -> Result<()> {
    let plot_format = args
        .plot
        .as_deref()
        .map(|p| Format::of(p, "--plot", &[Format::Svg, Format::Png]))
        .transpose()?;
    // A plot is remade as often as the report runs: replaced, never over a spectra file.
    let inputs: Vec<&std::path::Path> = args
        .spectra
        .iter()
        .chain(&args.train)
        .map(PathBuf::as_path)
        .collect();
    if let Some(p) = &args.plot {
        files::check_writable(p, &inputs, Replace::Allowed)?;
    }
    if args.colours == 0 {
        return Err(usage(anyhow::anyhow!("--colours must be at least 1")));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start worker threads")?;
    let mut rows = baseline_rows(&args, &pool)?;
    rows.extend(clustered_rows(&args, &pool)?);
    if let (Some(path), Some(format)) = (&args.plot, plot_format) {
        let points = rows_for_plot(&rows);
        let bytes = match format {
            Format::Svg => plot::svg(&points)?.into_bytes(),
            Format::Png => plot::png(&points)?,
        };
        files::write_atomically(path, &bytes, &inputs, Replace::Allowed)?;
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&rows)?)?;
    } else if args.csv {
        print_csv(&rows)?;
    } else {
        print_table(&rows, &args, pool.current_num_threads())?;
    }
    Ok(())
}

/// The rows of the baselines, in the setting of the flags.
fn baseline_rows(args: &Args, pool: &rayon::ThreadPool) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for name in [
        MethodName::Smits1999,
        MethodName::Meng2015,
        MethodName::Meng2015Bounded,
        MethodName::Jakob2019,
    ] {
        let d = StackSpec::measured(
            name,
            args.blend.options.blend,
            args.colorimetry.setting(),
            args.jakob.resolution,
            false,
        );
        let stack = methods::build(&d, Model::builtin())?;
        let (m, a) = (stack.method(), stack.colorimetry());
        let spectra = read(&args.spectra, &a.grid)?;
        let summary = eval::summarise(&eval::evaluate(a, m, &spectra, &args.shift.viewing(a)?));
        let setting = match name {
            MethodName::Jakob2019 => format!("{}³ table", args.jakob.resolution),
            _ => String::new(),
        };
        rows.push(row(args, pool, a, m, name.as_str(), setting, &summary));
        errln!("specconv: measured {name}");
    }
    Ok(rows)
}

/// The rows of the clustered models: each --clusters count on --bands (8 clusters also
/// bounded, the built-in model's setting), and 8 clusters on each --steps band width.
fn clustered_rows(args: &Args, pool: &rayon::ThreadPool) -> Result<Vec<Row>> {
    let bands = args.colorimetry.bands;
    let mut settings: Vec<(usize, Grid)> = args.clusters.iter().map(|&k| (k, bands)).collect();
    for &step in &args.steps {
        let g = Grid::new(bands.start, bands.end, step)?;
        if g != bands {
            settings.push((8, g));
        }
    }
    let rows_of = settings.iter().flat_map(|&(k, g)| {
        let twin = (k == 8 && g == bands).then_some((k, g, true));
        [(k, g, false)].into_iter().chain(twin)
    });
    let mut rows = Vec::new();
    for (k, grid, bounded) in rows_of.collect::<Vec<_>>() {
        let a = args.colorimetry.on(grid)?;
        let (model, summary, by_set_note) = clustered(args, &a, k, bounded)?;
        let stack = uplifter(args, &model, bounded)?;
        let name = match (k, bounded) {
            (1, _) => "pca",
            (_, false) => "otsu2018",
            (_, true) => "otsu2018-bounded",
        };
        let fewer = files::fewer_clusters(&model);
        let mut setting = if fewer.is_some() {
            format!("{} of {k} clusters", model.leaves.len())
        } else {
            format!("{} clusters", model.leaves.len())
        };
        if args.blend.options.blend > 0.0 && model.leaves.len() > 1 {
            setting = format!("{setting}, blend {}", args.blend.options.blend);
        }
        if grid != bands {
            setting = format!("{setting}, {} nm", grid.step);
        }
        if let Some(h) = args.holdout {
            setting = format!("{setting}, {h}-fold");
        }
        if let Some(why) = &fewer {
            errln!("specconv: warning: {name} on {grid}: {why}");
        }
        if args.by_set {
            setting = format!("{setting}, by set");
        }
        let note = [fewer, by_set_note]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>();
        rows.push(Row {
            note: (!note.is_empty()).then(|| note.join("; ")),
            ..row(args, pool, &a, stack.method(), name, setting, &summary)
        });
        errln!("specconv: measured {name} with {k} clusters on {grid}");
    }
    Ok(rows)
}

fn read(paths: &[PathBuf], grid: &Grid) -> Result<Vec<Vec<f64>>> {
    let mut spectra = Vec::new();
    for p in paths {
        spectra.extend(files::read_spectra(p)?.resampled(grid)?);
    }
    Ok(spectra)
}

/// The clustered uplift of `model` with the --blend width, bounded or not.
fn uplifter(args: &Args, model: &Model, bounded: bool) -> Result<Stack> {
    let d = StackSpec::measured(
        MethodName::Otsu2018,
        args.blend.options.blend,
        Setting::default(),
        args.jakob.resolution,
        bounded,
    );
    methods::build(&d, model)
}

/// The model used for timing (trained on all training data, or on the first fold's) and the
/// accuracy summary (on the evaluated spectra, or over the held-out folds).
fn clustered(
    args: &Args,
    a: &Colorimetry,
    k: usize,
    bounded: bool,
) -> Result<(Model, eval::Statistics, Option<String>)> {
    let opts = TrainOptions {
        clusters: k,
        min_cluster_size: args.min_cluster_size,
        ..TrainOptions::default()
    };
    let viewing = args.shift.viewing(a)?;
    let evaluate = |model: &Model, spectra: &[Vec<f64>]| -> Result<Vec<eval::Outcome>> {
        let stack = uplifter(args, model, bounded)?;
        Ok(eval::evaluate(a, stack.method(), spectra, &viewing))
    };
    if args.by_set {
        return by_set(args, a, opts, evaluate);
    }
    let eval_set = methods::training_set(&args.spectra, &a.grid)?;
    let Some(folds) = args.holdout.map(|h| h as usize) else {
        let train = if args.train.is_empty() {
            eval_set.clone()
        } else {
            methods::training_set(&args.train, &a.grid)?
        };
        let model = specconv_spectral::train(&train, a, &opts)?;
        let s = eval::summarise(&evaluate(&model, &eval_set.spectra)?);
        return Ok((model, s, None));
    };
    if eval_set.spectra.len() < folds {
        bail!(
            "--holdout {folds}: only {} spectra to split",
            eval_set.spectra.len()
        );
    }
    let (first, outcomes) = eval::cross_validate(&eval_set, a, &opts, folds, evaluate)?;
    Ok((first, eval::summarise(&outcomes), None))
}

/// Leave one set out over the --spectra files: the model on all of them (for timing), the
/// summary over every held-out spectrum, and a note with the mean over files and the worst.
fn by_set(
    args: &Args,
    a: &Colorimetry,
    options: TrainOptions,
    evaluate: impl Fn(&Model, &[Vec<f64>]) -> Result<Vec<eval::Outcome>>,
) -> Result<(Model, eval::Statistics, Option<String>)> {
    use specconv_evaluation::sets::{held_out_by_set, Holdout, Recipe};
    if args.spectra.len() < 2 {
        return Err(usage(anyhow::anyhow!(
            "--by-set leaves one --spectra file out at a time: give at least two"
        )));
    }
    let parts = methods::weighted_parts(&args.spectra, &a.grid, &args.weights)?;
    let tests: Vec<_> = parts.iter().map(|p| p.set.clone()).collect();
    let recipe = Recipe {
        parts,
        balance: args.weights.balance,
        options,
    };
    let mut outcomes = Vec::new();
    let scores = held_out_by_set(&recipe, &tests, a, Holdout::Set, |m, held| {
        let o = evaluate(m, held)?;
        outcomes.extend(o.iter().cloned());
        Ok::<_, anyhow::Error>(o)
    })?;
    let model = recipe.train(a)?;
    let shift: String = scores
        .colour_shift
        .iter()
        .map(|x| {
            format!(
                "; ΔE00 under {} mean {:.3}, worst {:.3} ({})",
                x.illuminant, x.mean_of_sets, x.worst, x.worst_set
            )
        })
        .collect();
    let note = format!(
        "by set: mean over {} files Δe {:.4}, worst {:.4} ({}){shift}",
        scores.sets.len(),
        scores.mean_of_sets,
        scores.worst,
        scores.worst_set
    );
    Ok((model, eval::summarise(&outcomes), Some(note)))
}

fn row(
    args: &Args,
    pool: &rayon::ThreadPool,
    a: &Colorimetry,
    m: &dyn Method,
    name: &str,
    setting: String,
    s: &eval::Statistics,
) -> Row {
    let xyz = cost::timing_colours(a, args.colours);
    let (t1, tn) = specconv_conversion::cost::time(m, &xyz, pool);
    let c = args.colours as f64;
    Row {
        method: name.to_string(),
        setting,
        bands: a.bands(),
        count: s.count,
        delta_e_mean: s.delta_e.mean,
        delta_e_median: s.delta_e.median,
        delta_e_max: s.delta_e.max,
        colour_shift: s.colour_shift.clone(),
        roundtrip_max: s.roundtrip_max,
        roundtrip_de2000_max: s.roundtrip_de2000_max,
        in_unit_range: s.in_unit_range,
        model_bytes: m.model_bytes(),
        ns_per_colour_1_thread: t1 * 1e9 / c,
        mpixel_per_s_1_thread: c / t1 / 1e6,
        ns_per_colour_all_threads: tn * 1e9 / c,
        mpixel_per_s_all_threads: c / tn / 1e6,
        threads: pool.current_num_threads(),
        note: None,
    }
}

fn rows_for_plot(rows: &[Row]) -> Vec<plot::Point> {
    rows.iter()
        .map(|r| plot::Point {
            label: if r.setting.is_empty() {
                r.method.clone()
            } else {
                format!("{} ({})", r.method, r.setting)
            },
            ns: r.ns_per_colour_1_thread,
            delta_e: r.delta_e_mean,
        })
        .collect()
}

fn print_csv(rows: &[Row]) -> Result<(), StdoutFailed> {
    let lights = rows.first().map_or(&[][..], |r| &r.colour_shift[..]);
    let shift_heads: String = lights
        .iter()
        .map(|s| {
            let l = s.illuminant;
            format!("ciede2000_{l}_mean,ciede2000_{l}_p95,ciede2000_{l}_max,")
        })
        .collect();
    outln!(
        "method,setting,bands,count,delta_e_mean,delta_e_median,delta_e_max,{shift_heads}\
         roundtrip_max,roundtrip_de2000_max,in_unit_range,model_bytes,ns_per_colour_1_thread,\
         mpixel_per_s_1_thread,ns_per_colour_all_threads,mpixel_per_s_all_threads,threads,note"
    )?;
    for r in rows {
        let shifts: String = r
            .colour_shift
            .iter()
            .map(|s| format!("{},{},{},", s.mean, s.p95, s.max))
            .collect();
        outln!(
            "{},\"{}\",{},{},{},{},{},{shifts}{},{},{},{},{},{},{},{},{},\"{}\"",
            r.method,
            r.setting,
            r.bands,
            r.count,
            r.delta_e_mean,
            r.delta_e_median,
            r.delta_e_max,
            r.roundtrip_max,
            r.roundtrip_de2000_max,
            r.in_unit_range,
            r.model_bytes,
            r.ns_per_colour_1_thread,
            r.mpixel_per_s_1_thread,
            r.ns_per_colour_all_threads,
            r.mpixel_per_s_all_threads,
            r.threads,
            r.note.as_deref().unwrap_or_default()
        )?;
    }
    Ok(())
}

/// A Markdown table, so that it can be pasted into documents as it is.
fn print_table(rows: &[Row], args: &Args, threads: usize) -> Result<(), StdoutFailed> {
    let heads: String = args
        .shift
        .shift_under
        .iter()
        .map(|l| format!(" shift {l}: ΔE00 mean / p95 / max |"))
        .collect();
    outln!(
        "| method | setting | bands | Δe mean | Δe median | Δe max |{heads} round trip | ΔE00 max | in [0,1] | bytes | ns/colour (1 thread) | Mpixel/s (1 thread) | Mpixel/s ({threads} threads) |"
    )?;
    outln!(
        "|---|---|---|---|---|---|{}---|---|---|---|---|---|---|",
        "---|".repeat(args.shift.shift_under.len())
    )?;
    for r in rows {
        let shifts: String = r
            .colour_shift
            .iter()
            .map(|s| format!(" {:.3} / {:.3} / {:.3} |", s.mean, s.p95, s.max))
            .collect();
        outln!(
            "| {} | {} | {} | {:.4} | {:.4} | {:.4} |{shifts} {:.1e} | {:.2e} | {:.3} | {} | {:.1} | {:.1} | {:.1} |",
            r.method,
            r.setting,
            r.bands,
            r.delta_e_mean,
            r.delta_e_median,
            r.delta_e_max,
            r.roundtrip_max,
            r.roundtrip_de2000_max,
            r.in_unit_range,
            r.model_bytes,
            r.ns_per_colour_1_thread,
            r.mpixel_per_s_1_thread,
            r.mpixel_per_s_all_threads,
        )?;
    }
    outln!()?;
    outln!(
        "{} spectra; {}, {}; cost: f32 uplift of {} colours, {} per tile.",
        rows.first().map_or(0, |r| r.count),
        args.colorimetry.observer,
        args.colorimetry.illuminant,
        args.colours,
        cost::TILE
    )?;
    for r in rows {
        if let Some(note) = &r.note {
            outln!("note: {} ({}): {note}", r.method, r.setting)?;
        }
    }
    Ok(())
}
