//! What specconv's tests share, so that no test file carries a copy: the measured spectra (they
//! live in ../shared beside the checkout, never in it), the paper's setting, and the training
//! sets that cannot make a model ([`untrainable`]), the seeded generators ([`Lcg`], [`SplitMix`]) and the
//! benches' timing ([`median_seconds`]). Dev-only: no library depends on it.

pub mod cmd;
pub mod sources;
pub mod untrainable;

/// The workspace's one seeded generator and its random colours, from `specconv_evaluation::cost`
/// (whose timings need them too).
pub use specconv_evaluation::cost::{random_colours, Lcg};

/// SplitMix64 (Steele, Lea and Flood, 2014): the seeded stream the object-colour solid's tests
/// and benches and the C encoder's test draw their colours from, the same every run (their
/// recorded figures were measured on it, so it is kept beside [`Lcg`] rather than replaced).
pub struct SplitMix(pub u64);

impl SplitMix {
    /// The next 64 bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1): the top 53 bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [a, b).
    pub fn in_range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
}

use specconv_colour::{Colorimetry, Grid, Illuminant, Observer, SpectralTable};
use specconv_spectral::{TrainOptions, TrainingSet};
use std::path::PathBuf;

/// `../shared` beside the repository (or `$SPECCONV_SHARED`).
pub fn shared() -> PathBuf {
    let dir = std::env::var_os("SPECCONV_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared")));
    assert!(
        dir.join("spectra").is_dir(),
        "measured spectra not found at {}: tests need ../shared beside the checkout (or SPECCONV_SHARED)",
        dir.display()
    );
    dir
}

pub fn table(file: &str) -> SpectralTable {
    let path = shared().join("spectra").join(file);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    SpectralTable::parse(file, &text).unwrap()
}

pub const MUNSELL: &str = "munsell1269_matte_380-800_1nm.csv";
pub const COLORCHECKER: &str = "colorchecker_n_ohta_380-780_5nm.csv";

/// The hash a model records of a shared set ([`specconv_spectral::otsu2018::terms::content_hash`]).
pub fn hash(file: &str) -> String {
    let path = shared().join("spectra").join(file);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    specconv_spectral::otsu2018::terms::content_hash(&bytes)
}

/// A shared set as `specconv train --spectra` reads it: with its hash and known terms.
pub fn set(file: &str, grid: &Grid) -> TrainingSet {
    TrainingSet::from_file(&table(file), &hash(file), grid, false).unwrap()
}

/// Every measured set in ../shared/spectra, by file name (its README lists them).
pub const ALL_SETS: [&str; 7] = [
    MUNSELL,
    COLORCHECKER,
    "usgs_splib07a_vegetation_380-780_5nm.csv",
    "usgs_splib07a_manmade_380-780_5nm.csv",
    "usgs_splib07a_soils_380-780_5nm.csv",
    "usgs_splib07a_minerals_380-780_5nm.csv",
    "rhododendron_leaves_380-780_5nm.csv",
];

/// A model trained again from what it records: its sets read from ../shared with their
/// recorded weights and licences, its options and its colorimetry.
pub fn retrain(m: &specconv_spectral::Model) -> specconv_spectral::Model {
    let a = m.colorimetry().unwrap();
    let parts: Vec<specconv_spectral::Part> = m
        .training
        .sets
        .iter()
        .map(|r| specconv_spectral::Part {
            set: TrainingSet::from_file(&table(&r.source), &hash(&r.source), &a.grid, r.held_ends)
                .unwrap(),
            weight: r.weight,
            terms: r.terms(),
        })
        .collect();
    let t = &m.training;
    let opts = TrainOptions {
        clusters: t.clusters_requested,
        min_cluster_size: t.min_cluster_size,
        max_condition: t.max_condition,
    };
    specconv_spectral::train(&TrainingSet::weighted(&parts), &a, &opts).unwrap()
}

/// The paper's setting: Wyman 2013 observer, no illuminant weighting, 380–730 nm at 10 nm.
pub fn paper() -> Colorimetry {
    Colorimetry::new(Grid::PAPER, Observer::Wyman2013, Illuminant::E).unwrap()
}

pub fn paper_options(clusters: usize) -> TrainOptions {
    TrainOptions {
        clusters,
        min_cluster_size: 4,
        ..TrainOptions::default()
    }
}

/// The median of `runs` timings of `f`, in seconds: what the benches compare against a
/// reference measured in the same run (the median shrugs off the machine's other work).
pub fn median_seconds(runs: usize, f: &mut dyn FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let s = std::time::Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}
