//! `specconv info`: what the image reader sees in a file, and which colour space specconv
//! would read it in.

use crate::stdio::{serialize_path, StdoutFailed};
use crate::{checks, exit, one_line, print_error};
use anyhow::Result;
use serde::Serialize;
use specconv_conversion::images::{choose_channels, open_subimage, ChannelReason};
use specconv_conversion::images::{ImageReader, ReadAs, Window};
use specconv_conversion::ocio::Config;
use std::path::{Path, PathBuf};

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv info albedo.tx
  specconv info --json textures/*.tx > info.jsonl
  specconv --ocio studio.ocio info --colorspace ACEScg plate.exr
";

/// Show images as specconv reads them: size, channels, pixel format, tiles, MIP levels,
/// the colour space the file declares and the one specconv would use, and for spectral
/// EXRs the wavelength bands.
///
/// The input colour space follows the rule of the conversion (docs/colour.md): --colorspace,
/// else what the file declares (ICC profile, EXR chromaticities and acesImageContainerFlag,
/// PNG sRGB/cHRM/gAMA, a colour-space name a tool wrote), else the OCIO config's file rules,
/// else linear Rec.709 (D65) for float pixels and sRGB texture for integer pixels. The route
/// to CIE XYZ is checked too, so `info` fails, saying why, where a conversion would (a data
/// colour space such as Raw, a config without an interchange role).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Image files, in any format OpenImageIO reads (EXR, TIFF/.tx, PNG, JPEG, HDR, ...). A
    /// file that cannot be read is reported and the others are still shown (exit status 1).
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// The global --ocio (see `specconv --help`).
    #[arg(skip)]
    pub(crate) ocio: Option<String>,
    /// Colour space to read the file in, overriding its declaration.
    #[arg(long, visible_alias = "iscolorspace", value_name = "NAME")]
    colorspace: Option<String>,
    #[command(flatten)]
    read: super::convert::ReadArgs,
    /// Print one JSON object per file, one per line, instead of text (docs/json.md).
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct Report<'a> {
    /// Written losslessly, bytes outside UTF-8 as `\udcXX` (docs/json.md).
    #[serde(serialize_with = "serialize_path")]
    file: &'a Path,
    format: &'a str,
    width: u32,
    height: u32,
    channels: Vec<Channel<'a>>,
    alpha_channel: Option<usize>,
    pixel_format: String,
    tile_size: Option<[u32; 2]>,
    mip_levels: Vec<[u32; 2]>,
    /// Where the pixels sit (level 0; OpenEXR's MIP levels share the data window's origin).
    data_window: Rect,
    display_window: Rect,
    subimages: u32,
    /// The subimage described, and every subimage's name ("" when unnamed).
    subimage: u32,
    subimage_names: &'a [String],
    /// The channels a conversion reads as colour (then alpha), and why (`channels-option`,
    /// `names`, `order`, `only-rgb-layer`); or why none can be chosen without --channels.
    colour_channels: Option<Vec<String>>,
    channels_rule: Option<&'static str>,
    channels_problem: Option<String>,
    declared_color_space: Option<&'a str>,
    /// The colour space specconv reads the file in (the config's name), the rule that chose
    /// it (`colorspace-option`, `declared`, `file-rule`, `default`) and the choice in words.
    colorspace: String,
    colorspace_rule: &'static str,
    colorspace_reason: String,
    /// Declarations of the file that were ignored or disagree.
    colorspace_warnings: Vec<String>,
    /// Straight (unassociated) colour, premultiplied once converted.
    straight_alpha: bool,
    /// How the colour space reaches CIE XYZ (D65).
    to_xyz: String,
    /// `colour`, `achromatic` (one channel its colour space calls colour) or `data` (never
    /// uplifted).
    role: &'static str,
    spectral: Option<Spectral>,
}

/// A window: origin and size.
#[derive(Serialize)]
struct Rect {
    x: i32,
    y: i32,
    width: u32,
    height: u32,
}

impl From<Window> for Rect {
    fn from(w: Window) -> Rect {
        Rect {
            x: w.x,
            y: w.y,
            width: w.width,
            height: w.height,
        }
    }
}

#[derive(Serialize)]
struct Channel<'a> {
    name: &'a str,
    format: String,
}

/// The spectral content of a file in the Fichet 2021 EXR layout.
#[derive(Serialize)]
struct Spectral {
    /// "reflective", "emissive", "bispectral", with "polarised" or "and emissive" added.
    kind: String,
    bands: usize,
    range_nm: [f64; 2],
    /// The spacing of evenly spaced bands; null when the layout's list is uneven.
    step_nm: Option<f64>,
    reflective_nm: Vec<f64>,
    emissive_nm: Vec<f64>,
    /// Wavelengths of the polarisation channels S1, S2, S3.
    polarised_nm: [Vec<f64>; 3],
    /// Re-radiation channels T.λi.λo of a bispectral file.
    reradiation: usize,
    /// Channels outside the layout (A excepted), e.g. an RGB preview beside the spectra.
    other_channels: Vec<String>,
    /// The `emissiveUnits` attribute of emissive files.
    emissive_units: Option<String>,
    /// How S0 becomes colour: reference, normalised or photometric (docs/spectral-exr.md).
    emission_convention: Option<String>,
    /// The file's `specconv*` attributes (model, method, observer, illuminant, settings, …).
    specconv: std::collections::BTreeMap<String, String>,
}

/// The spectral facts of a file whose channels follow the layout; `None` for other images.
fn spectral_facts(file: &std::path::Path, reader: &ImageReader) -> Result<Option<Spectral>> {
    let info = reader.info();
    let layout = specconv_exr::Layout::of(info.channels.iter().map(|c| c.name.as_str()));
    if !layout.is_spectral() {
        return Ok(None);
    }
    let attributes = specconv_exr::read_attributes(file)?;
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
        use specconv_conversion::provenance::ConventionFrom;
        let provenance = specconv_conversion::Provenance::from_attributes(&attributes)?;
        Some(match provenance.emission_convention() {
            (units, ConventionFrom::Recorded) => units.to_string(),
            (_, ConventionFrom::OlderSpecconv) => "normalised (an older specconv file)".into(),
            (_, ConventionFrom::Layout) => "reference (the layout's default)".into(),
        })
    } else {
        None
    };
    let [_, s1, s2, s3] = layout.stokes.clone();
    Ok(Some(Spectral {
        kind,
        bands: bands.len(),
        range_nm: [first, last],
        step_nm: step,
        reflective_nm: layout.reflective.clone(),
        emissive_nm: layout.stokes[0].clone(),
        polarised_nm: [s1, s2, s3],
        reradiation: layout.reradiation.len(),
        // In the file's (alphabetical) order, whatever order the reader lists them in.
        other_channels: {
            let mut o = layout.other.clone();
            o.sort();
            o
        },
        emissive_units: emissive.then(|| attr("emissiveUnits")).flatten(),
        emission_convention: convention,
        specconv: attributes
            .into_iter()
            .filter(|(k, _)| k.starts_with("specconv"))
            .collect(),
    }))
}

/// Shows every file; returns the exit status (1 when a file could not be shown).
pub fn run(args: Args) -> Result<i32> {
    let config = checks::config(args.ocio.as_deref())?;
    checks::input_colorspace(&config, args.colorspace.as_deref())?;
    let mut status = exit::OK;
    for (i, file) in args.files.iter().enumerate() {
        if !args.json && i > 0 {
            outln!()?;
        }
        if let Err(e) = show(&args, &config, file) {
            // Standard output failing ends the command; a file failing does not.
            if StdoutFailed::in_chain(&e).is_some() {
                return Err(e);
            }
            // Every error names its file, once, first.
            let line = crate::records::without_input(&one_line(e.as_ref()), file);
            print_error(&format!("{}: {line}", file.display()));
            status = exit::FAILED;
        }
    }
    Ok(status)
}

fn show(args: &Args, config: &Config, file: &Path) -> Result<()> {
    let reader = open_subimage(file, args.read.subimage.as_deref())?;
    // Text: a spectral file's facts instead of a colour-space choice; JSON keeps one schema
    // for every file, the facts under `spectral`.
    let spectral = spectral_facts(file, &reader)?;
    let spectral = match spectral {
        Some(s) if !args.json => return spectral_report(file, &reader, s),
        other => other,
    };
    let info = reader.info();
    // A file whose channels cannot be chosen alone is still described, with the reason.
    let chosen = choose_channels(info, args.read.channels.as_deref());
    let (colour_channels, channels_rule, channels_problem, alpha_channel) = match &chosen {
        Ok(c) => (
            Some(c.names.clone()),
            Some(match c.reason {
                ChannelReason::Option => "channels-option",
                ChannelReason::Named => "names",
                ChannelReason::InOrder => "order",
                ChannelReason::OnlyLayer => "only-rgb-layer",
            }),
            None,
            c.alpha,
        ),
        Err(e) => (None, None, Some(e.to_string()), info.alpha_channel),
    };
    let read_as = specconv_conversion::images::read_as(
        config,
        &reader,
        chosen.as_ref().ok(),
        args.colorspace.as_deref(),
    )
    .map_err(|e| anyhow::anyhow!(crate::explain(&e.into())))?;
    let (space_name, rule, warnings, to_xyz, role) = match read_as {
        ReadAs::Colour(space) => {
            let one = chosen.as_ref().is_ok_and(|c| c.colour.len() == 1);
            (
                space.name,
                space.rule,
                space.warnings,
                space.to_xyz.describe(),
                if one { "achromatic" } else { "colour" },
            )
        }
        ReadAs::Data(d) => (
            d.name.clone(),
            d.rule.clone(),
            Vec::new(),
            format!(
                "none: a data texture ({}), never uplifted (convert --data copy writes it through)",
                d.why()
            ),
            "data",
        ),
    };
    let straight_alpha = specconv_conversion::Alpha::Auto.premultiply(&reader, alpha_channel);
    let report = Report {
        file,
        format: &info.format_name,
        width: info.width(),
        height: info.height(),
        channels: info
            .channels
            .iter()
            .map(|c| Channel {
                name: &c.name,
                format: c.format.to_string(),
            })
            .collect(),
        alpha_channel: info.alpha_channel,
        pixel_format: info.pixel_format().to_string(),
        tile_size: info.tile_size().map(|(w, h)| [w, h]),
        mip_levels: info.levels.iter().map(|l| [l.width, l.height]).collect(),
        data_window: info.levels[0].data().into(),
        display_window: info.levels[0].display.into(),
        subimages: info.subimages,
        subimage: info.subimage,
        subimage_names: &info.subimage_names,
        colour_channels,
        channels_rule,
        channels_problem,
        declared_color_space: info.declared_color_space.as_deref(),
        colorspace: space_name,
        colorspace_rule: crate::records::colorspace_rule(&rule),
        colorspace_reason: crate::records::colorspace_reason(&rule),
        colorspace_warnings: warnings.iter().map(crate::records::warning).collect(),
        straight_alpha,
        to_xyz,
        role,
        spectral,
    };
    if args.json {
        outln!("{}", serde_json::to_string(&report)?)?;
    } else {
        print_text(&report, info)?;
    }
    Ok(())
}
/// What a spectral EXR holds, instead of an input colour space (a spectral file is not read
/// through a colour space).
struct SpectralReport<'a> {
    file: String,
    format: &'a str,
    width: u32,
    height: u32,
    channels: usize,
    pixel_format: String,
    tile_size: Option<[u32; 2]>,
    mip_levels: Vec<[u32; 2]>,
    alpha: bool,
    spectral: Spectral,
}

/// The text form of `info` for an image that is not spectral.
fn print_text(
    r: &Report,
    info: &specconv_conversion::images::ImageInfo,
) -> Result<(), StdoutFailed> {
    outln!("file:         {}", r.file.display())?;
    outln!("format:       {}", r.format)?;
    outln!("size:         {} x {}", r.width, r.height)?;
    let names: Vec<String> = r
        .channels
        .iter()
        .map(|c| {
            if c.format == r.pixel_format {
                c.name.to_owned()
            } else {
                format!("{} ({})", c.name, c.format)
            }
        })
        .collect();
    outln!("channels:     {} ({})", r.channels.len(), names.join(", "))?;
    if let Some(a) = r.alpha_channel {
        outln!("alpha:        {}", r.channels[a].name)?;
    }
    outln!("pixel format: {}", r.pixel_format)?;
    match r.tile_size {
        Some([w, h]) => outln!("storage:      tiles of {w} x {h}")?,
        None => outln!("storage:      scanlines")?,
    }
    let levels: Vec<String> = r
        .mip_levels
        .iter()
        .map(|[w, h]| format!("{w}x{h}"))
        .collect();
    outln!("MIP levels:   {} ({})", levels.len(), levels.join(" "))?;
    // As exrheader prints them: first and last pixel, inclusive.
    let corners = |w: &Rect| {
        format!(
            "({}, {}) - ({}, {})",
            w.x,
            w.y,
            i64::from(w.x) + i64::from(w.width) - 1,
            i64::from(w.y) + i64::from(w.height) - 1
        )
    };
    outln!("data window:  {}", corners(&r.data_window))?;
    outln!("display:      {}", corners(&r.display_window))?;
    if r.subimages > 1 {
        outln!(
            "subimages:    {} ({}); reading {} (--subimage picks another)",
            r.subimages,
            info.describe_subimages(),
            r.subimage
        )?;
    }
    match (&r.colour_channels, &r.channels_problem) {
        (Some(names), _) => outln!(
            "read as:      {} (chosen by {})",
            names.join(","),
            r.channels_rule.unwrap_or("")
        )?,
        (None, Some(problem)) => outln!("read as:      nothing yet: {problem}")?,
        (None, None) => {}
    }
    if let Some(label) = r.declared_color_space {
        outln!("OIIO label:   {label} (oiio:ColorSpace)")?;
    }
    outln!("colour space: {}", r.colorspace)?;
    outln!("chosen by:    {}", r.colorspace_reason)?;
    for w in &r.colorspace_warnings {
        outln!("warning:      {w}")?;
    }
    outln!("role:         {}", r.role)?;
    outln!("to XYZ:       {}", r.to_xyz)?;
    if r.straight_alpha {
        outln!("alpha:        straight; colour is converted, then premultiplied")?;
    }
    Ok(())
}

fn spectral_report(file: &Path, reader: &ImageReader, s: Spectral) -> Result<()> {
    let info = reader.info();
    let r = SpectralReport {
        file: file.display().to_string(),
        format: &info.format_name,
        width: info.width(),
        height: info.height(),
        channels: info.channels.len(),
        pixel_format: info.pixel_format().to_string(),
        tile_size: info.tile_size().map(|(w, h)| [w, h]),
        mip_levels: info.levels.iter().map(|l| [l.width, l.height]).collect(),
        alpha: info.alpha_channel.is_some(),
        spectral: s,
    };
    let rows = spectral_rows(&r);
    let width = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0)
        + 1;
    for (k, v) in rows {
        outln!("{:width$} {v}", format!("{k}:"))?;
    }
    Ok(())
}

/// The lines `info` prints for a spectral file, as (label, value).
fn spectral_rows<'a>(r: &'a SpectralReport) -> Vec<(&'a str, String)> {
    let s = &r.spectral;
    [
        ("file", r.file.clone()),
        (
            "format",
            format!("{} (spectral, Fichet 2021 layout)", r.format),
        ),
        ("size", format!("{} x {}", r.width, r.height)),
        (
            "channels",
            format!(
                "{} ({}{})",
                r.channels,
                r.pixel_format,
                if r.alpha { ", with alpha A" } else { "" }
            ),
        ),
        (
            "storage",
            match r.tile_size {
                Some([w, h]) => format!("tiles of {w} x {h}"),
                None => "scanlines".into(),
            },
        ),
        ("MIP levels", r.mip_levels.len().to_string()),
        ("kind", s.kind.clone()),
        ("bands", describe_bands(s)),
    ]
    .into_iter()
    .chain((s.reradiation > 0).then(|| {
        (
            "re-radiation",
            format!("{} channels T.λi.λo", s.reradiation),
        )
    }))
    .chain(
        s.polarised_nm
            .iter()
            .zip(["S1", "S2", "S3"])
            .filter(|(b, _)| !b.is_empty())
            .map(|(b, k)| ("polarised", format!("{k}: {} bands", b.len()))),
    )
    .chain(
        (!s.reflective_nm.is_empty() && !s.emissive_nm.is_empty()).then(|| {
            (
                "emissive",
                format!("also S0: {} bands", s.emissive_nm.len()),
            )
        }),
    )
    .chain(s.emissive_units.clone().map(|u| ("emission in", u)))
    .chain(s.emission_convention.clone().map(|c| ("emission units", c)))
    .chain((!s.other_channels.is_empty()).then(|| {
        (
            "not spectral",
            format!("{} (not used for colour)", s.other_channels.join(", ")),
        )
    }))
    .chain(s.specconv.iter().map(|(k, v)| (k.as_str(), v.clone())))
    .collect()
}

/// "36, 380 to 730 nm, every 10 nm", or the list of an uneven layout.
fn describe_bands(s: &Spectral) -> String {
    let spacing = match s.step_nm {
        Some(step) => format!("every {} nm", nm(step)),
        None => {
            let list = if s.reflective_nm.is_empty() {
                &s.emissive_nm
            } else {
                &s.reflective_nm
            };
            let list: Vec<String> = list.iter().map(|&w| nm(w)).collect();
            format!("uneven: {}", list.join(", "))
        }
    };
    format!(
        "{}, {} to {} nm, {spacing}",
        s.bands,
        nm(s.range_nm[0]),
        nm(s.range_nm[1])
    )
}

/// A wavelength to at most six decimals, without trailing zeros (`450.5`, not `450.500000`).
fn nm(w: f64) -> String {
    let s = format!("{w:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
