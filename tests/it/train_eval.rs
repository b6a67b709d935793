//! `specconv train` and `specconv eval` from the command line.

use crate::runner::*;

#[test]
fn eval_reproduces_table_1_with_the_papers_settings() {
    let dir = Scratch::new("table1");
    let model = dir.path("paper.json");
    let trained = Cmd::train(munsell())
        .args([
            "--observer",
            "wyman2013",
            "--illuminant",
            "E",
            "--bands",
            "380:730:10",
            "--clusters",
            "8",
            "--min-cluster-size",
            "4",
            "-o",
            model.to_str().unwrap(),
        ])
        .run();
    trained.ok();
    assert!(
        trained
            .stderr
            .contains("trained 8 clusters on 1269 spectra"),
        "{}",
        trained.stderr
    );
    let out = Cmd::eval(munsell())
        .args(["--model", model.to_str().unwrap(), "--json"])
        .run();
    let v = json(out.ok());
    assert_eq!(v["count"], 1269);
    let mean = v["delta_e"]["mean"].as_f64().unwrap();
    let median = v["delta_e"]["median"].as_f64().unwrap();
    assert!((mean - 0.0138).abs() <= 0.0007, "{mean}");
    assert!((median - 0.0053).abs() <= 0.0003, "{median}");
    assert!(v["delta_e"]["max"].as_f64().unwrap() > median);
    assert!(v["roundtrip_max"].as_f64().unwrap() <= 1e-9);
    assert!((0.0..=1.0).contains(&v["in_unit_range"].as_f64().unwrap()));
    // Only the model and nothing else was written.
    assert_eq!(dir.files(), vec!["paper.json"]);
}

#[test]
fn eval_uses_the_builtin_model_and_prints_a_readable_summary() {
    let out = Cmd::eval(colorchecker()).run();
    let text = out.ok();
    assert!(
        text.contains("model:      built-in (8 clusters, cie1931, D65, 380:730:10 nm"),
        "{text}"
    );
    assert!(text.contains("spectra:    24"), "{text}");
    assert!(text.contains("Δe = ‖s − r‖²: mean "), "{text}");
    let per = Cmd::eval(colorchecker())
        .args(["--json", "--per-spectrum"])
        .run();
    let v = json(per.ok());
    let rows = v["spectra"].as_array().unwrap();
    assert_eq!(rows.len(), 24);
    assert_eq!(rows[0]["name"], "dark skin");
    let mean: f64 = rows
        .iter()
        .map(|r| r["delta_e"].as_f64().unwrap())
        .sum::<f64>()
        / 24.0;
    assert!((mean - v["delta_e"]["mean"].as_f64().unwrap()).abs() < 1e-12);
}

#[test]
fn bad_inputs_get_one_clear_error_and_exit_1() {
    let dir = Scratch::new("bad");
    let ragged = dir.write("ragged.csv", "wavelength_nm,a,b\n380,0.1,0.2\n390,0.1\n");
    Cmd::eval(&ragged).fails(1, &["specconv: error: ragged.csv, line 3: ragged row"]);
    let short = dir.write("short.csv", "wavelength_nm,a\n400,0.1\n700,0.2\n");
    Cmd::eval(&short).fails(1, &["covers 400–700 nm", "--bands 400:700:10"]);
    Cmd::eval("/nonexistent/x.csv").fails(
        1,
        &[
            "cannot read spectra file /nonexistent/x.csv",
            "no such file",
        ],
    );
    let bad_model = dir.write(
        "model.json",
        "{\"format\": \"specconv-model\", \"version\": 1}",
    );
    Cmd::eval(colorchecker())
        .args(["--model", bad_model.to_str().unwrap()])
        .run()
        // A model that cannot be read is a setting no input can fix: exit 2.
        .fails(2, &["model.json: malformed model"]);
    let out = dir.path("m.json");
    Cmd::train(colorchecker())
        .args(["--min-cluster-size", "30", "-o", out.to_str().unwrap()])
        .fails(
            1,
            &["24 spectra are fewer than the minimum cluster size 30"],
        );
    assert!(!out.exists());
    // Writing the model over its own training data is refused, and the data is untouched.
    // (Named .json: an output of another extension is refused by its name first.)
    let copy = dir.write("cc.json", &std::fs::read_to_string(colorchecker()).unwrap());
    Cmd::train(&copy)
        .args(["--min-cluster-size", "4", "-o", copy.to_str().unwrap()])
        .fails(2, &["cc.json is the input"]);
    assert_eq!(
        std::fs::read_to_string(&copy).unwrap(),
        std::fs::read_to_string(colorchecker()).unwrap()
    );
    assert_eq!(
        dir.files(),
        vec!["cc.json", "model.json", "ragged.csv", "short.csv"]
    );
}

#[test]
fn usage_errors_exit_2() {
    Cmd::train("x.csv").fails(2, &["--output"]);
    Cmd::train("x.csv")
        .args(["-o", "m.json", "--bands", "380:730"])
        .fails(2, &["START:END:STEP"]);
    Cmd::train("x.csv")
        .args(["-o", "m.json", "--min-cluster-size", "3"])
        .fails(2, &["four spectra"]);
    Cmd::train("x.csv")
        .args(["-o", "m.json", "--illuminant", "D75"])
        .fails(2, &["blackbody:KELVIN"]);
    Cmd::train("x.csv")
        .args(["-o", "m.json", "--observer", "cie2000"])
        .fails(2, &["wyman2013"]);
    Cmd::new(["eval"]).fails(2, &["--spectra"]);
}

#[test]
fn trained_model_file_is_used_by_eval_with_its_own_setting() {
    let dir = Scratch::new("setting");
    let model = dir.path("a.json");
    Cmd::train(munsell())
        .args([
            "--clusters",
            "2",
            "--illuminant",
            "A",
            "--observer",
            "cie1964",
            "--bands",
            "400:700:5",
            "-o",
            model.to_str().unwrap(),
        ])
        .ok();
    let out = Cmd::eval(colorchecker())
        .args(["--model", model.to_str().unwrap()])
        .run();
    assert!(
        out.ok()
            .contains("(2 clusters, cie1964, A, 400:700:5 nm, trained on 1269 spectra"),
        "{}",
        out.stdout
    );
}

#[test]
fn untrainable_spectra_get_one_clear_error_and_no_model() {
    let dir = Scratch::new("untrainable");
    let a = specconv_colour::Colorimetry::new(
        specconv_colour::Grid::PAPER,
        specconv_colour::Observer::Cie1931,
        specconv_colour::Illuminant::D65,
    )
    .unwrap();
    for (k, case) in specconv_testkit::untrainable::cases(&a)
        .into_iter()
        .enumerate()
    {
        let csv = dir.write(
            &format!("case{k}.csv"),
            &specconv_testkit::untrainable::csv(&a.grid, &case.spectra),
        );
        let model = dir.path("m.json");
        let out = Cmd::train(&csv)
            .args(["--min-cluster-size", "4", "-o", model.to_str().unwrap()])
            .run();
        out.fails(1, &["specconv: error: cannot train: ", case.error]);
        assert!(!model.exists(), "{}: a model was written", case.name);
    }
}
