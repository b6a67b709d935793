//! The terms of use of training data, which travel with every model trained on it: per set its
//! licence, whether it may be used commercially and the attribution it asks for, and the
//! notices that must ship with anything derived from it (docs/licences.md).
//!
//! The sets of ../shared/spectra are known by their content (the SHA-256 of the file's bytes,
//! [`content_hash`]), never by their names, with the terms their README states: a file named
//! like one of them that holds other spectra is unknown, and a renamed copy is still known.
//! Any other set records what its trainer says (`--licence`, `--commercial`), else "unknown".
//! A model records each set's hash, so that a set read again (`train --with`) is checked to be
//! the one it was trained on. A model may be used commercially only when every one of its
//! sets may.

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
    /// The SHA-256 of the file's bytes ([`content_hash`]): what the terms are known by.
    sha256: &'static str,
    /// Its spectra.
    count: usize,
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
        sha256: "d090098c0015da7df9d6687e3c52b2ac998586ec0dbcabbd521b3327e9b2bd98",
        count: 1269,
        licence: "non-commercial use only (University of Eastern Finland spectral database)",
        commercial: Commercial::No,
        attribution: &["Munsell matte chips, University of Eastern Finland spectral database (Kohonen, Parkkinen, Jaaskelainen 2006)"],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_vegetation_380-780_5nm.csv",
        sha256: "a0dc94577dfb0dd6208dbbad2f5dd96230d65baff59a349a93d60e4015fb13cb",
        count: 235,
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_manmade_380-780_5nm.csv",
        sha256: "bd105c0b1273f95b3b1f85e6082ffc854d546810c494a03bd01c2c0162edff98",
        count: 138,
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_soils_380-780_5nm.csv",
        sha256: "89383c44f600586823ad31f1c4aeb41a34d9c74779de524e9a4160aad1982981",
        count: 144,
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "usgs_splib07a_minerals_380-780_5nm.csv",
        sha256: "01e449a62133de1141e8c7085cf526e3fab7d2545446ac4a4e8e52dabe088411",
        count: 743,
        licence: USGS_LICENCE,
        commercial: Commercial::Yes,
        attribution: &[USGS],
        notice: None,
    },
    Known {
        file: "rhododendron_leaves_380-780_5nm.csv",
        sha256: "11b7f5c40bc94e91540ed5d9b3d6e090c7ceab15737294374026a3e2144d8df9",
        count: 786,
        licence: "MIT (c) 2022 Beth McDonald, emcdona1/leaf_reflectance_spectroscopy",
        commercial: Commercial::Yes,
        attribution: &["Copyright (c) 2022 Beth McDonald (MIT License): Rhododendron leaves, Field Museum of Natural History, emcdona1/leaf_reflectance_spectroscopy"],
        notice: Some(RHODODENDRON),
    },
    Known {
        file: "colorchecker_n_ohta_380-780_5nm.csv",
        sha256: "96fc4b3428b6841001cede7f47e3b82e78fc1af89e00cba14607526519cb1ba0",
        count: 24,
        licence: "not stated by its origin (N. Ohta's measurement, shipped in colour-science 0.4.7, BSD-3-Clause)",
        commercial: Commercial::Unstated,
        attribution: &["X-Rite ColorChecker Classic, N. Ohta's measurement, via colour-science 0.4.7 (Copyright 2013 Colour Developers, BSD-3-Clause)"],
        notice: Some(COLOUR_SCIENCE),
    },
    Known {
        file: "nist_cqs90_vs_380-780_5nm.csv",
        sha256: "1fd02965f2a04ccc0965135c03e7b5116fd8c54c5bedba7648aa2ba6ecb7cdc2",
        count: 15,
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
        sha256: "916697891f52eff3e1cd0ad504085ae7efc4375894e3265a18ef69a2ac286b07",
        count: 30,
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
        sha256: "c80ab1c4a28a653f337386f91533a9006ed747c9e6d1e71601728dc3fd2a0b54",
        count: 1586,
        licence: "CC BY 4.0 (Hyperspectral Pigment Dataset, H. Deborah, NTNU, doi:10.5281/zenodo.5592485)",
        commercial: Commercial::Yes,
        // CC BY 4.0 asks for the creator, the licence and whether the data were changed.
        attribution: &["Hyperspectral Pigment Dataset, H. Deborah (NTNU), WHISPERS 2022, doi:10.1109/WHISPERS56178.2022.9955067, data doi:10.5281/zenodo.5592485, licensed CC BY 4.0 (https://creativecommons.org/licenses/by/4.0/); per-swatch averages resampled to 5 nm, 6 spectra above 1.0 left out"],
        notice: None,
    },
];

/// What a set whose file name is not known records, unless told.
pub const UNKNOWN_LICENCE: &str = "unknown (not stated when the model was trained)";

/// The SHA-256 of a set file's bytes, in lowercase hex (as `sha256sum` prints it): what a
/// model records of each set and what known terms are found by.
pub fn content_hash(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The shared set whose content hashes to `sha256`, if any.
fn known(sha256: &str) -> Option<&'static Known> {
    KNOWN.iter().find(|k| k.sha256 == sha256)
}

/// The spectra count and hash of the shared set that is named `source`, when its content is
/// not what `source` holds (`sha256`): a file that takes a known set's name without its data
/// (said in a warning, since its terms are then unknown).
pub fn named_like_known(source: &str, sha256: &str) -> Option<(usize, &'static str)> {
    KNOWN
        .iter()
        .find(|k| k.file == source && k.sha256 != sha256)
        .map(|k| (k.count, k.sha256))
}

impl Terms {
    /// The terms ../shared/spectra's README states for the set whose bytes hash to `sha256`
    /// ([`content_hash`]), or unknown ones (`None`: content never read from a file).
    pub fn of_content(sha256: Option<&str>) -> Terms {
        match sha256.and_then(known) {
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

    /// Whether these are the terms of a shared set (found by content, [`Terms::of_content`]).
    pub fn is_known(sha256: &str) -> bool {
        known(sha256).is_some()
    }

    /// A trainer's own statement: `licence`, and whether it allows commercial use. A licence
    /// is one line of text: one with a control character (a line break, an escape) is
    /// refused ([`one_line`]), so that no licence can pass for other lines where it is shown.
    pub fn stated(licence: &str, commercial: Commercial) -> Result<Terms, String> {
        one_line("the licence", licence)?;
        Ok(Terms {
            licence: licence.into(),
            commercial,
            attribution: Vec::new(),
        })
    }
}

/// Refuses text that is not one line: a control character (a line break, a tab, an escape,
/// U+0085, …), a line separator or a bidirectional override
/// ([`specconv_atomic_file::shown::hidden`]) would let it pass for other lines where it is
/// shown. `what` names it.
pub fn one_line(what: &str, text: &str) -> Result<(), String> {
    match text
        .char_indices()
        .find(|&(_, c)| specconv_atomic_file::shown::hidden(c))
    {
        None => Ok(()),
        Some((at, c)) => Err(format!(
            "{what} {:?} holds the control character U+{:04X} at byte {at}: give it as one line of text",
            text, c as u32
        )),
    }
}

/// The notices that must ship with a model trained on these sets, as (source, hash), each
/// once: found by the hash, or by the name where no hash was recorded (a notice is an
/// obligation: one too many is shipped rather than one missed).
pub fn notices<'a>(sets: impl IntoIterator<Item = (&'a str, Option<&'a str>)>) -> Vec<Notice> {
    let mut out: Vec<Notice> = Vec::new();
    for (source, sha256) in sets {
        let k = match sha256 {
            Some(h) => known(h),
            None => KNOWN.iter().find(|k| k.file == source),
        };
        if let Some(n) = k.and_then(|k| k.notice) {
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
        let n = notices(KNOWN.iter().map(|k| ("renamed.csv", Some(k.sha256))));
        assert_eq!(n, vec![RHODODENDRON, COLOUR_SCIENCE]);
        assert!(COLOUR_SCIENCE
            .text
            .starts_with("Copyright 2013 Colour Developers"));
    }

    #[test]
    fn sets_are_known_by_their_content_never_by_their_name() {
        // FIPS 180-2's test vector: the hash is SHA-256 as `sha256sum` prints it.
        assert_eq!(
            content_hash(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        let shared = std::env::var("SPECCONV_SHARED")
            .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared").into());
        for k in &KNOWN {
            let bytes = std::fs::read(format!("{shared}/spectra/{}", k.file)).unwrap();
            assert_eq!(content_hash(&bytes), k.sha256, "{}", k.file);
            let text = String::from_utf8(bytes).unwrap();
            let table = specconv_colour::SpectralTable::parse(k.file, &text).unwrap();
            assert_eq!(table.names.len(), k.count, "{}", k.file);
            // Known by content, whatever the name; unknown by name alone.
            assert_eq!(Terms::of_content(Some(k.sha256)).licence, k.licence);
            let other = content_hash(format!("{text}\n").as_bytes());
            assert_eq!(Terms::of_content(Some(&other)).licence, UNKNOWN_LICENCE);
            assert_eq!(named_like_known(k.file, &other), Some((k.count, k.sha256)));
            assert_eq!(named_like_known(k.file, k.sha256), None);
            assert_eq!(named_like_known("renamed.csv", &other), None);
        }
        assert_eq!(Terms::of_content(None).commercial, Commercial::Unstated);
    }

    #[test]
    fn a_stated_licence_is_one_line() {
        for bad in [
            "ours\nspecconvSource: FORGED.png\ncommercial use: yes",
            "ours\r",
            "ours\tyes",
            "\u{1b}[2Kcommercial use: yes",
            "ours\u{85}",
            "ours\u{2028}commercial use: yes",
            "ours\u{202e}sey",
            "ours\u{0}",
        ] {
            let e = Terms::stated(bad, Commercial::Yes).unwrap_err();
            assert!(e.contains("control character"), "{bad:?}: {e}");
        }
        for good in ["ours", "CC BY 4.0 (c) 山田 太郎 — Café", "MIT \\ BSD"] {
            assert_eq!(Terms::stated(good, Commercial::No).unwrap().licence, good);
        }
    }
}
