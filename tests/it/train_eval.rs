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
    assert!(text.contains("model:      built-in open ("), "{text}");
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

fn usgs(which: &str) -> std::path::PathBuf {
    shared(&format!("spectra/usgs_splib07a_{which}_380-780_5nm.csv"))
}

#[test]
fn eval_by_set_scores_each_file_with_a_model_trained_without_it() {
    let (cc, man, soils) = (colorchecker(), usgs("manmade"), usgs("soils"));
    let small = ["--clusters", "2", "--min-cluster-size", "10"];
    // The recipe: man-made and soils; the ColorChecker is not in it.
    let out = Cmd::eval(&cc)
        .args(["--spectra"])
        .arg(&man)
        .args(["--spectra"])
        .arg(&soils)
        .args(["--by-set", "--json", "--train"])
        .arg(&man)
        .args(["--train"])
        .arg(&soils)
        .args(small)
        .run();
    let v = json(out.ok());
    let sets = v["sets"].as_array().unwrap();
    let hows: Vec<&str> = sets.iter().map(|s| s["how"].as_str().unwrap()).collect();
    assert_eq!(hows, ["unseen", "left-out", "left-out"]);
    // Each figure is what plain eval gives with the model trained on the other files.
    let plain = |spectra: &std::path::Path, train: &[&std::path::Path]| {
        let mut cmd = Cmd::eval(spectra).args(["--json"]).args(small);
        for t in train {
            cmd = cmd.args(["--train"]).arg(t);
        }
        json(cmd.run().ok())["delta_e"]["mean"].as_f64().unwrap()
    };
    let want = [
        plain(&cc, &[&man, &soils]),
        plain(&man, &[&soils]),
        plain(&soils, &[&man]),
    ];
    for (s, w) in sets.iter().zip(want) {
        assert_eq!(s["summary"]["delta_e"]["mean"].as_f64().unwrap(), w, "{s}");
    }
    let worst = want.iter().copied().fold(f64::MIN, f64::max);
    assert_eq!(v["worst"].as_f64().unwrap(), worst);
    assert!((v["mean_of_sets"].as_f64().unwrap() - want.iter().sum::<f64>() / 3.0).abs() < 1e-15);
    // The text names the held-out kind of each row and the worst set.
    let text = Cmd::eval(&cc)
        .args(["--spectra"])
        .arg(&man)
        .args(["--by-set", "--train"])
        .arg(&man)
        .args(["--train"])
        .arg(&soils)
        .args(small)
        .run();
    let text = text.ok();
    assert!(text.contains("| not trained on | 24 |"), "{text}");
    assert!(text.contains("| left out | 138 |"), "{text}");
    assert!(text.contains("worst set:"), "{text}");
    // Baselines are not trained: nothing to hold out.
    Cmd::eval(&cc)
        .args(["--by-set", "--method", "smits1999"])
        .fails(2, &["--by-set measures trained models"]);
}

#[test]
fn eval_by_set_of_a_builtin_model_uses_its_recorded_recipe() {
    // The paper model records one set, Munsell: held out by 10-fold within it.
    let out = Cmd::eval(munsell())
        .args(["--spectra"])
        .arg(colorchecker())
        .args(["--by-set", "--model", "paper", "--json"])
        .run();
    let v = json(out.ok());
    assert_eq!(v["sets"][0]["how"], serde_json::json!({"folds": 10}));
    assert_eq!(v["sets"][1]["how"], "unseen");
    // The ColorChecker is not in its recipe: its figure is the paper model's own.
    let direct = Cmd::eval(colorchecker())
        .args(["--model", "paper", "--json"])
        .run();
    assert_eq!(
        v["sets"][1]["summary"]["delta_e"]["mean"],
        json(direct.ok())["delta_e"]["mean"]
    );
    // A model whose recorded sets are not among --spectra says which file to give.
    Cmd::eval(colorchecker())
        .args(["--by-set", "--model", "paper"])
        .fails(
            2,
            &["trained on munsell1269_matte_380-800_1nm.csv", "--spectra"],
        );
}

#[test]
fn train_records_weights_balance_and_licences_in_the_model() {
    let dir = Scratch::new("weights");
    let model = dir.path("w.json");
    let (cc, man) = (colorchecker(), usgs("manmade"));
    let read = |args: &[&str]| {
        Cmd::train(&cc)
            .args(["--spectra"])
            .arg(&man)
            .args([
                "--clusters",
                "2",
                "--min-cluster-size",
                "10",
                "--force",
                "-o",
            ])
            .arg(&model)
            .args(args)
            .run()
            .ok();
        json(&std::fs::read_to_string(&model).unwrap())["training"]["sets"].clone()
    };
    let sets = read(&["--weights", "3,1"]);
    let w = |v: &serde_json::Value, k: usize| v[k]["weight"].as_f64().unwrap();
    assert_eq!(sets[0]["source"], "colorchecker_n_ohta_380-780_5nm.csv");
    assert_eq!(sets[0]["count"], 24);
    assert!((w(&sets, 0) / w(&sets, 1) - 3.0).abs() < 1e-12);
    // Weights average 1 over the spectra.
    assert!((24.0 * w(&sets, 0) + 138.0 * w(&sets, 1) - 162.0).abs() < 1e-9);
    // The licences are those of ../shared/spectra/README.md.
    assert!(sets[1]["licence"]
        .as_str()
        .unwrap()
        .starts_with("public domain"));
    assert!(sets[0]["licence"].as_str().unwrap().contains("not stated"));
    // Balance 1: each file weighs the same in total.
    let sets = read(&["--balance", "1", "--licence", "mine", "--licence", "theirs"]);
    assert!((24.0 * w(&sets, 0) - 138.0 * w(&sets, 1)).abs() < 1e-9);
    assert_eq!(sets[0]["licence"], "mine");
    // Unweighted: every weight exactly 1.
    let sets = read(&[]);
    assert_eq!((w(&sets, 0), w(&sets, 1)), (1.0, 1.0));
    Cmd::train(&cc)
        .args(["--weights", "1,2", "--force", "-o"])
        .arg(&model)
        .fails(2, &["2 values of --weights for 1 --spectra files"]);
    Cmd::train(&cc)
        .args(["--weights", "0", "--force", "-o"])
        .arg(&model)
        .fails(2, &["finite weight above 0"]);
}

#[test]
fn builtin_models_are_named_and_say_their_data_and_licences() {
    for (name, clusters, words) in [
        (
            "extended",
            "8 clusters",
            &[
                "munsell1269",
                "usgs_splib07a",
                "rhododendron",
                "non-commercial",
            ][..],
        ),
        (
            "paper",
            "8 clusters",
            &["munsell1269", "non-commercial"][..],
        ),
        (
            "broad",
            "11 clusters",
            &["munsell1269", "usgs_splib07a", "non-commercial"][..],
        ),
        (
            "open",
            "clusters",
            &["usgs_splib07a", "public domain", "MIT"][..],
        ),
    ] {
        let out = Cmd::eval(colorchecker()).args(["--model", name]).run();
        let text = out.ok();
        assert!(
            text.contains(&format!("model:      built-in {name} (")),
            "{text}"
        );
        assert!(text.contains(clusters), "{text}");
        for w in words {
            assert!(text.contains(w), "{name}: {w}: {text}");
        }
        assert!(!(name == "open" && text.contains("munsell")), "{text}");
    }
    Cmd::eval(colorchecker()).args(["--model", "papers"]).fails(
        2,
        &[
            "no built-in model is called 'papers'",
            "open, extended, paper, broad",
        ],
    );
}

#[test]
fn models_lists_every_model_with_its_terms_and_version_is_one_line() {
    let text = Cmd::new(["models"]).run();
    let text = text.ok();
    for w in [
        "in force: open (the built-in default ($SPECCONV_MODEL is not set); commercial use: yes)",
        "open (built in, the default): commercial use: yes",
        "extended (built in): commercial use: no",
        "paper (built in): commercial use: no",
        "broad (built in): commercial use: no",
        "non-commercial",
        "public domain",
        "MIT",
        "credit: USGS Spectral Library Version 7",
        // The notices that ship with the data, verbatim (docs/licences.md).
        "notice for colour-science",
        "Copyright 2013 Colour Developers",
        "Redistributions in binary form must reproduce the above copyright notice",
        "Copyright (c) 2022 Beth McDonald",
    ] {
        assert!(text.contains(w), "{w}: {text}");
    }
    // Each notice once, however many models ship with it.
    let notices = text
        .lines()
        .filter(|l| l.starts_with("notice for colour-science"));
    assert_eq!(notices.count(), 1, "{text}");
    let v = json(Cmd::new(["models", "--json"]).run().ok());
    let names: Vec<&str> = v["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["open", "extended", "paper", "broad"]);
    assert_eq!(v["in_force"]["commercial"], "yes");
    assert_eq!(v["models"][0]["default"], true);

    // --version (and -V) is one line: the version, the model in force, its terms.
    for flag in ["--version", "-V"] {
        let out = Cmd::new([flag]).run();
        let line = out.ok();
        assert_eq!(line.lines().count(), 1, "{line}");
        assert!(
            line.starts_with(&format!("specconv {}", env!("CARGO_PKG_VERSION"))),
            "{line}"
        );
        assert!(
            line.contains("default model: open (commercial use: yes)"),
            "{line}"
        );
    }
}

#[test]
fn the_site_default_model_reaches_every_command() {
    let dir = Scratch::new("site-model");
    let input = crate::convert::testdata("srgb8.png");
    // A built-in name.
    let text = Cmd::new(["models"]).env("SPECCONV_MODEL", "paper").run();
    assert!(text
        .ok()
        .starts_with("in force: paper (the site default, $SPECCONV_MODEL; commercial use: no)"));
    let version = Cmd::new(["--version"]).env("SPECCONV_MODEL", "paper").run();
    assert!(
        version
            .ok()
            .contains("default model: paper from $SPECCONV_MODEL (commercial use: no)"),
        "{}",
        version.stdout
    );
    let out = dir.path("paper.exr");
    let run = Cmd::convert(&input, &out)
        .args(["--json"])
        .env("SPECCONV_MODEL", "paper")
        .run();
    assert!(run.json_lines()[0]["model"]
        .as_str()
        .unwrap()
        .starts_with("built-in paper (8 clusters"));
    let attrs = specconv_exr::read_attributes(&out).unwrap();
    assert!(
        attrs.contains(&("specconvCommercialUse".into(), "no".into())),
        "{attrs:?}"
    );
    // -u: up to date under the same model; another model in force (here the built-in
    // default, as after a change of default) rebuilds it.
    let again = Cmd::convert(&input, &out)
        .args(["--json", "-u"])
        .env("SPECCONV_MODEL", "paper")
        .run();
    assert_eq!(again.json_lines()[0]["status"], "skipped");
    let rebuilt = Cmd::convert(&input, &out).args(["--json", "-u"]).run();
    assert_eq!(rebuilt.json_lines()[0]["status"], "ok");
    assert!(rebuilt.json_lines()[0]["model"]
        .as_str()
        .unwrap()
        .starts_with("built-in open ("));
    // --model still wins.
    let run = Cmd::convert(&input, &out)
        .args(["--json", "--force", "--model", "open"])
        .env("SPECCONV_MODEL", "paper")
        .run();
    assert!(run.json_lines()[0]["model"]
        .as_str()
        .unwrap()
        .starts_with("built-in open ("));
    // A model file: eval and convert name it.
    let file = dir.path("studio.json");
    std::fs::write(
        &file,
        specconv_spectral::Model::builtin_named("broad")
            .unwrap()
            .to_json(),
    )
    .unwrap();
    let eval = Cmd::eval(colorchecker()).env("SPECCONV_MODEL", &file).run();
    assert!(
        eval.ok()
            .contains(&format!("model:      {} (11 clusters", file.display())),
        "{}",
        eval.stdout
    );
    // One that cannot be used is a usage error naming the variable, before any output.
    let bad = dir.path("bad.exr");
    Cmd::convert(&input, &bad)
        .env("SPECCONV_MODEL", "papers")
        .fails(
            2,
            &[
                "$SPECCONV_MODEL",
                "'papers'",
                "open, extended, paper, broad",
            ],
        );
    assert!(!bad.exists());
    let version = Cmd::new(["--version"])
        .env("SPECCONV_MODEL", "papers")
        .run();
    assert!(
        version.ok().contains("cannot be loaded"),
        "{}",
        version.stdout
    );
    // A hostile value: a line break cannot break --version's one line, nor imitate a line of
    // `models`; a FIFO or device is refused by its kind, never opened (no hang).
    let forged = "x.json\nin force: open (commercial use: yes)";
    let version = Cmd::new(["--version"]).env("SPECCONV_MODEL", forged).run();
    assert_eq!(version.ok().lines().count(), 1, "{}", version.stdout);
    let fifo = dir.path("fifo.json");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for value in [fifo.as_os_str(), "/dev/zero".as_ref()] {
        let out = Cmd::new(["models"])
            .env("SPECCONV_MODEL", value)
            .run_within(std::time::Duration::from_secs(20));
        assert_eq!(out.code, 2, "{}", out.stderr);
        assert!(out.stderr.contains("not a file"), "{}", out.stderr);
    }
    // Empty: unset.
    let run = Cmd::convert(&input, &out)
        .args(["--json", "--force"])
        .env("SPECCONV_MODEL", "")
        .run();
    assert!(run.json_lines()[0]["model"]
        .as_str()
        .unwrap()
        .starts_with("built-in open ("));
}

#[test]
fn eval_reports_the_colour_shift_under_other_lights() {
    let v = json(
        Cmd::eval(colorchecker())
            .args(["--json", "--per-spectrum", "--model", "extended"])
            .run()
            .ok(),
    );
    let shift = v["colour_shift"].as_array().unwrap();
    let lights: Vec<&str> = shift
        .iter()
        .map(|s| s["illuminant"].as_str().unwrap())
        .collect();
    assert_eq!(lights, ["A", "FL11"]);
    // The summary is the per-spectrum values' mean, 95th percentile (linear, numpy's
    // default) and maximum.
    for (k, s) in shift.iter().enumerate() {
        let mut per: Vec<f64> = v["spectra"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                assert_eq!(r["colour_shift"][k]["illuminant"], s["illuminant"]);
                r["colour_shift"][k]["ciede2000"].as_f64().unwrap()
            })
            .collect();
        per.sort_by(f64::total_cmp);
        let mean = per.iter().sum::<f64>() / per.len() as f64;
        let at = 0.95 * (per.len() - 1) as f64;
        let (lo, f) = (at.floor() as usize, at.fract());
        let p95 = per[lo] + f * (per[lo + 1] - per[lo]);
        assert!((s["mean"].as_f64().unwrap() - mean).abs() < 1e-12, "{s}");
        assert!((s["p95"].as_f64().unwrap() - p95).abs() < 1e-12, "{s}");
        assert_eq!(s["max"].as_f64().unwrap(), per[per.len() - 1]);
        assert!(mean > 0.1 && mean < 5.0, "{s}");
    }
    let text = Cmd::eval(colorchecker())
        .args(["--shift-under", "D50,blackbody:3000"])
        .run();
    let text = text.ok();
    assert!(
        text.contains("colour shift under D50: CIEDE2000 mean "),
        "{text}"
    );
    assert!(
        text.contains("colour shift under blackbody:3000: CIEDE2000 mean "),
        "{text}"
    );
    assert!(!text.contains("under A:"), "{text}");
    Cmd::eval(colorchecker())
        .args(["--shift-under", "F13"])
        .fails(2, &["illuminant 'F13'", "FL11"]);
    // A light whose table does not cover the grid says so, and what to do, before any work.
    Cmd::eval(colorchecker())
        .args([
            "--method",
            "meng2015",
            "--bands",
            "380:780:10",
            "--shift-under",
            "D65,FL2",
        ])
        .run()
        .ok();
    let dir = Scratch::new("shift-grid");
    let wide = dir.write(
        "wide.csv",
        &std::iter::once("wavelength_nm,a".to_string())
            .chain((360..=780).step_by(10).map(|l| format!("{l},0.5")))
            .collect::<Vec<_>>()
            .join("\n"),
    );
    Cmd::eval(&wide)
        .args(["--method", "meng2015", "--bands", "360:780:10"])
        .fails(
            2,
            &[
                "--shift-under",
                "FL11 covers 380–780 nm",
                "name illuminants",
            ],
        );
    // By set: per set and over sets, under each light.
    let v = json(
        Cmd::eval(colorchecker())
            .args(["--spectra"])
            .arg(usgs("soils"))
            .args(["--by-set", "--json", "--train"])
            .arg(usgs("soils"))
            .args(["--clusters", "2", "--min-cluster-size", "10"])
            .run()
            .ok(),
    );
    let over = v["colour_shift"].as_array().unwrap();
    assert_eq!(over.len(), 2);
    let sets = v["sets"].as_array().unwrap();
    let mean = |k: usize| {
        sets.iter()
            .map(|s| s["summary"]["colour_shift"][k]["mean"].as_f64().unwrap())
            .sum::<f64>()
            / sets.len() as f64
    };
    for (k, o) in over.iter().enumerate() {
        assert!(
            (o["mean_of_sets"].as_f64().unwrap() - mean(k)).abs() < 1e-12,
            "{o}"
        );
    }
}

#[test]
fn a_studio_trains_its_swatches_on_top_of_an_open_model() {
    let dir = Scratch::new("with");
    let data = crate::runner::shared("spectra");
    // The open model's own data alone gives it back, bit for bit: --with reads the recorded
    // sets, weights, terms and options.
    let again = dir.path("open-again.json");
    Cmd::new(["train", "--with", "open", "--with-data"])
        .arg(&data)
        .arg("-o")
        .arg(&again)
        .run()
        .ok();
    let builtin = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/spectral/models/open.json"
    );
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(builtin).unwrap()
    );
    // A studio's swatches (here: the ColorChecker, standing in for measured paint chips),
    // its own data for commercial use, weighted 8x on top of `open`.
    let studio = dir.path("studio.json");
    let run = Cmd::new(["train", "--spectra"])
        .arg(colorchecker())
        .args(["--weights", "8", "--licence", "ours", "--commercial", "yes"])
        .args(["--with", "open", "--with-data"])
        .arg(&data)
        .arg("-o")
        .arg(&studio)
        .run();
    let model = json(&std::fs::read_to_string(&studio).unwrap());
    let sets = model["training"]["sets"].as_array().unwrap();
    let own = sets.len() - 1;
    let open_sets = specconv_spectral::Model::builtin_named("open")
        .unwrap()
        .training
        .sets
        .len();
    assert_eq!(own, open_sets, "the open model's sets, then the swatches");
    assert_eq!(sets[own]["licence"], "ours");
    assert!(sets.iter().all(|s| s["commercial"] == "yes"), "{sets:?}");
    assert!(run.stderr.contains("commercial use: yes"), "{}", run.stderr);
    // Its outputs may be used commercially; with data whose terms are unstated they may not.
    let described = Cmd::eval(colorchecker()).arg("--model").arg(&studio).run();
    assert!(described.ok().contains("commercial use: yes"));
    let plain = dir.path("plain.json");
    Cmd::new(["train", "--spectra"])
        .arg(colorchecker())
        .args(["--with", "open", "--with-data"])
        .arg(&data)
        .arg("-o")
        .arg(&plain)
        .run()
        .ok();
    let described = Cmd::eval(colorchecker()).arg("--model").arg(&plain).run();
    assert!(described.ok().contains("commercial use: unstated"));
    // The swatches' gain and their cost elsewhere: each file held out 4-fold, against `open`'s
    // recipe held out the same way. A library of chips (the Munsell set standing in for a
    // studio's 1269 measured paint chips) on top of `open`: open never saw them, the chips'
    // model has, in its other folds, so it must do much better on them.
    let chips = dir.path("chips.json");
    Cmd::new(["train", "--spectra"])
        .arg(munsell())
        .args(["--weights", "4", "--with", "open", "--with-data"])
        .arg(&data)
        .arg("-o")
        .arg(&chips)
        .run()
        .ok();
    let by_set = |json: bool| {
        let mut cmd = Cmd::eval(munsell());
        for set in sets.iter().take(own) {
            cmd = cmd
                .arg("--spectra")
                .arg(data.join(set["source"].as_str().unwrap()));
        }
        // (The PMC set covers 400–700 nm: held at its ends, as when `open` was trained.)
        cmd = cmd.args(["--by-set", "--hold-ends", "--against", "open"]);
        if json {
            // Held out 4-fold, bounded, as JSON; the table: each set left out (quicker).
            cmd = cmd.args(["--bounded", "--folds", "4", "--json"]);
        }
        cmd.arg("--model").arg(&chips).run()
    };
    let out = by_set(true);
    let v = json(out.ok());
    let mean = |s: &serde_json::Value| s["summary"]["delta_e"]["mean"].as_f64().unwrap();
    let (mine, theirs) = (&v["sets"][0], &v["against"]["sets"][0]);
    assert_eq!(mine["source"], "munsell1269_matte_380-800_1nm.csv");
    assert_eq!(mine["how"], serde_json::json!({"folds": 4}), "{mine}");
    assert_eq!(theirs["how"], "unseen", "{theirs}");
    assert!(
        mean(mine) < 0.5 * mean(theirs),
        "{} vs {}",
        mean(mine),
        mean(theirs)
    );
    // Every other set is scored both ways, held out the same way.
    for k in 1..=own {
        assert_eq!(v["sets"][k]["how"], v["against"]["sets"][k]["how"]);
        assert_eq!(v["sets"][k]["source"], v["against"]["sets"][k]["source"]);
    }
    // The same in the table: a ratio column against the other model.
    let text = by_set(false);
    assert!(
        text.ok().contains("| open Δe mean | ratio |"),
        "{}",
        text.stdout
    );
    // A model file edited to name a set outside --with-data: nothing outside it is read.
    let edited = dir.path("edited.json");
    let text = std::fs::read_to_string(builtin).unwrap().replacen(
        "\"source\": \"usgs_splib07a_vegetation",
        "\"source\": \"../spectra/usgs_splib07a_vegetation",
        1,
    );
    assert!(text.contains("../spectra/"));
    std::fs::write(&edited, text).unwrap();
    Cmd::new(["train", "--with"])
        .arg(&edited)
        .arg("--with-data")
        .arg(&data)
        .args(["--force", "-o"])
        .arg(&plain)
        .fails(1, &["must be a plain file name"]);
    // (Folder missing, setting changed: clear errors.)
    Cmd::new(["train", "--with", "open", "--with-data"])
        .arg(dir.path("nowhere"))
        .args(["--force", "-o"])
        .arg(&plain)
        .fails(1, &["cannot read spectra file", "usgs_splib07a_vegetation"]);
    Cmd::new(["train", "--with", "open", "--with-data"])
        .arg(&data)
        .args(["--bands", "400:700:10", "--force", "-o"])
        .arg(&plain)
        .fails(2, &["--with trains in its model's setting"]);
}

#[test]
fn outputs_say_which_model_made_them() {
    let dir = Scratch::new("which-model");
    let input = crate::convert::testdata("srgb8.png");
    for (flags, want, commercial) in [
        (&[][..], "built-in open (", "yes"),
        (
            &["--model", "extended"][..],
            "built-in extended (8 clusters",
            "no",
        ),
        (
            &["--model", "paper"][..],
            "built-in paper (8 clusters",
            "no",
        ),
        (
            &["--model", "broad"][..],
            "built-in broad (11 clusters",
            "no",
        ),
        (&["--model", "open"][..], "built-in open (", "yes"),
    ] {
        let out = dir.path("out.exr");
        let run = Cmd::new(["--ocio", "aces", "--force", "--json"])
            .args(flags)
            .arg(&input)
            .arg(&out)
            .run();
        let record = &run.json_lines()[0];
        let model = record["model"].as_str().unwrap().to_string();
        assert!(model.starts_with(want), "{model}");
        assert!(
            model.contains("licence")
                || model.contains("public domain")
                || model.contains("non-commercial"),
            "{model}"
        );
        // Whether the model may be used commercially: only when every set may
        // (../shared/spectra/README.md: the Munsell data are non-commercial).
        assert!(
            model.ends_with(&format!("; commercial use: {commercial})")),
            "{model}"
        );
        // The file says the same, read by the EXR reader.
        let attrs = specconv_exr::read_attributes(&out).unwrap();
        assert!(
            attrs.contains(&("specconvModel".to_string(), model.clone())),
            "{attrs:?}"
        );
        // And a machine-readable flag beside it.
        assert!(
            attrs.contains(&("specconvCommercialUse".to_string(), commercial.to_string())),
            "{attrs:?}"
        );
        // And OpenImageIO reads the credit lines the data ask for.
        let info = tool("oiiotool", &["--info", "-v", out.to_str().unwrap()]);
        let credit = if commercial == "yes" {
            "USGS Spectral Library Version 7"
        } else {
            "University of Eastern Finland"
        };
        assert!(
            info.lines()
                .any(|l| l.contains("specconvModelAttribution") && l.contains(credit)),
            "{info}"
        );
        // And `info` shows it.
        let info = Cmd::new(["info"]).arg(&out).run();
        let text = info.ok();
        assert!(
            text.contains(&format!("specconvModel:            {want}")),
            "{text}"
        );
    }
}

#[test]
fn report_by_set_scores_each_file_held_out() {
    let (cc, man) = (colorchecker(), usgs("manmade"));
    let out = Cmd::new(["report", "--by-set", "--json", "--clusters", "1,2"])
        .args([
            "--steps",
            "10",
            "--colours",
            "1000",
            "--min-cluster-size",
            "10",
        ])
        .args(["--spectra"])
        .arg(&cc)
        .args(["--spectra"])
        .arg(&man)
        .run();
    let rows = json(out.ok());
    let clustered: Vec<&serde_json::Value> = rows
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["setting"].as_str().unwrap().contains("by set"))
        .collect();
    assert_eq!(clustered.len(), 2, "{rows}");
    for r in clustered {
        // Every spectrum of both files, each scored by the model of the other file.
        assert_eq!(r["count"], 24 + 138);
        let note = r["note"].as_str().unwrap();
        assert!(note.contains("by set: mean over 2 files"), "{note}");
        assert!(note.contains("ΔE00 under A mean"), "{note}");
        assert!(note.contains("ΔE00 under FL11 mean"), "{note}");
    }
    // Every row has the colour shift under A and F11 (mean, 95th percentile, max), the
    // baselines' too; the text table and the CSV say the same.
    for r in rows.as_array().unwrap() {
        let shift = r["colour_shift"].as_array().unwrap();
        assert_eq!(shift.len(), 2, "{r}");
        assert_eq!(
            (
                shift[0]["illuminant"].as_str(),
                shift[1]["illuminant"].as_str()
            ),
            (Some("A"), Some("FL11"))
        );
        for s in shift {
            let (mean, p95, max) = (
                s["mean"].as_f64().unwrap(),
                s["p95"].as_f64().unwrap(),
                s["max"].as_f64().unwrap(),
            );
            assert!(0.0 < mean && mean <= max && p95 <= max, "{r}");
        }
    }
    let small = |format: &[&str]| {
        Cmd::new([
            "report",
            "--clusters",
            "1",
            "--steps",
            "10",
            "--colours",
            "1000",
        ])
        .args(format)
        .args(["--spectra"])
        .arg(&cc)
        .run()
    };
    let text = small(&[]);
    assert!(
        text.ok()
            .contains("| shift A: ΔE00 mean / p95 / max | shift FL11: ΔE00 mean / p95 / max |"),
        "{}",
        text.stdout
    );
    let csv = small(&["--csv"]);
    assert!(csv
        .ok()
        .lines()
        .next()
        .unwrap()
        .contains("ciede2000_A_mean,ciede2000_A_p95,ciede2000_A_max,ciede2000_FL11_mean"));
    Cmd::new(["report", "--by-set", "--holdout", "2"])
        .args(["--spectra"])
        .arg(&cc)
        .fails(2, &["--holdout"]);
}

/// Issue 31, item 5: `train -o` replaced an existing model without being asked, and any name
/// was written. Now the library's rules for a model file (`models::save`): `.json` only, an
/// existing file only with `--force` (its mode kept), nothing written when refused.
#[test]
fn train_replaces_a_model_only_with_force_and_never_a_texture() {
    let dir = Scratch::new("train-force");
    let model = dir.path("m.json");
    std::fs::write(&model, b"{\"an\": \"older model\"}").unwrap();
    let m = model.to_str().unwrap();
    let cc = colorchecker();
    Cmd::train(&cc)
        .args(["--clusters", "2", "-o", m])
        .refused(&dir, 2, &[m, "exists", "--force"]);
    let texture = dir.write("victim.png", "a texture");
    for force in [&[][..], &["--force"][..]] {
        Cmd::train(&cc)
            .args(["--clusters", "2", "-o", texture.to_str().unwrap()])
            .args(force)
            .refused(&dir, 2, &["wrong extension", "ending in .json"]);
    }
    Cmd::train(&cc)
        .args(["--clusters", "2", "--force", "-o", m])
        .ok();
    let written = std::fs::read_to_string(&model).unwrap();
    assert!(written.contains("\"leaves\""), "{written}");
    assert_eq!(std::fs::read(&texture).unwrap(), b"a texture");
}

#[test]
fn train_never_replaces_a_file_it_reads_whatever_its_spelling() {
    // `--force` replaces an existing output, never the --with model's file nor a set it
    // records, however the output names it: `./`, `..`, a link to the file or its folder,
    // a hard link.
    let dir = Scratch::new("train-reads");
    let data = dir.path("data");
    std::fs::create_dir(&data).unwrap();
    // A studio's set whose file name ends in .json, as a model's does.
    let set = data.join("swatches.json");
    std::fs::copy(colorchecker(), &set).unwrap();
    let base = dir.path("base.json");
    Cmd::new(["train", "--spectra"])
        .arg(&set)
        .args(["--clusters", "2", "--min-cluster-size", "4", "-o"])
        .arg(&base)
        .ok();
    std::os::unix::fs::symlink(&base, dir.path("link.json")).unwrap();
    std::fs::hard_link(&base, dir.path("hard.json")).unwrap();
    std::os::unix::fs::symlink(&data, dir.path("alias")).unwrap();
    std::fs::hard_link(&set, dir.path("hard-set.json")).unwrap();
    let before = [std::fs::read(&base).unwrap(), std::fs::read(&set).unwrap()];
    let cases = [
        ("base.json", "base.json"),
        ("base.json", "./base.json"),
        ("base.json", "data/../base.json"),
        ("base.json", "link.json"),
        ("base.json", "hard.json"),
        ("link.json", "base.json"),
        ("./link.json", "hard.json"),
        ("base.json", "data/swatches.json"),
        ("base.json", "./data/./swatches.json"),
        ("base.json", "alias/swatches.json"),
        ("base.json", "alias/../data/swatches.json"),
        ("hard.json", "hard-set.json"),
    ];
    for (with, output) in cases {
        Cmd::new(["train", "--spectra"])
            .arg(munsell())
            .args([
                "--with",
                with,
                "--with-data",
                "data",
                "--force",
                "-o",
                output,
            ])
            .current_dir(&dir.0)
            .refused(&dir, 2, &["is the input"]);
        let after = [std::fs::read(&base).unwrap(), std::fs::read(&set).unwrap()];
        assert!(
            after == before,
            "--with {with} -o {output} changed a file it read"
        );
    }
    // Another name is written, with --force over an existing file that nothing reads.
    std::fs::write(dir.path("old.json"), "{}").unwrap();
    Cmd::new(["train", "--with", "base.json", "--with-data", "data"])
        .args(["--force", "-o", "old.json"])
        .current_dir(&dir.0)
        .ok();
    assert_eq!(std::fs::read(dir.path("old.json")).unwrap(), before[0]);
}

/// `text` with the last digit of its second line changed: the same spectra count, other data.
fn one_value_changed(text: &str) -> String {
    let start = text.find('\n').unwrap() + 1;
    let end = start + text[start..].find('\n').unwrap();
    let at = start
        + text[start..end]
            .rfind(|c: char| c.is_ascii_digit())
            .unwrap();
    let d = text.as_bytes()[at] - b'0';
    format!("{}{}{}", &text[..at], (d + 1) % 10, &text[at + 1..])
}

#[test]
fn recorded_sets_are_trusted_by_their_content_never_by_their_names() {
    let dir = Scratch::new("fake-sets");
    let shared = shared("spectra");
    let open = specconv_spectral::Model::builtin_named("open").unwrap();
    let fake = dir.path("fake");
    std::fs::create_dir(&fake).unwrap();
    for s in &open.training.sets {
        std::fs::copy(shared.join(&s.source), fake.join(&s.source)).unwrap();
    }
    let out = dir.path("m.json");
    let munsell_text = std::fs::read_to_string(munsell()).unwrap();
    // Each recorded set replaced by other spectra under its name (the Munsell set's), or by
    // its own with one value changed: refused, naming the set, both counts and both hashes.
    for s in &open.training.sets {
        let path = fake.join(&s.source);
        let genuine = std::fs::read_to_string(&path).unwrap();
        for (text, count) in [
            (munsell_text.clone(), 1269),
            (one_value_changed(&genuine), s.count),
        ] {
            std::fs::write(&path, &text).unwrap();
            let found = specconv_spectral::otsu2018::terms::content_hash(text.as_bytes());
            let recorded = s.sha256.as_deref().unwrap();
            Cmd::new(["train", "--with", "open", "--with-data"])
                .arg(&fake)
                .arg("-o")
                .arg(&out)
                .fails(
                    1,
                    &[
                        &format!(
                            "{} is not the set built-in open was trained on",
                            path.display()
                        ),
                        &format!(
                            "{} as {} spectra with SHA-256 {recorded}",
                            s.source, s.count
                        ),
                        &format!("holds {count} spectra with SHA-256 {found}"),
                        "--spectra",
                        "--licence",
                    ],
                );
            assert!(!out.exists());
        }
        std::fs::write(&path, genuine).unwrap();
    }
    // A model written before hashes were recorded: a set of another count is refused; one of
    // the recorded count is read, but passes no terms on (a warning says why); sets whose
    // content is known keep the terms of that content.
    let builtin = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/spectral/models/open.json"
    );
    let old: String = std::fs::read_to_string(builtin)
        .unwrap()
        .lines()
        .filter(|l| !l.contains("\"sha256\""))
        .map(|l| format!("{l}\n"))
        .collect();
    let old_model = dir.write("old.json", &old);
    let veg = fake.join(&open.training.sets[0].source);
    let genuine = std::fs::read_to_string(&veg).unwrap();
    std::fs::write(&veg, &munsell_text).unwrap();
    Cmd::new(["train", "--with"])
        .arg(&old_model)
        .arg("--with-data")
        .arg(&fake)
        .arg("-o")
        .arg(&out)
        .fails(1, &["with SHA-256 not recorded", "holds 1269 spectra"]);
    std::fs::write(&veg, one_value_changed(&genuine)).unwrap();
    let run = Cmd::new(["train", "--with"])
        .arg(&old_model)
        .arg("--with-data")
        .arg(&fake)
        .arg("-o")
        .arg(&out)
        .run();
    run.ok();
    assert!(
        run.stderr.contains(&format!(
            "warning: {} records no hash of {}",
            old_model.display(),
            open.training.sets[0].source
        )),
        "{}",
        run.stderr
    );
    assert!(
        run.stderr.contains("commercial use: unstated"),
        "{}",
        run.stderr
    );
    let model = json(&std::fs::read_to_string(&out).unwrap());
    let sets = model["training"]["sets"].as_array().unwrap();
    assert!(sets[0]["licence"].as_str().unwrap().starts_with("unknown"));
    assert!(
        sets[1..].iter().all(|s| s["commercial"] == "yes"),
        "{sets:?}"
    );
    assert!(sets
        .iter()
        .all(|s| s["sha256"].as_str().unwrap().len() == 64));
}

#[test]
fn a_set_s_terms_come_with_its_content_not_its_file_name() {
    let dir = Scratch::new("named-like");
    let small = ["--clusters", "2", "--min-cluster-size", "10"];
    let veg = "usgs_splib07a_vegetation_380-780_5nm.csv";
    let fake = dir.path(veg);
    let out = dir.path("m.json");
    // Under a public-domain set's name: other spectra (unknown terms), the Munsell data
    // (non-commercial, whatever the name), each with a warning naming both sets' figures.
    let cc = std::fs::read_to_string(colorchecker()).unwrap();
    let munsell_text = std::fs::read_to_string(munsell()).unwrap();
    for (text, count, says) in [
        (one_value_changed(&cc), 24, "commercial use: unstated"),
        (munsell_text, 1269, "commercial use: no"),
    ] {
        std::fs::write(&fake, text).unwrap();
        let run = Cmd::train(&fake)
            .args(small)
            .args(["--force", "-o"])
            .arg(&out)
            .run();
        run.ok();
        let warning = format!("is named like the shared set {veg} (235 spectra, SHA-256 a0dc9457");
        assert!(run.stderr.contains(&warning), "{}", run.stderr);
        assert!(
            run.stderr
                .contains(&format!("holds other data ({count} spectra")),
            "{}",
            run.stderr
        );
        assert!(run.stderr.contains(says), "{}", run.stderr);
        let model = json(&std::fs::read_to_string(&out).unwrap());
        assert!(!model["training"]["sets"][0]["licence"]
            .as_str()
            .unwrap()
            .contains("public domain"));
    }
    // The non-commercial Munsell data renamed: still known, still non-commercial.
    let renamed = dir.path("our-chips.csv");
    std::fs::copy(munsell(), &renamed).unwrap();
    let run = Cmd::train(&renamed)
        .args(small)
        .args(["--force", "-o"])
        .arg(&out)
        .run();
    run.ok();
    assert!(run.stderr.contains("commercial use: no"), "{}", run.stderr);
    let model = json(&std::fs::read_to_string(&out).unwrap());
    let set = &model["training"]["sets"][0];
    assert_eq!(set["source"], "our-chips.csv");
    assert!(set["licence"].as_str().unwrap().contains("non-commercial"));
    // The hash is the file's SHA-256, as sha256sum (outside the project) computes it.
    let sum = tool("sha256sum", &[renamed.to_str().unwrap()]);
    assert_eq!(
        set["sha256"].as_str().unwrap(),
        sum.split_whitespace().next().unwrap()
    );
}

#[test]
fn a_licence_is_one_line_and_a_model_file_cannot_hold_another() {
    let dir = Scratch::new("licence-lines");
    let out = dir.path("m.json");
    let forged = [
        "ours\nspecconvSource: FORGED.png\ncommercial use: yes",
        "ours\r\ncommercial use: yes",
        "ours\u{1b}[2K\rcommercial use: yes",
        "ours\u{85}commercial use: yes",
        "ours\u{2028}commercial use: yes",
        "ours\u{202e}sey :esu laicremmoc",
        "ours\tyes",
    ];
    for licence in forged {
        Cmd::train(colorchecker())
            .args(["--licence", licence, "--commercial", "yes", "-o"])
            .arg(&out)
            .refused(&dir, 2, &["--licence: the licence", "control character"]);
    }
    // A model file edited to hold one is refused when loaded, by every command.
    let good = dir.path("good.json");
    Cmd::train(colorchecker())
        .args(["--clusters", "1", "--licence", "ours", "-o"])
        .arg(&good)
        .ok();
    let text = std::fs::read_to_string(&good).unwrap();
    for licence in forged {
        let edited = text.replace(
            "\"licence\": \"ours\"",
            &format!("\"licence\": {}", serde_json::to_string(licence).unwrap()),
        );
        assert_ne!(edited, text);
        let bad = dir.write("bad.json", &edited);
        Cmd::eval(colorchecker())
            .arg("--model")
            .arg(&bad)
            .fails(2, &["control character", "give it as one line"]);
    }
}
