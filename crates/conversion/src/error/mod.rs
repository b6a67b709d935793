//! Why a conversion could not be set up or failed, by cause. Messages name no option of any
//! front-end; [`Error::remedy`] says which setting would fix it, and each front-end names that
//! setting its own way (the CLI's flags, the Python package's keywords).

use crate::models::ModelError;
use crate::options::Compression;
use crate::wrapped::ColourError;
use std::path::PathBuf;

pub use crate::pipeline::Error as ConversionError;

mod cause;
mod message;
mod remedy;

pub use cause::Cause;
pub use message::message;
pub use remedy::{remedy_of, Remedy, Spelling};

/// Why a [`crate::Converter`] could not be built, or one conversion failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A deflate level was given with a compression that does not deflate.
    #[error("a deflate level applies to zip and zips only; compression {compression} has none")]
    ZipLevelWithoutZip {
        /// The compression asked for.
        compression: Compression,
    },
    /// A deflate level above 9.
    #[error("deflate level {level} is not one of 0 to 9")]
    ZipLevel {
        /// The level asked for.
        level: u8,
    },
    /// Tiles of no width or height.
    #[error("tiles must be at least 1×1 (asked for {width}×{height})")]
    EmptyTile {
        /// Width asked for.
        width: usize,
        /// Height asked for.
        height: usize,
    },
    /// Tiles larger than OpenEXR's readers accept, at the method's band count.
    #[error(transparent)]
    TileTooLarge(#[from] specconv_exr::BlockTooLarge),
    /// More bands (with alpha) than OpenEXR's readers accept as channels.
    #[error(transparent)]
    TooManyChannels(#[from] specconv_exr::TooManyChannels),
    /// Blocks in flight that need more memory than the machine has
    /// ([`specconv_pipeline::memory::available`]).
    #[error("the blocks in flight would need {} MiB, more than the {} MiB this machine has available; use fewer bands, smaller tiles or fewer worker threads", needed >> 20, have >> 20)]
    TooMuchMemory {
        /// Bytes needed.
        needed: u64,
        /// Bytes the process may use.
        have: u64,
    },
    /// More worker threads than the limit.
    #[error("{threads} worker threads asked for; at most {limit} are started (this machine has {cores} cores)")]
    TooManyThreads {
        /// Threads asked for.
        threads: usize,
        /// The limit.
        limit: usize,
        /// Cores of this machine.
        cores: usize,
    },
    /// Zero worker threads.
    #[error("the conversion needs at least one worker thread")]
    NoThreads,
    /// The worker threads could not be started.
    #[error("cannot start worker threads: {0}")]
    Threads(String),
    /// The OCIO config, or a colour space named in the options, cannot be used.
    #[error(transparent)]
    Colour(#[from] ColourError),
    /// The model cannot be used.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The method cannot be built with these options and this model.
    #[error(transparent)]
    Method(#[from] specconv_spectral::Error),
    /// One conversion failed (the input, its colour, the output; see [`ConversionError`]).
    #[error(transparent)]
    Conversion(#[from] ConversionError),
    /// An input or output of a command other than a conversion may not be used (the output
    /// is an input, exists and may not be replaced, has no directory).
    #[error(transparent)]
    Plan(#[from] specconv_atomic_file::PlanError),
    /// A batch's plan that may not start ([`crate::plan`]): its outputs, their files, its
    /// shards.
    #[error(transparent)]
    Planning(#[from] crate::plan::Error),
    /// An input is not a file, or is missing.
    #[error(transparent)]
    Input(#[from] specconv_atomic_file::ReadError),
    /// An emissive file was asked to be lit by an illuminant.
    #[error("{} is an emission (S0 channels): it is its own light", input.display())]
    EmissionIsItsOwnLight {
        /// The file.
        input: PathBuf,
    },
    /// The OCIO config lacks a role that is needed.
    #[error("the OCIO config has no {role} role{purpose}")]
    NoRole {
        /// The role.
        role: &'static str,
        /// What it was needed for (with a leading space), or nothing.
        purpose: &'static str,
    },
    /// A spectral EXR cannot be read.
    #[error("cannot read {}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: specconv_exr::Error,
    },
    /// A file cannot be written.
    #[error("cannot write {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: specconv_exr::Error,
    },
    /// A `specconv*` attribute of a file does not parse.
    #[error("in {}", path.display())]
    BadProvenance {
        /// The file.
        path: PathBuf,
        /// The attribute and why.
        source: crate::provenance::BadAttribute,
    },
    /// A file of emission where reflectances are needed.
    #[error(
        "{} holds emission (S0 channels), not reflectances: it has no colour to bounce; \
         it is shown as its own colour with no bounces",
        input.display()
    )]
    NotReflectance {
        /// The file.
        input: PathBuf,
    },
    /// A bispectral file where plain reflectances are needed.
    #[error(
        "{} is bispectral (re-radiation channels): its bounces need the whole re-radiation \
         matrix, which preview does not follow; `to-rgb` shows its colour",
        input.display()
    )]
    Bispectral {
        /// The file.
        input: PathBuf,
    },
    /// A compact texture where a spectral file is needed ([`crate::compact`]).
    #[error(
        "{} is a compact texture ({layout}): six values a texel, decoded to spectra by the model \
         in its header, not bands; `expand` writes it in the spectral layout (docs/compact.md)",
        path.display()
    )]
    CompactNotSpectral {
        /// The file.
        path: PathBuf,
        /// Its `specconvLayout`.
        layout: String,
    },
    /// A measurement cannot be set up.
    #[error(transparent)]
    Evaluation(#[from] specconv_evaluation::Error),
    /// Colorimetry on a file's bands cannot be set up (an observer or illuminant that does not
    /// cover them).
    #[error(transparent)]
    Colorimetry(specconv_colour::Error),
    /// A spectral EXR's attributes cannot be read ([`crate::describe`]).
    #[error(transparent)]
    Attributes(specconv_exr::Error),
    /// A `specconv*` attribute of a described file does not parse ([`crate::describe`]).
    #[error(transparent)]
    Provenance(crate::provenance::BadAttribute),
    /// Settings the compact layout cannot hold, or a file that is not a compact texture.
    #[error("the compact layout: {why}")]
    Compact {
        /// Why, and what to do.
        why: String,
    },
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_ocio::Error> for Error {
    fn from(e: specconv_ocio::Error) -> Error {
        Error::Colour(e.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::Key;
    use crate::pipeline::input::Choose;
    use crate::plan;
    use specconv_atomic_file::{PlanError, WriteError};
    use std::collections::BTreeSet;

    /// The name of `e`'s variant (of the conversion's error, for [`Error::Conversion`]) and
    /// whether a setting fixes it. Exhaustive: a new variant must be decided here, named in
    /// [`VARIANTS`] and given a sample in [`every_error`].
    fn decided(e: &Error) -> (&'static str, bool) {
        match e {
            Error::ZipLevelWithoutZip { .. } => ("ZipLevelWithoutZip", true),
            Error::ZipLevel { .. } => ("ZipLevel", true),
            Error::EmptyTile { .. } => ("EmptyTile", true),
            Error::TileTooLarge(_) => ("TileTooLarge", true),
            Error::TooManyChannels(_) => ("TooManyChannels", true),
            Error::TooMuchMemory { .. } => ("TooMuchMemory", true),
            Error::TooManyThreads { .. } => ("TooManyThreads", true),
            Error::NoThreads => ("NoThreads", true),
            // The system refused: no setting.
            Error::Threads(_) => ("Threads", false),
            // A data space named where a colour is needed: name the encoding instead.
            Error::Colour(c) => ("Colour", c.is_data_space()),
            Error::Model(ModelError::Invalid(e)) => ("Model(Invalid)", spectral_fixable(e)),
            Error::Model(ModelError::Save(s)) => (
                "Model(Save)",
                matches!(s, WriteError::Plan(PlanError::Exists { .. })),
            ),
            Error::Model(_) => ("Model", false),
            Error::Method(e) => ("Method", spectral_fixable(e)),
            Error::Conversion(c) => match c {
                ConversionError::Input(_) => ("Conversion::Input", false),
                ConversionError::Color(c) => ("Conversion::Color", c.is_data_space()),
                ConversionError::Output(_) => ("Conversion::Output", false),
                ConversionError::Damaged(_) => ("Conversion::Damaged", false),
                ConversionError::Channels { choose, .. } => {
                    ("Conversion::Channels", choose.is_some())
                }
                ConversionError::DefaultColourSpace(_) => ("Conversion::DefaultColourSpace", true),
                // Pixels handed over as they cannot be: the caller's to fix.
                ConversionError::InMemory(_) => ("Conversion::InMemory", false),
                ConversionError::NonFinite { .. } => ("Conversion::NonFinite", true),
                ConversionError::TooManyNonFinite { .. } => ("Conversion::TooManyNonFinite", true),
                // The method's own colorimetry: not a setting.
                ConversionError::Weights { .. } => ("Conversion::Weights", false),
                ConversionError::NotAFile(_) => ("Conversion::NotAFile", false),
                ConversionError::Plan(p) => {
                    ("Conversion::Plan", matches!(p, PlanError::Exists { .. }))
                }
                ConversionError::Io { .. } => ("Conversion::Io", false),
                ConversionError::Cancelled => ("Conversion::Cancelled", false),
                ConversionError::Spectral { .. } => ("Conversion::Spectral", true),
                ConversionError::Compact { .. } => ("Conversion::Compact", true),
                ConversionError::Data(_) => ("Conversion::Data", true),
                // The caller's own gate: the warning says what is wrong.
                ConversionError::Strict { .. } => ("Conversion::Strict", false),
                // Another file is needed.
                ConversionError::NotCompact { .. } => ("Conversion::NotCompact", false),
                // Fewer bands, smaller tiles, or a machine with more memory.
                ConversionError::TooMuchMemory(_) => ("Conversion::TooMuchMemory", true),
            },
            Error::Plan(p) => ("Plan", matches!(p, PlanError::Exists { .. })),
            // Whether a plan's error is fixable is the plan's own test's.
            Error::Planning(plan::Error::NotMadeBySpecconv { .. }) => {
                ("Planning::NotMadeBySpecconv", true)
            }
            Error::Planning(plan::Error::PatternIntoOneFile { .. }) => {
                ("Planning::PatternIntoOneFile", true)
            }
            Error::Planning(plan::Error::Files(p)) => {
                ("Planning::Files", matches!(p, PlanError::Exists { .. }))
            }
            Error::Planning(_) => ("Planning", false),
            Error::Input(_) => ("Input", false),
            Error::EmissionIsItsOwnLight { .. } => ("EmissionIsItsOwnLight", true),
            // Only the input colour space's role can be stood in for by naming one.
            Error::NoRole { role, .. } => ("NoRole", *role == "scene_linear"),
            Error::Read { .. } => ("Read", false),
            Error::Write { .. } => ("Write", false),
            Error::BadProvenance { .. } => ("BadProvenance", false),
            // Another file is needed, not another setting.
            Error::NotReflectance { .. } => ("NotReflectance", false),
            Error::Bispectral { .. } => ("Bispectral", false),
            Error::CompactNotSpectral { .. } => ("CompactNotSpectral", false),
            Error::Evaluation(specconv_evaluation::Error::Colour(e)) => {
                ("Evaluation", colour_fixable(e))
            }
            Error::Evaluation(specconv_evaluation::Error::Spectral(e)) => {
                ("Evaluation", spectral_fixable(e))
            }
            Error::Evaluation(_) => ("Evaluation", false),
            Error::Colorimetry(e) => ("Colorimetry", colour_fixable(e)),
            Error::Attributes(_) => ("Attributes", false),
            Error::Provenance(_) => ("Provenance", false),
            // Two settings that do not go together; the message says which.
            Error::Compact { .. } => ("Compact", false),
        }
    }

    /// A grid that a table does not cover: choose one inside.
    fn colour_fixable(e: &specconv_colour::Error) -> bool {
        matches!(e, specconv_colour::Error::NotCovered { .. })
    }

    /// `pca` with a model of several clusters, or a grid not covered.
    fn spectral_fixable(e: &specconv_spectral::Error) -> bool {
        match e {
            specconv_spectral::Error::NeedsOneCluster { .. } => true,
            specconv_spectral::Error::Colour(c) => colour_fixable(c),
            _ => false,
        }
    }

    /// Every name [`decided`] gives.
    const VARIANTS: &[&str] = &[
        "ZipLevelWithoutZip",
        "ZipLevel",
        "EmptyTile",
        "TileTooLarge",
        "TooManyChannels",
        "TooMuchMemory",
        "TooManyThreads",
        "NoThreads",
        "Threads",
        "Colour",
        "Model(Invalid)",
        "Model(Save)",
        "Model",
        "Method",
        "Conversion::Input",
        "Conversion::Color",
        "Conversion::Output",
        "Conversion::Damaged",
        "Conversion::Channels",
        "Conversion::DefaultColourSpace",
        "Conversion::NonFinite",
        "Conversion::TooManyNonFinite",
        "Conversion::Weights",
        "Conversion::NotAFile",
        "Conversion::Plan",
        "Conversion::Io",
        "Conversion::Cancelled",
        "Conversion::Spectral",
        "Conversion::Compact",
        "Conversion::Data",
        "Conversion::Strict",
        "Conversion::NotCompact",
        "Conversion::TooMuchMemory",
        "Plan",
        "Planning::NotMadeBySpecconv",
        "Planning::Files",
        "Input",
        "EmissionIsItsOwnLight",
        "NoRole",
        "Read",
        "Write",
        "BadProvenance",
        "NotReflectance",
        "Bispectral",
        "CompactNotSpectral",
        "Evaluation",
        "Colorimetry",
        "Attributes",
        "Provenance",
        "Compact",
    ];

    fn not_covered() -> specconv_colour::Error {
        specconv_colour::Error::NotCovered {
            what: "the cie1931 observer".into(),
            first: 360.0,
            last: 830.0,
            grid: specconv_colour::Grid {
                start: 300.0,
                end: 700.0,
                step: 10.0,
            },
        }
    }

    /// Samples of every variant, fixable and not.
    fn every_error() -> Vec<Error> {
        let p = || PathBuf::from("/t/a.exr");
        let data_space = || specconv_ocio::Error::DataColorSpace { name: "Raw".into() };
        let no_config = || specconv_ocio::Error::ConfigNotFound {
            path: p(),
            kind: specconv_atomic_file::Kind::Missing,
        };
        let exists = || PlanError::Exists {
            output: p(),
            more: 0,
        };
        let not_a_file = || specconv_atomic_file::ReadError::NotAFile {
            path: p(),
            kind: specconv_atomic_file::Kind::Directory,
        };
        let one_cluster = || specconv_spectral::Error::NeedsOneCluster { clusters: 8 };
        let bad_attribute = || crate::provenance::BadAttribute {
            attribute: "specconvBands",
            source: specconv_colour::Error::Grid("1:0:1".into()),
        };
        let channels = |choose| ConversionError::Channels {
            path: p(),
            what: "no R, G, B".into(),
            channels: "X, Y".into(),
            choose,
        };
        let conversion = [
            ConversionError::Input(specconv_oiio::Error::NotFound { path: p() }.into()),
            ConversionError::Color(data_space().into()),
            ConversionError::Color(no_config().into()),
            ConversionError::Output(specconv_exr::Error::Invalid("no bands".into())),
            ConversionError::Damaged(specconv_exr::check::Problem::Damaged {
                path: p(),
                message: "short".into(),
            }),
            channels(Some(Choose::ChannelsOrLayer)),
            channels(Some(Choose::OneLayer)),
            channels(None),
            ConversionError::DefaultColourSpace("none".into()),
            ConversionError::NonFinite {
                input: p(),
                pixels: 1,
                first: (0, 0),
                rows: (0, 1),
            },
            ConversionError::TooManyNonFinite {
                input: p(),
                limit: 10,
            },
            ConversionError::Weights { have: 3, want: 36 },
            ConversionError::NotAFile(not_a_file()),
            ConversionError::Plan(exists()),
            ConversionError::Plan(PlanError::OutputIsInput {
                output: p(),
                input: p(),
            }),
            ConversionError::Io {
                path: p(),
                source: std::io::Error::other("full"),
            },
            ConversionError::Cancelled,
            ConversionError::Compact { path: p() },
            ConversionError::Spectral {
                path: p(),
                emissive: false,
                bands: 36,
                range_nm: (380.0, 730.0),
            },
            ConversionError::Data(Box::new(crate::DataTexture {
                path: p(),
                name: "Raw".into(),
                rule: crate::Rule::Flag { overrides: None },
                selection: None,
                size: (1, 1),
            })),
            ConversionError::Strict {
                input: p(),
                warning: "1 pixels above 1".into(),
            },
            ConversionError::NotCompact {
                path: p(),
                why: "no specconvLayout attribute".into(),
            },
            ConversionError::TooMuchMemory(crate::pipeline::memory::Shortfall {
                needed: 13 << 30,
                available: 4 << 30,
                bound: "MemAvailable of /proc/meminfo",
            }),
        ];
        let mut all = vec![
            Error::ZipLevelWithoutZip {
                compression: Compression::Piz,
            },
            Error::ZipLevel { level: 12 },
            Error::EmptyTile {
                width: 0,
                height: 4,
            },
            Error::TooManyChannels(specconv_exr::TooManyChannels {
                bands: 35_001,
                alpha: true,
            }),
            Error::TileTooLarge(specconv_exr::BlockTooLarge {
                width: 5000,
                height: 5000,
                channels: 402,
                bytes_per_sample: 2,
                bytes: 20_100_000_000,
            }),
            Error::TooMuchMemory {
                needed: 1 << 40,
                have: 1 << 30,
            },
            Error::TooManyThreads {
                threads: 100_000,
                limit: 1024,
                cores: 2,
            },
            Error::NoThreads,
            Error::Threads("no".into()),
            Error::Colour(data_space().into()),
            Error::Colour(no_config().into()),
            Error::Model(ModelError::Invalid(one_cluster())),
            Error::Model(ModelError::Invalid(specconv_spectral::Error::Blend(
                "-1".into(),
            ))),
            Error::Model(ModelError::NotText { path: p() }),
            Error::Model(ModelError::Save(WriteError::Plan(exists()))),
            Error::Model(ModelError::Save(WriteError::Plan(
                PlanError::WrongExtension {
                    output: p(),
                    extensions: crate::models::EXTENSIONS,
                    what: "a model file is JSON",
                },
            ))),
            Error::Method(one_cluster()),
            Error::Method(specconv_spectral::Error::Colour(not_covered())),
            Error::Method(specconv_spectral::Error::Blend("-1".into())),
            Error::Plan(exists()),
            Error::Plan(PlanError::OutputIsInput {
                output: p(),
                input: p(),
            }),
            Error::Planning(plan::Error::NotMadeBySpecconv {
                output: p(),
                more: 0,
            }),
            Error::Planning(plan::Error::Files(exists())),
            Error::Input(not_a_file()),
            Error::EmissionIsItsOwnLight { input: p() },
            Error::NoRole {
                role: "scene_linear",
                purpose: "",
            },
            Error::NoRole {
                role: "color_picking",
                purpose: "",
            },
            Error::Read {
                path: p(),
                source: specconv_exr::Error::Invalid("no bands".into()),
            },
            Error::Write {
                path: p(),
                source: specconv_exr::Error::Invalid("no bands".into()),
            },
            Error::BadProvenance {
                path: p(),
                source: bad_attribute(),
            },
            Error::NotReflectance { input: p() },
            Error::Bispectral { input: p() },
            Error::CompactNotSpectral {
                path: p(),
                layout: "compact 2".into(),
            },
            Error::Evaluation(specconv_evaluation::Error::Colour(not_covered())),
            Error::Evaluation(specconv_evaluation::Error::Spectral(one_cluster())),
            Error::Evaluation(specconv_evaluation::Error::Scene("no light".into())),
            Error::Colorimetry(not_covered()),
            Error::Colorimetry(specconv_colour::Error::Grid("1:0:1".into())),
            Error::Attributes(specconv_exr::Error::Invalid("no bands".into())),
            Error::Provenance(bad_attribute()),
            Error::Compact {
                why: "resized".into(),
            },
        ];
        all.extend(conversion.into_iter().map(Error::Conversion));
        all
    }

    #[test]
    fn every_error_a_setting_fixes_has_a_remedy() {
        let errors = every_error();
        let seen: BTreeSet<&str> = errors.iter().map(|e| decided(e).0).collect();
        let listed: BTreeSet<&str> = VARIANTS.iter().copied().collect();
        assert_eq!(
            seen, listed,
            "a variant without a sample, or one not listed"
        );
        for e in &errors {
            let (name, fixable) = decided(e);
            let remedy = e.remedy();
            assert_eq!(
                remedy.is_some(),
                fixable,
                "{name} ({e}): remedy {remedy:?}, yet a setting {} fix it",
                if fixable { "does" } else { "does not" }
            );
            // Every remedy names the options it changes, but those that are not a
            // conversion's (the illuminant of to-rgb, a model's training is the model's).
            if let Some(r) = remedy {
                assert!(
                    !r.keys().is_empty() || r == Remedy::DropIlluminant,
                    "{name}: {r:?} names no option"
                );
                // The library's words name every option the remedy changes, in the
                // front-end's spelling.
                if let Some(advice) = r.advice(&Angled) {
                    for k in r.keys() {
                        assert!(advice.contains(&format!("<{}", k.about().name)), "{advice}");
                    }
                }
            }
        }
    }

    /// A spelling that shows where each option is named: `<name>`, `<name value>`.
    struct Angled;

    impl crate::Spelling for Angled {
        fn option(&self, key: crate::Key) -> String {
            format!("<{}>", key.about().name)
        }
        fn given(&self, key: crate::Key, value: &str) -> String {
            format!("<{} {value}>", key.about().name)
        }
        fn value(&self, value: &str) -> String {
            value.into()
        }
        fn on(&self, key: crate::Key) -> String {
            self.option(key)
        }
        fn update(&self) -> String {
            "<update>".into()
        }
    }

    #[test]
    fn remedies_are_found_in_the_errors_of_the_science_too() {
        // `train` and `eval` meet these without this crate's Error around them.
        let grid = remedy_of(&not_covered());
        assert_eq!(
            grid,
            Some(Remedy::BandsInside {
                start: 360.0,
                end: 700.0,
                step: 10.0
            })
        );
        assert_eq!(
            remedy_of(&specconv_spectral::Error::NeedsOneCluster { clusters: 2 }),
            Some(Remedy::OneClusterModel)
        );
        assert_eq!(
            remedy_of(&specconv_evaluation::Error::Colour(not_covered())),
            grid
        );
        assert_eq!(remedy_of(&std::io::Error::other("x")), None);
        assert_eq!(
            remedy_of(&Error::TooManyThreads {
                threads: 9,
                limit: 8,
                cores: 2
            })
            .map(|r| r.keys()),
            Some(&[Key::Threads][..])
        );
    }
}
