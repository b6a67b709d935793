//! The study behind the built-in models (docs/methods.md, "Choosing the built-in models"):
//! training recipes scored set by set on spectra they were not trained on
//! (`specconv_evaluation::sets`, leave one set out), every set of ../shared/spectra, in the built-in
//! models' setting (CIE 1931 2°, D65, 380–730 nm at 10 nm), uplifted as `eval` does (blend
//! 0.02 unless the row says otherwise, not bounded).
//!
//!     cargo run --release -p specconv-evaluation --example model_study [--bounded] [--folds K] [SWEEP…|ROW…]
//!
//! SWEEP: today, all, open, k, balance, min, condition, blend, sets, open-weights, chosen
//! (default: every one). Prints one Markdown table per sweep: each set's mean Δe and mean
//! colour shift (CIEDE2000 under A and F11, issue 43), the means over sets, the worst set, each
//! recipe against `extended`'s scored in the same run, and its training time on all its sets.
//! Recipes are ranked by their colour shift: the mean over sets under A and under F11, averaged.

use specconv_colour::{Colorimetry, Grid, Illuminant, Observer, SpectralTable};
use specconv_evaluation::eval;
use specconv_evaluation::sets::{held_out_by_set, Holdout, Recipe, Scores};
use specconv_spectral::bounded::Bounded;
use specconv_spectral::otsu2018::blend::DEFAULT_WIDTH;
use specconv_spectral::{Part, TrainOptions, TrainingSet, Uplifter};

const SETS: [(&str, &str); 11] = [
    ("munsell", "munsell1269_matte_380-800_1nm.csv"),
    ("cc", "colorchecker_n_ohta_380-780_5nm.csv"),
    ("veg", "usgs_splib07a_vegetation_380-780_5nm.csv"),
    ("man", "usgs_splib07a_manmade_380-780_5nm.csv"),
    ("soil", "usgs_splib07a_soils_380-780_5nm.csv"),
    ("min", "usgs_splib07a_minerals_380-780_5nm.csv"),
    ("rhodo", "rhododendron_leaves_380-780_5nm.csv"),
    ("cqs", "nist_cqs90_vs_380-780_5nm.csv"),
    // 400–700 nm only: held at its end values outside (CIE 015's practice for missing data).
    ("pmc", "colour_pmc_400-700_5nm.csv"),
    // 405–780 nm: held at its end values below 405 nm, as PMC.
    ("pig", "hyppigments_405-780_5nm.csv"),
    // Derived, not measured: the man-made set's spectra squared and cubed (light through two
    // or three layers of the same material: more saturated colours, public domain as its
    // source). Only trained on, never a test set.
    ("man23", "usgs_splib07a_manmade_380-780_5nm.csv"),
];

const OPEN: [&str; 5] = ["veg", "man", "soil", "min", "rhodo"];
const ALL: [&str; 7] = ["munsell", "cc", "veg", "man", "soil", "min", "rhodo"];
/// The sets every recipe is scored on: all measured ones.
const TESTS: usize = 10;
/// `extended`'s recipe, the default every open candidate is compared with (issue 33).
const EXTENDED: &str = "munsell*48+cc*4+veg+man+soil+min+rhodo/8/20/100/0/0.02";

struct Study {
    a: Colorimetry,
    sets: Vec<TrainingSet>,
    /// Spectra kept in [0, 1] with their XYZ, as `convert` writes them by default.
    bounded: bool,
    holdout: Holdout,
}

/// One row: a label, the sets trained on with their weights, balance, options, blend.
struct Row {
    label: String,
    parts: Vec<(&'static str, f64)>,
    balance: f64,
    options: TrainOptions,
    blend: f64,
}

fn options(clusters: usize, min_cluster_size: usize, max_condition: f64) -> TrainOptions {
    TrainOptions {
        clusters,
        min_cluster_size,
        max_condition,
    }
}

fn row(label: &str, sets: &[&'static str], balance: f64, o: TrainOptions) -> Row {
    Row {
        label: label.into(),
        parts: sets.iter().map(|&s| (s, 1.0)).collect(),
        balance,
        options: o,
        blend: DEFAULT_WIDTH,
    }
}

impl Study {
    fn load() -> Study {
        let dir = std::env::var("SPECCONV_SHARED")
            .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared").into());
        let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
        let mut sets: Vec<TrainingSet> = SETS[..TESTS]
            .iter()
            .map(|(_, file)| {
                let text = std::fs::read_to_string(format!("{dir}/spectra/{file}"))
                    .expect("../shared/spectra beside the checkout (or SPECCONV_SHARED)");
                let table = SpectralTable::parse(file, &text).unwrap();
                let sha256 = specconv_spectral::otsu2018::terms::content_hash(text.as_bytes());
                TrainingSet::from_file(&table, &sha256, &a.grid, true).unwrap()
            })
            .collect();
        let man = sets[SETS.iter().position(|(s, _)| *s == "man").unwrap()].clone();
        let mut powers = TrainingSet {
            sources: vec!["manmade squared and cubed".into()],
            ..TrainingSet::default()
        };
        for p in [2, 3] {
            for (s, n) in man.spectra.iter().zip(&man.names) {
                powers
                    .spectra
                    .push(s.iter().map(|v| v.max(0.0).powi(p)).collect());
                powers.names.push(format!("{n}^{p}"));
            }
        }
        sets.push(powers);
        Study {
            a,
            sets,
            bounded: false,
            holdout: Holdout::Set,
        }
    }

    fn set(&self, short: &str) -> &TrainingSet {
        &self.sets[SETS.iter().position(|(s, _)| *s == short).expect("a set")]
    }

    fn recipe(&self, r: &Row) -> Recipe {
        Recipe {
            parts: r
                .parts
                .iter()
                .map(|&(s, weight)| Part {
                    set: self.set(s).clone(),
                    weight,
                    terms: self.set(s).sets[0].terms(),
                })
                .collect(),
            balance: r.balance,
            options: r.options.clone(),
        }
    }

    fn score(&self, r: &Row) -> (Scores, f64, usize) {
        let recipe = self.recipe(r);
        let viewing = eval::Viewing::new(&self.a, &eval::SHIFT_ILLUMINANTS).unwrap();
        let start = std::time::Instant::now();
        let model = recipe.train(&self.a).unwrap();
        let seconds = start.elapsed().as_secs_f64();
        let scores = held_out_by_set(
            &recipe,
            &self.sets[..TESTS],
            &self.a,
            self.holdout,
            |m, held| {
                let up = Uplifter::new(m)?.with_blend(r.blend)?;
                Ok::<_, specconv_spectral::Error>(if self.bounded {
                    let b = Bounded::new(up, self.a.clone())?;
                    eval::evaluate(&self.a, &b, held, &viewing)
                } else {
                    eval::evaluate(&self.a, &up, held, &viewing)
                })
            },
        )
        .unwrap();
        (scores, seconds, model.leaves.len())
    }

    /// Scores every row (in parallel: each row trains dozens of models) and prints them, with
    /// each row against `extended`'s recipe scored in the same run. A set's cell is its mean
    /// Δe / CIEDE2000 under A / under F11; † marks a set held out by folds (in the recipe).
    fn table(&self, title: &str, rows: &[Row]) {
        use rayon::prelude::*;
        println!("\n### {title}\n");
        let heads: Vec<&str> = SETS[..TESTS].iter().map(|(s, _)| *s).collect();
        println!(
            "| recipe | {} | Δe mean of sets | ΔE00 A | ΔE00 F11 | shift (A, F11) | worst set, A | vs extended: shift, Δe, munsell A | leaves | train s |",
            heads.join(" | ")
        );
        println!(
            "|---|{}---|---|---|---|---|---|---|---|",
            "---|".repeat(heads.len())
        );
        let reference = parse_row(EXTENDED);
        let (base, ..) = self.score(&reference);
        // Each row printed as soon as it is scored (rows finish out of order): a long sweep
        // cut short keeps what it has.
        std::iter::once(&reference)
            .chain(rows)
            .collect::<Vec<_>>()
            .par_iter()
            .for_each(|r| {
                let (s, seconds, leaves) = self.score(r);
                let cells: Vec<String> = s
                    .sets
                    .iter()
                    .map(|x| {
                        let mark = match x.how {
                            specconv_evaluation::sets::How::Folds(_) => "†",
                            _ => "",
                        };
                        let shift = &x.summary.colour_shift;
                        format!(
                            "{:.4}{mark} / {:.2} / {:.2}",
                            x.summary.delta_e.mean, shift[0].mean, shift[1].mean
                        )
                    })
                    .collect();
                let munsell = |s: &Scores| {
                    s.sets
                        .iter()
                        .find(|x| short(&x.source) == "munsell")
                        .map_or(f64::NAN, |x| x.summary.colour_shift[0].mean)
                };
                let a = &s.colour_shift[0];
                println!(
                    "| {} | {} | {:.4} | {:.3} | {:.3} | **{:.3}** | {:.2} ({}) | {:.2}, {:.2}, {:.2} | {leaves} | {seconds:.3} |",
                    r.label,
                    cells.join(" | "),
                    s.mean_of_sets,
                    a.mean_of_sets,
                    s.colour_shift[1].mean_of_sets,
                    shift(&s),
                    a.worst,
                    short(&a.worst_set),
                    shift(&s) / shift(&base),
                    s.mean_of_sets / base.mean_of_sets,
                    munsell(&s) / munsell(&base),
                );
            });
    }
}

/// What the study ranks recipes by: the mean over sets of the colour shift under A and under
/// F11, averaged over the two.
fn shift(s: &Scores) -> f64 {
    s.colour_shift.iter().map(|x| x.mean_of_sets).sum::<f64>() / s.colour_shift.len() as f64
}

/// A set's short name from its file name.
fn short(file: &str) -> &'static str {
    SETS.iter()
        .find(|(_, f)| *f == file)
        .map_or("?", |(s, _)| s)
}

fn main() {
    let mut study = Study::load();
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(i) = args.iter().position(|a| a == "--bounded") {
        args.remove(i);
        study.bounded = true;
    }
    if let Some(i) = args.iter().position(|a| a == "--folds") {
        args.remove(i);
        study.holdout = Holdout::Folds(args.remove(i).parse().expect("--folds K"));
    }
    println!(
        "held out: {:?}; {}",
        study.holdout,
        if study.bounded {
            "bounded"
        } else {
            "unbounded"
        }
    );
    let wants = |s: &str| args.is_empty() || args.iter().any(|a| a == s);
    let base = || options(8, 20, 100.0);

    // Rows given as SETS/K/MIN/COND/BALANCE/BLEND, SETS `all`, `open` or names joined by `+`,
    // a set's weight after `*` (man*4).
    let custom: Vec<Row> = args
        .iter()
        .filter(|a| a.contains('/'))
        .map(|a| parse_row(a))
        .collect();
    if !custom.is_empty() {
        study.table("Recipes", &custom);
        return;
    }
    if wants("time") {
        let recipe = study.recipe(&row("all", &ALL, 0.0, base()));
        let all = TrainingSet::union(&recipe.parts, 0.0).unwrap();
        for k in [8, 16, 32] {
            let t = std::time::Instant::now();
            let m = specconv_spectral::train(&all, &study.a, &options(k, 20, 100.0)).unwrap();
            println!(
                "{} spectra, k = {k}: {} leaves in {:.3} s",
                all.spectra.len(),
                m.leaves.len(),
                t.elapsed().as_secs_f64()
            );
        }
        return;
    }
    if wants("today") {
        study.table(
            "Today's default (Munsell, k = 8, min 20)",
            &[row("munsell k8", &["munsell"], 0.0, base())],
        );
    }
    if wants("all") {
        study.table(
            "All sets, k = 8, min 20, by balance",
            &[0.0, 0.5, 1.0].map(|b| row(&format!("all balance {b}"), &ALL, b, base())),
        );
    }
    if wants("k") {
        let rows: Vec<Row> = [4, 8, 12, 16, 24, 32]
            .iter()
            .flat_map(|&k| {
                [0.5, 1.0]
                    .map(|b| row(&format!("all k{k} bal {b}"), &ALL, b, options(k, 20, 100.0)))
            })
            .collect();
        study.table("All sets by clusters and balance (min 20)", &rows);
    }
    if wants("min") {
        let rows: Vec<Row> = [10, 20, 40, 80]
            .iter()
            .flat_map(|&m| {
                [8, 16].map(|k| {
                    row(
                        &format!("all k{k} min {m}"),
                        &ALL,
                        1.0,
                        options(k, m, 100.0),
                    )
                })
            })
            .collect();
        study.table("All sets by minimum cluster size (balance 1)", &rows);
    }
    if wants("condition") {
        let rows: Vec<Row> = [10.0, 30.0, 100.0, 300.0, 1000.0]
            .iter()
            .map(|&c| row(&format!("all k16 cond {c}"), &ALL, 1.0, options(16, 20, c)))
            .collect();
        study.table(
            "All sets by condition bound (k = 16, min 20, balance 1)",
            &rows,
        );
    }
    if wants("blend") {
        let rows: Vec<Row> = [0.0, 0.01, 0.02, 0.05]
            .iter()
            .map(|&w| Row {
                blend: w,
                ..row(
                    &format!("all k16 blend {w}"),
                    &ALL,
                    1.0,
                    options(16, 20, 100.0),
                )
            })
            .collect();
        study.table("All sets by blend width (k = 16, min 20, balance 1)", &rows);
    }
    if wants("sets") {
        let rows = vec![
            row(
                "munsell+cc k16",
                &["munsell", "cc"],
                1.0,
                options(16, 20, 100.0),
            ),
            row(
                "munsell+man k16",
                &["munsell", "man"],
                1.0,
                options(16, 20, 100.0),
            ),
            row(
                "all but minerals k16",
                &["munsell", "cc", "veg", "man", "soil", "rhodo"],
                1.0,
                options(16, 20, 100.0),
            ),
            row(
                "all but rhodo k16",
                &["munsell", "cc", "veg", "man", "soil", "min"],
                1.0,
                options(16, 20, 100.0),
            ),
            row("all k16", &ALL, 1.0, options(16, 20, 100.0)),
        ];
        study.table("Which sets (k = 16, min 20, balance 1)", &rows);
    }
    if wants("open") {
        let rows: Vec<Row> = [8, 16, 32]
            .iter()
            .flat_map(|&k| {
                [0.0, 0.5, 1.0].map(|b| {
                    row(
                        &format!("open k{k} bal {b}"),
                        &OPEN,
                        b,
                        options(k, 20, 100.0),
                    )
                })
            })
            .collect();
        study.table(
            "Open data (USGS ×4, Rhododendron) by clusters and balance",
            &rows,
        );
    }
    if wants("open-weights") {
        let weighted = |label: &str, man: f64, k: usize, min: usize, b: f64| Row {
            parts: OPEN
                .iter()
                .map(|&s| (s, if s == "man" { man } else { 1.0 }))
                .collect(),
            ..row(label, &OPEN, b, options(k, min, 100.0))
        };
        let rows = vec![
            weighted("open man×2 k16", 2.0, 16, 20, 1.0),
            weighted("open man×4 k16", 4.0, 16, 20, 1.0),
            weighted("open man×8 k16", 8.0, 16, 20, 1.0),
            weighted("open man×4 k16 min 10", 4.0, 16, 10, 1.0),
            weighted("open man×4 k32 min 10", 4.0, 32, 10, 1.0),
            row(
                "open but minerals k16",
                &["veg", "man", "soil", "rhodo"],
                1.0,
                options(16, 20, 100.0),
            ),
            row(
                "open man only k8 min 10",
                &["man"],
                0.0,
                options(8, 10, 100.0),
            ),
        ];
        study.table("Open data: what closes the gap", &rows);
    }
}

fn parse_row(spec: &str) -> Row {
    let f: Vec<&str> = spec.split('/').collect();
    assert_eq!(f.len(), 6, "SETS/K/MIN/COND/BALANCE/BLEND: {spec}");
    let names: Vec<String> = match f[0] {
        "all" => ALL.iter().map(|s| s.to_string()).collect(),
        "open" => OPEN.iter().map(|s| s.to_string()).collect(),
        list => list.split('+').map(str::to_string).collect(),
    };
    let parts = names
        .iter()
        .map(|n| {
            let (name, w) = n
                .split_once('*')
                .map_or((n.as_str(), 1.0), |(a, b)| (a, b.parse().unwrap()));
            let short = SETS.iter().find(|(s, _)| *s == name).expect("a set name").0;
            (short, w)
        })
        .collect();
    let num = |i: usize| f[i].parse::<f64>().unwrap();
    Row {
        label: spec.to_string(),
        parts,
        balance: num(4),
        options: options(num(1) as usize, num(2) as usize, num(3)),
        blend: num(5),
    }
}
