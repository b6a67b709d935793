//! `specconv info`: what the image reader sees in a file, and which colour space specconv
//! would read it in.

use crate::{checks, exit, one_line, print_error};
use anyhow::Result;
use serde::Serialize;
use specconv_ocio::Config;
use specconv_oiio::{ImageReader, Window};
use specconv_pipeline::input::{choose_channels, open_subimage, ChannelReason};
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
    file: String,
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

/// Wavelengths (nm) of the spectral channels, by the Fichet 2021 EXR layout.
#[derive(Serialize)]
struct Spectral {
    reflective_nm: Vec<f64>,
    emissive_nm: Vec<f64>,
    /// The `emissiveUnits` attribute of emissive files.
    emissive_units: Option<String>,
}

/// Parses `T.<wl>nm` / `S0.<wl>nm` channel names (comma decimal separator) into
/// wavelengths in nm. Other units of the layout are not written by specconv.
fn spectral_bands(reader: &ImageReader) -> Result<Option<Spectral>> {
    let info = reader.info();
    let parse = |prefix: &str| -> Vec<f64> {
        let mut v: Vec<f64> = info
            .channels
            .iter()
            .filter_map(|c| c.name.strip_prefix(prefix)?.strip_suffix("nm"))
            .filter_map(|wl| wl.replace(',', ".").parse().ok())
            .collect();
        // EXR sorts channels by name, so order by wavelength here.
        v.sort_by(f64::total_cmp);
        v
    };
    let emissive_nm = parse("S0.");
    let emissive_units = if emissive_nm.is_empty() {
        None
    } else {
        reader.string_attribute("emissiveUnits")?
    };
    let s = Spectral {
        reflective_nm: parse("T."),
        emissive_nm,
        emissive_units,
    };
    Ok((!s.reflective_nm.is_empty() || !s.emissive_nm.is_empty()).then_some(s))
}

/// Shows every file; returns the exit status (1 when a file could not be shown).
pub fn run(args: Args) -> Result<i32> {
    let config = checks::config(args.ocio.as_deref())?;
    checks::input_colorspace(&config, args.colorspace.as_deref())?;
    let mut status = exit::OK;
    for (i, file) in args.files.iter().enumerate() {
        if !args.json && i > 0 {
            println!();
        }
        if let Err(e) = show(&args, &config, file) {
            print_error(&one_line(&e));
            status = exit::FAILED;
        }
    }
    Ok(status)
}

fn show(args: &Args, config: &Config, file: &Path) -> Result<()> {
    let reader = open_subimage(file, args.read.subimage.as_deref())?;
    let info = reader.info();
    // A file whose channels cannot be chosen alone is still described, with the reason.
    let (colour_channels, channels_rule, channels_problem, alpha_channel) =
        match choose_channels(info, args.read.channels.as_deref()) {
            Ok(c) => (
                Some(c.names),
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
    let space = specconv_pipeline::input_space(config, &reader, args.colorspace.as_deref())?;
    let straight_alpha = specconv_pipeline::Alpha::Auto.premultiply(&reader, alpha_channel);
    let report = Report {
        file: file.display().to_string(),
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
        colorspace: space.name.clone(),
        colorspace_rule: crate::records::colorspace_rule(&space.rule),
        colorspace_reason: space.rule.to_string(),
        colorspace_warnings: space.warnings.clone(),
        straight_alpha,
        to_xyz: space.to_xyz.describe(),
        spectral: spectral_bands(&reader)?,
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    let r = &report;
    println!("file:         {}", r.file);
    println!("format:       {}", r.format);
    println!("size:         {} x {}", r.width, r.height);
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
    println!("channels:     {} ({})", r.channels.len(), names.join(", "));
    if let Some(a) = r.alpha_channel {
        println!("alpha:        {}", r.channels[a].name);
    }
    println!("pixel format: {}", r.pixel_format);
    match r.tile_size {
        Some([w, h]) => println!("storage:      tiles of {w} x {h}"),
        None => println!("storage:      scanlines"),
    }
    let levels: Vec<String> = r
        .mip_levels
        .iter()
        .map(|[w, h]| format!("{w}x{h}"))
        .collect();
    println!("MIP levels:   {} ({})", levels.len(), levels.join(" "));
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
    println!("data window:  {}", corners(&r.data_window));
    println!("display:      {}", corners(&r.display_window));
    if r.subimages > 1 {
        println!(
            "subimages:    {} ({}); reading {} (--subimage picks another)",
            r.subimages,
            info.describe_subimages(),
            r.subimage
        );
    }
    match (&r.colour_channels, &r.channels_problem) {
        (Some(names), _) => println!(
            "read as:      {} (chosen by {})",
            names.join(","),
            r.channels_rule.unwrap_or("")
        ),
        (None, Some(problem)) => println!("read as:      nothing yet: {problem}"),
        (None, None) => {}
    }
    if let Some(label) = r.declared_color_space {
        println!("OIIO label:   {label} (oiio:ColorSpace)");
    }
    println!("colour space: {}", r.colorspace);
    println!("chosen by:    {}", r.colorspace_reason);
    for w in &r.colorspace_warnings {
        println!("warning:      {w}");
    }
    println!("to XYZ:       {}", r.to_xyz);
    if r.straight_alpha {
        println!("alpha:        straight; colour is converted, then premultiplied");
    }
    if let Some(s) = &r.spectral {
        for (kind, bands) in [
            ("reflective", &s.reflective_nm),
            ("emissive", &s.emissive_nm),
        ] {
            if let (Some(first), Some(last)) = (bands.first(), bands.last()) {
                println!("{kind}:   {} bands, {first} to {last} nm", bands.len());
            }
        }
        if let Some(units) = &s.emissive_units {
            println!("emission in:  {units}");
        }
    }
    Ok(())
}
