//! How well a model reproduces measured spectra from their own colours: the paper's spectral
//! error (Table 1) and the colour shift a viewer sees when measured and uplifted spectra are
//! lit by another light than the one the colour was given under.

use serde::Serialize;
use specconv_colour::lab::{ciede2000, xyz_to_lab};
use specconv_colour::{Colorimetry, Illuminant};
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
    /// CIEDE2000 between s and r under each of the [`Viewing`]'s illuminants, in its order.
    pub colour_shift: Vec<Shift>,
}

/// The illuminants colour shift is measured under unless told (issue 43): CIE A (tungsten,
/// smooth and red) and F11 (three narrow phosphor bands), the two that tell metamers apart most.
pub const SHIFT_ILLUMINANTS: [Illuminant; 2] = [Illuminant::A, Illuminant::FL11];

/// Where colour shift is measured: the evaluation's grid and observer, lit by each illuminant.
///
/// Under illuminant I, XYZ of a reflectance is Σ r·I·x̄ / Σ I·ȳ on the grid and CIELAB's white
/// is the perfect reflector under I, so the shift is what a viewer adapted to I sees between
/// the measured spectrum and its uplift (which match exactly under the uplift's own light).
#[derive(Debug, Clone)]
pub struct Viewing {
    under: Vec<Colorimetry>,
}

impl Viewing {
    /// `illuminants` seen through `a`'s observer on `a`'s grid. Fails when an illuminant's
    /// table does not cover the grid.
    pub fn new(
        a: &Colorimetry,
        illuminants: &[Illuminant],
    ) -> Result<Viewing, specconv_colour::Error> {
        let under = illuminants
            .iter()
            .map(|&i| Colorimetry::new(a.grid, a.observer, i))
            .collect::<Result<_, _>>()?;
        Ok(Viewing { under })
    }

    /// No colour shift measured.
    pub fn none() -> Viewing {
        Viewing { under: Vec::new() }
    }

    /// The illuminants, in order.
    pub fn illuminants(&self) -> Vec<Illuminant> {
        self.under.iter().map(|a| a.illuminant).collect()
    }

    /// CIEDE2000 between `s` and `r` under each illuminant.
    pub fn shift(&self, s: &[f64], r: &[f64]) -> Vec<Shift> {
        self.under
            .iter()
            .map(|a| {
                let white = a.white_xyz();
                Shift {
                    illuminant: a.illuminant,
                    ciede2000: ciede2000(xyz_to_lab(a.xyz(s), white), xyz_to_lab(a.xyz(r), white)),
                }
            })
            .collect()
    }
}

/// One spectrum's colour shift under one illuminant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Shift {
    /// The light.
    pub illuminant: Illuminant,
    /// CIEDE2000 between the measured and the uplifted spectrum under it.
    pub ciede2000: f64,
}

/// Colour shift under one illuminant over many spectra.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ShiftStats {
    /// The light.
    pub illuminant: Illuminant,
    /// Mean CIEDE2000; NaN for no outcomes.
    pub mean: f64,
    /// 95th percentile (linear between order statistics, numpy's default); NaN for none.
    pub p95: f64,
    /// Largest CIEDE2000; NaN for none.
    pub max: f64,
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
pub struct Statistics {
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
    /// Colour shift under each illuminant of the evaluation's [`Viewing`].
    pub colour_shift: Vec<ShiftStats>,
}

/// Uplifts every spectrum's XYZ (f64) and compares the result with the spectrum: spectrally,
/// and as colours under each of `viewing`'s illuminants.
pub fn evaluate(
    a: &Colorimetry,
    up: &dyn Method,
    spectra: &[Vec<f64>],
    viewing: &Viewing,
) -> Vec<Outcome> {
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
                colour_shift: viewing.shift(s, &r),
            }
        })
        .collect()
}

/// Mean, median and maximum of Δe, the worst round trips and the in-range fraction of
/// `outcomes` (NaN statistics and fraction when there are none).
pub fn summarise(outcomes: &[Outcome]) -> Statistics {
    let de = sorted(outcomes.iter().map(|o| o.delta_e));
    let count = de.len();
    let illuminants = outcomes.first().map_or(&[][..], |o| &o.colour_shift[..]);
    let colour_shift = illuminants
        .iter()
        .enumerate()
        .map(|(k, first)| {
            let v = sorted(outcomes.iter().map(|o| o.colour_shift[k].ciede2000));
            ShiftStats {
                illuminant: first.illuminant,
                mean: mean(&v),
                p95: percentile(&v, 0.95),
                max: v.last().copied().unwrap_or(f64::NAN),
            }
        })
        .collect();
    Statistics {
        count,
        delta_e: Stats {
            mean: mean(&de),
            median: percentile(&de, 0.5),
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
        colour_shift,
    }
}

fn sorted(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v
}

/// The arithmetic mean; NaN for none.
fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

/// The q-quantile of sorted values, linear between the order statistics at (n − 1)·q (numpy's
/// default, so q = 0.5 is the median of an even count as the mean of the middle two); NaN for
/// none.
fn percentile(sorted: &[f64], q: f64) -> f64 {
    let Some(last) = sorted.len().checked_sub(1) else {
        return f64::NAN;
    };
    let at = q * last as f64;
    let (lo, f) = (at.floor() as usize, at - at.floor());
    if lo >= last {
        return sorted[last];
    }
    sorted[lo] + f * (sorted[lo + 1] - sorted[lo])
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
            colour_shift: vec![
                Shift {
                    illuminant: Illuminant::A,
                    ciede2000: delta_e,
                },
                Shift {
                    illuminant: Illuminant::FL11,
                    ciede2000: 2.0 * delta_e,
                },
            ],
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
        // numpy.percentile([1, 2, 3, 10], 95) = 8.95; under FL11 every value doubled.
        let shift = &s.colour_shift;
        assert_eq!(shift.len(), 2);
        assert_eq!(
            (shift[0].illuminant, shift[1].illuminant),
            (Illuminant::A, Illuminant::FL11)
        );
        assert_eq!((shift[0].mean, shift[0].max), (4.0, 10.0));
        assert!((shift[0].p95 - 8.95).abs() < 1e-12, "{}", shift[0].p95);
        assert!((shift[1].p95 - 17.9).abs() < 1e-12);
        assert_eq!(summarise(&[outcome(3.0, true)]).delta_e.median, 3.0);
        assert_eq!(summarise(&[outcome(3.0, true)]).colour_shift[1].p95, 6.0);
        assert!(summarise(&[]).colour_shift.is_empty());
    }

    /// Metamers under D65 (s and s plus a metameric black) match there and nowhere else:
    /// their shift is 0 under D65, positive under A and F11, and 0 between a spectrum and itself.
    #[test]
    fn colour_shift_tells_metamers_apart_under_other_lights() {
        let a = Colorimetry::new(
            specconv_colour::Grid::PAPER,
            specconv_colour::Observer::Cie1931,
            Illuminant::D65,
        )
        .unwrap();
        let n = a.bands();
        let s: Vec<f64> = (0..n).map(|i| 0.5 + 0.2 * (i as f64 * 0.3).sin()).collect();
        // v minus its projection on A's rows (Gram–Schmidt) is black under D65.
        let mut black: Vec<f64> = (0..n).map(|i| (i as f64 * 0.9).cos()).collect();
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for row in &a.weights {
            let mut b = row.clone();
            for q in &basis {
                let d: f64 = b.iter().zip(q).map(|(x, y)| x * y).sum();
                b.iter_mut().zip(q).for_each(|(x, y)| *x -= d * y);
            }
            let norm = b.iter().map(|x| x * x).sum::<f64>().sqrt();
            basis.push(b.iter().map(|x| x / norm).collect());
        }
        for q in &basis {
            let d: f64 = black.iter().zip(q).map(|(x, y)| x * y).sum();
            black.iter_mut().zip(q).for_each(|(x, y)| *x -= d * y);
        }
        let r: Vec<f64> = s.iter().zip(&black).map(|(x, b)| x + 0.1 * b).collect();
        let v = Viewing::new(&a, &[Illuminant::D65, Illuminant::A, Illuminant::FL11]).unwrap();
        let shift = v.shift(&s, &r);
        assert!(shift[0].ciede2000 < 1e-9, "{shift:?}");
        assert!(
            shift[1].ciede2000 > 0.05 && shift[2].ciede2000 > 0.05,
            "{shift:?}"
        );
        assert!(v.shift(&s, &s).iter().all(|x| x.ciede2000 == 0.0));
        assert_eq!(
            v.illuminants(),
            [Illuminant::D65, Illuminant::A, Illuminant::FL11]
        );
        assert!(Viewing::none().shift(&s, &r).is_empty());
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
