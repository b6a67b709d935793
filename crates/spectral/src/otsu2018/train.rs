//! Training: the greedy kd-tree on CIE xy (Eq. 10–13).
//!
//! Each leaf's best split is searched on both axes at every position between two distinct
//! coordinates, with moments updated one spectrum at a time, so a candidate costs two PCAs of
//! scatter matrices and no pass over the data. The leaf whose best split lowers the summed
//! error most is split next, until the requested number of clusters is reached or no leaf has
//! a split that lowers the error while keeping both sides at least `min_cluster_size` spectra
//! and M's condition number within `max_condition`.
//!
//! Training data that cannot make a model gets an error that says what is wrong with it, or a
//! defined outcome:
//!
//! | training data | outcome |
//! |---|---|
//! | fewer than 4 spectra (one, three) | error: three components need four spectra that differ |
//! | fewer than `min_cluster_size` spectra | error: give more, or lower the minimum |
//! | all spectra identical (up to rounding, [`super::pca::RANK_TOL`]) | error: the spectra must differ |
//! | spectra varying in only 1 or 2 directions (copies, mixtures or scalings of 2–3 spectra) | error: add other colours; the third component would be rounding noise, and the uplift along it arbitrary |
//! | three directions the observer barely tells apart: M singular or its condition above `max_condition` | error: add more varied colours, or raise the bound |
//! | a spectrum that reflects no light (all zero) | error naming it: it has no chromaticity |
//! | duplicated spectra among others | trained: a copy weighs as one more measurement (a copy never splits from its original: same xy) |
//! | a band that is zero in every spectrum | trained: that band is zero in μ and B, so 0 in every uplift |
//! | a split whose side would be rank-deficient or ill-conditioned | not taken: training stops with fewer clusters when no other split helps (the CLI warns) |
//! | the best split's side fits with tracked eigenvectors but its exact ones fall just outside the condition bound (seen on weighted mixes of sets, never on the Munsell set) | that cluster is kept whole; the others may still split |
//!
//! Spectra may be weighted ([`TrainingSet::weights`], made by [`TrainingSet::union`]): the
//! error summed and minimised is then Σ w·‖s − r‖², each cluster's mean and scatter are
//! weighted, and a set of many similar spectra no longer outvotes a small set of other
//! colours. The minimum cluster size still counts spectra. Weights of 1 give the unweighted
//! model bit for bit.
//!
//! No regularisation is applied: a Tikhonov term on B or M would break the exact round trip
//! (Eq. 9) or make up a component the data does not have, so a leaf either has three real
//! components and a bounded M, or it is not made.

use super::model::{Leaf, SetRecord, Training, FORMAT, VERSION};
use super::pca::{
    check_rank, check_rank_products, fit, fit_basis, fit_products, top_three, weighted_scatter,
    ErrorFloor, Moments, Tracker, Unfit,
};
use super::terms::Terms;
use super::tree::{Axis, Tree};
use crate::error::Error;
use crate::Model;
use specconv_colour::Colorimetry;

/// The smallest cluster that has three principal components.
pub const SMALLEST_CLUSTER: usize = 4;

/// Bound on the condition number σ_max/σ_min of a leaf's M (with A normalised so that a white
/// has Y = 1). A leaf near the bound turns small colour differences into large spectral ones;
/// the Munsell set's well-populated clusters stay below 30 (see the README).
pub const DEFAULT_MAX_CONDITION: f64 = 100.0;

/// How to train ([`train`]); the default is 8 clusters, at least 20 spectra each, condition
/// bound [`DEFAULT_MAX_CONDITION`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrainOptions {
    /// Number of leaves wanted.
    pub clusters: usize,
    /// The fewest training spectra a cluster may have, at least [`SMALLEST_CLUSTER`]: a split
    /// leaving fewer on either side is not taken.
    pub min_cluster_size: usize,
    /// The bound on each leaf's condition number of M, at least 1: a split making a worse M is
    /// not taken.
    pub max_condition: f64,
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            clusters: 8,
            min_cluster_size: 20,
            max_condition: DEFAULT_MAX_CONDITION,
        }
    }
}

/// Measured spectra on the colorimetry's grid, with their names and where they came from.
#[derive(Debug, Clone, Default)]
pub struct TrainingSet {
    /// Where the spectra came from (the tables' file names), recorded in the model.
    pub sources: Vec<String>,
    /// One name per spectrum, for error messages.
    pub names: Vec<String>,
    /// The spectra, each on the colorimetry's grid.
    pub spectra: Vec<Vec<f64>>,
    /// One weight per spectrum (finite, above 0), or none: every spectrum weighs 1.
    pub weights: Vec<f64>,
    /// Per source, its count, weight and licence, recorded in the model as they are; none
    /// when not known.
    pub sets: Vec<SetRecord>,
}

/// One source's part of a [`TrainingSet::union`]: its spectra (one source each), the weight
/// asked for it and its terms of use.
#[derive(Debug, Clone)]
pub struct Part {
    /// The spectra, one source.
    pub set: TrainingSet,
    /// How much its spectra count, before balancing (1: as any other).
    pub weight: f64,
    /// Its terms of use.
    pub terms: Terms,
}

impl TrainingSet {
    /// A table's spectra on `grid`, unweighted, with unknown terms and no hash: spectra that
    /// were never a file's (arrays), or whose terms the caller states. A file's set is
    /// [`TrainingSet::from_file`].
    pub fn from_table(
        table: &specconv_colour::SpectralTable,
        grid: &specconv_colour::Grid,
    ) -> Result<TrainingSet, Error> {
        let spectra = table.resampled(grid)?;
        Ok(TrainingSet {
            sources: vec![table.source.clone()],
            names: table.names.clone(),
            sets: vec![SetRecord::new(
                table.source.clone(),
                spectra.len(),
                1.0,
                Terms::of_content(None),
            )],
            spectra,
            weights: Vec::new(),
        })
    }

    /// As [`TrainingSet::from_table_holding`], for the table read from a file whose bytes hash
    /// to `sha256` ([`super::terms::content_hash`]): recorded with the hash, under the terms
    /// known for that content ([`Terms::of_content`]; unknown for any other, whatever its name).
    pub fn from_file(
        table: &specconv_colour::SpectralTable,
        sha256: &str,
        grid: &specconv_colour::Grid,
        hold_ends: bool,
    ) -> Result<TrainingSet, Error> {
        let mut set = TrainingSet::from_table_holding(table, grid, hold_ends)?;
        let terms = Terms::of_content(Some(sha256));
        set.sets[0] = SetRecord {
            sha256: Some(sha256.to_string()),
            held_ends: set.sets[0].held_ends,
            ..SetRecord::new(set.sets[0].source.clone(), set.sets[0].count, 1.0, terms)
        };
        Ok(set)
    }

    /// As [`TrainingSet::from_table`]; with `hold_ends`, a table that stops short of `grid` is
    /// held at its end values ([`specconv_colour::SpectralTable::held_to`]) and its record
    /// says so, so that training it again does the same.
    pub fn from_table_holding(
        table: &specconv_colour::SpectralTable,
        grid: &specconv_colour::Grid,
        hold_ends: bool,
    ) -> Result<TrainingSet, Error> {
        match table.held_to(grid).filter(|_| hold_ends) {
            Some(held) => {
                let mut set = TrainingSet::from_table(&held, grid)?;
                set.sets[0].held_ends = true;
                Ok(set)
            }
            None => TrainingSet::from_table(table, grid),
        }
    }

    /// The spectra for which `keep(k)` holds, with their weights, and the sets' counts
    /// recounted (the sets' spectra lie in the order of [`TrainingSet::sets`]).
    pub fn subset(&self, keep: impl Fn(usize) -> bool) -> TrainingSet {
        let mut out = TrainingSet {
            sources: self.sources.clone(),
            sets: self.sets.clone(),
            ..TrainingSet::default()
        };
        let mut first = 0;
        let recounted = self.sets.iter().map(|s| s.count).sum::<usize>() == self.spectra.len();
        for (j, record) in self.sets.iter().enumerate() {
            let range = first..first + record.count;
            first = range.end;
            if recounted {
                out.sets[j].count = range.filter(|&k| keep(k)).count();
            }
        }
        for (k, s) in self.spectra.iter().enumerate() {
            if keep(k) {
                out.spectra.push(s.clone());
                out.names
                    .push(self.names.get(k).cloned().unwrap_or_default());
                if !self.weights.is_empty() {
                    out.weights.push(self.weights[k]);
                }
            }
        }
        out
    }

    /// The weight of spectrum `k`.
    #[inline]
    pub fn weight(&self, k: usize) -> f64 {
        self.weights.get(k).copied().unwrap_or(1.0)
    }

    /// The parts as one training set. Spectrum weights are each part's weight times
    /// (mean part size / part size)^`balance`, scaled so that they average 1: `balance` 0 lets
    /// every spectrum count the same (the largest set decides most), 1 lets every set count
    /// the same in total whatever its size. Unweighted (no weights stored) when every weight
    /// comes out 1.
    pub fn union(parts: &[Part], balance: f64) -> Result<TrainingSet, Error> {
        let bad = |msg: String| Err(Error::Training(msg));
        if !(balance.is_finite() && (0.0..=1.0).contains(&balance)) {
            return bad(format!("the balance must be in [0, 1], not {balance}"));
        }
        if let Some(p) = parts
            .iter()
            .find(|p| !(p.weight.is_finite() && p.weight > 0.0))
        {
            return bad(format!(
                "the weight of {} is {}: give a finite weight above 0",
                p.set.sources.join(", "),
                p.weight
            ));
        }
        let total: usize = parts.iter().map(|p| p.set.spectra.len()).sum();
        if total == 0 {
            return bad("no spectra to train on".into());
        }
        let mean_size = total as f64 / parts.len() as f64;
        let raw: Vec<f64> = parts
            .iter()
            .map(|p| p.weight * (mean_size / p.set.spectra.len().max(1) as f64).powf(balance))
            .collect();
        let mass: f64 = parts
            .iter()
            .zip(&raw)
            .map(|(p, w)| w * p.set.spectra.len() as f64)
            .sum();
        let scale = total as f64 / mass;
        let uniform = raw.iter().all(|&w| w * scale == 1.0);
        let weighted: Vec<Part> = parts
            .iter()
            .zip(&raw)
            .map(|(p, w)| Part {
                weight: if uniform { 1.0 } else { w * scale },
                ..p.clone()
            })
            .collect();
        Ok(TrainingSet::weighted(&weighted))
    }

    /// A model's recorded sets `base` (with their recorded weights) joined by `own` sets, as
    /// one training set (`train --with`): balanced by `balance` ([`TrainingSet::union`]); with
    /// no `own` sets the recorded weights stay as they are ([`TrainingSet::weighted`]), so
    /// training gives the model back bit for bit.
    pub fn on_top(mut base: Vec<Part>, own: Vec<Part>, balance: f64) -> Result<TrainingSet, Error> {
        if own.is_empty() {
            return Ok(TrainingSet::weighted(&base));
        }
        base.extend(own);
        TrainingSet::union(&base, balance)
    }

    /// The parts as one training set, each part's spectra weighing its `weight` as it is (no
    /// balancing or scaling: a model's recorded sets give its training set back bit for bit).
    pub fn weighted(parts: &[Part]) -> TrainingSet {
        let mut out = TrainingSet::default();
        let uniform = parts.iter().all(|p| p.weight == 1.0);
        for p in parts {
            let w = p.weight;
            out.sources.extend(p.set.sources.iter().cloned());
            out.names.extend(p.set.names.iter().cloned());
            out.spectra.extend(p.set.spectra.iter().cloned());
            if !uniform {
                out.weights
                    .extend(std::iter::repeat_n(w, p.set.spectra.len()));
            }
            // A part of one file keeps its hash; one of several has none to keep.
            let sha256 = match &p.set.sets[..] {
                [one] => one.sha256.clone(),
                _ => None,
            };
            out.sets.push(SetRecord {
                held_ends: p.set.sets.iter().any(|s| s.held_ends),
                sha256,
                ..SetRecord::new(
                    p.set.sources.join(", "),
                    p.set.spectra.len(),
                    w,
                    p.terms.clone(),
                )
            });
        }
        out
    }
}

struct Cluster {
    members: Vec<usize>,
    error: f64,
    /// The best split once searched (searched only when a split may still follow).
    best: Option<Option<Candidate>>,
}

struct Candidate {
    axis: Axis,
    value: f64,
    below: Vec<usize>,
    above: Vec<usize>,
    gain: f64,
}

/// Trains a model. Deterministic: the same data and options give the same model, bit for bit.
pub fn train(set: &TrainingSet, a: &Colorimetry, opts: &TrainOptions) -> Result<Model, Error> {
    check_training(set, opts)?;
    let xy = chromaticities(set, a)?;
    let count = set.spectra.len();
    let root = cluster(set, a, opts, (0..count).collect())
        .map_err(|why| Error::Training(unfit_root(why, count, a, opts)))?;
    let (tree, clusters) = grow(set, &xy, a, opts, root);
    Ok(model(set, a, opts, tree, &clusters))
}

/// Refuses options and data that cannot make a model (see the module's table), saying why.
fn check_training(set: &TrainingSet, opts: &TrainOptions) -> Result<(), Error> {
    let invalid = |msg: String| Err(Error::Training(msg));
    if opts.clusters == 0 {
        return invalid("the number of clusters must be at least 1".into());
    }
    if opts.min_cluster_size < SMALLEST_CLUSTER {
        return invalid(format!(
            "the minimum cluster size must be at least {SMALLEST_CLUSTER}: three principal components need four spectra"
        ));
    }
    if opts.max_condition.is_nan() || opts.max_condition < 1.0 {
        return invalid("the condition bound must be at least 1".into());
    }
    if !set.weights.is_empty() && set.weights.len() != set.spectra.len() {
        return invalid(format!(
            "{} weights for {} spectra: give one weight per spectrum, or none",
            set.weights.len(),
            set.spectra.len()
        ));
    }
    if let Some(k) = set
        .weights
        .iter()
        .position(|w| !(w.is_finite() && *w > 0.0))
    {
        let name = set.names.get(k).map_or("?", String::as_str);
        return invalid(format!(
            "spectrum '{name}' has weight {}: weights must be finite and above 0",
            set.weights[k]
        ));
    }
    if set.spectra.len() < SMALLEST_CLUSTER {
        let only = match set.spectra.len() {
            1 => "1 spectrum".to_string(),
            k => format!("{k} spectra"),
        };
        return invalid(format!(
            "only {only}: three principal components need at least {SMALLEST_CLUSTER} spectra that differ; give more spectra"
        ));
    }
    if set.spectra.len() < opts.min_cluster_size {
        return invalid(format!(
            "{} spectra are fewer than the minimum cluster size {}; give more spectra or lower the minimum cluster size",
            set.spectra.len(),
            opts.min_cluster_size
        ));
    }
    Ok(())
}

/// The xy of every spectrum, what the tree splits on; refuses a spectrum that reflects no light.
fn chromaticities(set: &TrainingSet, a: &Colorimetry) -> Result<Vec<[f64; 2]>, Error> {
    let n = a.bands();
    let mut xy = Vec::with_capacity(set.spectra.len());
    for (k, s) in set.spectra.iter().enumerate() {
        debug_assert_eq!(s.len(), n);
        match specconv_colour::colorimetry::xy(a.xyz(s)) {
            Some(c) => xy.push(c),
            None => {
                let name = set.names.get(k).map_or("?", String::as_str);
                return Err(Error::Training(format!(
                    "spectrum '{name}' reflects no light on {} under {}: it has no chromaticity to cluster by; remove it",
                    a.grid, a.illuminant
                )));
            }
        }
    }
    Ok(xy)
}

/// Why the `count` spectra, as one cluster, make no leaf, in words that say what to add.
fn unfit_root(why: Unfit, count: usize, a: &Colorimetry, opts: &TrainOptions) -> String {
    match why {
        Unfit::Rank(0) => format!(
            "all {count} spectra are identical spectra (up to rounding): principal components \
             need spectra that differ; give spectra of different colours"
        ),
        Unfit::Rank(k) => format!(
            "the {count} spectra vary in only {k} independent direction{} (as copies or mixtures \
             of {} spectra do), but the model needs 3, one per XYZ component; add spectra of other colours",
            if k == 1 { "" } else { "s" },
            k + 1
        ),
        Unfit::IllConditioned(cond) => format!(
            "the spectra's three main variations look almost alike to the observer under {}, so \
             colours cannot tell them apart: M's condition number is {cond:.3e} (bound {}); add \
             spectra of more varied colours, or raise the condition bound",
            a.illuminant, opts.max_condition
        ),
    }
}

/// Splits, one at a time, the cluster whose best split lowers the summed error most, until
/// there are `opts.clusters` or no split lowers it. In the tree returned, `Leaf { leaf: k }`
/// refers to `clusters[k]` (`None` once split).
fn grow(
    set: &TrainingSet,
    xy: &[[f64; 2]],
    a: &Colorimetry,
    opts: &TrainOptions,
    root: Cluster,
) -> (Tree, Vec<Option<Cluster>>) {
    let mut tree = Tree::single_leaf();
    let mut clusters = vec![Some(root)];
    let mut live = 1;
    while live < opts.clusters {
        for c in clusters.iter_mut().flatten() {
            if c.best.is_none() {
                c.best = Some(best_split(set, xy, a, opts, &c.members, c.error));
            }
        }
        let Some(k) = most_gain(&clusters) else { break };
        let split = clusters[k]
            .as_mut()
            .and_then(|c| c.best.take().flatten())
            .expect("picked cluster has a split");
        // The split search checked both sides with tracked eigenvectors; at the edge of the
        // condition bound the exact ones can fall just outside it. Then the cluster stays.
        let sides = cluster(set, a, opts, split.below)
            .and_then(|below| Ok([below, cluster(set, a, opts, split.above)?]));
        let Ok(sides) = sides else {
            if let Some(c) = clusters[k].as_mut() {
                c.best = Some(None);
            }
            continue;
        };
        clusters[k] = None;
        let new = [clusters.len(), clusters.len() + 1];
        tree.split_leaf(k, split.axis, split.value, new);
        clusters.extend(sides.map(Some));
        live += 1;
    }
    (tree, clusters)
}

/// The cluster whose best split gains most (the first of equals), if any has a split.
fn most_gain(clusters: &[Option<Cluster>]) -> Option<usize> {
    clusters
        .iter()
        .enumerate()
        .filter_map(|(k, c)| Some((k, c.as_ref()?.best.as_ref()?.as_ref()?.gain)))
        .fold(None, |best: Option<(usize, f64)>, (k, g)| match best {
            Some((_, bg)) if bg >= g => best,
            _ => Some((k, g)),
        })
        .map(|(k, _)| k)
}

/// The model of the grown `tree`: the remaining clusters numbered in order of creation, their
/// leaves fitted exactly.
fn model(
    set: &TrainingSet,
    a: &Colorimetry,
    opts: &TrainOptions,
    mut tree: Tree,
    clusters: &[Option<Cluster>],
) -> Model {
    let mut number = vec![usize::MAX; clusters.len()];
    let mut leaves = Vec::new();
    for (k, c) in clusters.iter().enumerate() {
        let Some(c) = c else { continue };
        number[k] = leaves.len();
        leaves.push(leaf(set, a, &c.members));
    }
    tree.renumber_leaves(&number);
    let total_error = leaves.iter().map(|l| l.error).sum();
    Model {
        format: FORMAT.into(),
        version: VERSION,
        grid: a.grid,
        observer: a.observer,
        illuminant: a.illuminant,
        training: Training {
            sources: set.sources.clone(),
            count: set.spectra.len(),
            clusters_requested: opts.clusters,
            min_cluster_size: opts.min_cluster_size,
            max_condition: opts.max_condition,
            total_error,
            sets: set.sets.clone(),
        },
        tree,
        leaves,
    }
}

fn refs<'a>(set: &'a TrainingSet, members: &[usize]) -> Vec<&'a [f64]> {
    members.iter().map(|&i| set.spectra[i].as_slice()).collect()
}

/// The weighted mean and scatter of a cluster's spectra.
fn scatter(set: &TrainingSet, members: &[usize]) -> (Vec<f64>, Vec<f64>) {
    weighted_scatter(&refs(set, members), |k| set.weight(members[k]))
}

/// A cluster with its exact error, or why it cannot be fitted.
fn cluster(
    set: &TrainingSet,
    a: &Colorimetry,
    opts: &TrainOptions,
    members: Vec<usize>,
) -> Result<Cluster, Unfit> {
    let (_, c) = scatter(set, &members);
    let basis = top_three(&c, a.bands());
    let energy = members
        .iter()
        .map(|&i| set.weight(i) * super::pca::dot(&set.spectra[i], &set.spectra[i]))
        .sum();
    check_rank(&c, &basis, energy)?;
    let error = fit_basis(&c, a, opts.max_condition, basis)?.error;
    Ok(Cluster {
        members,
        error,
        best: None,
    })
}

fn leaf(set: &TrainingSet, a: &Colorimetry, members: &[usize]) -> Leaf {
    let (mean, c) = scatter(set, members);
    // Conditioning was checked when the split was chosen; rounding must not undo a leaf now.
    let f = fit(&c, a, f64::INFINITY).expect("a leaf chosen by training is invertible");
    Leaf {
        count: members.len(),
        c_mean: a.xyz(&mean),
        mean,
        basis: f.basis,
        m: f.m,
        m_inv: f.m_inv,
        condition: f.condition,
        error: f.error,
    }
}

/// The split of a cluster that lowers the summed error most (Eq. 12), if any lowers it.
///
/// Every candidate gets a lower bound on its summed error first, in O(n) ([`ErrorFloor`]); the
/// candidate with the lowest bound that fits is evaluated exactly, and only candidates whose
/// bound does not exceed its error (with a margin far above rounding) are then evaluated as
/// before, in the same order, by tracked eigenvectors. The others cannot be the best, so the
/// split chosen is the one a search of every candidate chooses.
fn best_split(
    set: &TrainingSet,
    xy: &[[f64; 2]],
    a: &Colorimetry,
    opts: &TrainOptions,
    members: &[usize],
    error: f64,
) -> Option<Candidate> {
    if members.len() < 2 * opts.min_cluster_size {
        return None;
    }
    let search = SplitSearch::new(set, xy, a, opts, members);
    // A candidate skipped has an error above its floor > bound + 2·margin: it cannot beat a
    // split found within bound + margin. Otherwise (the bound's split did not fit with tracked
    // eigenvectors, at the edge of the condition bound), every candidate is searched.
    let best = match search.bound() {
        Some(bound) => search
            .best(bound + 2.0 * search.margin(bound))
            .filter(|b| b.0 <= bound + search.margin(bound))
            .or_else(|| search.best(f64::INFINITY)),
        None => search.best(f64::INFINITY),
    };
    let (sum, ax, k, value) = best?;
    let gain = error - sum;
    let order = &search.orders[ax];
    (gain > 0.0).then(|| Candidate {
        axis: [Axis::X, Axis::Y][ax],
        value,
        below: order[..k].to_vec(),
        above: order[k..].to_vec(),
        gain,
    })
}

/// A split found: (summed error, axis, position in that axis' order, split value).
type Found = (f64, usize, usize, f64);

/// The search for one cluster's best split: its members in xy order on each axis, their
/// moments, and each candidate's floor. A split at k on axis `ax` puts `orders[ax][..k]` below.
struct SplitSearch<'a> {
    set: &'a TrainingSet,
    xy: &'a [[f64; 2]],
    a: &'a Colorimetry,
    opts: &'a TrainOptions,
    /// Bands.
    n: usize,
    /// The moments of every member.
    total: Moments,
    /// The members by x, then by y (ties by index).
    orders: [Vec<usize>; 2],
    /// The members' mean, the origin of the colour sums.
    origin: Vec<f64>,
    /// The colour sums of every member.
    whole: ErrorFloor,
    /// Each candidate's floor, +∞ where there is no candidate.
    floors: [Vec<f64>; 2],
}

impl<'a> SplitSearch<'a> {
    fn new(
        set: &'a TrainingSet,
        xy: &'a [[f64; 2]],
        a: &'a Colorimetry,
        opts: &'a TrainOptions,
        members: &[usize],
    ) -> SplitSearch<'a> {
        let n = a.bands();
        let mut total = Moments::zero(n);
        members
            .iter()
            .for_each(|&i| total.add_weighted(&set.spectra[i], set.weight(i)));
        let orders: [Vec<usize>; 2] = std::array::from_fn(|ax| {
            let mut order = members.to_vec();
            order.sort_by(|&i, &j| xy[i][ax].total_cmp(&xy[j][ax]).then(i.cmp(&j)));
            order
        });
        let origin = total.mean();
        let mut whole = ErrorFloor::zero(&origin, a);
        for &i in members {
            let s = set.spectra[i].as_slice();
            whole.add_weighted(s, a.xyz(s), set.weight(i));
        }
        let mut search = SplitSearch {
            set,
            xy,
            a,
            opts,
            n,
            total,
            orders,
            origin,
            whole,
            floors: [Vec::new(), Vec::new()],
        };
        search.floors = std::array::from_fn(|ax| search.floors_on(ax));
        search
    }

    fn spectrum(&self, i: usize) -> &'a [f64] {
        self.set.spectra[i].as_slice()
    }

    fn weight(&self, i: usize) -> f64 {
        self.set.weight(i)
    }

    /// Whether there is a split at k on axis `ax`: both sides of at least the minimum cluster
    /// size, and two distinct coordinates to split between.
    fn splits_at(&self, ax: usize, k: usize) -> bool {
        let (order, min) = (&self.orders[ax], self.opts.min_cluster_size);
        !(k < min || order.len() - k < min || self.xy[order[k - 1]][ax] >= self.xy[order[k]][ax])
    }

    /// The floor of every split on axis `ax`, in O(n) each ([`ErrorFloor`]).
    fn floors_on(&self, ax: usize) -> Vec<f64> {
        let order = &self.orders[ax];
        let mut below = ErrorFloor::zero(&self.origin, self.a);
        let mut far = self.whole.clone();
        let mut floors = vec![f64::INFINITY; order.len()];
        for (k, floor) in floors.iter_mut().enumerate().skip(1) {
            let i = order[k - 1];
            let s = self.spectrum(i);
            below.add_weighted(s, self.a.xyz(s), self.weight(i));
            if self.splits_at(ax, k) {
                self.whole.minus_into(&below, &mut far);
                *floor = below.floor() + far.floor();
            }
        }
        floors
    }

    /// A side's error: it needs three real components and a well-conditioned M.
    fn side(&self, c: &[f64], m: &Moments, basis: [Vec<f64>; 3]) -> Result<f64, Unfit> {
        let f = fit_basis(c, self.a, self.opts.max_condition, basis)?;
        check_rank(c, &f.basis, m.energy()).map(|()| f.error)
    }

    /// The same with tracked eigenvectors, from C·B and the colour sums: O(n), not O(n²).
    fn tracked_side(
        &self,
        c: &[f64],
        m: &Moments,
        colours: &ErrorFloor,
        tracker: &mut Tracker,
    ) -> Result<f64, Unfit> {
        let n = self.n;
        let (basis, cb) = tracker.top_three(c, n);
        let trace_c = (0..n).map(|i| c[i * n + i]).sum();
        let g = colours.colour_scatter();
        let f = fit_products(self.a, self.opts.max_condition, basis, &cb, &g, trace_c)?;
        check_rank_products(&f.basis, &cb, m.energy()).map(|()| f.error)
    }

    /// The exact summed error of the candidate with the lowest floor that fits (among the
    /// [`PROBES`] lowest), which bounds the best's.
    fn bound(&self) -> Option<f64> {
        let (n, len) = (self.n, self.orders[0].len());
        let mut by_floor: Vec<(usize, usize)> = (0..2)
            .flat_map(|ax| (1..len).map(move |k| (ax, k)))
            .filter(|&(ax, k)| self.floors[ax][k].is_finite())
            .collect();
        let floors = &self.floors;
        by_floor.sort_by(|p, q| floors[p.0][p.1].total_cmp(&floors[q.0][q.1]).then(p.cmp(q)));
        let mut above = Moments::zero(n);
        let (mut c1, mut c2, mut mu) = (Vec::new(), Vec::new(), Vec::new());
        for &(ax, k) in by_floor.iter().take(PROBES) {
            let mut below = Moments::zero(n);
            self.orders[ax][..k]
                .iter()
                .for_each(|&i| below.add_weighted(self.spectrum(i), self.weight(i)));
            self.total.minus_into(&below, &mut above);
            below.scatter_into(&mut c1, &mut mu);
            above.scatter_into(&mut c2, &mut mu);
            let sides = self
                .side(&c1, &below, top_three(&c1, n))
                .and_then(|e1| Ok(e1 + self.side(&c2, &above, top_three(&c2, n))?));
            if let Ok(sum) = sides {
                return Some(sum);
            }
        }
        None
    }

    /// Far above the floors' rounding and the tracked errors' own: those depend on where the
    /// tracker started by up to 7.5e-7 of the error (measured on the Munsell set), so a margin
    /// of 1e-4 leaves two orders of magnitude.
    fn margin(&self, sum: f64) -> f64 {
        1e-4 * sum + 1e-9 * self.whole.variance()
    }

    /// The split of lowest summed error among the candidates whose floor is at most `limit`,
    /// evaluated in order with tracked eigenvectors.
    fn best(&self, limit: f64) -> Option<Found> {
        let mut best = None;
        for ax in 0..2 {
            self.best_on(ax, limit, &mut best);
        }
        best
    }

    /// [`SplitSearch::best`] on axis `ax`, updating `best`.
    fn best_on(&self, ax: usize, limit: f64, best: &mut Option<Found>) {
        let (n, order) = (self.n, &self.orders[ax]);
        let mut below = Moments::zero(n);
        let mut above = Moments::zero(n);
        let mut colours_below = ErrorFloor::zero(&self.origin, self.a);
        let mut far = self.whole.clone();
        let (mut c1, mut c2, mut mu) = (Vec::new(), Vec::new(), Vec::new());
        let (mut track_below, mut track_above) = (Tracker::default(), Tracker::default());
        let mut last = 0;
        for k in 1..order.len() {
            let (s, w) = (self.spectrum(order[k - 1]), self.weight(order[k - 1]));
            below.add_weighted(s, w);
            colours_below.add_weighted(s, self.a.xyz(s), w);
            // Only splits the rules allow (their floor is finite): with no limit (the search of
            // every candidate) an infinite floor is not above it, and a side of 4 spectra under
            // a minimum of 30 was once chosen.
            if !self.splits_at(ax, k) || self.floors[ax][k] > limit {
                continue;
            }
            // Far from the last candidate evaluated, a fresh decomposition beats iterating.
            if k - last > TRACK_GAP {
                (track_below, track_above) = (Tracker::default(), Tracker::default());
            }
            last = k;
            self.total.minus_into(&below, &mut above);
            below.scatter_into(&mut c1, &mut mu);
            above.scatter_into(&mut c2, &mut mu);
            self.whole.minus_into(&colours_below, &mut far);
            let Ok(e1) = self.tracked_side(&c1, &below, &colours_below, &mut track_below) else {
                continue;
            };
            let Ok(e2) = self.tracked_side(&c2, &above, &far, &mut track_above) else {
                continue;
            };
            let sum = e1 + e2;
            if best.as_ref().is_none_or(|b| sum < b.0) {
                // Split halfway between the two sides' colours (Eq. 10: above means ≥ value).
                let (lo, hi) = (self.xy[order[k - 1]][ax], self.xy[order[k]][ax]);
                let mid = 0.5 * (lo + hi);
                let value = if mid > lo { mid } else { hi };
                *best = Some((sum, ax, k, value));
            }
        }
    }
}

/// Candidates with the lowest floors evaluated exactly to find a bound on the best split's
/// error; when none of them fits (rank or condition), every candidate is searched.
const PROBES: usize = 8;

/// Steps from the last candidate evaluated beyond which the trackers start afresh.
const TRACK_GAP: usize = 8;
