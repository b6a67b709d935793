//! Training cost on the Munsell set (read from ../shared), against a reference measured in the
//! same run: one PCA of the whole set (a 1-cluster model). The ratio says how many whole-set
//! PCAs the greedy tree costs.
//!
//! Also the work of `specconv train` on that set in this process, part by part (read and parse
//! the 1 nm CSV, resample it to the default 36 bands, train 8 clusters, the model's JSON),
//! against the numpy reference figure of issue 15: 2.9 s for the same training.
//!
//! And how training scales: every set of ../shared/spectra together (3339 spectra), a quarter,
//! a half and all of them (every 4th, 2nd spectrum) at 8, 16 and 32 clusters (minimum 20),
//! as times and as ratios to the quarter at 8 clusters (issue 23 asks all of them at 32
//! clusters in under 1 s). What the
//! process spends before `main` (loading the CLI's shared libraries) is not in it; see
//! docs/performance.md.

use criterion::{criterion_group, criterion_main, Criterion};
use specconv_colour::{Colorimetry, Grid, Illuminant, Observer, SpectralTable};
use specconv_spectral::{train, TrainOptions, TrainingSet};

const FILE: &str = "munsell1269_matte_380-800_1nm.csv";

/// The numpy reference's time for training 8 clusters on the Munsell set (issue 15).
const NUMPY_SECONDS: f64 = 2.9;

fn path() -> String {
    let dir = std::env::var("SPECCONV_SHARED")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared").into());
    format!("{dir}/spectra/{FILE}")
}

fn parse() -> SpectralTable {
    let text = std::fs::read_to_string(path()).expect("../shared/spectra beside the checkout");
    SpectralTable::parse(FILE, &text).unwrap()
}

fn training_set(t: &SpectralTable, grid: &Grid) -> TrainingSet {
    TrainingSet::from_table(t, grid).unwrap()
}

fn munsell(grid: &Grid) -> TrainingSet {
    training_set(&parse(), grid)
}

fn training(c: &mut Criterion) {
    let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
    let set = munsell(&a.grid);
    let opts = |clusters, min_cluster_size| TrainOptions {
        clusters,
        min_cluster_size,
        ..TrainOptions::default()
    };
    let mut g = c.benchmark_group("train_munsell_36_bands");
    g.sample_size(10);
    g.bench_function("reference_1_cluster", |b| {
        b.iter(|| train(&set, &a, &opts(1, 20)).unwrap())
    });
    g.bench_function("8_clusters_min_20", |b| {
        b.iter(|| train(&set, &a, &opts(8, 20)).unwrap())
    });
    g.bench_function("8_clusters_min_4", |b| {
        b.iter(|| train(&set, &a, &opts(8, 4)).unwrap())
    });
    g.finish();

    // The ratio, from medians of a few runs measured here.
    let median = |f: &dyn Fn()| specconv_testkit::median_seconds(7, &mut || f());
    // `specconv train`'s work, part by part, as the command does it.
    let table = parse();
    let t_parse = median(&|| drop(parse()));
    let t_resample = median(&|| drop(training_set(&table, &a.grid)));
    let model = train(&set, &a, &opts(8, 20)).unwrap();
    let t_json = median(&|| drop(model.to_json()));
    let t_whole = median(&|| {
        let t = parse();
        drop(
            train(&training_set(&t, &a.grid), &a, &opts(8, 20))
                .unwrap()
                .to_json(),
        )
    });
    println!(
        "specconv train's work (Munsell 1269 at 1 nm → 36 bands, 8 clusters, min 20): {:.1} ms \
         = {:.3} × numpy's {NUMPY_SECONDS} s (read and parse {:.1} ms, resample {:.1} ms, train \
         the rest, JSON {:.1} ms; load {})",
        t_whole * 1e3,
        t_whole / NUMPY_SECONDS,
        t_parse * 1e3,
        t_resample * 1e3,
        t_json * 1e3,
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .split(' ')
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );
    let reference = median(&|| drop(train(&set, &a, &opts(1, 20)).unwrap()));
    for (k, min) in [(8, 20), (8, 4)] {
        let t = median(&|| drop(train(&set, &a, &opts(k, min)).unwrap()));
        println!(
            "train {k} clusters (min {min}): {:.1} ms = {:.0} × one whole-set PCA ({:.3} ms)",
            t * 1e3,
            t / reference,
            reference * 1e3
        );
    }
}

fn scaling(_: &mut Criterion) {
    let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
    let parts: Vec<specconv_spectral::Part> = specconv_testkit::ALL_SETS
        .iter()
        .map(|f| specconv_spectral::Part {
            set: specconv_testkit::set(f, &a.grid),
            weight: 1.0,
            terms: Default::default(),
        })
        .collect();
    let all = TrainingSet::weighted(&parts);
    let median = |f: &dyn Fn()| specconv_testkit::median_seconds(5, &mut || f());
    let mut reference = None;
    for every in [4, 2, 1] {
        let set = all.subset(|k| k % every == 0);
        for k in [8, 16, 32] {
            let opts = TrainOptions {
                clusters: k,
                ..TrainOptions::default()
            };
            let leaves = train(&set, &a, &opts).unwrap().leaves.len();
            let t = median(&|| drop(train(&set, &a, &opts).unwrap()));
            let r = *reference.get_or_insert(t);
            println!(
                "train all sets, n = {:4}, k = {k:2} ({leaves:2} leaves grown): {:7.1} ms = {:5.2} × n = {}, k = 8",
                set.spectra.len(),
                t * 1e3,
                t / r,
                all.spectra.len().div_ceil(4)
            );
        }
    }
}

criterion_group!(benches, training, scaling);
criterion_main!(benches);
