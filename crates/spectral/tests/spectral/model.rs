//! Training, the model file and the runtime on the Munsell set with the built-in settings.

use proptest::prelude::*;
use specconv_colour::{Colorimetry, Grid, Illuminant, Observer};
use specconv_evaluation::eval;
use specconv_spectral::otsu2018::tree::{Node, Split, Tree};
use specconv_spectral::Method;
use specconv_spectral::{train, Model, TrainOptions, Uplifter};
use specconv_testkit::*;

fn default_setting() -> Colorimetry {
    Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap()
}

fn default_model() -> Model {
    let a = default_setting();
    train(&set(MUNSELL, &a.grid), &a, &TrainOptions::default()).unwrap()
}

#[test]
fn builtin_models_are_what_train_makes_from_shared() {
    for b in specconv_spectral::otsu2018::model::BUILTIN {
        let builtin = Model::builtin_named(b.name).unwrap();
        let retrained = retrain(builtin);
        // Bit for bit: JSON floats round-trip exactly, so compare values and text.
        assert!(*builtin == retrained, "the embedded model {} differs from a retrain: regenerate crates/spectral/models/{}.json with `specconv train` (docs/methods.md)", b.name, b.name);
        assert_eq!(builtin.to_json(), retrained.to_json());
        assert!(builtin
            .leaves
            .iter()
            .all(|l| l.count >= builtin.training.min_cluster_size
                && l.condition <= builtin.training.max_condition));
        // Every source says under which terms its data may be used, and which data (by hash).
        assert!(!builtin.training.sets.is_empty());
        for s in &builtin.training.sets {
            assert_eq!(s.sha256.as_deref(), Some(hash(&s.source).as_str()));
            assert_eq!(
                s.terms(),
                specconv_spectral::otsu2018::terms::Terms::of_content(s.sha256.as_deref())
            );
        }
    }
    // The default is the open model, whose every set allows commercial use (issue 43,
    // docs/methods.md says which recipe and why); the others stay by name.
    assert!(std::ptr::eq(
        Model::builtin(),
        Model::builtin_named("open").unwrap()
    ));
    assert_eq!(
        Model::builtin().training.commercial(),
        specconv_spectral::otsu2018::terms::Commercial::Yes
    );
}

#[test]
fn the_paper_model_is_munsell_alone_and_unchanged() {
    // The built-in default until issue 23: 8 clusters on the
    // Munsell set, CIE 1931, D65, minimum 20, unweighted. Its numbers must not move.
    let paper = Model::builtin_named("paper").unwrap();
    assert!(*paper == default_model());
    assert_eq!(paper.leaves.len(), 8);
    assert_eq!(paper.training.min_cluster_size, 20);
    assert_eq!(paper.training.total_error, 17.978871748824027);
    assert_eq!(paper.training.sets.len(), 1);
    assert_eq!(paper.training.sets[0].weight, 1.0);
}

#[test]
fn the_open_model_is_trained_on_open_data_only() {
    use specconv_spectral::otsu2018::terms::Commercial;
    let open = Model::builtin_named("open").unwrap();
    for s in &open.training.sets {
        assert_eq!(s.commercial, Commercial::Yes, "{}: {}", s.source, s.licence);
        assert!(!s.source.starts_with("munsell") && !s.source.starts_with("colorchecker"));
    }
    assert_eq!(open.training.commercial(), Commercial::Yes);
    // Every other built-in model is trained partly on the Munsell data: not for commercial use.
    for b in specconv_spectral::otsu2018::model::BUILTIN {
        let m = Model::builtin_named(b.name).unwrap();
        assert_eq!(m.training.commercial() == Commercial::Yes, b.name == "open");
    }
}

#[test]
fn training_is_deterministic_and_files_read_back_bit_for_bit() {
    let a = paper();
    let s = set(MUNSELL, &a.grid);
    let m1 = train(&s, &a, &paper_options(8)).unwrap();
    let m2 = train(&s, &a, &paper_options(8)).unwrap();
    assert_eq!(m1, m2);
    let back = Model::from_json("m.json", &m1.to_json()).unwrap();
    assert_eq!(back, m1);
}

#[test]
fn every_munsell_spectrum_round_trips_in_f64_and_f32_agrees() {
    for b in specconv_spectral::otsu2018::model::BUILTIN {
        round_trips_in_f64_and_f32_agrees(Model::builtin_named(b.name).unwrap());
    }
}

fn round_trips_in_f64_and_f32_agrees(model: &Model) {
    let a = default_setting();
    let up = Uplifter::new(model).unwrap();
    let spectra = set(MUNSELL, &a.grid).spectra;
    let s = eval::summarise(&eval::evaluate(&a, &up, &spectra, &eval::Viewing::none()));
    assert!(s.roundtrip_max <= 1e-9, "{}", s.roundtrip_max);

    let n = a.bands();
    let xyz: Vec<f64> = spectra.iter().flat_map(|s| a.xyz(s)).collect();
    let mut r64 = vec![0.0; xyz.len() / 3 * n];
    up.uplift_f64(&xyz, &mut r64);
    let xyz32: Vec<f32> = xyz.iter().map(|&v| v as f32).collect();
    let mut r32 = vec![0.0f32; r64.len()];
    up.uplift_f32(&xyz32, &mut r32);
    let worst = r64
        .iter()
        .zip(&r32)
        .map(|(a, b)| (a - *b as f64).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-5, "f32 differs from f64 by {worst}");
}

#[test]
fn more_clusters_lower_the_training_error_and_leaves_respect_the_bounds() {
    let a = default_setting();
    let s = set(MUNSELL, &a.grid);
    let mut last = f64::INFINITY;
    for k in [1, 2, 4, 8] {
        let m = train(
            &s,
            &a,
            &TrainOptions {
                clusters: k,
                ..TrainOptions::default()
            },
        )
        .unwrap();
        assert_eq!(m.leaves.len(), k);
        assert!(
            m.training.total_error < last,
            "{k} clusters: {} !< {last}",
            m.training.total_error
        );
        last = m.training.total_error;
        assert_eq!(m.leaves.iter().map(|l| l.count).sum::<usize>(), 1269);
        for l in &m.leaves {
            assert!(
                l.count >= 20 && l.condition <= 100.0,
                "{} spectra, condition {}",
                l.count,
                l.condition
            );
        }
    }
}

#[test]
fn tight_bounds_make_fewer_clusters() {
    let a = default_setting();
    let s = set(COLORCHECKER, &a.grid);
    let m = train(
        &s,
        &a,
        &TrainOptions {
            clusters: 8,
            min_cluster_size: 10,
            ..TrainOptions::default()
        },
    )
    .unwrap();
    // 24 spectra hold at most two clusters of 10.
    assert!(m.leaves.len() <= 2);
    let err = train(
        &s,
        &a,
        &TrainOptions {
            clusters: 2,
            min_cluster_size: 25,
            ..TrainOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("fewer than the minimum cluster size"),
        "{err}"
    );
}

#[test]
fn untrainable_sets_give_clear_errors() {
    let a = default_setting();
    let n = a.bands();
    let same = specconv_spectral::TrainingSet {
        sources: vec!["x".into()],
        names: vec!["grey".into(); 30],
        spectra: vec![vec![0.5; n]; 30],
        ..Default::default()
    };
    let err = train(&same, &a, &TrainOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("identical spectra"), "{err}");
    let mut black = set(COLORCHECKER, &a.grid);
    black.spectra[3] = vec![0.0; n];
    let err = train(
        &black,
        &a,
        &TrainOptions {
            min_cluster_size: 4,
            ..TrainOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("'foliage' reflects no light"), "{err}");
    for opts in [
        TrainOptions {
            clusters: 0,
            ..TrainOptions::default()
        },
        TrainOptions {
            min_cluster_size: 3,
            ..TrainOptions::default()
        },
        TrainOptions {
            max_condition: 0.5,
            ..TrainOptions::default()
        },
    ] {
        assert!(train(&black, &a, &opts).is_err(), "{opts:?}");
    }
}

/// A model file broken in each way it can be: every one is refused with a reason.
#[test]
fn corrupt_model_files_are_refused() {
    let good = Model::builtin().clone();
    let json = good.to_json();
    let edit = |f: &dyn Fn(&mut Model)| {
        let mut m = good.clone();
        f(&mut m);
        m.to_json()
    };
    let cases: Vec<(String, &str)> = vec![
        (String::new(), "not valid JSON"),
        ("[1,2]".into(), "not a specconv model"),
        (
            json.replace("specconv-model", "other"),
            "not a specconv model",
        ),
        (
            json.replace("\"version\": 1", "\"version\": 99"),
            "version Some(99) is not supported",
        ),
        (
            json[..json.len() / 2].to_string(),
            "truncated, damaged or not a specconv model",
        ),
        (
            json.replace("\"observer\": \"cie1931\"", "\"observer\": \"cie2000\""),
            "malformed model",
        ),
        (
            json.replacen("\"count\"", "\"extra\": 1, \"count\"", 1),
            "malformed model",
        ),
        (
            edit(&|m| m.observer = Observer::Cie1964),
            "M does not equal A·B",
        ),
        (
            edit(&|m| m.illuminant = Illuminant::A),
            "M does not equal A·B",
        ),
        (
            edit(&|m| m.leaves[2].mean.pop().map(drop).unwrap_or(())),
            "vectors must have 36 values",
        ),
        (
            edit(&|m| m.leaves[1].m_inv[0][0] *= 1.5),
            "M⁻¹ is not the inverse",
        ),
        (
            edit(&|m| m.leaves[1].c_mean[1] += 0.1),
            "c_μ does not equal A·μ",
        ),
        (
            edit(&|m| m.leaves[0].basis[0][3] = f64::NAN),
            "malformed model",
        ),
        (edit(&|m| m.grid.step = 7.5), "bad wavelength grid"),
        (
            edit(&|m| m.tree.nodes_mut().truncate(1)),
            "refers to node 2, which does not exist",
        ),
        (
            edit(&|m| m.tree = Tree::single_leaf()),
            "leaf 1 is not used by the tree",
        ),
        (
            edit(&|m| m.tree.nodes_mut()[0] = Node::Leaf { leaf: 40 }),
            "does not exist",
        ),
        (
            edit(&|m| {
                if let Some(split) = m.tree.split(0) {
                    m.tree.nodes_mut()[0] = Split { above: 0, ..split }.into();
                }
            }),
            "reached twice",
        ),
        (edit(&|m| m.leaves.clear()), "no leaves"),
    ];
    for (text, want) in cases {
        let err = Model::from_json("bad.json", &text).unwrap_err().to_string();
        assert!(err.starts_with("bad.json: "), "{err}");
        assert!(err.contains(want), "want {want:?}, got {err:?}");
    }
}

#[test]
fn colours_without_chromaticity_are_defined() {
    let model = Model::builtin();
    let a = model.colorimetry().unwrap();
    let up = Uplifter::new(model).unwrap();
    let white_leaf = up.leaf([0.9505, 1.0, 1.089]);
    let n = a.bands();
    let mut r = vec![0.0; n];
    for c in [[0.0, 0.0, 0.0], [-0.1, -0.2, 0.05], [f64::NAN, 0.5, 0.5]] {
        assert_eq!(up.leaf(c), white_leaf, "{c:?}");
        up.uplift_f64(&c, &mut r);
        if c.iter().all(|v| v.is_finite()) {
            let back = a.xyz(&r);
            assert!(
                (0..3).all(|k| (back[k] - c[k]).abs() < 1e-12),
                "{c:?} -> {back:?}"
            );
        } else {
            assert!(
                r.iter().all(|v| v.is_nan()),
                "NaN in must be NaN in every band"
            );
        }
    }
}

fn uplifter() -> &'static (Colorimetry, Uplifter) {
    static U: std::sync::OnceLock<(Colorimetry, Uplifter)> = std::sync::OnceLock::new();
    U.get_or_init(|| {
        (
            Model::builtin().colorimetry().unwrap(),
            Uplifter::new(Model::builtin()).unwrap(),
        )
    })
}

proptest! {
    /// Eq. 9: any XYZ comes back from its uplift, whichever leaf it lands in.
    #[test]
    fn round_trip_holds_for_any_in_range_xyz(x in 0.0f64..1.0, y in 1e-6f64..1.0, z in 0.0f64..1.1) {
        let (a, up) = uplifter();
        let mut r = vec![0.0; a.bands()];
        up.uplift_f64(&[x, y, z], &mut r);
        let back = a.xyz(&r);
        for (b, c) in back.iter().zip([x, y, z]) {
            prop_assert!((b - c).abs() <= 1e-12 * (1.0 + c.abs()), "{:?} -> {:?}", [x, y, z], back);
        }
    }

    #[test]
    fn f32_uplift_matches_f64(x in 0.0f32..1.0, y in 1e-3f32..1.0, z in 0.0f32..1.1) {
        let (a, up) = uplifter();
        let n = a.bands();
        let (mut r32, mut r64) = (vec![0.0f32; n], vec![0.0f64; n]);
        up.uplift_f32(&[x, y, z], &mut r32);
        up.uplift_f64(&[x as f64, y as f64, z as f64], &mut r64);
        for (p, q) in r32.iter().zip(&r64) {
            prop_assert!((*p as f64 - q).abs() <= 1e-5 * (1.0 + q.abs()));
        }
    }
}

#[test]
fn a_weight_of_three_is_a_spectrum_counted_three_times() {
    // One cluster: the weighted mean, scatter, basis and error are those of the set with every
    // spectrum of the weighted file repeated, up to rounding.
    let a = default_setting();
    let cc = set(COLORCHECKER, &a.grid);
    let soils = set("usgs_splib07a_soils_380-780_5nm.csv", &a.grid);
    let part = |set: &specconv_spectral::TrainingSet, weight| specconv_spectral::Part {
        set: set.clone(),
        weight,
        terms: Default::default(),
    };
    let weighted = specconv_spectral::TrainingSet::weighted(&[part(&cc, 3.0), part(&soils, 1.0)]);
    let mut repeated = specconv_spectral::TrainingSet::weighted(&[part(&soils, 1.0)]);
    for _ in 0..3 {
        repeated.spectra.extend(cc.spectra.iter().cloned());
        repeated.names.extend(cc.names.iter().cloned());
    }
    let opts = TrainOptions {
        clusters: 1,
        min_cluster_size: 4,
        ..TrainOptions::default()
    };
    let (w, r) = (
        train(&weighted, &a, &opts).unwrap(),
        train(&repeated, &a, &opts).unwrap(),
    );
    let close = |x: &[f64], y: &[f64], tol: f64| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= tol);
    assert!(close(&w.leaves[0].mean, &r.leaves[0].mean, 1e-12));
    for k in 0..3 {
        assert!(
            close(&w.leaves[0].basis[k], &r.leaves[0].basis[k], 1e-9),
            "b{k}"
        );
    }
    let (ew, er) = (w.training.total_error, r.training.total_error);
    assert!((ew - er).abs() <= 1e-9 * er, "{ew} against {er}");
    // Unweighted, the ColorChecker counts once: another model.
    let once = train(
        &specconv_spectral::TrainingSet::weighted(&[part(&cc, 1.0), part(&soils, 1.0)]),
        &a,
        &opts,
    )
    .unwrap();
    assert!(!close(&once.leaves[0].mean, &w.leaves[0].mean, 1e-6));
    // The model records the weights it was trained with.
    assert_eq!(w.training.sets[0].weight, 3.0);
    assert_eq!(w.training.sets[0].count, 24);
}
