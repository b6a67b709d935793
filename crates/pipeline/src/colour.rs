//! The input's colour space, by one rule, and the way its pixels reach CIE XYZ (D65).
//!
//! **The precedence of colour evidence** ([`specconv_description::PRECEDENCE`], docs/colour.md), first that
//! applies:
//! 1. `--colorspace`;
//! 2. the OCIO config's explicit `file_rules` (a rule other than the Default rule matches the
//!    path): a studio's config says what its files are, whatever writers added to them;
//! 3. strong declarations in the file, written on purpose: an embedded ICC profile; OpenEXR
//!    `colorInteropID` (a Color Interop Forum ID, [`crate::interop`], or a name of the
//!    config), `chromaticities` (and `acesImageContainerFlag`, which means AP0 with the ACES
//!    white); a colour-space name a tool wrote in `oiio:ColorSpace` (not OpenImageIO's own labels
//!    "Linear" and "sRGB", which it gives every OpenEXR file and most integer files whatever
//!    they hold);
//! 4. weak declarations: PNG `sRGB`, then `cHRM`/`gAMA`, which OpenImageIO and most writers
//!    add to every PNG, normal maps included (`sRGB` with the `gAMA` 45455 and Rec.709
//!    `cHRM` the PNG specification writes beside it is one declaration, not two);
//! 5. the Default rule of a config the user gave (`--ocio FILE`, `$OCIO`): for float pixels
//!    a colour space, for any pixels a data space. The built-in configs' Default rule
//!    (ACES2065-1) is no one's policy for a file, and integer pixels are display-encoded
//!    textures whatever a Default rule (made for scene-linear EXRs) says;
//! 6. the format's default: float pixels are linear Rec.709 with a D65 white (the OpenEXR
//!    specification's meaning of a file without `chromaticities`), integer pixels sRGB texture.
//!
//! Where a higher row overrules evidence of a lower one that converts otherwise, the rule
//! ([`Rule::overrides`]) names it, once; declarations of one row that disagree give a warning
//! naming both and the one used.
//!
//! **Data maps** ([`texture_space`]): a data colour space (OCIO `isdata`: `Raw`) from any row
//! wins over weak declarations (the config's Default rule comes before them when it names a
//! data space), and one channel (one- and two-channel images: grey, grey and alpha) is data
//! unless rows 1 to 3 call it colour ([`Rule::OneChannel`], the data-map rule). Data is never
//! uplifted ([`DataTexture`]).
//!
//! **The routes to XYZ** ([`ToXyz`]): an OCIO processor, when the config has the colour space
//! (a declaration by primaries, white and transfer is matched to the config's colour space
//! that converts the same way); else the exact 3×3 matrix of the primaries and white with
//! linear Bradford adaptation to D65 ([`specconv_colour::rgb::RgbSpace::to_xyz_adapted`]),
//! after the declared transfer function; or, for an ICC profile, Little CMS to its D50 PCS
//! (relative colorimetric) then Bradford to D65.

use crate::choices::Alpha;
pub use crate::data_texture::{DataTexture, ONE_CHANNEL};
use crate::error::{Error, Result};
pub use crate::header::Header;
use crate::report::says;
pub use crate::report::{Rule, Strength, Warning};
use crate::transfer::Decode;
use crate::{input, interop, png};
use specconv_colour::rgb::{self, RgbSpace};
use specconv_icc::ToPcs;
use specconv_ocio::{Config, Processor};
use specconv_oiio::ImageReader;
use specconv_spectral::compact::Compact;
use std::fmt;
use std::path::Path;

/// D65 as OCIO's CIE-XYZ-D65 has it: the chromaticity (0.3127, 0.3290) of ITU-R BT.709, Y = 1.
const D65: [f64; 3] = [0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290];

/// OpenEXR's default chromaticities (ITU-R BT.709 primaries, D65 white).
const REC709: RgbSpace = rgb::SRGB;

/// Whether colour must be multiplied by alpha after conversion, as `how` says, given the
/// alpha channel selected (none: nothing to multiply by).
pub fn premultiply(how: Alpha, reader: &ImageReader, alpha: Option<usize>) -> bool {
    let info = reader.info();
    alpha.is_some()
        && match how {
            Alpha::Auto => info.unassociated_alpha,
            Alpha::Straight => true,
            Alpha::Premultiplied => false,
        }
}

/// How pixels reach CIE XYZ (D65, white Y = 1): the one interface the pipeline converts with.
pub enum ToXyz {
    /// Through the OCIO config.
    Ocio(Processor),
    /// The declared transfer function, then a 3×3 matrix to XYZ D65.
    Matrix {
        /// The transfer function.
        decode: Decode,
        /// Linear RGB to XYZ D65.
        m: [[f64; 3]; 3],
    },
    /// Little CMS to the ICC PCS (D50), then Bradford to D65.
    Icc {
        /// The profile's transform to its PCS.
        pcs: ToPcs,
        /// D50 to D65 (Bradford).
        adapt: [[f64; 3]; 3],
    },
}

impl fmt::Debug for ToXyz {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe())
    }
}

fn mul(m: &[[f64; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    specconv_colour::mat3::mul_vec(m, v.map(f64::from)).map(|x| x as f32)
}

impl ToXyz {
    /// Converts interleaved RGB triples to XYZ in place.
    pub fn apply_rgb(&self, rgb: &mut [f32]) -> Result<()> {
        match self {
            ToXyz::Ocio(p) => p.apply_rgb(rgb)?,
            ToXyz::Matrix { decode, m } => {
                for px in rgb.chunks_exact_mut(3) {
                    let lin = [px[0], px[1], px[2]].map(|v| decode.apply(v));
                    px.copy_from_slice(&mul(m, lin));
                }
            }
            ToXyz::Icc { pcs, adapt } => {
                pcs.apply_rgb(rgb);
                for px in rgb.chunks_exact_mut(3) {
                    px.copy_from_slice(&mul(adapt, [px[0], px[1], px[2]]));
                }
            }
        }
        Ok(())
    }

    /// Converts interleaved RGB triples in place to `compact`'s working space (linear RGB of
    /// matrix m to XYZ). Where this route converts as the sRGB curve or no curve followed by m
    /// does (within `same_conversion`'s 1e-4: OpenColorIO's sRGB
    /// texture, an sRGB ICC profile, a linear Rec.709 OpenEXR), the pixels are that space's
    /// already, and they are decoded by the curve alone, in double: the half a compact file
    /// stores is then the one nearest the input's own colour, not one moved to a neighbour by
    /// the roundings of a trip through XYZ (Little CMS's fixed-point profile, OCIO's float
    /// ops, the matrix back). Else through XYZ.
    pub fn apply_to_working(&self, compact: &Compact, rgb: &mut [f32]) -> Result<()> {
        let m = compact.rgb_to_xyz();
        let straight = [Decode::Linear, Decode::Srgb]
            .into_iter()
            .find(|&decode| same_conversion(self, &ToXyz::Matrix { decode, m }));
        if let Some(decode) = straight {
            rgb.iter_mut().for_each(|v| *v = decode.apply(*v));
            return Ok(());
        }
        self.apply_rgb(rgb)?;
        compact.xyz_to_rgb(rgb);
        Ok(())
    }

    /// One triple.
    pub fn convert(&self, rgb: [f32; 3]) -> Result<[f32; 3]> {
        let mut px = rgb;
        self.apply_rgb(&mut px)?;
        Ok(px)
    }

    /// How the route reaches XYZ, for `info`.
    pub fn describe(&self) -> String {
        match self {
            ToXyz::Ocio(p) => match p.route() {
                specconv_ocio::XyzRoute::CieXyzD65Interchange(cs) => {
                    format!("OCIO, through cie_xyz_d65_interchange ({cs})")
                }
                specconv_ocio::XyzRoute::AcesInterchange(cs) => format!(
                    "OCIO, through aces_interchange ({cs}) and UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD"
                ),
                specconv_ocio::XyzRoute::Direct(cs) => format!("OCIO, directly to {cs}"),
            },
            ToXyz::Matrix { decode, .. } => format!(
                "{}the 3×3 matrix of the declared primaries and white, Bradford-adapted to D65",
                match decode {
                    Decode::Linear => String::new(),
                    Decode::Power(e) => format!("power {e:.5}, then "),
                    Decode::Srgb => "the sRGB transfer function, then ".into(),
                }
            ),
            ToXyz::Icc { pcs, .. } => format!(
                "Little CMS, ICC profile '{}' to its D50 PCS (relative colorimetric), then Bradford to D65",
                pcs.name()
            ),
        }
    }
}

/// The input colour space, the rule that chose it, and how its pixels reach XYZ.
#[derive(Debug)]
pub struct InputSpace {
    /// The config's name for it, or a description where the config has none.
    pub name: String,
    /// The rule that chose it.
    pub rule: Rule,
    /// How its pixels reach XYZ.
    pub to_xyz: ToXyz,
    /// Declarations that were ignored or disagree.
    pub warnings: Vec<Warning>,
}

/// What a file may declare about its colour.
enum Declared {
    /// A colour-space name, to look up in the config.
    Named(String),
    /// Primaries and white, with a transfer function.
    Space {
        space: RgbSpace,
        decode: Decode,
        label: &'static str,
    },
    Icc(Vec<u8>),
    /// CIE XYZ with the D65 white: the connection space.
    XyzD65,
}

/// One declaration of the file: what declared it, how much that says, and what it declares.
type Declaration = (String, Strength, Declared);

/// The file's declarations, strong ones first (most authoritative first within each).
fn declarations(h: &Header) -> Vec<Declaration> {
    let mut out = Vec::new();
    if let Some(bytes) = h.icc.clone().filter(|b| !b.is_empty()) {
        out.push((
            "ICC profile".to_owned(),
            Strength::Strong,
            Declared::Icc(bytes),
        ));
    }
    // OpenImageIO 3's and OpenEXR's colour-space name; it supplants the chromaticities.
    if let Some(id) = h.interop_id.clone().filter(|id| !id.trim().is_empty()) {
        out.push((
            format!("EXR colorInteropID '{id}'"),
            Strength::Strong,
            Declared::Named(id),
        ));
    }
    if let Some([rx, ry, gx, gy, bx, by, wx, wy]) = h.chromaticities {
        out.push((
            "EXR chromaticities".into(),
            Strength::Strong,
            Declared::Space {
                space: RgbSpace {
                    name: "chromaticities",
                    primaries: [[rx, ry], [gx, gy], [bx, by]],
                    white: [wx, wy],
                },
                decode: Decode::Linear,
                label: "chromaticities",
            },
        ));
    }
    if h.aces_container == Some(1.0) {
        out.push((
            "EXR acesImageContainerFlag".into(),
            Strength::Strong,
            Declared::Space {
                space: rgb::ACES2065_1,
                decode: Decode::Linear,
                label: "ACES container (AP0)",
            },
        ));
    }
    if let Some(name) = h.declared_name() {
        out.push((
            format!("oiio:ColorSpace '{name}'"),
            Strength::Strong,
            Declared::Named(name.to_owned()),
        ));
    }
    if let Some(p) = &h.png {
        out.extend(png_declarations(p));
    }
    out
}

/// A PNG's colour chunks as weak declarations: `sRGB`, then `cHRM`/`gAMA` unless they are
/// the companions the specification writes beside `sRGB` (then one declaration, no warning).
fn png_declarations(p: &png::PngColour) -> Vec<Declaration> {
    let mut out = Vec::new();
    let srgb = Declared::Space {
        space: REC709,
        decode: Decode::Srgb,
        label: "sRGB",
    };
    if p.companions_of_srgb() && (p.gamma.is_some() || p.chrm.is_some()) {
        let what = "PNG sRGB chunk with its gAMA and cHRM";
        return vec![(what.into(), Strength::Weak, srgb)];
    }
    if p.srgb {
        out.push(("PNG sRGB chunk".into(), Strength::Weak, srgb));
    }
    if p.chrm.is_some() || p.gamma.is_some() {
        let space = p
            .chrm
            .map_or(REC709, |[wx, wy, rx, ry, gx, gy, bx, by]| RgbSpace {
                name: "cHRM",
                primaries: [[rx, ry], [gx, gy], [bx, by]],
                white: [wx, wy],
            });
        let what = match (p.chrm.is_some(), p.gamma) {
            (true, Some(g)) => format!("PNG cHRM and gAMA {g}"),
            (true, None) => "PNG cHRM".into(),
            (false, Some(g)) => format!("PNG gAMA {g}"),
            (false, None) => unreachable!(),
        };
        out.push((
            what,
            Strength::Weak,
            Declared::Space {
                space,
                // Without gAMA the transfer is unknown; sRGB's is the PNG convention.
                decode: p.gamma.map_or(Decode::Srgb, |g| Decode::Power(1.0 / g)),
                label: "PNG cHRM/gAMA",
            },
        ));
    }
    out
}

/// Sample colours on which two routes must agree to count as the same colour space.
const SAMPLES: [[f32; 3]; 9] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [0.18, 0.18, 0.18],
    [0.9, 0.5, 0.1],
    [0.05, 0.3, 0.7],
    [0.02, 0.01, 0.005],
    [0.6, 0.8, 0.35],
];

/// Whether two routes convert every sample to XYZ within 1e-4 (absolute, white Y = 1).
fn same_conversion(a: &ToXyz, b: &ToXyz) -> bool {
    SAMPLES.iter().all(|&s| match (a.convert(s), b.convert(s)) {
        (Ok(x), Ok(y)) => (0..3).all(|k| (x[k] - y[k]).abs() <= 1e-4),
        _ => false,
    })
}

/// The config's scene- or display-encoded colour space (not data, not display-referred)
/// that converts as `route` does, first in config order.
fn config_equivalent(config: &Config, route: &ToXyz) -> Result<Option<(String, Processor)>> {
    for cs in config.color_spaces()? {
        if cs.is_data || cs.is_display {
            continue;
        }
        let Ok(p) = config.processor_to_xyz(&cs.name) else {
            continue;
        };
        let p = ToXyz::Ocio(p);
        if same_conversion(&p, route) {
            let ToXyz::Ocio(p) = p else { unreachable!() };
            return Ok(Some((cs.name, p)));
        }
    }
    Ok(None)
}

/// A declaration as a colour space: its name and route; `Ok(None)` when it declares nothing
/// usable (a name the config does not know, impossible chromaticities), with the reason.
fn resolve(config: &Config, d: &Declared) -> Result<std::result::Result<(String, ToXyz), String>> {
    match d {
        Declared::Named(name) => Ok(Err(format!("the config has no colour space '{name}'"))),
        Declared::XyzD65 => {
            let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            let route = ToXyz::Matrix {
                decode: Decode::Linear,
                m: identity,
            };
            Ok(Ok(match config_equivalent(config, &route)? {
                Some((name, p)) => (name, ToXyz::Ocio(p)),
                None => ("CIE XYZ, D65 white".to_owned(), route),
            }))
        }
        Declared::Space {
            space,
            decode,
            label,
        } => {
            let Some(m) = space.to_xyz_adapted(D65) else {
                return Ok(Err(format!(
                    "primaries {:?} and white {:?} describe no RGB space",
                    space.primaries, space.white
                )));
            };
            let route = ToXyz::Matrix { decode: *decode, m };
            Ok(Ok(match config_equivalent(config, &route)? {
                Some((name, p)) => (name, ToXyz::Ocio(p)),
                None => (describe_space(label, space, *decode), route),
            }))
        }
        Declared::Icc(bytes) => {
            let profile = match specconv_icc::Profile::new(bytes) {
                Ok(p) => p,
                Err(e) => return Ok(Err(e.to_string())),
            };
            let pcs = match profile.to_pcs() {
                Ok(p) => p,
                Err(e) => return Ok(Err(e.to_string())),
            };
            Ok(Ok((
                format!("ICC '{}'", pcs.name()),
                ToXyz::Icc {
                    pcs,
                    adapt: rgb::bradford(specconv_icc::PCS_WHITE, D65),
                },
            )))
        }
    }
}

/// A name for a colour space the config does not have.
fn describe_space(label: &str, s: &RgbSpace, decode: Decode) -> String {
    let xy = |p: [f64; 2]| format!("{:.4} {:.4}", p[0], p[1]);
    let transfer = match decode {
        Decode::Linear => "linear".to_owned(),
        Decode::Power(e) => format!("power {e:.4}"),
        Decode::Srgb => "sRGB transfer".into(),
    };
    format!(
        "{label}: {transfer}, R {}, G {}, B {}, white {}",
        xy(s.primaries[0]),
        xy(s.primaries[1]),
        xy(s.primaries[2]),
        xy(s.white)
    )
}

/// The config's data colour space, for a texture that is data by no colour space's say.
fn data_space_name(config: &Config) -> String {
    config
        .color_spaces()
        .ok()
        .and_then(|all| all.into_iter().find(|c| c.is_data))
        .map_or_else(|| "data".to_owned(), |c| c.name)
}

/// [`input_space`] for the channels `selection` reads: a data space, or one channel that no
/// row from 1 to 3 calls colour (the data-map rule), is a [`DataTexture`] (as
/// [`Error::Data`]).
pub fn texture_space(
    config: &Config,
    reader: &ImageReader,
    selection: &input::Selection,
    flag: Option<&str>,
) -> Result<InputSpace> {
    let header = Header::of_reader(reader)?;
    let colour = selection.channels.colour.len();
    match header_space(config, &header, colour, flag) {
        Err(Error::Data(mut d)) => {
            d.selection = Some(selection.clone());
            Err(Error::Data(d))
        }
        other => other,
    }
}

/// The colour space of pixels of `colour_channels` (1: grey, 3: RGB) from the file `header`
/// describes, by the precedence of colour evidence ([`space_of`]) and the data-map rule: a
/// data space, or one channel that no row from 1 to 3 calls colour, is a [`DataTexture`].
/// One rule for a conversion ([`texture_space`]) and for pixels a renderer's reader decoded
/// ([`crate::in_memory`]).
pub fn header_space(
    config: &Config,
    header: &Header,
    colour_channels: usize,
    flag: Option<&str>,
) -> Result<InputSpace> {
    let space = space_of(config, header, flag)?;
    if colour_channels == 1 && !space.rule.may_call_one_channel_colour() {
        let overrides = match &space.rule {
            Rule::Default(_) => None,
            rule => rule.evidence(&space.name),
        };
        return Err(data_texture(
            &header.path,
            header.size,
            data_space_name(config),
            Rule::OneChannel {
                overrides,
                colour: space.name,
            },
        ));
    }
    Ok(space)
}

/// Chooses the input colour space of the open file by the precedence of colour evidence
/// ([`space_of`], on what OpenImageIO reports of it).
pub fn input_space(
    config: &Config,
    reader: &ImageReader,
    flag: Option<&str>,
) -> Result<InputSpace> {
    space_of(config, &Header::of_reader(reader)?, flag)
}

/// Chooses the input colour space of the file `header` describes by the precedence of colour
/// evidence (the module's table): the flag, the config's explicit file rule, strong
/// declarations, weak ones (after a data space from the config's Default rule), the config's
/// Default rule, the format's default.
pub fn space_of(config: &Config, info: &Header, flag: Option<&str>) -> Result<InputSpace> {
    let Evidence {
        strong,
        weak,
        mut warnings,
    } = evidence(config, info)?;
    let rule = file_rule(config, info)?;
    if let Some(flag) = flag {
        let top = rule
            .as_ref()
            .map(|r| &r.1)
            .or(strong.first())
            .or(weak.first());
        return by_flag(config, info, flag, top);
    }
    if let Some((name, found)) = rule {
        // The rule settles what the file declares: nothing of it is a warning.
        let overrides = strong
            .first()
            .or(weak.first())
            .filter(|d| d.differs(&found))
            .map(|d| d.says.clone());
        return found.chosen(
            info,
            Rule::FileRule {
                rule: name,
                overrides,
            },
        );
    }
    let mut strong = strong.into_iter();
    if let Some(first) = strong.next() {
        let rest = strong.collect();
        let space = by_declarations(
            info,
            first,
            rest,
            weak.first(),
            Strength::Strong,
            &mut warnings,
        )?;
        return Ok(InputSpace { warnings, ..space });
    }
    let (data_default, colour_default) = match config_default(config, info)? {
        Some((rule, found)) if found.route.is_none() => (Some((rule, found)), None),
        other => (None, other),
    };
    // A data space from any rule wins over weak declarations.
    if let Some((rule, found)) = data_default {
        let overrides = weak.first().map(|d| d.says.clone());
        return found.chosen(info, Rule::ConfigDefault { rule, overrides });
    }
    let mut weak = weak.into_iter();
    let space = if let Some(first) = weak.next() {
        by_declarations(
            info,
            first,
            weak.collect(),
            None,
            Strength::Weak,
            &mut warnings,
        )?
    } else if let Some((rule, found)) = colour_default {
        let rule = Rule::ConfigDefault {
            rule,
            overrides: None,
        };
        found.chosen(info, rule)?
    } else {
        by_format_default(config, info.integer)?
    };
    Ok(InputSpace { warnings, ..space })
}

/// A piece of colour evidence resolved in the config.
struct Found {
    /// What declared it, as warnings and [`Rule::Declared`] name it ("EXR chromaticities").
    what: String,
    /// Who says what, as an overruled piece is named ("the file's EXR chromaticities (ACEScg)").
    says: String,
    /// The colour space (the config's name, or a description).
    name: String,
    /// How it reaches XYZ; `None` for a data space.
    route: Option<ToXyz>,
}

impl Found {
    /// A colour space of the config by name; `says` names the evidence for its name.
    fn in_config(
        config: &Config,
        name: &str,
        what: String,
        says: impl Fn(&str) -> String,
    ) -> Result<Found> {
        let cs = config.color_space(name)?;
        let route = if cs.is_data {
            None
        } else {
            Some(ToXyz::Ocio(config.processor_to_xyz(&cs.name)?))
        };
        Ok(Found {
            says: says(&cs.name),
            what,
            name: cs.name,
            route,
        })
    }

    /// Whether the two would convert otherwise (a data space and a colour one always do).
    fn differs(&self, other: &Found) -> bool {
        match (&self.route, &other.route) {
            (Some(a), Some(b)) => !same_conversion(a, b),
            (None, None) => false,
            _ => true,
        }
    }

    /// The input space it makes, chosen by `rule`; [`Error::Data`] for a data space.
    fn chosen(self, info: &Header, rule: Rule) -> Result<InputSpace> {
        self.chosen_at(&info.path, info.size, rule)
    }

    /// [`Found::chosen`] for the image at `path` of `size`.
    fn chosen_at(self, path: &Path, size: (u32, u32), rule: Rule) -> Result<InputSpace> {
        match self.route {
            None => Err(data_texture(path, size, self.name, rule)),
            Some(to_xyz) => Ok(InputSpace {
                name: self.name,
                rule,
                to_xyz,
                warnings: Vec::new(),
            }),
        }
    }
}

/// What the file declares, every declaration resolved once.
struct Evidence {
    /// The strong declarations the config can use, most authoritative first.
    strong: Vec<Found>,
    /// The weak ones.
    weak: Vec<Found>,
    /// The declarations left out, and why.
    warnings: Vec<Warning>,
}

/// Resolves every declaration of the open file in `config`.
fn evidence(config: &Config, header: &Header) -> Result<Evidence> {
    let mut found = Evidence {
        strong: Vec::new(),
        weak: Vec::new(),
        warnings: Vec::new(),
    };
    for (what, strength, d) in declarations(header) {
        let resolved = match &d {
            Declared::Named(name) => match named(config, name, &what)? {
                Some(Ok(found)) => found,
                None => continue,
                Some(Err(why)) => {
                    found.warnings.push(Warning::Ignored { what, why });
                    continue;
                }
            },
            _ => match resolve(config, &d)? {
                Ok((name, route)) => Found {
                    says: says::file(&what, &name),
                    what,
                    name,
                    route: Some(route),
                },
                Err(why) => {
                    found.warnings.push(Warning::Ignored { what, why });
                    continue;
                }
            },
        };
        match strength {
            Strength::Strong => found.strong.push(resolved),
            Strength::Weak => found.weak.push(resolved),
        }
    }
    Ok(found)
}

/// The config's colour space for a name declared outside a file (a material's MaterialX
/// `colorspace`), by the rule of `named`: a name, alias or role of the config, else a Color
/// Interop Forum ID (`data`: the config's data space). `Ok(None)` for `unknown`; `Ok(Some(Err(why)))`
/// for a name neither knows.
pub fn named_space(
    config: &Config,
    name: &str,
) -> Result<Option<std::result::Result<String, String>>> {
    Ok(named(config, name, "")?.map(|found| found.map(|f| f.name)))
}

/// A colour-space name the file declares (`colorInteropID`, `oiio:ColorSpace`), resolved by
/// one rule: a name, alias or role of the config; else a Color Interop Forum ID
/// ([`crate::interop`]) as the config's equivalent space (`data`: its data space); `None` for
/// `unknown`, which declares nothing; `Some(Err(why))` for a name neither knows.
fn named(
    config: &Config,
    name: &str,
    what: &str,
) -> Result<Option<std::result::Result<Found, String>>> {
    let naming = |cs: &str| says::file(what, cs);
    if config.find_color_space(name)?.is_some() {
        return Ok(Some(Ok(Found::in_config(
            config,
            name,
            what.into(),
            naming,
        )?)));
    }
    let declared = match interop::meaning(name) {
        None => {
            return Ok(Some(Err(format!(
                "the config has no colour space '{name}', and it is not a Color Interop \
                 Forum ID (docs/colour.md lists them)"
            ))))
        }
        Some((_, interop::Meaning::Unknown)) => return Ok(None),
        Some((id, interop::Meaning::Unsupported(why))) => {
            return Ok(Some(Err(format!("'{id}' is {why}"))))
        }
        Some((_, interop::Meaning::Data)) => {
            let name = data_space_name(config);
            return Ok(Some(Ok(Found {
                says: naming(&name),
                what: what.into(),
                name,
                route: None,
            })));
        }
        Some((_, interop::Meaning::XyzD65)) => Declared::XyzD65,
        Some((id, interop::Meaning::Rgb(space, decode))) => Declared::Space {
            space,
            decode,
            label: id,
        },
    };
    Ok(Some(resolve(config, &declared)?.map(|(name, route)| {
        Found {
            says: naming(&name),
            what: what.into(),
            name,
            route: Some(route),
        }
    })))
}

/// [`Error::Data`] for the file at `path` of `size` in the data space `name`, chosen by `rule`.
fn data_texture(path: &Path, size: (u32, u32), name: String, rule: Rule) -> Error {
    Error::Data(Box::new(DataTexture {
        path: path.to_path_buf(),
        name,
        rule,
        selection: None,
        size,
    }))
}

/// The space the caller named; `top`, the evidence that would have decided, is named when it
/// converts otherwise. The declarations' warnings are not given: the flag settles them.
fn by_flag(config: &Config, info: &Header, flag: &str, top: Option<&Found>) -> Result<InputSpace> {
    let asked = Found::in_config(config, flag, String::new(), |_| String::new())?;
    let overrides = top.filter(|t| t.differs(&asked)).map(|t| t.says.clone());
    asked.chosen(info, Rule::Flag { overrides })
}

/// `first` of one row's declarations, with those of `rest` that agree with it; a warning for
/// each that does not. `lower`, the first declaration of a lower row, is named when it
/// converts otherwise.
fn by_declarations(
    info: &Header,
    first: Found,
    rest: Vec<Found>,
    lower: Option<&Found>,
    strength: Strength,
    warnings: &mut Vec<Warning>,
) -> Result<InputSpace> {
    let mut what = vec![first.what.clone()];
    for other in rest {
        if !other.differs(&first) {
            what.push(other.what);
        } else if other.route.is_none() {
            warnings.push(Warning::Ignored {
                why: format!(
                    "'{}' is a data colour space and a colour was declared first",
                    other.name
                ),
                what: other.what,
            });
        } else {
            warnings.push(Warning::Disagree {
                what: first.what.clone(),
                name: first.name.clone(),
                other: other.what,
                other_name: other.name,
            });
        }
    }
    let overrides = lower.filter(|l| l.differs(&first)).map(|l| l.says.clone());
    first.chosen(
        info,
        Rule::Declared {
            what,
            strength,
            overrides,
        },
    )
}

/// The config's explicit file rule that matches the file's path (not the Default rule), with
/// its colour space, if one does.
fn file_rule(config: &Config, info: &Header) -> Result<Option<(String, Found)>> {
    let Some((name, rule)) = config.file_rule(&info.path)? else {
        return Ok(None);
    };
    let naming = |cs: &str| says::file_rule(&rule, cs);
    let found = Found::in_config(config, &name, format!("file rule '{rule}'"), naming)?;
    Ok(Some((rule, found)))
}

/// The Default rule of a config the user gave (a file or `$OCIO`) and its colour space, when
/// it applies: a data space for any file, a colour space for float pixels only (integer
/// pixels are display-encoded textures whatever a Default rule made for scene-linear EXRs
/// says). The built-in configs' Default rule is no one's policy for a file, nor is that of
/// the Academy's official configs given as files ([`Config::builtin_twin`]): `--ocio aces`
/// and `--ocio cg-config-….ocio` decide alike.
fn config_default(config: &Config, info: &Header) -> Result<Option<(String, Found)>> {
    // The built-in configs, and the official files they follow, are no studio's policy.
    if config.builtin_twin()?.is_some() {
        return Ok(None);
    }
    let default = config
        .file_rules()?
        .into_iter()
        .find(|r| r.name.eq_ignore_ascii_case("default"));
    let Some(rule) = default else {
        return Ok(None);
    };
    let naming = |cs: &str| says::default_rule(&rule.name, cs);
    let found = Found::in_config(config, &rule.color_space, rule.name.clone(), naming)?;
    if found.route.is_some() && info.integer {
        return Ok(None);
    }
    Ok(Some((rule.name, found)))
}

/// The format's default: integer pixels are sRGB texture (the config's, else our own), float
/// pixels without chromaticities linear Rec.709 (OpenEXR).
fn by_format_default(config: &Config, srgb_encoded: bool) -> Result<InputSpace> {
    let (d, why) = if srgb_encoded {
        if let Some(name) = config.srgb_texture()? {
            return Ok(InputSpace {
                to_xyz: ToXyz::Ocio(config.processor_to_xyz(&name)?),
                name,
                rule: Rule::Default("integer pixels are sRGB texture"),
                warnings: Vec::new(),
            });
        }
        (
            Declared::Space {
                space: REC709,
                decode: Decode::Srgb,
                label: "sRGB",
            },
            "integer pixels are sRGB texture",
        )
    } else {
        (
            Declared::Space {
                space: REC709,
                decode: Decode::Linear,
                label: "linear Rec.709",
            },
            "float pixels without chromaticities are linear Rec.709, D65 white (OpenEXR)",
        )
    };
    let (name, to_xyz) = resolve(config, &d)?.map_err(Error::DefaultColourSpace)?;
    Ok(InputSpace {
        name,
        rule: Rule::Default(why),
        to_xyz,
        warnings: Vec::new(),
    })
}

/// Pixels that a renderer's reader has already decoded (Mitsuba's `Bitmap`): the file they
/// came from, whose header says what they are ([`Header::read`], weighed by
/// [`header_space`]), and their size.
#[derive(Debug, Clone, Copy)]
pub struct Decoded<'a> {
    /// The file they were read from.
    pub path: &'a Path,
    /// Width and height.
    pub size: (u32, u32),
}
