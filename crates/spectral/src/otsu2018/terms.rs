//! The terms of use of training data, which travel with every model trained on it: per set its
//! licence, whether it may be used commercially and the attribution it asks for, and the
//! notices that must ship with anything derived from it (docs/licences.md).
//!
//! The sets of ../shared/spectra are known by file name, with the terms their README states;
//! any other set records what its trainer says (`--licence`, `--commercial`), else "unknown".
//! A model may be used commercially only when every one of its sets may.

use serde::{Deserialize, Serialize};

/// Whether data may be used commercially.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Commercial {
    /// Its terms allow it (public domain, MIT, BSD, or the trainer's own data).
    Yes,
    /// Its terms forbid it (non-commercial use only).
    No,
    /// Its terms do not say, or were not recorded: ask before shipping.
    #[default]
    Unstated,
}

impl Commercial {
    /// Every set's answer combined: no if one says no, unstated if one is unstated, else yes.
    pub fn all(answers: impl IntoIterator<Item = Commercial>) -> Commercial {
        answers
            .into_iter()
            .fold(Commercial::Yes, |acc, c| match (acc, c) {
                (Commercial::No, _) | (_, Commercial::No) => Commercial::No,
                (Commercial::Unstated, _) | (_, Commercial::Unstated) => Commercial::Unstated,
                _ => Commercial::Yes,
            })
    }
}

impl std::fmt::Display for Commercial {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Commercial::Yes => "yes",
            Commercial::No => "no",
            Commercial::Unstated => "unstated",
        })
    }
}

impl std::str::FromStr for Commercial {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "yes" => Ok(Commercial::Yes),
            "no" => Ok(Commercial::No),
            "unstated" => Ok(Commercial::Unstated),
            _ => Err(format!("{s:?} is not yes, no or unstated")),
        }
    }
}

/// A set's terms of use, as a model records them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Terms {
    /// The licence, as its origin states it.
    pub licence: String,
    /// Whether its data may be used commercially.
    pub commercial: Commercial,
    /// The lines a user of the data must credit.
    pub attribution: Vec<String>,
}

/// A notice that must ship with anything derived from some sets: its title and full text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Notice {
    /// What it covers.
    pub title: &'static str,
    /// Its text, verbatim.
    pub text: &'static str,
}

/// colour-science's licence, verbatim from colour_science-0.4.7.dist-info/licenses/LICENSE:
/// the NIST CQS and PMC sets come through colour-science under it.
pub const COLOUR_SCIENCE: Notice = Notice {
    title: "colour-science 0.4.7 (the ColorChecker, NIST CQS 9.0 and Preferred Memory Colour data it ships)",
    text: include_str!("../../notices/colour-science-BSD-3-Clause.txt"),
};

/// The MIT licence of the Rhododendron leaf data (its repository's terms, as
/// ../shared/spectra/README.md states them; the standard MIT text).
pub const RHODODENDRON: Notice = Notice {
    title: "Rhododendron leaf reflectance (emcdona1/leaf_reflectance_spectroscopy)",
    text: include_str!("../../notices/rhododendron-MIT.txt"),
};

struct Known {
    file: &'static str,
    licence: &'static str,
    commercial: Commercial,
    attribution: &'static [&'static str],
    notice: Option<Notice>,
}

const USGS: &str = "USGS Spectral Library Version 7, Kokaly et al. 2017, U.S. Geological Survey Data Series 1035, doi:10.5066/F7RR1WDJ";
const USGS_LICENCE: &str = "public domain (USGS Spectral Library 7, doi:10.5066/F7RR1WDJ)";

/// The sets of ../shared/spectra by file name, with the terms its README states (their
/// origins: UEF spectral database, USGS Data Series 1035, the repository
/// emcdona1/leaf_reflectance_spectroscopy, colour-science 0.4.7, hildatobing/vis-hyppigments).
const KNOWN: [Known; 10] = [
    Known {
        file: "munsell1269_matte_380-800_1nm.csv",
        licence: "non-commercial use only (University of Eastern Finland spectral database)",
        commercial: Commercial::No,
        attribution: &["Munsell matte chips, University of Eastern Finland spectral database (Kohonen, Parkkinen, Jaaskelainen 2006)"],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_vegetation_380-780_5nm.csv",
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_manmade_380-780_5nm.csv",
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_soils_380-780_5nm.csv",
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_minerals_380-780_5nm.csv",
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "rhododendron_leaves_380-780_5nm.csv",
        licence: "MIT (c) 2022 Beth McDonald, emcdona1/leaf_reflectance_spectroscopy",
        commercial: Commercial::Yes,
        attribution: &["Copyright (c) 2022 Beth McDonald (MIT License): Rhododendron leaves, Field Museum of Natural History, emcdona1/leaf_reflectance_spectroscopy"],
        notice: Some(RHODODENDRON),
    },
    Known {
        file: "colorchecker_n_ohta_380-780_5nm.csv",
        licence: "not stated by its origin (N. Ohta's measurement, shipped in colour-science 0.4.7, BSD-3-Clause)",
        commercial: Commercial::Unstated,
        attribution: &["X-Rite ColorChecker Classic, N. Ohta's measurement, via colour-science 0.4.7 (Copyright 2013 Colour Developers, BSD-3-Clause)"],
        notice: Some(COLOUR_SCIENCE),
    },
    Known {
        file: "nist_cqs90_vs_380-780_5nm.csv",
        licence: "BSD-3-Clause through colour-science 0.4.7 (NIST CQS 9.0 test samples, a US Government work)",
        commercial: Commercial::Yes,
        attribution: &[
            "NIST Colour Quality Scale 9.0 test samples VS1-VS15 (Ohno & Davis, NIST)",
            "Copyright 2013 Colour Developers (colour-science, BSD-3-Clause)",
        ],
        notice: Some(COLOUR_SCIENCE),
    },
    Known {
        file: "colour_pmc_400-700_5nm.csv",
        licence: "BSD-3-Clause through colour-science 0.4.7 (Luo 2024, Preferred Memory Colour chart)",
        commercial: Commercial::Yes,
        attribution: &[
            "Preferred Memory Colour chart, Luo 2024, Color Res. Appl., doi:10.1002/col.22940",
            "Copyright 2013 Colour Developers (colour-science, BSD-3-Clause)",
        ],
        notice: Some(COLOUR_SCIENCE),
    },
    Known {
        file: "hyppigments_405-780_5nm.csv",
        licence: "CC BY 4.0 (Hyperspectral Pigment Dataset, H. Deborah, NTNU, doi:10.5281/zenodo.5592485)",
        commercial: Commercial::Yes,
        // CC BY 4.0 asks for the creator, the licence and whether the data were changed.
        attribution: &["Hyperspectral Pigment Dataset, H. Deborah (NTNU), WHISPERS 2022, doi:10.1109/WHISPERS56178.2022.9955067, data doi:10.5281/zenodo.5592485, licensed CC BY 4.0 (https://creativecommons.org/licenses/by/4.0/); per-swatch averages resampled to 5 nm, 6 spectra above 1.0 left out"],
        notice: None,
    },
];

/// What a set whose file name is not known records, unless told.
pub const UNKNOWN_LICENCE: &str = "unknown (not stated when the model was trained)";

impl Terms {
    /// The terms ../shared/spectra's README states for a file name, or unknown ones.
    pub fn known(source: &str) -> Terms {
        match KNOWN.iter().find(|k| k.file == source) {
            Some(k) => Terms {
                licence: k.licence.into(),
                commercial: k.commercial,
                attribution: k.attribution.iter().map(|s| s.to_string()).collect(),
            },
            None => Terms {
                licence: UNKNOWN_LICENCE.into(),
                ..Terms::default()
            },
        }
    }

    /// A trainer's own statement: `licence`, and whether it allows commercial use.
    pub fn stated(licence: &str, commercial: Commercial) -> Terms {
        Terms {
            licence: licence.into(),
            commercial,
            attribution: Vec::new(),
        }
    }
}

/// The notices that must ship with a model trained on these sources (each once).
pub fn notices<'a>(sources: impl IntoIterator<Item = &'a str>) -> Vec<Notice> {
    let mut out: Vec<Notice> = Vec::new();
    for s in sources {
        if let Some(n) = KNOWN.iter().find(|k| k.file == s).and_then(|k| k.notice) {
            if !out.contains(&n) {
                out.push(n);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_model_is_commercial_only_when_every_set_is() {
        use Commercial::*;
        assert_eq!(Commercial::all([Yes, Yes]), Yes);
        assert_eq!(Commercial::all([Yes, Unstated]), Unstated);
        assert_eq!(Commercial::all([Unstated, No, Yes]), No);
        assert_eq!(Commercial::all([]), Yes);
    }

    #[test]
    fn the_shared_sets_terms_follow_their_readme() {
        // The README beside the data is the source of the table: every file it lists is known,
        // and its licence words agree.
        let readme = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/spectra/README.md"
        ))
        .expect("../shared/spectra beside the checkout");
        let listed = readme.lines().filter(|l| l.contains(".csv |")).count();
        assert_eq!(
            listed,
            KNOWN.len(),
            "every set of the README is known, and no other"
        );
        for k in &KNOWN {
            let row = readme
                .lines()
                .find(|l| l.starts_with(&format!("| {} |", k.file)))
                .unwrap_or_else(|| panic!("{} is in the README's table", k.file));
            let says = match k.commercial {
                Commercial::No => "non-commercial",
                Commercial::Yes if k.licence.starts_with("public domain") => "Public domain",
                Commercial::Yes if k.licence.starts_with("MIT") => "MIT License",
                Commercial::Yes if k.licence.starts_with("CC BY 4.0") => "**CC BY 4.0**",
                Commercial::Yes => "BSD-3-Clause",
                Commercial::Unstated => "colour-science",
            };
            assert!(row.contains(says), "{}: README row lacks {says:?}", k.file);
        }
        let n = notices(KNOWN.iter().map(|k| k.file));
        assert_eq!(n, vec![RHODODENDRON, COLOUR_SCIENCE]);
        assert!(COLOUR_SCIENCE
            .text
            .starts_with("Copyright 2013 Colour Developers"));
    }
}
