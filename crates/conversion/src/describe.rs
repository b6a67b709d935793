//! What a conversion would make of an image, without converting it ([`describe`]): its
//! geometry and storage, the channels read as colour and why, the colour space chosen and the
//! rule that chose it, whether it is colour or data, and for a spectral EXR its bands. Plain
//! data, for a front-end to print (`specconv info`) or return.

use crate::colour_config::ColourConfig;
use crate::error::Error;
use crate::options::Options;
use crate::pipeline::input::{choose_channels, open_subimage, Channels};
use crate::pipeline::{input_space, texture_space, DataTexture, InputSpace};
use crate::provenance::{ConventionFrom, Provenance};
use crate::{Role, Rule, Warning};
use specconv_colour::EmissionUnits;
use specconv_oiio::ImageReader;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use crate::pipeline::input::ChannelReason;

/// An image as a conversion would read it ([`describe`]).
#[derive(Debug)]
#[non_exhaustive]
pub struct Inspection {
    /// The image.
    pub path: PathBuf,
    /// The reader's name of its format (`openexr`, `tiff`, `png`, …).
    pub format: String,
    /// Width of the full-resolution level.
    pub width: u32,
    /// Height of the full-resolution level.
    pub height: u32,
    /// Its channels, in file order.
    pub channels: Vec<Channel>,
    /// The channel the file marks as alpha.
    pub alpha_channel: Option<usize>,
    /// The pixel format of most channels (`half`, `uint8`, …).
    pub pixel_format: String,
    /// Tile width and height; `None` for scanlines.
    pub tile_size: Option<[u32; 2]>,
    /// Width and height of every MIP level, the full resolution first.
    pub levels: Vec<[u32; 2]>,
    /// Where the full-resolution level's pixels sit (OpenEXR's MIP levels share its origin).
    pub data_window: Window,
    /// The display window.
    pub display_window: Window,
    /// The subimage described (0: the first).
    pub subimage: u32,
    /// Subimages in the file.
    pub subimages: u32,
    /// Every subimage's name, empty where it has none.
    pub subimage_names: Vec<String>,
    /// The colour-space name the file carries (`oiio:ColorSpace`; the reader's own guess
    /// for many formats).
    pub declared_colour_space: Option<String>,
    /// The channels read as colour (then alpha) and why; or why none can be chosen without
    /// naming them.
    pub channel_choice: Result<ChannelChoice, String>,
    /// The colour is straight (unassociated): a conversion premultiplies it once converted.
    pub straight_alpha: bool,
    /// The bands and attributes of a spectral EXR (the Fichet 2021 layout); `None` for any
    /// other image.
    pub spectral: Option<SpectralFacts>,
    /// What a compact texture holds (`--layout compact`: [`crate::compact`]); `None` for any
    /// other image. Its channels are no colour: `expand` writes its bands.
    pub compact: Option<crate::CompactFacts>,
    /// What its colour is read as, or why it cannot be converted (a colour space that cannot
    /// be reached, a data space that cannot be named). A spectral EXR is not read through a
    /// colour space: a front-end may show its bands instead.
    pub colour: Result<ReadAs, Error>,
}

/// One channel of an image.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct Channel {
    /// Its name (`R`, `diffuse.G`, `T.380,000000nm`, …).
    pub name: String,
    /// Its stored format (`half`, `float`, `uint8`, …).
    pub format: String,
}

/// A rectangle of an image's pixel space: its origin (which may be negative) and size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Window {
    /// Left edge (first column).
    pub x: i32,
    /// Top edge (first row).
    pub y: i32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Window {
    fn of(w: specconv_oiio::Window) -> Window {
        Window {
            x: w.x,
            y: w.y,
            width: w.width,
            height: w.height,
        }
    }
}

/// The channels a conversion reads as colour and alpha.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct ChannelChoice {
    /// Names of the colour channels (three, or one grey), then of alpha.
    pub names: Vec<String>,
    /// Colour channels: 3, or 1 for grey.
    pub colour: usize,
    /// The alpha channel's index, if any.
    pub alpha: Option<usize>,
    /// Why these.
    pub reason: ChannelReason,
}

/// What an image's colour is read as, by the conversion's rule.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReadAs {
    /// Colour ([`Role::Colour`], or [`Role::Achromatic`] for one channel its colour space
    /// calls colour), uplifted from this colour space.
    Colour {
        /// The config's name of the colour space, or a description where it has none.
        space: String,
        /// The rule that chose it.
        rule: Rule,
        /// Declarations of the file that were ignored or disagree.
        warnings: Vec<Warning>,
        /// How it reaches CIE XYZ (D65), in words.
        to_xyz: String,
        /// Colour or achromatic.
        role: Role,
    },
    /// Data ([`Role::Data`]): numbers, never uplifted.
    Data {
        /// The data colour space (the config's name).
        space: String,
        /// The rule that chose it.
        rule: Rule,
        /// Why it is data, in words.
        why: String,
    },
}

impl ReadAs {
    /// Colour, achromatic or data.
    pub fn role(&self) -> Role {
        match self {
            ReadAs::Colour { role, .. } => *role,
            ReadAs::Data { .. } => Role::Data,
        }
    }
}

/// The spectral content of a file in the Fichet 2021 EXR layout.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SpectralFacts {
    /// `reflective`, `emissive` or `bispectral`, with `and emissive` or `, polarised` added.
    pub kind: String,
    /// Bands of the reflectance (else of the emission).
    pub bands: usize,
    /// Their first and last wavelengths, nm.
    pub range_nm: [f64; 2],
    /// The spacing of evenly spaced bands; `None` when the layout's list is uneven.
    pub step_nm: Option<f64>,
    /// Wavelengths of the `T.` channels.
    pub reflective_nm: Vec<f64>,
    /// Wavelengths of the `S0.` channels.
    pub emissive_nm: Vec<f64>,
    /// Wavelengths of the polarisation channels S1, S2, S3.
    pub polarised_nm: [Vec<f64>; 3],
    /// Re-radiation channels `T.λi.λo` of a bispectral file.
    pub reradiation: usize,
    /// Channels outside the layout (alpha excepted), e.g. an RGB preview beside the spectra,
    /// in the file's (alphabetical) order.
    pub other_channels: Vec<String>,
    /// The `emissiveUnits` attribute of an emissive file.
    pub emissive_units: Option<String>,
    /// How an emissive file's `S0` becomes colour, and where that comes from.
    pub emission_convention: Option<(EmissionUnits, ConventionFrom)>,
    /// The file's `specconv*` attributes (model, method, observer, illuminant, settings, …).
    pub specconv: BTreeMap<String, String>,
}

/// Describes `path` as a conversion with `options` would read it: the subimage, channels,
/// colour space (the options' `subimage`, `channels`, `colorspace`, `alpha`; `config` in
/// place of `ocio`) and the rules that choose them when the options do not.
///
/// Fails when the image cannot be opened, or a spectral EXR's attributes cannot be read;
/// a colour that cannot be converted is described ([`Inspection::colour`]).
pub fn describe(
    config: &ColourConfig,
    path: &Path,
    options: &Options,
) -> Result<Inspection, Error> {
    let reader = open_subimage(path, options.subimage.as_deref())?;
    let spectral = spectral_facts(path, &reader)?;
    let compact = crate::compact::facts(path, &reader)?;
    let info = reader.info();
    let chosen = choose_channels(info, options.channels.as_deref());
    let alpha = match &chosen {
        Ok(c) => c.alpha,
        Err(_) => info.alpha_channel,
    };
    let colour = read_as(
        config,
        &reader,
        chosen.as_ref().ok(),
        options.colorspace.as_deref(),
    );
    Ok(Inspection {
        path: path.to_path_buf(),
        format: info.format_name.clone(),
        width: info.width(),
        height: info.height(),
        channels: info
            .channels
            .iter()
            .map(|c| Channel {
                name: c.name.clone(),
                format: c.format.to_string(),
            })
            .collect(),
        alpha_channel: info.alpha_channel,
        pixel_format: info.pixel_format().to_string(),
        tile_size: info.tile_size().map(|(w, h)| [w, h]),
        levels: info.levels.iter().map(|l| [l.width, l.height]).collect(),
        data_window: Window::of(info.levels[0].data()),
        display_window: Window::of(info.levels[0].display),
        subimage: info.subimage,
        subimages: info.subimages,
        subimage_names: info.subimage_names.clone(),
        declared_colour_space: info.declared_color_space.clone(),
        straight_alpha: crate::pipeline::colour::premultiply(options.alpha, &reader, alpha),
        channel_choice: chosen
            .map(|c| ChannelChoice {
                names: c.names,
                colour: c.colour.len(),
                alpha: c.alpha,
                reason: c.reason,
            })
            .map_err(|e| e.to_string()),
        spectral,
        compact,
        colour,
    })
}

impl Inspection {
    /// `0 'beauty', 1 'albedo'`: every subimage, by index and name.
    pub fn describe_subimages(&self) -> String {
        specconv_oiio::describe_subimages(self.subimages, &self.subimage_names)
    }
}

/// What `reader`'s image is read as when `channels` carry its colour (`None`: channels not
/// chosen, so the single-channel rule is not applied), as a conversion decides it.
fn read_as(
    config: &ColourConfig,
    reader: &ImageReader,
    channels: Option<&Channels>,
    colorspace: Option<&str>,
) -> Result<ReadAs, Error> {
    let chosen = match channels {
        Some(c) => {
            let selection = crate::pipeline::input::selection(reader.info(), c.clone());
            texture_space(&config.0, reader, &selection, colorspace)
        }
        None => input_space(&config.0, reader, colorspace),
    };
    match chosen {
        Ok(InputSpace {
            name,
            rule,
            to_xyz,
            warnings,
        }) => Ok(ReadAs::Colour {
            space: name,
            rule,
            warnings,
            to_xyz: to_xyz.describe(),
            role: if channels.is_some_and(|c| c.colour.len() == 1) {
                Role::Achromatic
            } else {
                Role::Colour
            },
        }),
        Err(crate::pipeline::Error::Data(d)) => {
            let DataTexture { name, rule, .. } = &*d;
            Ok(ReadAs::Data {
                why: d.why(),
                space: name.clone(),
                rule: rule.clone(),
            })
        }
        Err(e) => Err(e.into()),
    }
}

/// The spectral facts of a file whose channels follow the layout; `None` for other images.
fn spectral_facts(path: &Path, reader: &ImageReader) -> Result<Option<SpectralFacts>, Error> {
    let info = reader.info();
    let layout = specconv_exr::ChannelKinds::of(info.channels.iter().map(|c| c.name.as_str()));
    if !layout.is_spectral() {
        return Ok(None);
    }
    let attributes = specconv_exr::read_attributes(path).map_err(Error::Attributes)?;
    let attr = |name: &str| {
        attributes
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.clone())
    };
    let reflective = !layout.reflective.is_empty();
    let emissive = !layout.stokes[0].is_empty();
    let bands = if reflective {
        &layout.reflective
    } else {
        &layout.stokes[0]
    };
    let mut kind = String::from(match (reflective, layout.reradiation.is_empty()) {
        (true, false) => "bispectral",
        (true, true) => "reflective",
        (false, _) => "emissive",
    });
    if reflective && emissive {
        kind += " and emissive";
    }
    if layout.polarised() {
        kind += ", polarised";
    }
    let (first, last) = (bands[0], bands[bands.len() - 1]);
    let step = (bands.len() > 1)
        .then(|| (last - first) / (bands.len() - 1) as f64)
        .filter(|step| {
            bands
                .iter()
                .enumerate()
                .all(|(i, w)| (w - (first + step * i as f64)).abs() <= 1e-3)
        });
    let convention = if emissive {
        let provenance = Provenance::from_attributes(&attributes).map_err(Error::Provenance)?;
        Some(provenance.emission_convention())
    } else {
        None
    };
    let [_, s1, s2, s3] = layout.stokes.clone();
    let mut other_channels = layout.other.clone();
    // In the file's (alphabetical) order, whatever order the reader lists them in.
    other_channels.sort();
    Ok(Some(SpectralFacts {
        kind,
        bands: bands.len(),
        range_nm: [first, last],
        step_nm: step,
        reflective_nm: layout.reflective.clone(),
        emissive_nm: layout.stokes[0].clone(),
        polarised_nm: [s1, s2, s3],
        reradiation: layout.reradiation.len(),
        other_channels,
        emissive_units: emissive.then(|| attr("emissiveUnits")).flatten(),
        emission_convention: convention,
        specconv: attributes
            .into_iter()
            .filter(|(k, _)| k.starts_with("specconv"))
            .collect(),
    }))
}
