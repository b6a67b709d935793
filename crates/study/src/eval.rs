//! How well a model reproduces measured spectra from their own colours (the paper's Table 1).

use serde::Serialize;
use specconv_colour::Colorimetry;
use specconv_spectral::{train, Method, Model, TrainOptions, TrainingSet};

/// One measured spectrum's outcome.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Outcome {
    /// Δe = ‖s − r‖²
    pub delta_e: f64,
    /// max over X, Y, Z of |XYZ(r) − XYZ(s)| / Y(s) (absolute where Y(s) ≤ 0).
    pub roundtrip: f64,
    /// CIEDE2000 between the colours of r and s, white = the perfect reflector.
    pub roundtrip_de2000: f64,
    /// Every band of r within [0, 1].
    pub in_unit_range: bool,
    /// The cluster used, for methods with clusters.
    pub leaf: Option<usize>,
}

/// Mean, median and maximum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    /// Arithmetic mean; NaN for no outcomes.
    pub mean: f64,
    /// Median (the mean of the middle two for an even count); NaN for no outcomes.
    pub median: f64,
    /// Largest value; NaN for no outcomes.
    pub max: f64,
}

/// The outcomes of one evaluation in a few numbers ([`summarise`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Spectra evaluated.
    pub count: usize,
    /// Statistics of [`Outcome::delta_e`], the squared spectral error.
    pub delta_e: Stats,
    /// Largest [`Outcome::roundtrip`] (relative XYZ error of the round trip); 0 for no outcomes.
    pub roundtrip_max: f64,
    /// Largest [`Outcome::roundtrip_de2000`]; 0 for no outcomes.
    pub roundtrip_de2000_max: f64,
    /// Fraction of reconstructions inside [0, 1].
    pub in_unit_range: f64,
}

/// Uplifts every spectrum's XYZ (f64) and compares the result with the spectrum.
pub fn evaluate(a: &Colorimetry, up: &dyn Method, spectra: &[Vec<f64>]) -> Vec<Outcome> {
    assert_eq!(
        up.grid(),
        a.grid,
        "the method and the colorimetry must share a grid"
    );
    let white = a.white_xyz();
    let mut r = vec![0.0; a.bands()];
    spectra
        .iter()
        .map(|s| {
            let c = a.xyz(s);
            up.uplift_f64(&c, &mut r);
            let back = a.xyz(&r);
            let scale = if c[1] > 0.0 { c[1] } else { 1.0 };
            Outcome {
                delta_e: s.iter().zip(&r).map(|(x, y)| (x - y) * (x - y)).sum(),
                roundtrip: (0..3)
                    .map(|k| (back[k] - c[k]).abs() / scale)
                    .fold(0.0, f64::max),
                roundtrip_de2000: specconv_colour::lab::ciede2000(
                    specconv_colour::lab::xyz_to_lab(c, white),
                    specconv_colour::lab::xyz_to_lab(back, white),
                ),
                in_unit_range: r.iter().all(|v| (0.0..=1.0).contains(v)),
                leaf: up.cluster_of(c),
            }
        })
        .collect()
}

/// Mean, median and maximum of Δe, the worst round trips and the in-range fraction of
/// `outcomes` (NaN statistics and fraction when there are none).
pub fn summarise(outcomes: &[Outcome]) -> Summary {
    let mut de: Vec<f64> = outcomes.iter().map(|o| o.delta_e).collect();
    de.sort_by(f64::total_cmp);
    let count = de.len();
    let median = match count {
        0 => f64::NAN,
        c if c % 2 == 1 => de[c / 2],
        c => 0.5 * (de[c / 2 - 1] + de[c / 2]),
    };
    Summary {
        count,
        delta_e: Stats {
            mean: if count == 0 {
                f64::NAN
            } else {
                de.iter().sum::<f64>() / count as f64
            },
            median,
            max: de.last().copied().unwrap_or(f64::NAN),
        },
        roundtrip_max: outcomes.iter().map(|o| o.roundtrip).fold(0.0, f64::max),
        roundtrip_de2000_max: outcomes
            .iter()
            .map(|o| o.roundtrip_de2000)
            .fold(0.0, f64::max),
        in_unit_range: if count == 0 {
            f64::NAN
        } else {
            outcomes.iter().filter(|o| o.in_unit_range).count() as f64 / count as f64
        },
    }
}

/// K-fold cross-validation: fold f holds out every spectrum i of `set` with i mod K = f (so
/// each fold samples the whole set), trains on the others with `opts` in `a`, and evaluates
/// `held_out(model, held-out spectra)`. Returns the first fold's model and the outcomes of
/// every held-out spectrum, fold after fold.
pub fn cross_validate<E: From<specconv_spectral::Error>>(
    set: &TrainingSet,
    a: &Colorimetry,
    opts: &TrainOptions,
    folds: usize,
    mut held_out: impl FnMut(&Model, &[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<(Model, Vec<Outcome>), E> {
    if folds < 2 || set.spectra.len() < folds {
        let msg = format!(
            "{folds}-fold cross-validation needs 2 to {} folds (one per spectrum at most)",
            set.spectra.len()
        );
        return Err(specconv_spectral::Error::Training(msg).into());
    }
    let mut outcomes = Vec::new();
    let mut first = None;
    for f in 0..folds {
        let rest = set.subset(|i| i % folds != f);
        let held: Vec<Vec<f64>> = (f..set.spectra.len())
            .step_by(folds)
            .map(|i| set.spectra[i].clone())
            .collect();
        let model = train(&rest, a, opts)?;
        outcomes.extend(held_out(&model, &held)?);
        first.get_or_insert(model);
    }
    Ok((first.expect("at least two folds"), outcomes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(delta_e: f64, in_unit_range: bool) -> Outcome {
        Outcome {
            delta_e,
            roundtrip: delta_e / 10.0,
            roundtrip_de2000: delta_e / 100.0,
            in_unit_range,
            leaf: None,
        }
    }

    #[test]
    fn summary_statistics() {
        let s = summarise(&[
            outcome(3.0, true),
            outcome(1.0, false),
            outcome(2.0, true),
            outcome(10.0, true),
        ]);
        assert_eq!(s.count, 4);
        assert_eq!(
            s.delta_e,
            Stats {
                mean: 4.0,
                median: 2.5,
                max: 10.0
            }
        );
        assert_eq!(s.roundtrip_max, 1.0);
        assert_eq!(s.roundtrip_de2000_max, 0.1);
        assert_eq!(s.in_unit_range, 0.75);
        assert_eq!(summarise(&[outcome(3.0, true)]).delta_e.median, 3.0);
    }

    #[test]
    fn each_fold_trains_without_what_it_holds_out() {
        let a = Colorimetry::new(
            specconv_colour::Grid::PAPER,
            specconv_colour::Observer::Cie1931,
            specconv_colour::Illuminant::D65,
        )
        .unwrap();
        let set = specconv_testkit::set(specconv_testkit::COLORCHECKER, &a.grid);
        let opts = specconv_testkit::paper_options(1);
        let mut seen = Vec::new();
        let (first, outcomes) = cross_validate(
            &set,
            &a,
            &opts,
            3,
            |m, held| -> Result<_, specconv_spectral::Error> {
                seen.push((m.training.count, held.to_vec()));
                Ok(held.iter().map(|_| outcome(0.0, true)).collect())
            },
        )
        .unwrap();
        assert_eq!(outcomes.len(), 24);
        assert_eq!(first.training.count, 16);
        for (f, (count, held)) in seen.iter().enumerate() {
            assert_eq!(*count, 16);
            let want: Vec<_> = (f..24).step_by(3).map(|i| set.spectra[i].clone()).collect();
            assert_eq!(*held, want);
        }
        for folds in [1, 25] {
            let e = cross_validate(
                &set,
                &a,
                &opts,
                folds,
                |_, _| -> Result<_, specconv_spectral::Error> { Ok(vec![]) },
            );
            assert!(e.err().unwrap().to_string().contains("cross-validation"));
        }
    }
}
