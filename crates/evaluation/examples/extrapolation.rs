//! Worst spectral gain (‖r‖ / (X+Y+Z), see `crate::extrapolation`) of the uplift per leaf on
//! dense sRGB and Rec.2020 cubes, against the gains of the Munsell spectra of the same leaf.
//!
//!     cargo run --release -p specconv-spectral --example extrapolation -- \
//!         [builtin|paper|MODEL.json] [STEPS] [MAX_CONDITION]
//!
//! `paper` trains the paper's Table 1 model (Wyman 2013, E, 8 clusters of at least 4) with the
//! condition bound MAX_CONDITION (default: the training default). Needs the measured spectra in
//! $SPECCONV_SHARED (default ../shared beside the checkout).

use specconv_colour::rgb::{REC2020, SRGB};
use specconv_colour::{Grid, Illuminant, Observer, SpectralTable};
use specconv_evaluation::extrapolation::{rgb_cube, training_gains, uplift_gains, worst, Gain};
use specconv_spectral::{Model, TrainOptions, TrainingSet};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let which = args.first().map_or("builtin", String::as_str);
    let steps: usize = args.get(1).map_or(Ok(65), |s| s.parse())?;
    let max_condition: f64 = args
        .get(2)
        .map_or(Ok(TrainOptions::default().max_condition), |s| s.parse())?;
    let shared = std::env::var_os("SPECCONV_SHARED")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared").into());
    let file = "munsell1269_matte_380-800_1nm.csv";
    let text = std::fs::read_to_string(shared.join("spectra").join(file))?;
    let table = SpectralTable::parse(file, &text)?;
    let model = match which {
        "builtin" => Model::builtin().clone(),
        "paper" => {
            let a =
                specconv_colour::Colorimetry::new(Grid::PAPER, Observer::Wyman2013, Illuminant::E)?;
            let set = TrainingSet::from_table(&table, &a.grid)?;
            let opts = TrainOptions {
                clusters: 8,
                min_cluster_size: 4,
                max_condition,
            };
            specconv_spectral::train(&set, &a, &opts)?
        }
        path => Model::from_json(path, &std::fs::read_to_string(path)?)?,
    };
    let a = model.colorimetry()?;
    let up = specconv_spectral::Uplifter::new(&model)?;
    let measured = training_gains(&a, &up, &table.resampled(&a.grid)?);
    let cubes = [SRGB, REC2020].map(|s| {
        (
            s.name,
            uplift_gains(&up, &rgb_cube(&s, a.white_xyz(), steps)),
        )
    });
    println!(
        "model {which}: {} leaves; gain = ‖r‖ / (X+Y+Z) over {steps}³ cubes (L∞, and L2 as RMS over bands)",
        model.leaves.len()
    );
    println!(
        "{:>4} {:>5} {:>6} | {:>15} | {:>15} {:>7} | {:>15} {:>7}",
        "leaf", "cond", "train", "Munsell L∞/L2", "sRGB L∞/L2", "×Mun", "Rec2020 L∞/L2", "×Mun"
    );
    let get = |v: &[Gain], k: usize| v.get(k).copied().unwrap_or_default();
    let row = |label: String, cond: String, m: Gain, s: Gain, r: Gain| {
        println!(
            "{label:>4} {cond:>5} {:>6} | {:>7.3} {:>7.3} | {:>7.3} {:>7.3} {:>7.2} | {:>7.3} {:>7.3} {:>7.2}",
            m.count, m.linf, m.l2, s.linf, s.l2, s.linf / m.linf, r.linf, r.l2, r.linf / m.linf
        )
    };
    for (k, leaf) in model.leaves.iter().enumerate() {
        let (m, s, r) = (get(&measured, k), get(&cubes[0].1, k), get(&cubes[1].1, k));
        row(k.to_string(), format!("{:.1}", leaf.condition), m, s, r);
    }
    let (m, s, r) = (worst(&measured), worst(&cubes[0].1), worst(&cubes[1].1));
    row("all".into(), String::new(), m, s, r);
    for (name, g) in &cubes {
        let w = worst(g);
        println!("{name}: worst L∞ gain {:.3} at XYZ {:.4?}", w.linf, w.worst);
    }
    Ok(())
}
