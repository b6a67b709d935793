//! Who can fix an error by a setting: the [`Remedy`] each front-end names its own way.

use super::{ConversionError, Error};
use crate::models::ModelError;
use crate::options::Key;
use crate::plan;
use crate::wrapped::ColourError;
use specconv_atomic_file::{PlanError, WriteError};

/// The setting that would fix an error ([`Error::remedy`], [`remedy_of`]): the options it
/// changes ([`Remedy::keys`]), which each front-end names its own way from [`Key::about`]
/// (the command line's flags, the Python package's keywords), and what to do with them.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Remedy {
    /// Replace the existing output, or skip outputs that are up to date.
    ReplaceOrSkip,
    /// Repair NaN and infinite input values, or keep them.
    RepairNonFinite,
    /// Repair NaN and infinite input values with black (too many for a 3×3 repair).
    RepairBlack,
    /// Name the input's colour space.
    NameColourSpace,
    /// Name the colour space the texture is encoded in (the file's is a data space).
    NameEncodingColourSpace,
    /// Name the channels or the layer that carry the colour.
    NameChannelsOrLayer,
    /// Name one of several layers.
    NameLayer,
    /// Drop the deflate level, or choose a compression that deflates.
    DropZipLevel,
    /// A deflate level from 0 to 9.
    ZipLevelInRange,
    /// Tiles of at least 1×1.
    NonEmptyTiles,
    /// At least one worker thread.
    SomeThreads,
    /// Fewer worker threads.
    FewerThreads,
    /// Smaller tiles or fewer bands: blocks that OpenEXR's readers accept.
    SmallerBlocks,
    /// Fewer bands, smaller tiles or fewer worker threads: blocks in flight that fit in memory.
    LessMemory,
    /// Fewer bands: channels that OpenEXR's readers accept.
    FewerBands,
    /// A wavelength grid inside the range a table covers; this one would do.
    BandsInside {
        /// First wavelength, nm.
        start: f64,
        /// Last wavelength, nm.
        end: f64,
        /// Spacing, nm.
        step: f64,
    },
    /// A model of one cluster (`pca` takes no other): one trained with one cluster.
    OneClusterModel,
    /// Replace the existing output.
    Replace,
    /// Drop the illuminant (emission is its own light).
    DropIlluminant,
    /// A data texture: skip it, write it through as data, or name its colour space if it is
    /// colour.
    DataTexture,
    /// A spectral image as input: use it as it is, integrate it to colour, or convert its
    /// colour source on the grid wanted; channels of a colour preview can be named.
    AlreadySpectral,
    /// A compact spectral texture as input: expand it; channels of its colour can be named.
    ExpandCompact,
    /// A UDIM pattern into one output: name the outputs by a template with the tile instead.
    TileTemplate,
}

impl Remedy {
    /// The conversion options it changes, first the one it is mostly about; none where the
    /// setting is not a conversion's (an illuminant to look under, a model's training).
    pub fn keys(&self) -> &'static [Key] {
        match self {
            Remedy::ReplaceOrSkip | Remedy::Replace => &[Key::Overwrite],
            Remedy::RepairNonFinite | Remedy::RepairBlack => &[Key::NonFinite],
            Remedy::NameColourSpace | Remedy::NameEncodingColourSpace => &[Key::Colorspace],
            Remedy::NameChannelsOrLayer | Remedy::NameLayer => &[Key::Channels],
            Remedy::DropZipLevel => &[Key::ZipLevel, Key::Compression],
            Remedy::ZipLevelInRange => &[Key::ZipLevel],
            Remedy::NonEmptyTiles => &[Key::Tile],
            Remedy::SomeThreads | Remedy::FewerThreads => &[Key::Threads],
            Remedy::SmallerBlocks => &[Key::Tile, Key::Bands],
            Remedy::LessMemory => &[Key::Bands, Key::Tile, Key::Threads],
            Remedy::FewerBands => &[Key::Bands],
            Remedy::BandsInside { .. } => &[Key::Bands],
            Remedy::OneClusterModel => &[Key::Model],
            // The output naming of the front-end (`--output-template`, `output_template=`).
            Remedy::DropIlluminant | Remedy::TileTemplate => &[],
            Remedy::DataTexture => &[Key::Data, Key::Colorspace],
            Remedy::AlreadySpectral => &[Key::Bands, Key::Channels],
            Remedy::ExpandCompact => &[Key::Channels],
        }
    }
}

/// How a front-end spells the options a remedy names: the command line's flags, the Python
/// package's keywords. [`Remedy::advice`] words each remedy once with it.
pub trait Spelling {
    /// The option itself: `--colorspace`, `-j/--threads`; `colorspace=`.
    fn option(&self, key: Key) -> String;
    /// The option given a value: `--fixnan box3`; `non_finite="box3"`.
    fn given(&self, key: Key, value: &str) -> String;
    /// A value alone, as [`Spelling::given`] writes it: `black`; `"black"`.
    fn value(&self, value: &str) -> String;
    /// A switch turned on: `--force`; `overwrite=True`.
    fn on(&self, key: Key) -> String;
    /// What skips outputs that are up to date (a batch's, not a conversion's option): `-u`;
    /// `update=True`.
    fn update(&self) -> String;
}

impl Remedy {
    /// What to do, in a front-end's spelling, appended to the error's message (`; pass
    /// --force to replace it`); `None` for the remedies a front-end words itself: its own
    /// commands and outputs (a spectral or compact input, a UDIM template, an illuminant, a
    /// model's training) and the rules of one option that it may say whole (a deflate level
    /// without zip, empty tiles, no threads).
    pub fn advice(&self, s: &dyn Spelling) -> Option<String> {
        let non_finite = crate::Named::name(crate::NonFinite::Keep);
        Some(match *self {
            Remedy::ReplaceOrSkip => format!(
                "; pass {} to replace it (or {} to skip outputs that are up to date)",
                s.on(Key::Overwrite),
                s.update()
            ),
            Remedy::Replace => format!("; pass {} to replace it", s.on(Key::Overwrite)),
            Remedy::RepairNonFinite => format!(
                "; repair them with {} (or {}), or write them as they are with {}",
                s.given(Key::NonFinite, "box3"),
                s.value("black"),
                s.given(Key::NonFinite, non_finite)
            ),
            Remedy::RepairBlack => {
                format!("; repair them with {}", s.given(Key::NonFinite, "black"))
            }
            Remedy::NameColourSpace => format!("; pass {}", s.option(Key::Colorspace)),
            Remedy::NameEncodingColourSpace => format!(
                "; pass {} with the colour space the texture is encoded in",
                s.option(Key::Colorspace)
            ),
            Remedy::NameChannelsOrLayer => format!(
                "; choose with {} or {}",
                s.given(Key::Channels, "LAYER"),
                s.given(Key::Channels, "NAME,NAME,NAME")
            ),
            Remedy::NameLayer => format!("; choose one with {}", s.given(Key::Channels, "LAYER")),
            Remedy::DataTexture => format!(
                "; {} leaves it out, {} writes it through as a data texture, and {} reads it as \
                 colour if it is one",
                s.given(Key::Data, "skip"),
                s.given(Key::Data, "copy"),
                s.given(Key::Colorspace, "NAME")
            ),
            Remedy::ZipLevelInRange => format!("; give {} 0 to 9", s.option(Key::ZipLevel)),
            Remedy::FewerThreads => format!("; lower {}", s.option(Key::Threads)),
            Remedy::SmallerBlocks | Remedy::LessMemory | Remedy::FewerBands => {
                let options: Vec<String> = self.keys().iter().map(|&k| s.option(k)).collect();
                format!(" ({})", options.join(", "))
            }
            Remedy::BandsInside { start, end, step } => format!(
                "; choose bands inside that range (e.g. {})",
                s.given(Key::Bands, &format!("{start}:{end}:{step}"))
            ),
            Remedy::DropZipLevel
            | Remedy::NonEmptyTiles
            | Remedy::SomeThreads
            | Remedy::OneClusterModel
            | Remedy::DropIlluminant
            | Remedy::TileTemplate
            | Remedy::AlreadySpectral
            | Remedy::ExpandCompact => return None,
        })
    }
}

impl Error {
    /// The setting that would fix it, when one would (every rule of every front-end: a
    /// test below lists the errors a setting fixes).
    pub fn remedy(&self) -> Option<Remedy> {
        match self {
            Error::ZipLevelWithoutZip { .. } => Some(Remedy::DropZipLevel),
            Error::ZipLevel { .. } => Some(Remedy::ZipLevelInRange),
            Error::EmptyTile { .. } => Some(Remedy::NonEmptyTiles),
            Error::TileTooLarge(_) => Some(Remedy::SmallerBlocks),
            Error::TooManyChannels(_) => Some(Remedy::FewerBands),
            Error::TooMuchMemory { .. } => Some(Remedy::LessMemory),
            // A strip's spectra: fewer bands or shorter tiles shrink it, fewer threads do not.
            Error::Conversion(ConversionError::TooMuchMemory(_)) => Some(Remedy::SmallerBlocks),
            Error::TooManyThreads { .. } => Some(Remedy::FewerThreads),
            Error::NoThreads => Some(Remedy::SomeThreads),
            Error::Plan(PlanError::Exists { .. })
            | Error::Model(ModelError::Save(WriteError::Plan(PlanError::Exists { .. })))
            | Error::Planning(plan::Error::NotMadeBySpecconv { .. }) => Some(Remedy::Replace),
            Error::Planning(plan::Error::Files(PlanError::Exists { .. })) => {
                Some(Remedy::ReplaceOrSkip)
            }
            Error::Planning(plan::Error::PatternIntoOneFile { .. }) => Some(Remedy::TileTemplate),
            Error::EmissionIsItsOwnLight { .. } => Some(Remedy::DropIlluminant),
            Error::NoRole {
                role: "scene_linear",
                ..
            } => Some(Remedy::NameColourSpace),
            Error::Colour(e) => colour_remedy(e),
            Error::Method(e) | Error::Model(ModelError::Invalid(e)) => spectral_remedy(e),
            Error::Evaluation(specconv_evaluation::Error::Spectral(e)) => spectral_remedy(e),
            Error::Colorimetry(e) | Error::Evaluation(specconv_evaluation::Error::Colour(e)) => {
                colorimetry_remedy(e)
            }
            Error::Conversion(e) => match e {
                ConversionError::Plan(PlanError::Exists { .. }) => Some(Remedy::ReplaceOrSkip),
                ConversionError::NonFinite { .. } => Some(Remedy::RepairNonFinite),
                ConversionError::TooManyNonFinite { .. } => Some(Remedy::RepairBlack),
                ConversionError::Channels { choose, .. } => choose.map(|c| match c {
                    crate::pipeline::input::Choose::ChannelsOrLayer => Remedy::NameChannelsOrLayer,
                    crate::pipeline::input::Choose::OneLayer => Remedy::NameLayer,
                }),
                ConversionError::Color(e) => colour_remedy(e),
                ConversionError::DefaultColourSpace(_) => Some(Remedy::NameColourSpace),
                ConversionError::Data(_) => Some(Remedy::DataTexture),
                ConversionError::Spectral { .. } => Some(Remedy::AlreadySpectral),
                ConversionError::Compact { .. } => Some(Remedy::ExpandCompact),
                _ => None,
            },
            _ => None,
        }
    }
}

/// The colour-management error that naming the colour space fixes: a data space.
fn colour_remedy(e: &ColourError) -> Option<Remedy> {
    e.is_data_space().then_some(Remedy::NameEncodingColourSpace)
}

/// The remedy of an uplift method's error: a model of one cluster for `pca`, a grid inside
/// what the tables cover.
fn spectral_remedy(e: &specconv_spectral::Error) -> Option<Remedy> {
    match e {
        specconv_spectral::Error::NeedsOneCluster { .. } => Some(Remedy::OneClusterModel),
        specconv_spectral::Error::Colour(c) => colorimetry_remedy(c),
        _ => None,
    }
}

/// The remedy of colorimetry's error: for a table that stops inside the grid, the grid
/// inside what it covers (whole nanometres, the same step).
fn colorimetry_remedy(e: &specconv_colour::Error) -> Option<Remedy> {
    match e {
        specconv_colour::Error::NotCovered {
            first, last, grid, ..
        } => Some(Remedy::BandsInside {
            start: first.max(grid.start).ceil(),
            end: last.min(grid.end).floor(),
            step: grid.step,
        }),
        _ => None,
    }
}

/// The remedy of one cause of an error chain, whichever library it comes from: this crate's
/// [`Error`] ([`Error::remedy`]), or the uplift's and colorimetry's errors that other commands
/// (training, evaluation) meet. A front-end walks the chain and says the first it finds.
pub fn remedy_of(cause: &(dyn std::error::Error + 'static)) -> Option<Remedy> {
    if let Some(e) = cause.downcast_ref::<Error>() {
        return e.remedy();
    }
    if let Some(e) = cause.downcast_ref::<specconv_spectral::Error>() {
        return spectral_remedy(e);
    }
    if let Some(e) = cause.downcast_ref::<specconv_evaluation::Error>() {
        return match e {
            specconv_evaluation::Error::Spectral(e) => spectral_remedy(e),
            specconv_evaluation::Error::Colour(e) => colorimetry_remedy(e),
            _ => None,
        };
    }
    cause
        .downcast_ref::<specconv_colour::Error>()
        .and_then(colorimetry_remedy)
}
