//! Training cost on the Munsell set (read from ../shared), against a reference measured in the
//! same run: one PCA of the whole set (a 1-cluster model). The ratio says how many whole-set
//! PCAs the greedy tree costs.

use criterion::{criterion_group, criterion_main, Criterion};
use specconv_colour::{Colorimetry, Grid, Illuminant, Observer, SpectralTable};
use specconv_spectral::{train, TrainOptions, TrainingSet};

fn munsell(grid: &Grid) -> TrainingSet {
    let dir = std::env::var("SPECCONV_SHARED")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared").into());
    let file = "munsell1269_matte_380-800_1nm.csv";
    let text = std::fs::read_to_string(format!("{dir}/spectra/{file}"))
        .expect("../shared/spectra beside the checkout");
    let t = SpectralTable::parse(file, &text).unwrap();
    TrainingSet {
        sources: vec![file.into()],
        names: t.names.clone(),
        spectra: t.resampled(grid).unwrap(),
    }
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

criterion_group!(benches, training);
criterion_main!(benches);
