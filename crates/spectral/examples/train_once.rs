//! `specconv train`'s work on the Munsell set, once: read and parse the 1 nm CSV, resample to
//! the default 36 bands, train 8 clusters (minimum 20), write the JSON. For profilers
//! (`valgrind --tool=callgrind`, `perf`), whose counts do not depend on the machine's load.
//! Arguments: [clusters] [min cluster size].

use specconv_colour::{Colorimetry, Grid, Illuminant, Observer, SpectralTable};
use specconv_spectral::{train, TrainOptions, TrainingSet};

fn main() {
    let arg = |i: usize, default: usize| {
        std::env::args()
            .nth(i)
            .map_or(default, |s| s.parse().expect("a count"))
    };
    let dir = std::env::var("SPECCONV_SHARED")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared").into());
    let file = "munsell1269_matte_380-800_1nm.csv";
    let text = std::fs::read_to_string(format!("{dir}/spectra/{file}")).expect("the Munsell CSV");
    let table = SpectralTable::parse(file, &text).unwrap();
    let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
    let set = TrainingSet::from_table(&table, &a.grid).unwrap();
    let opts = TrainOptions {
        clusters: arg(1, 8),
        min_cluster_size: arg(2, 20),
        ..TrainOptions::default()
    };
    let json = train(&set, &a, &opts).unwrap().to_json();
    println!("{} bytes of JSON", json.len());
}
