//! Cost of blending across cluster boundaries (f32, 36 bands, 4096 colours per call), as
//! ratios to the hard switch measured in the same run: on random linear sRGB colours, and on
//! colours all within the blend width of a split line of the built-in model. And the one-off
//! cost of making the blend (the per-split widths), in colours of hard uplift.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specconv_spectral::otsu2018::blend::DEFAULT_WIDTH;
use specconv_spectral::otsu2018::tree::Axis;
use specconv_spectral::{Method, Model, Uplifter};
use std::time::Instant;

const N: usize = 4096;

/// Random linear sRGB colours in [0, 1]³, as XYZ.
fn uniform() -> Vec<f32> {
    let a = Model::builtin().colorimetry().unwrap();
    specconv_testkit::random_colours(&a, N, 1)
}

/// Colours whose xy lies within the default width of a split line (Y in [0.05, 0.8]).
fn near_boundaries() -> Vec<f32> {
    let splits: Vec<(Axis, f64)> = Model::builtin()
        .tree
        .splits()
        .map(|(_, s)| (s.axis, s.value))
        .collect();
    let mut rng = specconv_testkit::Lcg::new(2);
    let mut next = || rng.uniform();
    (0..N)
        .flat_map(|i| {
            let (axis, v) = splits[i % splits.len()];
            let mut xy = [0.2 + 0.3 * next(), 0.2 + 0.3 * next()];
            xy[if axis == Axis::X { 0 } else { 1 }] = v + (2.0 * next() - 1.0) * DEFAULT_WIDTH;
            let y = 0.05 + 0.75 * next();
            [xy[0] / xy[1] * y, y, (1.0 - xy[0] - xy[1]) / xy[1] * y].map(|v| v as f32)
        })
        .collect()
}

fn blend(c: &mut Criterion) {
    let hard = Uplifter::new(Model::builtin()).unwrap();
    let soft = hard.clone().with_blend(DEFAULT_WIDTH).unwrap();
    let mut out = vec![0f32; N * hard.bands()];
    let sets = [
        ("uniform", uniform()),
        ("near_boundaries", near_boundaries()),
    ];
    let mut g = c.benchmark_group("blend_f32_36_bands");
    g.throughput(Throughput::Elements(N as u64));
    for (name, xyz) in &sets {
        g.bench_function(format!("{name}/hard"), |b| {
            b.iter(|| hard.uplift_f32(xyz, &mut out))
        });
        g.bench_function(format!("{name}/blend"), |b| {
            b.iter(|| soft.uplift_f32(xyz, &mut out))
        });
    }
    g.finish();

    // Ratios from medians of interleaved runs measured here.
    for (name, xyz) in &sets {
        let (mut th, mut ts) = (Vec::new(), Vec::new());
        for _ in 0..41 {
            for (up, t) in [(&hard, &mut th), (&soft, &mut ts)] {
                let s = Instant::now();
                up.uplift_f32(xyz, &mut out);
                t.push(s.elapsed().as_secs_f64());
            }
        }
        let median = |t: &mut Vec<f64>| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        };
        let (h, s) = (median(&mut th), median(&mut ts));
        eprintln!(
            "{name:16} hard {:6.1} M colours/s, blend {:6.1} M colours/s: {:.2}× the hard switch's time",
            N as f64 / h / 1e6,
            N as f64 / s / 1e6,
            s / h
        );
    }

    // Making the blend, against uplifting the uniform colours by the hard switch.
    let (mut tm, mut th) = (Vec::new(), Vec::new());
    for _ in 0..11 {
        let s = Instant::now();
        let made = hard.clone().with_blend(DEFAULT_WIDTH).unwrap();
        tm.push(s.elapsed().as_secs_f64());
        assert_eq!(made.blend_width(), DEFAULT_WIDTH);
        let s = Instant::now();
        hard.uplift_f32(&sets[0].1, &mut out);
        th.push(s.elapsed().as_secs_f64());
    }
    tm.sort_by(f64::total_cmp);
    th.sort_by(f64::total_cmp);
    let (m, h) = (tm[tm.len() / 2], th[th.len() / 2]);
    eprintln!(
        "with_blend       {:.2} ms: the time of uplifting {:.0} colours by the hard switch",
        m * 1e3,
        m / h * N as f64
    );
}

criterion_group!(benches, blend);
criterion_main!(benches);
