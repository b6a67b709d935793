//! `specconv eval --method` and `specconv report` from the command line.

use crate::runner::*;

fn eval_json(method: &str) -> serde_json::Value {
    let cc = colorchecker();
    let out = Cmd::eval(&cc)
        .args(["--method", method, "--jakob-resolution", "16", "--json"])
        .run();
    json(out.ok())
}

#[test]
fn every_baseline_evaluates_through_the_same_command() {
    for m in ["smits1999", "meng2015", "meng2015-bounded"] {
        let v = eval_json(m);
        assert_eq!(v["method"], m);
        assert_eq!(v["count"], 24);
        let mean = v["delta_e"]["mean"].as_f64().unwrap();
        assert!(mean > 0.05 && mean < 1.0, "{m}: {mean}");
    }
    // The smoothest spectrum has the colour exactly; the bounded one also stays in [0, 1].
    let m = eval_json("meng2015");
    assert!(m["roundtrip_max"].as_f64().unwrap() < 1e-12);
    let b = eval_json("meng2015-bounded");
    assert!(b["roundtrip_de2000_max"].as_f64().unwrap() < 1e-9);
    assert_eq!(b["in_unit_range"].as_f64().unwrap(), 1.0);
    assert!(m["in_unit_range"].as_f64().unwrap() < 1.0);
    // otsu2018 as named, and bounded (as convert writes it): in [0, 1], colours kept.
    let cc = colorchecker();
    let raw = Cmd::eval(&cc).arg("--json").ok().json();
    let bounded = Cmd::eval(&cc).args(["--json", "--bounded"]).run();
    let bounded = json(bounded.ok());
    assert_eq!(raw["method"], "otsu2018");
    assert_eq!(bounded["method"], "otsu2018-bounded");
    assert_eq!(bounded["in_unit_range"].as_f64().unwrap(), 1.0);
    assert!(bounded["roundtrip_de2000_max"].as_f64().unwrap() < 1e-6);
    // Smits does not round-trip exactly.
    assert!(
        eval_json("smits1999")["roundtrip_de2000_max"]
            .as_f64()
            .unwrap()
            > 0.1
    );
}

#[test]
fn pca_needs_a_one_cluster_model_and_unknown_methods_are_usage_errors() {
    let cc = colorchecker();
    let cc = cc.to_str().unwrap();
    Cmd::eval(cc)
        .args(["--method", "pca"])
        .fails(2, &["pca", "--clusters 1", "--train"]);
    Cmd::eval(cc)
        .args(["--method", "nope"])
        .fails(2, &["nope", "smits1999"]);
    let m = munsell();
    let out = Cmd::eval(cc)
        .args(["--method", "pca", "--train", m.to_str().unwrap(), "--json"])
        .run();
    let v = json(out.ok());
    // The paper's "PCA only" on the ColorChecker, trained on Munsell: worse than 8 clusters.
    assert!(v["delta_e"]["mean"].as_f64().unwrap() > 0.0625);
}

/// The jakob2019 table is built once into the cache directory, reused, and rebuilt when the
/// file is damaged or the setting changes.
#[test]
fn jakob2019_table_is_cached_and_rebuilt_when_stale() {
    let dir = Scratch::new("jakob-cache");
    let cc = colorchecker();
    let run = |extra: &[&str]| {
        let out = Cmd::eval(&cc)
            .args([
                "--method",
                "jakob2019",
                "--jakob-resolution",
                "12",
                "--json",
            ])
            .args(extra)
            .env("SPECCONV_CACHE_DIR", &dir.0)
            .ok();
        (out.json(), out.stderr)
    };
    let (first, err) = run(&[]);
    assert!(err.contains("built the jakob2019 table"), "{err}");
    let files = dir.files();
    assert_eq!(files.len(), 1, "{files:?}");
    let (second, err) = run(&[]);
    assert!(!err.contains("built"), "{err}");
    assert_eq!(first, second);
    // Damage the file: refused, rebuilt, same answer.
    let path = dir.path(&files[0]);
    let mut bytes = std::fs::read(&path).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    std::fs::write(&path, bytes).unwrap();
    let (third, err) = run(&[]);
    assert!(err.contains("rebuilding") && err.contains("built"), "{err}");
    assert_eq!(first, third);
    // Another illuminant is another table.
    let (_, err) = run(&["--illuminant", "A"]);
    assert!(err.contains("built"), "{err}");
    assert_eq!(dir.files().len(), 2);
}

#[test]
fn report_measures_every_method_and_draws_the_plot() {
    let dir = Scratch::new("report");
    let plot = dir.path("cost.svg");
    let cc = colorchecker();
    let m = munsell();
    let v = Cmd::new(["report", "--spectra", cc.to_str().unwrap(), "--train"])
        .args([
            m.to_str().unwrap(),
            "--colours",
            "20000",
            "--clusters",
            "1,8",
        ])
        .args([
            "--steps",
            "5",
            "--jakob-resolution",
            "12",
            "-j",
            "2",
            "--json",
            "--plot",
        ])
        .arg(&plot)
        .env("SPECCONV_CACHE_DIR", &dir.0)
        .ok()
        .json();
    let rows = v.as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "smits1999",
            "meng2015",
            "meng2015-bounded",
            "jakob2019",
            "pca",
            "otsu2018",
            "otsu2018-bounded",
            "otsu2018"
        ]
    );
    for r in rows {
        for k in [
            "delta_e_mean",
            "delta_e_median",
            "delta_e_max",
            "roundtrip_max",
            "roundtrip_de2000_max",
            "in_unit_range",
            "ns_per_colour_1_thread",
            "mpixel_per_s_all_threads",
        ] {
            let x = r[k].as_f64().unwrap_or(f64::NAN);
            assert!(x.is_finite() && x >= 0.0, "{k} of {r}");
        }
        assert!(r["model_bytes"].as_u64().unwrap() > 0);
        assert_eq!(r["count"], 24);
    }
    // The 8-cluster model trained on Munsell, blended at the default width: the README's
    // ColorChecker figure (0.0625 with the paper's hard switch, `--blend 0`).
    assert!((rows[5]["delta_e_mean"].as_f64().unwrap() - 0.0716).abs() < 5e-4);
    // Bounded: every spectrum in [0, 1], the colours kept.
    assert_eq!(rows[6]["in_unit_range"].as_f64().unwrap(), 1.0);
    assert!(rows[6]["roundtrip_de2000_max"].as_f64().unwrap() < 1e-6);
    assert_eq!(rows[7]["bands"], 71);
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("otsu2018 (8 clusters, blend 0.02)"),
        "{svg}"
    );

    // The axis titles survive: text is drawn with the registered font, not dropped.
    assert!(svg.contains("nanoseconds per colour"), "{svg}");

    // Formats other than SVG and PNG are refused with a reason; so is an empty measurement.
    let cc = cc.to_str().unwrap();
    Cmd::new(["report", "--spectra", cc, "--plot", "x.gif"]).fails(2, &["*.svg or *.png"]);
    Cmd::new(["report", "--spectra", cc, "--colours", "0"]).fails(2, &["--colours"]);
}

#[test]
fn report_holdout_trains_on_the_other_folds() {
    let m = munsell();
    let out = Cmd::new([
        "report",
        "--spectra",
        m.to_str().unwrap(),
        "--holdout",
        "5",
        "--clusters",
        "8",
        "--steps",
        "10",
        "--colours",
        "4096",
        "--jakob-resolution",
        "8",
        "--csv",
    ])
    .run();
    let text = out.ok();
    let lines: Vec<&str> = text.lines().collect();
    let row = lines.iter().find(|l| l.starts_with("otsu2018")).unwrap();
    assert!(row.contains("5-fold"), "{row}");
    let mean: f64 = row.split(',').nth(4).unwrap().parse().unwrap();
    // On its own training set the 8-cluster model has mean 0.0142 (README); held out, more.
    assert!(mean > 0.0142, "{mean}");
}
