//! [`Report`]: what one conversion did, filled by the job itself (the one translation of a
//! conversion's facts on the way up to every front-end).

use specconv_spectral::bounded::Counts;
use std::fmt;

/// What one conversion did, and nothing else's.
#[derive(Debug, Clone)]
pub struct Report {
    /// Size of the full-resolution level.
    pub width: usize,
    /// Height of the full-resolution level.
    pub height: usize,
    /// Pixels uplifted (level 0: smaller levels are filtered from its spectra).
    pub pixels: u64,
    /// MIP levels written.
    pub levels: usize,
    /// Wrap modes recorded (tiled outputs), and whether the input declared them.
    pub wrap: Option<(crate::WrapModes, bool)>,
    /// Pixels of the input with NaN or infinite values in a channel read, and whether they
    /// were repaired (else they were kept: refused inputs fail).
    pub non_finite_input: (u64, bool),
    /// Every pixel was the same: written as one tile.
    pub constant: bool,
    /// Alpha was 1 everywhere and was not written.
    pub opaque_dropped: bool,
    /// The hash of the source pixels `-u` compares (empty for a data texture).
    pub source_hash: String,
    /// Bands of every spectrum.
    pub bands: usize,
    /// The subimage and the channels read.
    pub selection: Selection,
    /// The input's colour space (the config's name, or a description).
    pub colorspace: String,
    /// The rule that chose it.
    pub colorspace_rule: Rule,
    /// Declarations of the file that were ignored or disagree.
    pub warnings: Vec<Warning>,
    /// The input's texture metadata not carried into the output ([`crate::metadata::Carry`]).
    pub metadata_dropped: Vec<crate::metadata::Dropped>,
    /// Straight colour was multiplied by alpha after conversion.
    pub premultiplied: bool,
    /// Pixels whose colour had a NaN or infinite component.
    pub non_finite: u64,
    /// Pixels above 1 (an input channel or Y above `specconv_pipeline::ABOVE_ONE`).
    pub above_one: u64,
    /// Pixels with a band beyond the half range, stored as ±65504.
    pub saturated: u64,
    /// Pixels of made levels (and of a resized level 0) clamped after a filter with negative
    /// lobes pushed a band out of range (`[0, 1]` for bounded reflectance) or alpha out of
    /// [0, 1].
    pub clamped: u64,
    /// The filter the levels were made with; `None` when none was made (one level, not
    /// resized).
    pub filter: Option<crate::Filter>,
    /// Bounded reflectance: the outcomes of the projection into [0, 1]; `None` otherwise.
    pub bounded: Option<Counts>,
    /// Emission: colours no emission spectrum of the method matched; `None` otherwise.
    pub unmatched: Option<u64>,
    /// Seconds the conversion took.
    pub seconds: f64,
    /// What the texture was read as: colour, one achromatic channel, or data.
    pub role: Role,
    /// For a data texture, what was done with it; `None` for colour.
    pub data: Option<DataOutcome>,
}

impl Report {
    /// Pixels above 1 in a reflectance conversion where they are at least 1 % of the image
    /// (an emission map's, not a few highlights'); 0 otherwise and for emission.
    pub fn clipped(&self) -> u64 {
        clipped(self.unmatched.is_some(), self.above_one, self.pixels)
    }

    /// Every warning of this conversion, in the words every front-end prints and records: the
    /// file's declarations not followed, then pixels clipped, then metadata not carried.
    pub fn notices(&self) -> Vec<Notice> {
        let mut notices: Vec<Notice> = self
            .warnings
            .iter()
            .map(|w| Notice {
                kind: NoticeKind::Colour(w.clone()),
                text: w.to_string(),
            })
            .collect();
        let n = self.clipped();
        if n > 0 {
            notices.push(Notice {
                kind: NoticeKind::Clipped,
                text: format!(
                    "{n} pixels above 1 in a reflectance conversion (no reflectance is brighter \
                     than white: clipped); an emission map is converted as emission"
                ),
            });
        }
        if !self.metadata_dropped.is_empty() {
            notices.push(Notice {
                kind: NoticeKind::Metadata,
                text: crate::metadata::describe(&self.metadata_dropped),
            });
        }
        notices
    }
}

/// The one rule of what counts as clipped: pixels above 1 (an input channel or Y above
/// `specconv_pipeline::ABOVE_ONE`) of a reflectance conversion of `pixels`, when they are at
/// least 1 % of them: an emission map converted as reflectance, not a few highlights of an
/// albedo. Emission has no such limit.
pub fn clipped(emissive: bool, above_one: u64, pixels: u64) -> u64 {
    if emissive || above_one == 0 || above_one * 100 < pixels {
        0
    } else {
        above_one
    }
}

/// A warning of one conversion: its kind (the same for the same trouble in any input, so that
/// a batch says it once with a count) and its words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Notice {
    /// What kind of trouble.
    pub kind: NoticeKind,
    /// It in words, without the input's path and without options.
    pub text: String,
}

/// The kinds of warning a batch counts.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum NoticeKind {
    /// A declaration of the file not followed ([`Warning`]): one kind per distinct warning.
    Colour(Warning),
    /// Pixels above 1 in a reflectance conversion ([`Report::clipped`]).
    Clipped,
    /// Input metadata not carried ([`Report::metadata_dropped`]): one warning for a batch,
    /// naming the attributes of every input.
    Metadata,
}

/// One kind of warning in a batch: how many inputs had it, and the first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NoticeCount {
    /// The kind.
    pub kind: NoticeKind,
    /// The first input's words for it.
    pub text: String,
    /// Inputs that had it.
    pub inputs: usize,
    /// The first input that had it.
    pub first: std::path::PathBuf,
    /// For [`NoticeKind::Metadata`], the attributes not carried of every input that had it,
    /// each name once.
    pub metadata: Vec<crate::metadata::Dropped>,
}

/// Adds `report`'s notices of `input` to `tally`, one entry per kind in the order first met.
pub fn tally(tally: &mut Vec<NoticeCount>, input: &std::path::Path, report: &Report) {
    for n in report.notices() {
        let metadata = match n.kind {
            NoticeKind::Metadata => report.metadata_dropped.clone(),
            _ => Vec::new(),
        };
        match tally.iter_mut().find(|c| c.kind == n.kind) {
            Some(c) => {
                c.inputs += 1;
                for d in metadata {
                    if !c.metadata.iter().any(|m| m.name == d.name) {
                        c.metadata.push(d);
                    }
                }
                if c.kind == NoticeKind::Metadata {
                    c.text = crate::metadata::describe(&c.metadata);
                }
            }
            None => tally.push(NoticeCount {
                kind: n.kind,
                text: n.text,
                inputs: 1,
                first: input.to_path_buf(),
                metadata,
            }),
        }
    }
}

/// What a texture holds (`specconv_pipeline::colour::texture_space`'s rule).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Colour, three channels.
    Colour,
    /// One channel read as achromatic colour (its colour space says it is colour).
    Achromatic,
    /// Data, not colour: never uplifted.
    Data,
}

impl Role {
    /// The name records give it: `colour`, `achromatic` or `data`.
    pub fn name(self) -> &'static str {
        match self {
            Role::Colour => "colour",
            Role::Achromatic => "achromatic",
            Role::Data => "data",
        }
    }
}

/// What was done with a data texture ([`crate::DataPolicy`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataOutcome {
    /// Nothing written.
    Skipped,
    /// Written through as a data texture.
    Copied,
}

/// Which rule chose the input colour space: a row of the precedence of colour evidence
/// ([`PRECEDENCE`], docs/colour.md), or the data-map rule, with the evidence of a lower row
/// that it overruled, if any (said once, here, not as a warning: the precedence is the why).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Rule {
    /// Row 1: named by the caller (the command line's `--colorspace`).
    Flag {
        /// The evidence it overrides, if any ("the file's EXR chromaticities (ACEScg)").
        overrides: Option<String>,
    },
    /// Row 2: the OCIO config's explicit file rule of this name (not its Default rule).
    FileRule {
        /// The rule's name.
        rule: String,
        /// The file's declaration it overrides, if any.
        overrides: Option<String>,
    },
    /// Row 3 (strong) or 4 (weak): the file's declarations that agree with the one used
    /// ("EXR chromaticities", ...).
    Declared {
        /// The declarations, the one used first.
        what: Vec<String>,
        /// Strong (row 3) or weak (row 4).
        strength: Strength,
        /// The weaker declaration it overrides, if any.
        overrides: Option<String>,
    },
    /// Row 5: the Default file rule of a config the user gave (a file or `$OCIO`); holds the
    /// rule's name. A colour space for float pixels that declare nothing; a data space for
    /// any file no stronger row decides, over weak declarations.
    ConfigDefault {
        /// The rule's name.
        rule: String,
        /// The weak declaration it overrides (a data space only), if any.
        overrides: Option<String>,
    },
    /// The data-map rule: one channel (with or without alpha) that no row from 1 to 3 calls
    /// colour is data.
    OneChannel {
        /// The evidence of rows 4 to 6 that would have called it colour, if any.
        overrides: Option<String>,
        /// The colour space rows 4 to 6 give it: what `--colorspace` names to uplift it as
        /// colour after all ([`Rule::colour_after_all`]).
        colour: String,
    },
    /// Row 6: the format's default, with its reason.
    Default(&'static str),
}

/// How much a declaration in a file says ([`Rule::Declared`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strength {
    /// Written on purpose: an ICC profile, OpenEXR chromaticities or the ACES container flag,
    /// a colour-space name a tool wrote (row 3).
    Strong,
    /// Written by every writer whatever the pixels hold: PNG `sRGB`, `gAMA`, `cHRM` (row 4).
    Weak,
}

/// The precedence of colour evidence, rows 1 to 6 in order: what each row is, in words
/// ([`Rule::row`] indexes it from 1).
pub const PRECEDENCE: [&str; 6] = [
    "the colour space the caller names (--colorspace)",
    "a studio config's explicit file rule (not its Default rule)",
    "a strong declaration in the file (ICC profile, EXR colorInteropID, chromaticities or ACES container flag, a colour-space name a tool wrote)",
    "a weak declaration in the file (PNG sRGB, gAMA, cHRM chunks, which writers add to every PNG)",
    "the Default rule of a config the user gave",
    "the built-in default (OpenEXR without chromaticities: linear Rec.709; integer pixels: sRGB texture)",
];

/// What the data-map rule is, in words (the rule [`Rule::OneChannel`] applies).
pub const DATA_MAP_RULE: &str = "one or two channels are data unless rows 1 to 3 call them colour";

impl Rule {
    /// The rule's keyword, as JSON records name it: `colorspace-option`, `file-rule`,
    /// `declared`, `config-default`, `one-channel` or `default`.
    pub fn kind(&self) -> &'static str {
        match self {
            Rule::Flag { .. } => "colorspace-option",
            Rule::Declared { .. } => "declared",
            Rule::FileRule { .. } => "file-rule",
            Rule::ConfigDefault { .. } => "config-default",
            Rule::OneChannel { .. } => "one-channel",
            Rule::Default(_) => "default",
        }
    }

    /// The row of [`PRECEDENCE`] that decided, from 1; `None` for the data-map rule.
    pub fn row(&self) -> Option<u8> {
        Some(match self {
            Rule::Flag { .. } => 1,
            Rule::FileRule { .. } => 2,
            Rule::Declared {
                strength: Strength::Strong,
                ..
            } => 3,
            Rule::Declared { .. } => 4,
            Rule::ConfigDefault { .. } => 5,
            Rule::OneChannel { .. } => return None,
            Rule::Default(_) => 6,
        })
    }

    /// What the row that decided is, in words ([`PRECEDENCE`] or [`DATA_MAP_RULE`]).
    pub fn row_text(&self) -> String {
        match self.row() {
            Some(row) => format!(
                "row {row} of {}: {}",
                PRECEDENCE.len(),
                PRECEDENCE[usize::from(row) - 1]
            ),
            None => format!("the data-map rule: {DATA_MAP_RULE}"),
        }
    }

    /// The evidence of a lower row that this rule overruled, if any.
    pub fn overrides(&self) -> Option<&str> {
        match self {
            Rule::Flag { overrides }
            | Rule::FileRule { overrides, .. }
            | Rule::Declared { overrides, .. }
            | Rule::ConfigDefault { overrides, .. }
            | Rule::OneChannel { overrides, .. } => overrides.as_deref(),
            Rule::Default(_) => None,
        }
    }

    /// The evidence this rule stands for, named as an overruled piece is named ("the file's
    /// PNG sRGB chunk (sRGB - Texture)") for its colour space `name`; `None` for the flag,
    /// the data-map rule and the format's default, which are no evidence of the file's.
    pub fn evidence(&self, name: &str) -> Option<String> {
        match self {
            Rule::Declared { what, .. } => what.first().map(|w| says::file(w, name)),
            Rule::FileRule { rule, .. } => Some(says::file_rule(rule, name)),
            Rule::ConfigDefault { rule, .. } => Some(says::default_rule(rule, name)),
            Rule::Flag { .. } | Rule::OneChannel { .. } | Rule::Default(_) => None,
        }
    }

    /// For a texture this rule made data, the colour space to name (`--colorspace`) to uplift
    /// it as colour after all: the one rows 4 to 6 gave a one-channel map the data-map rule
    /// took; `None` where a data colour space decided (only the caller knows the encoding).
    pub fn colour_after_all(&self) -> Option<&str> {
        match self {
            Rule::OneChannel { colour, .. } => Some(colour),
            _ => None,
        }
    }

    /// Whether the rule may call one channel colour: rows 1 to 3.
    pub fn may_call_one_channel_colour(&self) -> bool {
        self.row().is_some_and(|row| row <= 3)
    }
}

/// How an overruled piece of evidence is named ([`Rule::overrides`]), in one place.
pub mod says {
    /// A declaration of the file: "the file's EXR chromaticities (ACEScg)".
    pub fn file(what: &str, name: &str) -> String {
        format!("the file's {what} ({name})")
    }

    /// An explicit file rule: "the OCIO config's file rule 'normals' (Raw)".
    pub fn file_rule(rule: &str, name: &str) -> String {
        format!("the OCIO config's file rule '{rule}' ({name})")
    }

    /// The Default rule: "the OCIO config's 'Default' file rule (ACES2065-1)".
    pub fn default_rule(rule: &str, name: &str) -> String {
        format!("the OCIO config's '{rule}' file rule ({name})")
    }
}

/// A declaration of the file that was not followed. Said without options: a front-end adds
/// how to choose the colour space.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Warning {
    /// A declaration that cannot be used.
    Ignored {
        /// The declaration ("ICC profile", …).
        what: String,
        /// Why it cannot be used.
        why: String,
    },
    /// Two declarations that disagree: the first is used.
    Disagree {
        /// The declaration used.
        what: String,
        /// The colour space it says.
        name: String,
        /// The declaration not followed.
        other: String,
        /// The colour space that one says.
        other_name: String,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::Ignored { what, why } => write!(f, "the file's {what} is ignored: {why}"),
            Warning::Disagree {
                what,
                name,
                other,
                other_name,
            } => write!(
                f,
                "the file's {what} says '{name}' but its {other} says '{other_name}'; using '{name}'"
            ),
        }
    }
}

/// Why these channels carry the colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelReason {
    /// `--channels`.
    Option,
    /// The channels are named R, G, B.
    Named,
    /// The file's channels, in order (no layers; no R, G, B names).
    InOrder,
    /// The only layer with R, G and B channels.
    OnlyLayer,
}

/// The channels read as colour and alpha.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Channels {
    /// Three indices (R, G, B) or one (grey, repeated).
    pub colour: Vec<usize>,
    /// The alpha channel's index, if any.
    pub alpha: Option<usize>,
    /// Names of the colour channels, then of alpha.
    pub names: Vec<String>,
    /// Why these channels.
    pub reason: ChannelReason,
}

/// What an input is read as: its subimage and channels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Selection {
    /// The subimage read (0: the first).
    pub subimage: u32,
    /// Subimages in the file.
    pub subimages: u32,
    /// The subimage's (part) name, empty when it has none.
    pub subimage_name: String,
    /// The channels read.
    pub channels: Channels,
}

impl Selection {
    /// `subimage 1 'albedo' of 2, ` for files with several subimages, else empty.
    pub fn describe_subimage(&self) -> String {
        if self.subimages <= 1 {
            return String::new();
        }
        let name = if self.subimage_name.is_empty() {
            String::new()
        } else {
            format!(" '{}'", self.subimage_name)
        };
        format!("subimage {}{name} of {}", self.subimage, self.subimages)
    }
}
