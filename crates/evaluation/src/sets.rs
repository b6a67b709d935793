//! Cross-validation across measured sets: how a training recipe (which sets, their weights,
//! the training options) does on kinds of material it has not seen.
//!
//! [`held_out_by_set`] scores every test set on spectra the model was not trained on. A set
//! outside the recipe is uplifted by the recipe's model as it is. A set inside it is left out:
//! the model is trained on the recipe's other sets ([`Holdout::Set`], leave one set out), or,
//! for a recipe with no other set, on the set's other folds (K-fold within it, the only
//! held-out figure such a recipe has). [`Holdout::Folds`] instead trains on the other sets
//! *and* the set's other folds: how the model does on new samples of a kind it knows.
//!
//! A recipe is judged by its worst set as much as by its mean ([`Scores`]): a model that wins
//! on average by losing badly on one kind of material is not the better default.

use crate::eval::{self, Outcome, Statistics};
use serde::Serialize;
use specconv_colour::Colorimetry;
use specconv_colour::Illuminant;
use specconv_spectral::{train, Model, Part, TrainOptions, TrainingSet};

/// How a set inside the recipe is held out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Holdout {
    /// The whole set: trained on the recipe's other sets (K-fold within the set when it is the
    /// recipe's only one).
    Set,
    /// K-fold: trained on the recipe's other sets and the set's other K − 1 folds.
    Folds(usize),
}

/// The folds used within a set when nothing else holds it out, and by `Holdout::Folds`
/// unless told: 10, the usual choice.
pub const DEFAULT_FOLDS: usize = 10;

/// How a set's figure was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum How {
    /// Not in the recipe: its model as trained.
    Unseen,
    /// In the recipe: trained without the set.
    LeftOut,
    /// In the recipe: K-fold, trained without each fold.
    Folds(usize),
}

impl std::fmt::Display for How {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            How::Unseen => f.write_str("not trained on"),
            How::LeftOut => f.write_str("left out"),
            How::Folds(k) => write!(f, "{k}-fold"),
        }
    }
}

/// One test set's held-out outcome.
#[derive(Debug, Clone, Serialize)]
pub struct SetScore {
    /// The set's source (file name).
    pub source: String,
    /// How its figure was obtained.
    pub how: How,
    /// Its summary over its spectra.
    pub summary: Statistics,
}

/// Every set's score, and the figures a recipe is judged by.
#[derive(Debug, Clone, Serialize)]
pub struct Scores {
    /// Per test set, in the order given.
    pub sets: Vec<SetScore>,
    /// The mean over sets of each set's mean Δe: every set counts once, whatever its size.
    pub mean_of_sets: f64,
    /// The largest of the sets' mean Δe.
    pub worst: f64,
    /// The set with the largest mean Δe.
    pub worst_set: String,
    /// The same figures for the mean colour shift under each illuminant of the evaluation.
    pub colour_shift: Vec<SetsShift>,
}

/// The mean over sets and the worst set of the sets' mean colour shift under one illuminant.
#[derive(Debug, Clone, Serialize)]
pub struct SetsShift {
    /// The light.
    pub illuminant: Illuminant,
    /// The mean over sets of each set's mean CIEDE2000.
    pub mean_of_sets: f64,
    /// The largest of the sets' mean CIEDE2000.
    pub worst: f64,
    /// The set with the largest.
    pub worst_set: String,
}

/// The mean of `means`, their largest and the source of the largest.
fn mean_and_worst(sets: &[SetScore], means: &[f64]) -> (f64, f64, String) {
    let worst = means.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let worst_set = sets
        .iter()
        .zip(means)
        .find(|(_, &m)| m == worst)
        .map_or_else(String::new, |(s, _)| s.source.clone());
    (
        means.iter().sum::<f64>() / means.len().max(1) as f64,
        worst,
        worst_set,
    )
}

impl Scores {
    /// The scores of `sets`, with the mean and worst of their mean Δe.
    pub fn of(sets: Vec<SetScore>) -> Scores {
        let means: Vec<f64> = sets.iter().map(|s| s.summary.delta_e.mean).collect();
        let (mean_of_sets, worst, worst_set) = mean_and_worst(&sets, &means);
        let lights = sets
            .first()
            .map_or(&[][..], |s| &s.summary.colour_shift[..]);
        let colour_shift = lights
            .iter()
            .enumerate()
            .map(|(k, first)| {
                let means: Vec<f64> = sets
                    .iter()
                    .map(|s| s.summary.colour_shift[k].mean)
                    .collect();
                let (mean_of_sets, worst, worst_set) = mean_and_worst(&sets, &means);
                SetsShift {
                    illuminant: first.illuminant,
                    mean_of_sets,
                    worst,
                    worst_set,
                }
            })
            .collect();
        Scores {
            mean_of_sets,
            worst,
            worst_set,
            colour_shift,
            sets,
        }
    }

    /// The score of the set from `source`.
    pub fn set(&self, source: &str) -> Option<&SetScore> {
        self.sets.iter().find(|s| s.source == source)
    }
}

/// What is trained: the sets with their weights and licences, the balance between them and the
/// training options.
#[derive(Debug, Clone)]
pub struct Recipe {
    /// The training sets, one source each.
    pub parts: Vec<Part>,
    /// [`TrainingSet::union`]'s balance.
    pub balance: f64,
    /// The training options.
    pub options: TrainOptions,
}

impl Recipe {
    /// The recipe's model on all its sets.
    pub fn train(&self, a: &Colorimetry) -> Result<Model, specconv_spectral::Error> {
        train(
            &TrainingSet::union(&self.parts, self.balance)?,
            a,
            &self.options,
        )
    }

    /// The training set without part `skip` (and, with `fold`, without fold `f` of K of it).
    fn without(
        &self,
        skip: usize,
        fold: Option<(usize, usize)>,
    ) -> Result<TrainingSet, specconv_spectral::Error> {
        let mut parts: Vec<Part> = Vec::with_capacity(self.parts.len());
        for (j, p) in self.parts.iter().enumerate() {
            match (j == skip, fold) {
                (false, _) => parts.push(p.clone()),
                (true, Some((f, k))) => parts.push(Part {
                    set: p.set.subset(|i| i % k != f),
                    ..p.clone()
                }),
                (true, None) => {}
            }
        }
        TrainingSet::union(&parts, self.balance)
    }
}

/// Which sources a set holds (each test set and each part is one source).
fn source(set: &TrainingSet) -> String {
    set.sources.join(", ")
}

/// Scores `recipe` on every set of `tests` with spectra it was not trained on, as the module
/// says; `held_out(model, spectra)` evaluates a model (with the blend, bounds… of the study).
pub fn held_out_by_set<E: From<specconv_spectral::Error>>(
    recipe: &Recipe,
    tests: &[TrainingSet],
    a: &Colorimetry,
    holdout: Holdout,
    mut held_out: impl FnMut(&Model, &[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Scores, E> {
    let mut whole: Option<Model> = None;
    let mut scores = Vec::with_capacity(tests.len());
    for test in tests {
        let name = source(test);
        let inside = recipe.parts.iter().position(|p| source(&p.set) == name);
        let (how, outcomes) = match (inside, holdout) {
            (None, _) => {
                if whole.is_none() {
                    whole = Some(recipe.train(a)?);
                }
                let model = whole.as_ref().expect("trained above");
                (How::Unseen, held_out(model, &test.spectra)?)
            }
            (Some(j), Holdout::Set) if recipe.parts.len() > 1 => {
                let model = train(&recipe.without(j, None)?, a, &recipe.options)?;
                (How::LeftOut, held_out(&model, &test.spectra)?)
            }
            (Some(j), Holdout::Set) => (
                How::Folds(DEFAULT_FOLDS),
                folds(recipe, j, test, a, DEFAULT_FOLDS, &mut held_out)?,
            ),
            (Some(j), Holdout::Folds(k)) => {
                (How::Folds(k), folds(recipe, j, test, a, k, &mut held_out)?)
            }
        };
        scores.push(SetScore {
            source: name,
            how,
            summary: eval::summarise(&outcomes),
        });
    }
    Ok(Scores::of(scores))
}

/// Part `j`'s spectra held out fold by fold (fold f: every spectrum i with i mod K = f).
fn folds<E: From<specconv_spectral::Error>>(
    recipe: &Recipe,
    j: usize,
    test: &TrainingSet,
    a: &Colorimetry,
    k: usize,
    held_out: &mut impl FnMut(&Model, &[Vec<f64>]) -> Result<Vec<Outcome>, E>,
) -> Result<Vec<Outcome>, E> {
    let count = test.spectra.len();
    if k < 2 || count < k {
        let msg = format!(
            "{k}-fold cross-validation needs 2 to {count} folds (one per spectrum at most)"
        );
        return Err(specconv_spectral::Error::Training(msg).into());
    }
    let mut outcomes = Vec::with_capacity(count);
    for f in 0..k {
        let model = train(&recipe.without(j, Some((f, k)))?, a, &recipe.options)?;
        let held: Vec<Vec<f64>> = (f..count)
            .step_by(k)
            .map(|i| test.spectra[i].clone())
            .collect();
        outcomes.extend(held_out(&model, &held)?);
    }
    Ok(outcomes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::{Grid, Illuminant, Observer};

    fn set(name: &str, count: usize, tilt: f64) -> TrainingSet {
        let spectra = (0..count)
            .map(|k| {
                let (p, q) = ((k as f64 * 0.37).sin(), (k as f64 * 1.13).cos());
                (0..36)
                    .map(|i| {
                        let t = i as f64 / 36.0;
                        0.4 + tilt * t
                            + 0.2 * p * (3.0 * t).sin()
                            + 0.1 * q * (7.0 * t).cos()
                            + 0.01 * (k as f64 * i as f64).sin()
                    })
                    .collect()
            })
            .collect();
        TrainingSet {
            sources: vec![name.into()],
            names: (0..count).map(|k| format!("{name}{k}")).collect(),
            spectra,
            ..TrainingSet::default()
        }
    }

    fn part(set: TrainingSet) -> Part {
        Part {
            set,
            weight: 1.0,
            terms: Default::default(),
        }
    }

    /// Records which training set sizes and held-out counts it saw.
    fn run(
        recipe: &Recipe,
        tests: &[TrainingSet],
        holdout: Holdout,
    ) -> (Scores, Vec<(usize, usize)>) {
        let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
        let mut seen = Vec::new();
        let scores = held_out_by_set(recipe, tests, &a, holdout, |m, held| {
            seen.push((m.training.count, held.len()));
            Ok::<_, specconv_spectral::Error>(
                held.iter()
                    .map(|_| Outcome {
                        delta_e: m.training.count as f64,
                        roundtrip: 0.0,
                        roundtrip_de2000: 0.0,
                        in_unit_range: true,
                        leaf: None,
                        colour_shift: vec![eval::Shift {
                            illuminant: Illuminant::A,
                            ciede2000: 2.0 * m.training.count as f64,
                        }],
                    })
                    .collect(),
            )
        })
        .unwrap();
        (scores, seen)
    }

    #[test]
    fn each_set_is_scored_by_a_model_trained_without_it() {
        let (a, b, c) = (set("a", 40, 0.1), set("b", 30, -0.1), set("c", 24, 0.2));
        let recipe = Recipe {
            parts: vec![part(a.clone()), part(b.clone())],
            balance: 0.0,
            options: TrainOptions {
                clusters: 1,
                min_cluster_size: 4,
                // Synthetic spectra: what is tested is which model scores which set.
                max_condition: 1e6,
            },
        };
        let (scores, seen) = run(&recipe, &[a.clone(), b.clone(), c.clone()], Holdout::Set);
        // a is scored by the model of b alone, b by a's, c by both.
        assert_eq!(seen, vec![(30, 40), (40, 30), (70, 24)]);
        let hows: Vec<How> = scores.sets.iter().map(|s| s.how).collect();
        assert_eq!(hows, vec![How::LeftOut, How::LeftOut, How::Unseen]);
        assert_eq!(scores.worst, 70.0);
        assert_eq!(scores.worst_set, "c");
        assert!((scores.mean_of_sets - (30.0 + 40.0 + 70.0) / 3.0).abs() < 1e-12);
        let shift = &scores.colour_shift[0];
        assert_eq!((shift.illuminant, shift.worst), (Illuminant::A, 140.0));
        assert_eq!(shift.worst_set, "c");
        assert!((shift.mean_of_sets - 2.0 * (30.0 + 40.0 + 70.0) / 3.0).abs() < 1e-12);

        // K-fold: the set's other folds join the other sets.
        let (_, seen) = run(&recipe, std::slice::from_ref(&a), Holdout::Folds(4));
        assert_eq!(seen, vec![(60, 10); 4]);
        // A recipe of one set has no other: K-fold within it.
        let single = Recipe {
            parts: vec![part(b.clone())],
            ..recipe
        };
        let (scores, seen) = run(&single, &[b], Holdout::Set);
        assert_eq!(scores.sets[0].how, How::Folds(DEFAULT_FOLDS));
        assert_eq!(seen.len(), DEFAULT_FOLDS);
        assert!(seen.iter().all(|&(trained, held)| trained + held == 30));
    }
}
