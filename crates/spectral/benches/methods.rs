//! Per-colour cost of every uplift method (f32, 36 bands, 4096 colours per call), against a
//! reference measured in the same run: writing the same 36 floats per colour with no arithmetic
//! (the store bandwidth an uplift cannot beat). The ratio says how far each method is from it.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specconv_colour::{Colorimetry, Grid, Illuminant, Observer};
use specconv_spectral::baselines::jakob::Table;
use specconv_spectral::baselines::{Jakob2019, Meng2015, Smits1999};
use specconv_spectral::{Method, Model, Uplifter};

const N: usize = 4096;

/// The reference: the stores of an uplift without its arithmetic.
fn store_only(xyz: &[f32], out: &mut [f32], n: usize) {
    for (c, r) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
        r.fill(c[1]);
    }
}

fn methods(c: &mut Criterion) {
    let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
    let n = a.bands();
    let xyz = specconv_testkit::random_colours(&a, N, 1);
    let mut out = vec![0f32; N * n];
    let all: Vec<Box<dyn Method>> = vec![
        Box::new(Uplifter::new(Model::builtin()).unwrap()),
        Box::new(Smits1999::new(&a).unwrap()),
        Box::new(Meng2015::new(&a, false).unwrap()),
        Box::new(Meng2015::new(&a, true).unwrap()),
        Box::new(Jakob2019::new(&a, Table::build(&a, 32).unwrap()).unwrap()),
    ];
    let mut g = c.benchmark_group("uplift_f32_36_bands");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("reference_store_only", |b| {
        b.iter(|| store_only(&xyz, &mut out, n))
    });
    for m in &all {
        g.bench_function(m.name(), |b| b.iter(|| m.uplift_f32(&xyz, &mut out)));
    }
    g.finish();

    // Ratios to the reference from medians of runs measured here.
    let median = |f: &mut dyn FnMut()| specconv_testkit::median_seconds(21, f);
    let reference = median(&mut || store_only(&xyz, &mut out, n));
    eprintln!(
        "reference (stores only): {:.2} ns/colour, {:.0} M colours/s",
        reference * 1e9 / N as f64,
        N as f64 / reference / 1e6
    );
    for m in &all {
        let t = median(&mut || m.uplift_f32(&xyz, &mut out));
        eprintln!(
            "{:18} {:8.2} ns/colour {:8.1} M colours/s  {:6.2}× the reference",
            m.name(),
            t * 1e9 / N as f64,
            N as f64 / t / 1e6,
            t / reference
        );
    }
}

criterion_group!(benches, methods);
criterion_main!(benches);
