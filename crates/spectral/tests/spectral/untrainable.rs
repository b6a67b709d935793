//! Training data that cannot make a model: each kind gets an error that says what is wrong
//! (the table in `specconv_spectral::train`), and the data that can is trained with a defined outcome.

use specconv_colour::rgb::SRGB;
use specconv_colour::{Colorimetry, Grid, Illuminant, Observer};
use specconv_evaluation::extrapolation::rgb_cube;
use specconv_spectral::{train, Method, TrainOptions, TrainingSet, Uplifter};
use specconv_testkit::untrainable::{cases, metameric_black, mixture_weights, smooth};
use specconv_testkit::*;

fn setting() -> Colorimetry {
    Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap()
}

fn training_set(spectra: Vec<Vec<f64>>) -> TrainingSet {
    TrainingSet {
        sources: vec!["synthetic".into()],
        names: (0..spectra.len()).map(|k| format!("s{k}")).collect(),
        spectra,
        ..TrainingSet::default()
    }
}

fn small(clusters: usize) -> TrainOptions {
    TrainOptions {
        clusters,
        min_cluster_size: 4,
        ..TrainOptions::default()
    }
}

#[test]
fn each_untrainable_set_names_what_is_wrong() {
    let a = setting();
    for case in cases(&a) {
        for opts in [small(1), small(8)] {
            let err = train(&training_set(case.spectra.clone()), &a, &opts)
                .map(|m| format!("trained {} leaves", m.leaves.len()))
                .unwrap_or_else(|e| e.to_string());
            assert!(err.contains(case.error), "{}: {err}", case.name);
            assert!(err.starts_with("cannot train: "), "{}: {err}", case.name);
        }
    }
}

#[test]
fn the_metameric_black_is_invisible() {
    let a = setting();
    let black = metameric_black(&a, &smooth(11, a.bands()));
    let size = black.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(size > 0.05, "{size}");
    assert!(
        a.xyz(&black).iter().all(|v| v.abs() < 1e-12 * size),
        "{:?}",
        a.xyz(&black)
    );
}

#[test]
fn a_nearly_singular_m_is_refused_unless_the_bound_allows_it() {
    let a = setting();
    let n = a.bands();
    // Variation along a metameric black with a trace of visible colour: M is invertible but
    // ill-conditioned, 1/ε-fold.
    let base = smooth(3, n);
    let (v1, v2) = (smooth(5, n), smooth(8, n));
    let black = metameric_black(&a, &smooth(11, n));
    let visible = smooth(13, n);
    let dir: Vec<f64> = black
        .iter()
        .zip(&visible)
        .map(|(b, v)| b + 1e-3 * v)
        .collect();
    let spectra = (0..30)
        .map(|k| {
            let t = k as f64;
            (0..n)
                .map(|i| {
                    0.6 * base[i]
                        + 0.1 * (1.3 * t).sin() * v1[i]
                        + 0.1 * (2.9 * t).cos() * v2[i]
                        + (0.7 * t).sin() * dir[i]
                })
                .collect()
        })
        .collect();
    let set = training_set(spectra);
    let err = train(&set, &a, &small(1)).unwrap_err().to_string();
    assert!(
        err.contains("look almost alike") && err.contains("raise the condition bound"),
        "{err}"
    );
    let loose = TrainOptions {
        max_condition: 1e9,
        ..small(1)
    };
    let m = train(&set, &a, &loose).unwrap();
    assert!(
        m.leaves[0].condition > TrainOptions::default().max_condition,
        "{}",
        m.leaves[0].condition
    );
}

#[test]
fn duplicates_weigh_as_more_measurements() {
    // Every spectrum twice, with twice the minimum cluster size: the same scatter matrices
    // doubled, so the same splits and the same leaves, and twice the error.
    let a = setting();
    let once: Vec<Vec<f64>> = (0..200).map(|k| smooth(k, a.bands())).collect();
    let twice: Vec<Vec<f64>> = once.iter().flat_map(|s| [s.clone(), s.clone()]).collect();
    let opts = |min| TrainOptions {
        clusters: 4,
        min_cluster_size: min,
        ..TrainOptions::default()
    };
    let m1 = train(&training_set(once), &a, &opts(10)).unwrap();
    let m2 = train(&training_set(twice), &a, &opts(20)).unwrap();
    assert_eq!(m1.leaves.len(), 4);
    assert_eq!(m1.tree.len(), m2.tree.len());
    for (n1, n2) in m1.tree.iter().zip(m2.tree.iter()) {
        match (n1.split(), n2.split()) {
            (Some(s1), Some(s2)) => assert!(
                s1.axis == s2.axis && (s1.value - s2.value).abs() < 1e-12,
                "{n1:?} vs {n2:?}"
            ),
            _ => assert_eq!(n1, n2),
        }
    }
    for (l1, l2) in m1.leaves.iter().zip(&m2.leaves) {
        assert_eq!(2 * l1.count, l2.count);
        assert!(
            (2.0 * l1.error - l2.error).abs() <= 1e-9 * l2.error,
            "{} vs {}",
            l1.error,
            l2.error
        );
    }
}

#[test]
fn a_band_zero_in_every_spectrum_stays_zero() {
    let a = setting();
    let spectra: Vec<Vec<f64>> = (0..60)
        .map(|k| {
            let mut s = smooth(k, a.bands());
            s[0] = 0.0;
            s
        })
        .collect();
    let model = train(&training_set(spectra), &a, &small(2)).unwrap();
    let up = Uplifter::new(&model).unwrap();
    let mut r = vec![0.0; a.bands()];
    for c in rgb_cube(&SRGB, a.white_xyz(), 9) {
        up.uplift_f64(&c, &mut r);
        assert!(r[0].abs() <= 1e-12, "{c:?}: {}", r[0]);
        assert!(
            r[1..].iter().any(|v| v.abs() > 1e-6) || c == [0.0; 3],
            "{c:?}"
        );
    }
}

#[test]
fn measured_sets_with_one_spectrum_too_few_or_a_copy_too_many() {
    // The boundary of "too few": four differing spectra train; three do not.
    let a = setting();
    let cc = set(COLORCHECKER, &a.grid);
    let first = |k: usize| training_set(cc.spectra[..k].to_vec());
    assert!(train(&first(3), &a, &small(1)).is_err());
    let m = train(&first(4), &a, &small(1)).unwrap();
    assert_eq!(m.leaves[0].count, 4);
    // A copy among 24 measured spectra changes nothing but its weight.
    let mut copy = cc.clone();
    copy.spectra.push(cc.spectra[0].clone());
    copy.names.push("copy".into());
    assert_eq!(train(&copy, &a, &small(1)).unwrap().leaves[0].count, 25);
}

#[test]
fn a_split_that_would_leave_a_flat_side_is_not_taken() {
    // 12 mixtures of three reds (varying in only 2 directions), redder than 40 varied spectra:
    // the split between them would give the reds a leaf that fits them perfectly but whose
    // third component is rounding noise. It is not taken; the reds' leaf holds others too.
    let a = setting();
    let n = a.bands();
    let mut spectra: Vec<Vec<f64>> = (0..40).map(|k| smooth(k, n)).collect();
    let red = |edge: usize, low: f64| -> Vec<f64> {
        (0..n).map(|i| if i > edge { 0.9 } else { low }).collect()
    };
    let reds = [red(25, 0.05), red(27, 0.08), red(23, 0.03)];
    let mixtures: Vec<Vec<f64>> = (0..12)
        .map(|k| {
            let (u, v) = mixture_weights(k);
            (0..n)
                .map(|b| u * reds[0][b] + v * reds[1][b] + (1.0 - u - v) * reds[2][b])
                .collect()
        })
        .collect();
    let x = |s: &[f64]| {
        let c = a.xyz(s);
        c[0] / (c[0] + c[1] + c[2])
    };
    let reddest_other = spectra.iter().map(|s| x(s)).fold(0.0, f64::max);
    assert!(mixtures.iter().all(|s| x(s) > reddest_other));
    spectra.extend(mixtures.iter().cloned());
    let model = train(&training_set(spectra.clone()), &a, &small(2)).unwrap();
    assert_eq!(model.leaves.len(), 2);
    let up = Uplifter::new(&model).unwrap();
    // Per leaf: spectra of the set in it, and mixtures among them.
    let mut members = [(0, 0); 2];
    for (k, s) in spectra.iter().enumerate() {
        let leaf = up.leaf(a.xyz(s));
        members[leaf].0 += 1;
        members[leaf].1 += usize::from(k >= 40);
    }
    for (leaf, (all, mixed)) in members.iter().enumerate() {
        assert_eq!(*all, model.leaves[leaf].count);
        assert!(
            *mixed == 0 || all > mixed,
            "leaf {leaf}: {mixed} mixtures alone"
        );
    }
}
