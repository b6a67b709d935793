//! Cost of bounded reflectances against the plain clustered-PCA uplift, measured in the same run
//! on whole RGB cubes (33³ colours of sRGB, Rec.2020 and ACEScg, built-in model, f32 as in
//! `convert`): the share of each cube's colours that need the projection or lie outside the
//! object-colour solid, the whole cube's cost, and the extra cost per pixel of each kind (the
//! cube's colours of that kind, bounded against plain). Outside the solid, the nearest colour
//! in CIELAB against the previous policy (the bisection towards grey): ΔE76 and ΔE2000 to the
//! input, and the cost of each, per colour.

use criterion::{criterion_group, criterion_main, Criterion};
use specconv_colour::lab::{ciede2000, xyz_to_lab};
use specconv_colour::mat3::mul_vec as apply;
use specconv_colour::rgb::{RgbSpace, ACESCG, REC2020, SRGB};
use specconv_spectral::bounded::{Bounded, Outcome};
use specconv_spectral::{Method, Model, Uplifter};
use std::hint::black_box;

const STEPS: usize = 33;

fn cube(space: RgbSpace, white: [f64; 3]) -> Vec<[f64; 3]> {
    let m = space.to_xyz(white);
    let s = (STEPS - 1) as f64;
    let mut out = Vec::with_capacity(STEPS * STEPS * STEPS);
    for r in 0..STEPS {
        for g in 0..STEPS {
            for b in 0..STEPS {
                out.push(apply(&m, [r as f64 / s, g as f64 / s, b as f64 / s]));
            }
        }
    }
    out
}

/// Median of 9 runs, in seconds.
fn median(f: &mut dyn FnMut()) -> f64 {
    specconv_testkit::median_seconds(9, f)
}

fn f32s(colours: &[[f64; 3]]) -> Vec<f32> {
    colours.iter().flatten().map(|&v| v as f32).collect()
}

fn stats(v: &[f64]) -> (f64, f64) {
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    (mean, v.iter().fold(0.0f64, |m, &x| m.max(x)))
}

fn bounded(c: &mut Criterion) {
    let model = Model::builtin();
    let a = model.colorimetry().unwrap();
    let white = a.white_xyz();
    let plain = Uplifter::new(model).unwrap();
    let bounded = Bounded::new(Uplifter::new(model).unwrap(), a.clone()).unwrap();
    let n = a.bands();
    for space in [SRGB, REC2020, ACESCG] {
        let colours = cube(space, white);
        // Each colour's kind, from the f32 uplift as `convert` sees it.
        let mut kinds: [Vec<[f64; 3]>; 3] = Default::default();
        let mut r = vec![0.0; n];
        let mut out32 = vec![0.0f32; n];
        for &col in &colours {
            let counts = bounded.uplift_f32_counted(&col.map(|v| v as f32), &mut out32);
            let k = [counts.in_range, counts.projected, counts.outside]
                .iter()
                .position(|&c| c == 1)
                .expect("finite colours");
            kinds[k].push(col);
        }
        let xyz = f32s(&colours);
        let count = colours.len();
        let mut out = vec![0.0f32; count * n];
        let t_plain = median(&mut || plain.uplift_f32(black_box(&xyz), &mut out));
        let t_bounded = median(&mut || bounded.uplift_f32(black_box(&xyz), &mut out));
        let share = |k: usize| 100.0 * kinds[k].len() as f64 / count as f64;
        println!(
            "{:9} {STEPS}³: projected {:5.1} %, outside the solid {:5.1} %; plain {:6.1} ns/px, \
             bounded {:7.1} ns/px, ratio {:6.2}",
            space.name,
            share(1),
            share(2),
            t_plain / count as f64 * 1e9,
            t_bounded / count as f64 * 1e9,
            t_bounded / t_plain
        );
        let mut extra = [f64::NAN; 3];
        for (k, name) in ["in range", "projected", "outside"].iter().enumerate() {
            if kinds[k].is_empty() {
                continue;
            }
            let xyz = f32s(&kinds[k]);
            let mut out = vec![0.0f32; kinds[k].len() * n];
            let tp = median(&mut || plain.uplift_f32(black_box(&xyz), &mut out));
            let tb = median(&mut || bounded.uplift_f32(black_box(&xyz), &mut out));
            extra[k] = (tb - tp) / kinds[k].len() as f64 * 1e9;
            println!(
                "{:9}   {name:>9}: {:6} colours, plain {:6.1} ns/px, bounded {:8.1} ns/px, \
                 extra {:8.1} ns/px, ratio {:7.2}",
                "",
                kinds[k].len(),
                tp / kinds[k].len() as f64 * 1e9,
                tb / kinds[k].len() as f64 * 1e9,
                extra[k],
                tb / tp
            );
        }
        if !kinds[2].is_empty() {
            // Outside: the CIELAB search against the bisection towards grey, in f64.
            let outside = &kinds[2];
            let mut r0 = vec![0.0; n];
            let (mut de76, mut de00, mut old76, mut old00) = (vec![], vec![], vec![], vec![]);
            for &col in outside {
                bounded.inner().uplift_f64(&col, &mut r0);
                r.copy_from_slice(&r0);
                let Outcome::Outside { reached, .. } = bounded.bound(col, &mut r) else {
                    continue;
                };
                let grey = bounded.towards_grey(col, &r0, &mut r);
                let lab = xyz_to_lab(col, white);
                for (to, e76, e00) in [
                    (reached, &mut de76, &mut de00),
                    (grey, &mut old76, &mut old00),
                ] {
                    let l = xyz_to_lab(to, white);
                    e76.push((0..3).map(|k| (l[k] - lab[k]).powi(2)).sum::<f64>().sqrt());
                    e00.push(ciede2000(lab, l));
                }
            }
            let r0s: Vec<Vec<f64>> = outside
                .iter()
                .map(|col| {
                    bounded.inner().uplift_f64(col, &mut r0);
                    r0.clone()
                })
                .collect();
            let t_new = median(&mut || {
                for (col, r0) in outside.iter().zip(&r0s) {
                    r.copy_from_slice(r0);
                    black_box(bounded.bound(*col, &mut r));
                }
            });
            let t_old = median(&mut || {
                for (col, r0) in outside.iter().zip(&r0s) {
                    black_box(bounded.solid().project(*col, r0, &mut r));
                    black_box(bounded.towards_grey(*col, r0, &mut r));
                }
            });
            let [(m76, x76), (m00, x00), (o76, ox76), (o00, ox00)] =
                [&de76, &de00, &old76, &old00].map(|v| stats(v));
            println!(
                "{:9}   outside, nearest in CIELAB: ΔE76 mean {m76:6.2} max {x76:6.2}, ΔE2000 \
                 mean {m00:6.2} max {x00:6.2}, {:7.1} ns/colour; towards grey: ΔE76 mean \
                 {o76:6.2} max {ox76:6.2}, ΔE2000 mean {o00:6.2} max {ox00:6.2}, {:7.1} ns/colour",
                "",
                t_new / outside.len() as f64 * 1e9,
                t_old / outside.len() as f64 * 1e9,
            );
        }
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
