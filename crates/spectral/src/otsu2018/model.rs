//! The model: a kd-tree on CIE xy whose leaves hold a cluster's PCA (Eq. 5–8), and its file.
//!
//! The file is JSON, versioned and self-describing: the grid, observer and illuminant it was
//! trained in, how it was trained and on what, the tree and per leaf μ, B, M, M⁻¹ and c_μ.
//! Floats are written in shortest round-trip form, so a model reads back bit for bit. Loading
//! checks everything that the uplift relies on, and M against A·B recomputed from the named
//! observer and illuminant, so a hand-edited or mismatched file is refused, not trusted.

use super::terms::{Commercial, Terms};
use super::tree::Tree;
use crate::error::Error;
use serde::{Deserialize, Serialize};
use specconv_colour::{Colorimetry, Grid, Illuminant, Observer};

/// The `format` of every model file, checked before anything else is read.
pub const FORMAT: &str = "specconv-model";
/// The model file version this specconv writes and reads; others are refused.
pub const VERSION: u32 = 1;

/// A trained clustered-PCA model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Model {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// The band grid of μ, B and every spectrum the model makes.
    pub grid: Grid,
    /// The observer of the colorimetry the model was trained in.
    pub observer: Observer,
    /// The illuminant of that colorimetry; its perfect reflector has Y = 1.
    pub illuminant: Illuminant,
    /// How and on what the model was trained (a record; the uplift does not read it).
    pub training: Training,
    /// Node 0 is the root.
    pub tree: Tree,
    /// The clusters, one per leaf node of the tree.
    pub leaves: Vec<Leaf>,
}

/// How and on what a model was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Training {
    /// The training set: file names of the spectra tables.
    pub sources: Vec<String>,
    /// Number of spectra.
    pub count: usize,
    /// The clusters asked for; the model has fewer when no further split lowered the error.
    pub clusters_requested: usize,
    /// The fewest training spectra a cluster could keep ([`crate::TrainOptions`]).
    pub min_cluster_size: usize,
    /// The bound on each leaf's condition number of M.
    pub max_condition: f64,
    /// Σ w·‖s − r‖² over the training set (Eq. 13; w = 1 unless the sets are weighted).
    pub total_error: f64,
    /// Per source: its spectra, their weight in training and the terms of use of the data.
    /// Absent in files written before sources were recorded.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sets: Vec<SetRecord>,
}

/// One source of a model's training data, as the model records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetRecord {
    /// The spectra table's file name.
    pub source: String,
    /// Spectra taken from it.
    pub count: usize,
    /// The SHA-256 of its file's bytes ([`super::terms::content_hash`]), by which a set read
    /// again is known to be this one. Absent in files written before it was recorded, and for
    /// spectra that never were a file (Python arrays).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sha256: Option<String>,
    /// The weight of each of its spectra in the summed error (1: unweighted).
    pub weight: f64,
    /// The terms its data may be used under, as its origin states them.
    pub licence: String,
    /// Whether its data may be used commercially (unstated in files written before it was
    /// recorded).
    #[serde(default)]
    pub commercial: Commercial,
    /// The lines a user of its data must credit.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub attribution: Vec<String>,
    /// Its spectra stop short of the grid and were held at their end values to cover it
    /// ([`specconv_colour::SpectralTable::held_to`]); training it again does the same.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub held_ends: bool,
}

impl SetRecord {
    /// The record of `count` spectra from `source`, each weighing `weight`, under `terms`.
    pub fn new(source: String, count: usize, weight: f64, terms: Terms) -> SetRecord {
        SetRecord {
            source,
            count,
            sha256: None,
            weight,
            licence: terms.licence,
            commercial: terms.commercial,
            attribution: terms.attribution,
            held_ends: false,
        }
    }

    /// Its terms of use.
    pub fn terms(&self) -> Terms {
        Terms {
            licence: self.licence.clone(),
            commercial: self.commercial,
            attribution: self.attribution.clone(),
        }
    }
}

impl Training {
    /// Whether a model trained on these sets may be used commercially: only when every set
    /// may (unstated when the sets were not recorded).
    pub fn commercial(&self) -> Commercial {
        if self.sets.is_empty() {
            return Commercial::Unstated;
        }
        Commercial::all(self.sets.iter().map(|s| s.commercial))
    }

    /// Refuses recorded text that is not one line ([`super::terms::one_line`]): a source,
    /// licence or attribution with a line break was written by hand, to pass for other lines
    /// where it is shown.
    fn validate_text(&self) -> Result<(), String> {
        for s in &self.sets {
            let lines = s.attribution.iter().map(|a| ("an attribution", a));
            for (what, text) in [("the source", &s.source), ("the licence", &s.licence)]
                .into_iter()
                .chain(lines)
            {
                super::terms::one_line(&format!("training set {:?}: {what}", s.source), text)?;
            }
        }
        Ok(())
    }

    /// The notices that must ship with the model ([`super::terms::notices`]).
    pub fn notices(&self) -> Vec<super::terms::Notice> {
        super::terms::notices(
            self.sets
                .iter()
                .map(|s| (s.source.as_str(), s.sha256.as_deref())),
        )
    }
}

/// One cluster.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Leaf {
    /// Training spectra in the cluster.
    pub count: usize,
    /// μ
    pub mean: Vec<f64>,
    /// b₁, b₂, b₃
    pub basis: [Vec<f64>; 3],
    /// M = A·[b₁ b₂ b₃], row-major (Eq. 6).
    pub m: [[f64; 3]; 3],
    /// M⁻¹, row-major (Eq. 7).
    pub m_inv: [[f64; 3]; 3],
    /// c_μ = A·μ
    pub c_mean: [f64; 3],
    /// M's condition number σ_max / σ_min, within the training's `max_condition`.
    pub condition: f64,
    /// Σ ‖s − r‖² over the cluster's training spectra.
    pub error: f64,
}

impl Model {
    /// The colorimetry the model was trained in (its grid, observer and illuminant), which its
    /// uplift is exact under.
    pub fn colorimetry(&self) -> Result<Colorimetry, Error> {
        Ok(Colorimetry::new(self.grid, self.observer, self.illuminant)?)
    }

    /// The model file: pretty-printed JSON ending in a newline, floats in shortest round-trip form,
    /// so that [`Model::from_json`] reads back an equal model.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("a model serialises");
        s.push('\n');
        s
    }

    /// Reads and validates a model. `source` names it in errors.
    pub fn from_json(source: &str, text: &str) -> Result<Model, Error> {
        let bad = |msg: String| Error::Model {
            file: source.to_string(),
            msg,
        };
        // Check the header first, so that a file of another kind or version gets a clear word.
        #[derive(Deserialize)]
        struct Header {
            format: Option<String>,
            version: Option<u32>,
        }
        let header: Header = serde_json::from_str(text).map_err(|e| {
            if e.is_data() {
                bad(format!("not a specconv model ({e})"))
            } else {
                bad(format!(
                    "not valid JSON ({e}): the file is truncated, damaged or not a specconv model"
                ))
            }
        })?;
        if header.format.as_deref() != Some(FORMAT) {
            return Err(bad(format!(
                "not a specconv model (its \"format\" is not \"{FORMAT}\")"
            )));
        }
        if header.version != Some(VERSION) {
            return Err(bad(format!(
                "model version {:?} is not supported by this specconv, which reads version {VERSION}; retrain it with `specconv train`",
                header.version
            )));
        }
        let model: Model =
            serde_json::from_str(text).map_err(|e| bad(format!("malformed model: {e}")))?;
        model.validate().map_err(bad)?;
        Ok(model)
    }

    /// The checks behind [`Model::from_json`].
    pub fn validate(&self) -> Result<(), String> {
        Grid::new(self.grid.start, self.grid.end, self.grid.step).map_err(|e| e.to_string())?;
        let n = self.grid.len();
        if self.leaves.is_empty() {
            return Err("the model has no leaves".into());
        }
        self.tree.validate(self.leaves.len())?;
        if let Some(s) = self
            .training
            .sets
            .iter()
            .find(|s| !(s.weight.is_finite() && s.weight > 0.0))
        {
            return Err(format!(
                "training set {} has weight {}: weights must be finite and above 0",
                s.source, s.weight
            ));
        }
        self.training.validate_text()?;
        let a = self.colorimetry().map_err(|e| e.to_string())?;
        for (k, leaf) in self.leaves.iter().enumerate() {
            let at = |what: &str| format!("leaf {k}: {what}");
            if leaf.mean.len() != n || leaf.basis.iter().any(|b| b.len() != n) {
                return Err(at(&format!(
                    "vectors must have {n} values, one per band of {}",
                    self.grid
                )));
            }
            let finite = leaf
                .mean
                .iter()
                .chain(leaf.basis.iter().flatten())
                .chain(leaf.m.iter().flatten())
                .chain(leaf.m_inv.iter().flatten())
                .chain(&leaf.c_mean)
                .all(|v| v.is_finite());
            if !finite {
                return Err(at("holds a value that is not a finite number"));
            }
            let scale = leaf.m.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
            for i in 0..3 {
                for j in 0..3 {
                    let ab = super::pca::dot(&a.weights[i], &leaf.basis[j]);
                    if (ab - leaf.m[i][j]).abs() > 1e-9 * scale {
                        return Err(at(&format!(
                            "M does not equal A·B for observer {} and illuminant {}: the file was changed or mislabelled",
                            self.observer, self.illuminant
                        )));
                    }
                    let id: f64 = (0..3).map(|k| leaf.m_inv[i][k] * leaf.m[k][j]).sum();
                    if (id - if i == j { 1.0 } else { 0.0 }).abs() > 1e-9 {
                        return Err(at("M⁻¹ is not the inverse of M"));
                    }
                }
            }
            let c_mu = a.xyz(&leaf.mean);
            let c_scale = c_mu.iter().fold(1e-300f64, |s, v| s.max(v.abs()));
            if (0..3).any(|i| (c_mu[i] - leaf.c_mean[i]).abs() > 1e-9 * c_scale) {
                return Err(at("c_μ does not equal A·μ"));
            }
        }
        Ok(())
    }

    /// The built-in default model ([`BUILTIN`]'s first).
    pub fn builtin() -> &'static Model {
        Model::builtin_named(BUILTIN[0].name).expect("the default is built in")
    }

    /// The built-in model of that name ([`BUILTIN`]), or `None`.
    pub fn builtin_named(name: &str) -> Option<&'static Model> {
        static MODELS: [std::sync::OnceLock<Model>; BUILTIN.len()] =
            [const { std::sync::OnceLock::new() }; BUILTIN.len()];
        let k = BUILTIN.iter().position(|b| b.name == name)?;
        Some(MODELS[k].get_or_init(|| {
            let b = &BUILTIN[k];
            Model::from_json(&format!("built-in model {}", b.name), b.json)
                .expect("the built-in models are valid (checked by their tests)")
        }))
    }
}

/// A model built into specconv, by name.
#[derive(Debug, Clone, Copy)]
pub struct Builtin {
    /// The name that `--model` takes.
    pub name: &'static str,
    /// What it is, in a line: its data and their terms.
    pub summary: &'static str,
    /// The model file.
    pub json: &'static str,
}

/// The built-in models, the default first. Each is what `specconv train` makes from
/// ../shared/spectra with the options its file records (tests retrain them bit for bit);
/// docs/methods.md has the study that chose them and their figures.
pub const BUILTIN: [Builtin; 4] = [
    Builtin {
        name: "open",
        summary: "the default, for commercial use: open data only, USGS Spectral Library 7 sets (public domain), Rhododendron leaves (MIT), NIST CQS 9.0 saturated chips and Luo's memory colours (BSD-3-Clause), painted pigments (CC BY 4.0), weighted; over ten held-out sets its mean colour shift under A and F11 is 13 % below extended's (spectral error 10 % below), 1.6x extended's on Munsell colours",
        json: include_str!("../../models/open.json"),
    },
    Builtin {
        name: "extended",
        summary: "the paper's Munsell data extended with the ColorChecker, USGS and Rhododendron sets, Munsell weighted so its colours stay within 5 % of the paper model's error while every other set improves; the default until issue 43 (Munsell data: non-commercial use only)",
        json: include_str!("../../models/extended.json"),
    },
    Builtin {
        name: "paper",
        summary: "the paper's dataset I, 8 clusters on the Munsell matte set (non-commercial use only), reproduces Table 1",
        json: include_str!("../../models/paper.json"),
    },
    Builtin {
        name: "broad",
        summary: "Munsell, ColorChecker, USGS and Rhododendron sets, weighted: far better on plants, soils, minerals and man-made materials, 1.5x the paper model's error on Munsell colours (Munsell data: non-commercial use only)",
        json: include_str!("../../models/broad.json"),
    },
];
