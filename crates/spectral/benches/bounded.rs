//! Cost of bounded reflectances against the plain clustered-PCA uplift, measured in the same run
//! on whole RGB cubes (33³ colours of sRGB, Rec.2020 and ACEScg, built-in model, f32 as in
//! `convert`), and the share of each cube's colours that need the projection or lie outside
//! the object-colour solid.

use criterion::{criterion_group, criterion_main, Criterion};
use spectral::bounded::Bounded;
use spectral::primaries::{apply, RgbSpace, ACESCG, REC2020, SRGB};
use spectral::{Method, Model, Uplifter};
use std::hint::black_box;
use std::time::Instant;

const STEPS: usize = 33;

fn cube(space: RgbSpace, white: [f64; 3]) -> Vec<f32> {
    let m = space.to_xyz(white);
    let s = (STEPS - 1) as f64;
    let mut out = Vec::with_capacity(STEPS * STEPS * STEPS * 3);
    for r in 0..STEPS {
        for g in 0..STEPS {
            for b in 0..STEPS {
                let c = apply(&m, [r as f64 / s, g as f64 / s, b as f64 / s]);
                out.extend(c.map(|v| v as f32));
            }
        }
    }
    out
}

fn bounded(c: &mut Criterion) {
    let model = Model::builtin();
    let a = model.colorimetry().unwrap();
    let plain = Uplifter::new(model).unwrap();
    let bounded = Bounded::new(Uplifter::new(model).unwrap(), a.clone()).unwrap();
    let n = a.bands();
    let median = |f: &mut dyn FnMut()| {
        let mut t: Vec<f64> = (0..9)
            .map(|_| {
                let s = Instant::now();
                f();
                s.elapsed().as_secs_f64()
            })
            .collect();
        t.sort_by(f64::total_cmp);
        t[4]
    };
    for space in [SRGB, REC2020, ACESCG] {
        let xyz = cube(space, a.white_xyz());
        let count = xyz.len() / 3;
        let mut out = vec![0.0f32; count * n];
        let counts = bounded.uplift_f32_counted(&xyz, &mut out);
        let share = |k: usize| 100.0 * k as f64 / count as f64;
        let t_plain = median(&mut || plain.uplift_f32(black_box(&xyz), &mut out));
        let t_bounded = median(&mut || bounded.uplift_f32(black_box(&xyz), &mut out));
        println!(
            "{:9} {STEPS}³: projected {:5.1} %, outside the solid {:5.1} %; plain {:6.1} ns/px, \
             bounded {:7.1} ns/px, ratio {:5.1}",
            space.name,
            share(counts.projected),
            share(counts.outside),
            t_plain / count as f64 * 1e9,
            t_bounded / count as f64 * 1e9,
            t_bounded / t_plain
        );
        let mut g = c.benchmark_group(format!("uplift_f32_{}_cube", space.name));
        g.sample_size(10);
        g.bench_function("reference_plain", |b| {
            b.iter(|| plain.uplift_f32(black_box(&xyz), &mut out))
        });
        g.bench_function("bounded", |b| {
            b.iter(|| bounded.uplift_f32(black_box(&xyz), &mut out))
        });
        g.finish();
    }
}

criterion_group!(benches, bounded);
criterion_main!(benches);
