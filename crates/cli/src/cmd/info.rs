//! `specconv info`: what the image reader sees in a file, and which colour space specconv
//! would read it in.

use anyhow::Result;
use serde::Serialize;
use specconv_atomic_file::shown::escaped;
use specconv_conversion::{
    ChannelReason, ColourConfig, CompactFacts, Inspection, ReadAs, SpectralFacts,
};
use specconv_convert_cmd::errors::{explain, one_line, print_error};
use specconv_convert_cmd::stdio::{serialize_path, StdoutFailed};
use specconv_convert_cmd::{checks, exit, records};
use specconv_flags::defs;
use std::path::{Path, PathBuf};

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv info albedo.tx
  specconv info --json textures/*.tx > info.jsonl
  specconv --ocio studio.ocio info --colorspace ACEScg plate.exr
";

specconv_flags::args! {
    /// Show images as specconv reads them: size, channels, pixel format, tiles, MIP levels,
    /// the colour space the file declares and the one specconv would use, and for spectral
    /// EXRs the wavelength bands.
    ///
    /// The input colour space follows the precedence of colour evidence (docs/colour.md), and
    /// `info` shows which row decided: 1 --colorspace; 2 the OCIO config's explicit file rules;
    /// 3 strong declarations in the file (ICC profile, EXR chromaticities and
    /// acesImageContainerFlag, a colour-space name a tool wrote); 4 weak ones (PNG sRGB, gAMA,
    /// cHRM); 5 the Default rule of a config given by --ocio or $OCIO; 6 linear Rec.709 (D65)
    /// for float pixels and sRGB texture for integer pixels. One channel is data unless rows 1
    /// to 3 call it colour. The route to CIE XYZ is checked too, so `info` fails, saying why,
    /// where a conversion would (a config without an interchange role).
    #[derive(Debug)]
    pub struct Args {
        files: Vec<PathBuf> = (defs::INFO_FILES),
        /// The global --ocio (see `specconv --help`).
        pub(crate) ocio: Option<String> = skip,
        colorspace: Option<String> = (defs::INFO_COLORSPACE),
        read: specconv_flags::OptionArgs<specconv_flags::Reading> = flatten,
        json: bool = (defs::INFO_JSON),
    }
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
    /// The row of the precedence of colour evidence that decided (1 to 6; null for the
    /// data-map rule), in words too, and the evidence of a lower row it overruled.
    colorspace_row: Option<u8>,
    colorspace_row_text: String,
    colorspace_overrides: Option<&'a str>,
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
    /// For a compact texture (docs/compact.md): its layout, texel channels and bands.
    compact: Option<Compact>,
}

/// What a compact texture holds (`--layout compact`), for JSON.
#[derive(Serialize)]
struct Compact {
    /// Its `specconvLayout` (`compact 2`), null where only its channels say it is compact.
    layout: Option<String>,
    /// The texel's channels it has, and those it lacks.
    texel_channels: Vec<String>,
    missing_channels: Vec<String>,
    /// The wavelengths its header decodes to, or null with the reason this version cannot.
    bands_nm: Option<Vec<f64>>,
    problem: Option<String>,
    /// Its `specconv*` attributes but the decoding text.
    specconv: std::collections::BTreeMap<String, String>,
}

impl From<&CompactFacts> for Compact {
    fn from(c: &CompactFacts) -> Compact {
        Compact {
            layout: c.layout.clone(),
            texel_channels: c.texel_channels.clone(),
            missing_channels: c.missing_channels.clone(),
            bands_nm: c.bands_nm.clone().ok(),
            problem: c.bands_nm.clone().err(),
            specconv: c.specconv.clone(),
        }
    }
}

/// A window: origin and size.
#[derive(Serialize)]
struct Rect {
    x: i32,
    y: i32,
    width: u32,
    height: u32,
}

impl From<specconv_conversion::Window> for Rect {
    fn from(w: specconv_conversion::Window) -> Rect {
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

impl From<SpectralFacts> for Spectral {
    fn from(s: SpectralFacts) -> Spectral {
        use specconv_conversion::provenance::ConventionFrom;
        Spectral {
            kind: s.kind,
            bands: s.bands,
            range_nm: s.range_nm,
            step_nm: s.step_nm,
            reflective_nm: s.reflective_nm,
            emissive_nm: s.emissive_nm,
            polarised_nm: s.polarised_nm,
            reradiation: s.reradiation,
            other_channels: s.other_channels,
            emissive_units: s.emissive_units,
            emission_convention: s.emission_convention.map(|c| match c {
                (units, ConventionFrom::Recorded) => units.to_string(),
                (_, ConventionFrom::OlderSpecconv) => "normalised (an older specconv file)".into(),
                (_, ConventionFrom::Layout) => "reference (the layout's default)".into(),
            }),
            specconv: s.specconv,
        }
    }
}

/// Shows every file; returns the exit status (1 when a file could not be shown).
pub fn run(args: Args) -> Result<i32> {
    let config = checks::config(args.ocio.as_deref())?;
    checks::input_colorspace(&config, args.colorspace.as_deref())?;
    let mut options = specconv_conversion::Options::default();
    options.colorspace.clone_from(&args.colorspace);
    options.subimage.clone_from(&args.read.options.subimage);
    options.channels.clone_from(&args.read.options.channels);
    let mut status = exit::OK;
    for (i, file) in args.files.iter().enumerate() {
        if !args.json && i > 0 {
            outln!()?;
        }
        if let Err(e) = show(&args, &config, &options, file) {
            // Standard output failing ends the command; a file failing does not.
            if StdoutFailed::in_chain(&e).is_some() {
                return Err(e);
            }
            // Every error names its file, once, first.
            let line = records::without_input(&one_line(e.as_ref()), file);
            print_error(&format!("{}: {line}", file.display()));
            status = exit::FAILED;
        }
    }
    Ok(status)
}

fn show(
    args: &Args,
    config: &ColourConfig,
    options: &specconv_conversion::Options,
    file: &Path,
) -> Result<()> {
    let d = specconv_conversion::describe(config, file, options)?;
    // Text: a spectral file's facts instead of a colour-space choice; JSON keeps one schema
    // for every file, the facts under `spectral`.
    if let (Some(s), false) = (&d.spectral, args.json) {
        return spectral_report(file, &d, s.clone().into());
    }
    // A compact texture's channels are no colour: what it holds, and how to get its bands.
    if let (Some(c), false) = (&d.compact, args.json) {
        return print_rows(compact_rows(file, &d, c));
    }
    // A file whose channels cannot be chosen alone is still described, with the reason.
    let (colour_channels, channels_rule, channels_problem) = match &d.channel_choice {
        Ok(c) => (
            Some(c.names.clone()),
            Some(match c.reason {
                ChannelReason::Option => "channels-option",
                ChannelReason::Named => "names",
                ChannelReason::InOrder => "order",
                ChannelReason::OnlyLayer => "only-rgb-layer",
            }),
            None,
        ),
        Err(problem) => (None, None, Some(problem.clone())),
    };
    let read_as = match &d.colour {
        Ok(r) => r,
        Err(e) => return Err(anyhow::anyhow!(explain(e))),
    };
    let (space_name, rule, warnings, to_xyz) = match read_as {
        ReadAs::Colour {
            space,
            rule,
            warnings,
            to_xyz,
            ..
        } => (space.clone(), rule, warnings.as_slice(), to_xyz.clone()),
        ReadAs::Data { space, rule, why } => (
            space.clone(),
            rule,
            &[][..],
            format!(
                "none: a data texture ({why}), never uplifted (convert: {})",
                records::data_remedy(rule)
            ),
        ),
    };
    let report = Report {
        file,
        format: &d.format,
        width: d.width,
        height: d.height,
        channels: d
            .channels
            .iter()
            .map(|c| Channel {
                name: &c.name,
                format: c.format.clone(),
            })
            .collect(),
        alpha_channel: d.alpha_channel,
        pixel_format: d.pixel_format.clone(),
        tile_size: d.tile_size,
        mip_levels: d.levels.clone(),
        data_window: d.data_window.into(),
        display_window: d.display_window.into(),
        subimages: d.subimages,
        subimage: d.subimage,
        subimage_names: &d.subimage_names,
        colour_channels,
        channels_rule,
        channels_problem,
        declared_color_space: d.declared_colour_space.as_deref(),
        colorspace: space_name,
        colorspace_rule: records::colorspace_rule(rule),
        colorspace_reason: records::colorspace_reason(rule),
        colorspace_row: rule.row(),
        colorspace_row_text: rule.row_text(),
        colorspace_overrides: rule.overrides(),
        colorspace_warnings: warnings.iter().map(records::warning).collect(),
        straight_alpha: d.straight_alpha,
        to_xyz,
        role: read_as.role().name(),
        spectral: d.spectral.clone().map(Spectral::from),
        compact: d.compact.as_ref().map(Compact::from),
    };
    if args.json {
        outln!("{}", serde_json::to_string(&report)?)?;
    } else {
        print_text(&report, &d)?;
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

/// One line of `info`'s text, shown through [`escaped`]: a file name, channel name, label or
/// attribute from the file cannot break it into lines that pass for others.
macro_rules! row {
    ($($t:tt)*) => {
        outln!("{}", escaped(&format!($($t)*)))
    };
}

/// The text form of `info` for an image that is not spectral.
fn print_text(r: &Report, d: &Inspection) -> Result<(), StdoutFailed> {
    row!("file:         {}", r.file.display())?;
    row!("format:       {}", r.format)?;
    row!("size:         {} x {}", r.width, r.height)?;
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
    row!("channels:     {} ({})", r.channels.len(), names.join(", "))?;
    if let Some(a) = r.alpha_channel {
        row!("alpha:        {}", r.channels[a].name)?;
    }
    row!("pixel format: {}", r.pixel_format)?;
    match r.tile_size {
        Some([w, h]) => row!("storage:      tiles of {w} x {h}")?,
        None => row!("storage:      scanlines")?,
    }
    let levels: Vec<String> = r
        .mip_levels
        .iter()
        .map(|[w, h]| format!("{w}x{h}"))
        .collect();
    row!("MIP levels:   {} ({})", levels.len(), levels.join(" "))?;
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
    row!("data window:  {}", corners(&r.data_window))?;
    row!("display:      {}", corners(&r.display_window))?;
    if r.subimages > 1 {
        row!(
            "subimages:    {} ({}); reading {} (--subimage picks another)",
            r.subimages,
            d.describe_subimages(),
            r.subimage
        )?;
    }
    match (&r.colour_channels, &r.channels_problem) {
        (Some(names), _) => row!(
            "read as:      {} (chosen by {})",
            names.join(","),
            r.channels_rule.unwrap_or("")
        )?,
        (None, Some(problem)) => row!("read as:      nothing yet: {problem}")?,
        (None, None) => {}
    }
    if let Some(label) = r.declared_color_space {
        row!("OIIO label:   {label} (oiio:ColorSpace)")?;
    }
    row!("colour space: {}", r.colorspace)?;
    row!("chosen by:    {}", r.colorspace_reason)?;
    row!("precedence:   {}", r.colorspace_row_text)?;
    for w in &r.colorspace_warnings {
        row!("warning:      {w}")?;
    }
    row!("role:         {}", r.role)?;
    row!("to XYZ:       {}", r.to_xyz)?;
    if r.straight_alpha {
        row!("alpha:        straight; colour is converted, then premultiplied")?;
    }
    Ok(())
}

fn spectral_report(file: &Path, d: &Inspection, s: Spectral) -> Result<()> {
    let r = SpectralReport {
        file: file.display().to_string(),
        format: &d.format,
        width: d.width,
        height: d.height,
        channels: d.channels.len(),
        pixel_format: d.pixel_format.clone(),
        tile_size: d.tile_size,
        mip_levels: d.levels.clone(),
        alpha: d.alpha_channel.is_some(),
        spectral: s,
    };
    print_rows(spectral_rows(&r))
}

/// Rows of `label: value`, the values aligned.
fn print_rows(rows: Vec<(&str, String)>) -> Result<()> {
    let width = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0)
        + 1;
    for (k, v) in rows {
        row!("{:width$} {v}", format!("{k}:"))?;
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

/// The lines `info` prints for a compact texture: what it holds and how to get its bands.
fn compact_rows<'a>(file: &Path, d: &Inspection, c: &'a CompactFacts) -> Vec<(&'a str, String)> {
    let bands = match &c.bands_nm {
        Ok(wl) if wl.len() > 1 => format!(
            "{}, {} to {} nm, every {} nm, decoded from the model in its header",
            wl.len(),
            nm(wl[0]),
            nm(wl[wl.len() - 1]),
            nm(wl[1] - wl[0])
        ),
        Ok(wl) => format!("{} band, decoded from the model in its header", wl.len()),
        Err(why) => format!("not decodable by this version: {why}"),
    };
    let mut texel = format!(
        "{} ({}; colour XYZ and the projection's three dual unknowns)",
        c.texel_channels.join(", "),
        d.pixel_format
    );
    if !c.missing_channels.is_empty() {
        texel += &format!("; missing {}", c.missing_channels.join(", "));
    }
    if d.alpha_channel.is_some() {
        texel += "; alpha A";
    }
    [
        ("file", file.display().to_string()),
        (
            "format",
            format!("{} (compact layout, docs/compact.md)", d.format),
        ),
        ("size", format!("{} x {}", d.width, d.height)),
        (
            "storage",
            match d.tile_size {
                Some([w, h]) => format!("tiles of {w} x {h}"),
                None => "scanlines".into(),
            },
        ),
        ("MIP levels", d.levels.len().to_string()),
        (
            "layout",
            c.layout
                .clone()
                .unwrap_or_else(|| "compact texel channels, no specconvLayout attribute".into()),
        ),
        ("bands", bands),
        ("texel", texel),
        (
            "spectral file",
            format!(
                "specconv expand {} OUTPUT.exr writes its bands (to-rgb and preview read that)",
                file.display()
            ),
        ),
    ]
    .into_iter()
    .chain(c.specconv.iter().map(|(k, v)| (k.as_str(), v.clone())))
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
