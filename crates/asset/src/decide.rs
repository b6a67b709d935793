//! The rule: what a texture is, decided by the material inputs it feeds (docs/assets.md). The
//! material is the strongest evidence of colour there is (docs/colour.md): it outranks every
//! row of the precedence table; where it says "colour" without a space, the table decides the
//! space from the file.

use crate::stage::{Node, Use};
use serde::Serialize;
use std::path::PathBuf;

/// The types shader definitions give colour, in each one's words: MaterialX's `color3` and
/// `color4`, USD's `color3f`… (Sdf), RenderMan's `color`, Arnold's `RGB` and `RGBA`. A use
/// whose input has one of these types takes colour; any other type (`float`, `vector3`,
/// `normal3f`) takes data.
pub const COLOUR_TYPES: [&str; 11] = [
    "color3", "color4", "color3f", "color4f", "color3d", "color4d", "color3h", "color4h", "color",
    "RGB", "RGBA",
];

/// Words that make a colour-typed input a quantity per channel rather than a colour: a
/// subsurface radius or mean free path is a distance, an index of refraction or extinction
/// coefficient is no reflectance, an opacity is coverage. Uplifting one would bound it to a
/// reflectance's 0 to 1 and smooth it as one; they stay data (docs/assets.md, "Roles from
/// shader definitions", lists the inputs of the known definitions they make data).
pub const PER_CHANNEL: [(&str, &str); 7] = [
    ("radius", "a distance"),
    ("distance", "a distance"),
    ("dmfp", "a mean free path (a distance)"),
    ("mfp", "a mean free path (a distance)"),
    ("ior", "an index of refraction"),
    ("extinction", "an extinction coefficient"),
    ("opacity", "a coverage"),
];

/// The words of an input's name (`subsurfaceDmfpColor`: subsurface, dmfp, color;
/// `specular_IOR`: specular, ior), lower-case.
fn words_of(name: &str) -> Vec<String> {
    let mut words = vec![String::new()];
    let mut previous_lower = false;
    for c in name.chars() {
        if c == '_' || c == ':' {
            words.push(String::new());
            previous_lower = false;
            continue;
        }
        if c.is_uppercase() && previous_lower {
            words.push(String::new());
        }
        previous_lower = c.is_lowercase() || c.is_ascii_digit();
        if let Some(word) = words.last_mut() {
            word.extend(c.to_lowercase());
        }
    }
    words.retain(|w| !w.is_empty());
    words
}

/// What a colour-typed input holds if it is no colour (a [`PER_CHANNEL`] word is in its name).
pub fn per_channel(input: &str) -> Option<&'static str> {
    let words = words_of(input);
    PER_CHANNEL
        .iter()
        .find(|(w, _)| words.iter().any(|x| x == w))
        .map(|(_, what)| *what)
}

/// MaterialX's colour-space names (MaterialX specification, "Color Spaces") as Color Interop
/// Forum IDs, which the config's spaces are matched against (docs/colour.md).
const MATERIALX_SPACES: [(&str, &str); 13] = [
    ("srgb_texture", "srgb_rec709_scene"),
    ("lin_rec709", "lin_rec709_scene"),
    ("g18_rec709", "g18_rec709_scene"),
    ("g22_rec709", "g22_rec709_scene"),
    ("rec709_display", "g24_rec709_display"),
    ("acescg", "lin_ap1_scene"),
    ("lin_ap1", "lin_ap1_scene"),
    ("g22_ap1", "g22_ap1_scene"),
    ("adobergb", "g22_adobergb_scene"),
    ("lin_adobergb", "lin_adobergb_scene"),
    ("srgb_displayp3", "srgb_p3d65_scene"),
    ("lin_displayp3", "lin_p3d65_scene"),
    ("raw", "data"),
];

/// The Color Interop Forum ID of a MaterialX colour-space name, if MaterialX names it.
pub fn materialx_space(name: &str) -> Option<&'static str> {
    MATERIALX_SPACES
        .iter()
        .find(|(m, _)| m.eq_ignore_ascii_case(name.trim()))
        .map(|(_, id)| *id)
}

/// Which colour space a colour texture is read in.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "from", content = "name")]
pub enum Space {
    /// The material names none (`auto`, or nothing): the file's own evidence decides, by the
    /// precedence table.
    File,
    /// `sourceColorSpace = "sRGB"`: the config's sRGB texture space.
    Srgb,
    /// `sourceColorSpace = "raw"` on a colour input: the values as read, which a renderer takes
    /// as linear colour (UsdPreviewSurface specification): linear Rec.709.
    Linear,
    /// A MaterialX `colorspace`, as written.
    Named(String),
}

/// What a texture is.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Decision {
    /// Colour, uplifted, in this space.
    Colour {
        /// Where its colour space comes from.
        space: Space,
        /// The rule's keyword.
        rule: &'static str,
        /// Why, in words.
        why: String,
    },
    /// Data: never uplifted.
    Data {
        /// The rule's keyword.
        rule: &'static str,
        /// Why, in words.
        why: String,
    },
    /// The material says both (or two colour spaces): never converted, both uses named.
    Conflict {
        /// Why, in words.
        why: String,
    },
    /// The file does not exist (or the resolver could not find it).
    Missing {
        /// Why, in words.
        why: String,
    },
    /// The reader's walk from a node gave up before it reached what the node feeds (a chain
    /// longer than it follows): never converted, and said (issue 57, item 5).
    Undecided {
        /// Why, in words.
        why: String,
    },
}

impl Decision {
    /// The rule's keyword (`colour-input`, `source-color-space`, `materialx-colorspace`,
    /// `data-input`, `alpha-only`, `unknown-input`, `conflict`, `missing`, `undecided`).
    pub fn rule(&self) -> &'static str {
        match self {
            Decision::Colour { rule, .. } | Decision::Data { rule, .. } => rule,
            Decision::Conflict { .. } => "conflict",
            Decision::Missing { .. } => "missing",
            Decision::Undecided { .. } => "undecided",
        }
    }

    /// Why, in words.
    pub fn why(&self) -> &str {
        match self {
            Decision::Colour { why, .. }
            | Decision::Data { why, .. }
            | Decision::Conflict { why }
            | Decision::Missing { why }
            | Decision::Undecided { why } => why,
        }
    }
}

/// A texture file and everything the stage says of it.
#[derive(Debug, Clone, Serialize)]
pub struct Texture {
    /// The file (a UDIM pattern keeps its `<UDIM>`), or the package member's name where it is
    /// inside a usdz and was not extracted.
    pub file: PathBuf,
    /// The nodes (UsdUVTexture, MaterialX image) that read it.
    pub nodes: Vec<Node>,
    /// What it is.
    pub decision: Decision,
}

/// A use with the node it is a use of.
type Said<'a> = (&'a Node, &'a Use);

/// What one use says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Says {
    Colour,
    Data,
    Alpha,
    Unknown,
}

/// The outputs that are a texture node's alpha channel alone: UsdUVTexture's `a` (the
/// UsdPreviewSurface specification) and MaterialX's `gltf_colorimage` `outa` (its nodedef,
/// `ND_gltf_colorimage`, in the MaterialX standard library's glTF PBR definitions). Read
/// beside a colour output, they leave the texture colour (issue 56, item 2). Arnold's image
/// `a` too (arnold-usd names a component output by its channel), and RenderMan's PxrTexture
/// `resultA` (RenderMan documentation, "PxrTexture").
pub const ALPHA_OUTPUTS: [&str; 3] = ["a", "outa", "resultA"];

/// What a use says, by the type its input has in the definition of the node it reaches.
fn says(u: &Use) -> Says {
    if ALPHA_OUTPUTS.contains(&u.output.as_str()) {
        return Says::Alpha;
    }
    match u.input_type.as_deref() {
        None => Says::Unknown,
        Some(t) if COLOUR_TYPES.contains(&t) && per_channel(&u.input).is_none() => Says::Colour,
        Some(_) => Says::Data,
    }
}

/// Whether a use takes data by its type (its file keeps the original for it).
pub fn takes_data(u: &Use) -> bool {
    says(u) == Says::Data
}

/// Whether a use takes colour by its type.
pub fn takes_colour(u: &Use) -> bool {
    says(u) == Says::Colour
}

/// A use's type, in words: ` (color3 in MaterialX's ND_standard_surface_surfaceshader)`; a
/// colour type that holds a quantity per channel says what it holds.
fn typed(u: &Use) -> String {
    let (Some(t), Some(by)) = (&u.input_type, &u.defined_by) else {
        return String::new();
    };
    match per_channel(&u.input).filter(|_| COLOUR_TYPES.contains(&t.as_str())) {
        Some(what) => format!(" ({t} in {by}, but {what} per channel, not a colour)"),
        None => format!(" ({t} in {by})"),
    }
}

/// The space a node declares for its colour.
fn declared(node: &Node) -> Space {
    if let Some(cs) = node.colorspace.as_deref().filter(|c| !c.is_empty()) {
        return Space::Named(cs.to_owned());
    }
    match node.source_color_space.as_deref() {
        Some("sRGB") => Space::Srgb,
        Some("raw") => Space::Linear,
        _ => Space::File,
    }
}

/// A use in words: `/Looks/Rock/Surface.inputs:diffuseColor reads rgb of /Looks/Rock/Albedo`.
pub fn describe(node: &Node, u: &Use) -> String {
    let through = if u.through.is_empty() {
        String::new()
    } else {
        format!(" through {}", u.through.join(", "))
    };
    // A MaterialX node's input is `SR_brick.base_color`; a USD prim's, `…/Surface.inputs:…`.
    let port = if node.document.is_some() {
        ""
    } else {
        "inputs:"
    };
    format!(
        "{}.{port}{} reads {} of {}{through}",
        u.shader, u.input, u.output, node.node
    )
}

/// Decides what a file is from every node that reads it (the nodes of one file, any number of
/// materials): colour where colour channels feed colour inputs, data where they feed data
/// inputs, a conflict where they feed both or two declared spaces disagree.
pub fn decide(nodes: &[Node]) -> Decision {
    // A walk that gave up decides nothing: what lies past it may be any input.
    for n in nodes {
        if let Some(u) = n.uses.iter().find(|u| u.cut) {
            return Decision::Undecided {
                why: format!(
                    "the walk from {} gave up at {} after {} nodes: what it feeds there is not \
                     known, so it is not converted; shorten the chain of nodes",
                    n.node,
                    u.shader,
                    u.through.len()
                ),
            };
        }
    }
    let mut colour: Vec<(&Node, &Use)> = Vec::new();
    let mut data: Vec<(&Node, &Use)> = Vec::new();
    let mut alpha: Vec<(&Node, &Use)> = Vec::new();
    let mut unknown: Vec<(&Node, &Use)> = Vec::new();
    for n in nodes {
        for u in &n.uses {
            match says(u) {
                Says::Colour => colour.push((n, u)),
                Says::Data => data.push((n, u)),
                Says::Alpha => alpha.push((n, u)),
                Says::Unknown => unknown.push((n, u)),
            }
        }
    }
    // Colour wins where each data use can keep reading the original file in the spectral
    // choice (docs/assets.md, "Colour and data from one file"); a data use of a node that
    // also feeds colour and cannot is a conflict.
    // Linear in the uses: the nodes with a colour use, once.
    let coloured: std::collections::HashSet<(&str, Option<&PathBuf>)> = colour
        .iter()
        .map(|(n, _)| (n.node.as_str(), n.document.as_ref()))
        .collect();
    let blocked = data.iter().find(|(n, u)| {
        u.inseparable.is_some() && coloured.contains(&(n.node.as_str(), n.document.as_ref()))
    });
    if let (Some(c), Some(&(n, d))) = (colour.first(), blocked) {
        return Decision::Conflict {
            why: format!(
                "colour in one use and data in another, and the data use cannot keep the \
                 original file beside the spectral one ({}): {}{} (colour), {}{} (data)",
                d.inseparable.as_deref().unwrap_or_default(),
                describe(c.0, c.1),
                typed(c.1),
                describe(n, d),
                typed(d),
            ),
        };
    }
    if let Some(&(first, u)) = colour.first() {
        return colour_decision(&colour, first, u, (&alpha, &data));
    }
    if let Some(&(n, u)) = data.first() {
        let more = match data.len() {
            1 => String::new(),
            k => format!(" (and {} more data uses)", k - 1),
        };
        return Decision::Data {
            rule: "data-input",
            why: format!("{} takes data{}{more}", describe(n, u), typed(u)),
        };
    }
    if let Some(&(n, u)) = alpha.first() {
        return Decision::Data {
            rule: "alpha-only",
            why: format!("only its alpha is read: {}", describe(n, u)),
        };
    }
    let why = match unknown.first() {
        Some(&(n, u)) => format!(
            "{}: no shader definition specconv knows types this input; the file's evidence \
             decides",
            describe(n, u)
        ),
        None => "no material input reads it; the file's evidence decides".to_owned(),
    };
    Decision::Colour {
        space: Space::File,
        rule: "unknown-input",
        why,
    }
}

/// Colour: the space the colour uses' nodes declare, one for all of them.
fn colour_decision(
    colour: &[(&Node, &Use)],
    first: &Node,
    u: &Use,
    (alpha, data): (&[Said], &[Said]),
) -> Decision {
    let mut space = Space::File;
    let mut by: Option<&Node> = None;
    for &(n, _) in colour {
        let s = declared(n);
        match by {
            _ if s == Space::File || s == space => {}
            None => {
                space = s;
                by = Some(n);
            }
            Some(other) => {
                return Decision::Conflict {
                    why: format!(
                        "two colour spaces: {} declares {} and {} declares {}",
                        other.node,
                        words(&space),
                        n.node,
                        words(&s)
                    ),
                }
            }
        }
    }
    let mut with_alpha = match alpha.first() {
        Some(&(n, a)) => format!(", with alpha ({})", describe(n, a)),
        None => String::new(),
    };
    if let Some(&(n, d)) = data.first() {
        let more = match data.len() {
            1 => String::new(),
            k => format!(" and {} more", k - 1),
        };
        with_alpha += &format!(
            "; its data uses keep the original file ({}{}{more})",
            describe(n, d),
            typed(d)
        );
    }
    let rule = match &space {
        Space::File => "colour-input",
        Space::Srgb | Space::Linear => "source-color-space",
        Space::Named(_) => "materialx-colorspace",
    };
    let of_space = match &space {
        Space::File => "; the file's evidence gives its space".to_owned(),
        s => format!("; {}", words(s)),
    };
    Decision::Colour {
        why: format!(
            "{} takes colour{}{of_space}{with_alpha}",
            describe(first, u),
            typed(u)
        ),
        space,
        rule,
    }
}

/// A declared space in words.
pub fn words(s: &Space) -> String {
    match s {
        Space::File => "nothing (the file's evidence)".to_owned(),
        Space::Srgb => "sourceColorSpace sRGB".to_owned(),
        Space::Linear => "sourceColorSpace raw (linear colour)".to_owned(),
        Space::Named(n) => format!("the material's colour space '{n}'"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The types UsdPreviewSurface's definition gives its inputs (usd-core's Sdr), for the
    /// uses below.
    fn preview_type(input: &str) -> &'static str {
        match input {
            "diffuseColor" | "emissiveColor" | "specularColor" => "color3f",
            "normal" => "normal3f",
            _ => "float",
        }
    }

    fn node(path: &str, scs: Option<&str>, uses: &[(&str, &str)]) -> Node {
        Node {
            file_input: "file".into(),
            raw_input: None,
            looked_for: None,
            node: path.into(),
            node_id: Some("UsdUVTexture".into()),
            source_color_space: scs.map(Into::into),
            colorspace: None,
            authored: Some("./t.png".into()),
            resolved: Some("/t.png".into()),
            layer: None,
            package: None,
            document: None,
            uses: uses
                .iter()
                .map(|(output, input)| Use {
                    material: "/M".into(),
                    shader: "/M/Surface".into(),
                    shader_id: Some("UsdPreviewSurface".into()),
                    input: (*input).into(),
                    input_type: Some(preview_type(input).into()),
                    defined_by: Some("usd-core's Sdr UsdPreviewSurface".into()),
                    output: (*output).into(),
                    through: vec![],
                    inseparable: None,
                    cut: false,
                })
                .collect(),
        }
    }

    #[test]
    fn the_words_of_a_name_split_at_underscores_and_case() {
        assert_eq!(
            words_of("subsurfaceDmfpColor"),
            ["subsurface", "dmfp", "color"]
        );
        assert_eq!(words_of("specular_IOR"), ["specular", "ior"]);
        assert_eq!(
            words_of("subsurface_radius_scale"),
            ["subsurface", "radius", "scale"]
        );
        assert_eq!(words_of("opacityThreshold"), ["opacity", "threshold"]);
        // A word is whole: `priority` has no `ior`, `coloration` no `radius`.
        assert_eq!(per_channel("priority"), None);
        assert_eq!(per_channel("transmission_scatter"), None);
        assert_eq!(per_channel("specularIor"), Some("an index of refraction"));
        assert_eq!(per_channel("subsurfaceDistance"), Some("a distance"));
    }

    /// The role is the type's, whatever the name says: a colour-typed input named as data
    /// is colour, a float-typed one named as colour is data, an untyped one is the file's.
    #[test]
    fn the_type_decides_not_the_name() {
        let mut n = node("/M/T", None, &[("rgb", "diffuseColor")]);
        n.uses[0].input = "roughness".into();
        n.uses[0].input_type = Some("RGB".into());
        assert!(matches!(decide(&[n.clone()]), Decision::Colour { .. }));
        n.uses[0].input = "base_color".into();
        n.uses[0].input_type = Some("float".into());
        assert_eq!(decide(&[n.clone()]).rule(), "data-input");
        n.uses[0].input_type = None;
        assert_eq!(decide(&[n]).rule(), "unknown-input");
    }

    /// Issue 56, item 2: a base colour image that also feeds `subsurface_radius` (color3 in
    /// standard_surface's nodedef, a distance: OpenChessSet's pieces) is colour, the radius a
    /// data use that keeps the original file; where it could not, a conflict naming it.
    #[test]
    fn a_colour_typed_radius_is_data() {
        let mut n = node(
            "/M/T",
            None,
            &[("out", "base_color"), ("out", "subsurface_radius")],
        );
        for u in &mut n.uses {
            u.input_type = Some("color3".into());
            u.defined_by = Some("MaterialX's ND_standard_surface_surfaceshader".into());
        }
        let d = decide(&[n.clone()]);
        assert_eq!(d.rule(), "colour-input", "{d:?}");
        assert!(
            d.why().contains(
                "its data uses keep the original file (/M/Surface.inputs:subsurface_radius \
                 reads out of /M/T (color3 in MaterialX's ND_standard_surface_surfaceshader, \
                 but a distance per channel, not a colour))"
            ),
            "{}",
            d.why()
        );
        n.uses[1].inseparable = Some("it runs through /M/Between".into());
        let d = decide(&[n.clone()]);
        assert_eq!(d.rule(), "conflict");
        assert!(
            d.why().contains("(it runs through /M/Between)"),
            "{}",
            d.why()
        );
        n.uses.remove(0);
        assert_eq!(decide(&[n]).rule(), "data-input");
    }

    #[test]
    fn rgb_to_colour_and_alpha_to_opacity_is_one_colour_texture() {
        let d = decide(&[node(
            "/M/A",
            Some("sRGB"),
            &[("rgb", "diffuseColor"), ("a", "opacity")],
        )]);
        assert_eq!(d.rule(), "source-color-space");
        assert!(matches!(
            d,
            Decision::Colour {
                space: Space::Srgb,
                ..
            }
        ));
        assert!(d.why().contains("with alpha"), "{}", d.why());
    }

    /// Issue 56, item 2: glTF's colour image with its `outa` feeding alpha is one colour
    /// texture, as UsdUVTexture's `a` is, not a conflict.
    #[test]
    fn gltf_colorimage_outa_to_alpha_is_one_colour_texture() {
        let mut n = node(
            "/M/Base",
            None,
            &[("outcolor", "base_color"), ("outa", "alpha")],
        );
        n.uses[0].input_type = Some("color3".into()); // ND_gltf_pbr_surfaceshader's
        let d = decide(&[n]);
        assert!(matches!(d, Decision::Colour { .. }), "{d:?}");
        assert!(d.why().contains("with alpha"), "{}", d.why());
    }

    #[test]
    fn an_arm_texture_is_data_and_raw_on_a_colour_input_is_linear_colour() {
        let arm = node(
            "/M/Arm",
            None,
            &[("r", "occlusion"), ("g", "roughness"), ("b", "metallic")],
        );
        assert_eq!(decide(&[arm]).rule(), "data-input");
        let raw = node("/M/Lin", Some("raw"), &[("rgb", "diffuseColor")]);
        assert!(matches!(
            decide(&[raw]),
            Decision::Colour {
                space: Space::Linear,
                ..
            }
        ));
        let alpha = node("/M/Mask", Some("sRGB"), &[("a", "opacity")]);
        assert_eq!(decide(&[alpha]).rule(), "alpha-only");
    }

    /// One file as colour in one node and data in another: colour, the data node untouched.
    /// One node feeding both where the data use cannot keep the file: a conflict naming both.
    #[test]
    fn colour_and_data_uses_of_one_file_are_a_conflict_only_where_data_cannot_keep_it() {
        let a = node("/A/Tex", Some("sRGB"), &[("rgb", "diffuseColor")]);
        let b = node("/B/Tex", Some("raw"), &[("rgb", "normal")]);
        let d = decide(&[a.clone(), b]);
        assert_eq!(d.rule(), "source-color-space", "{d:?}");
        assert!(d.why().contains("keep the original file"), "{}", d.why());
        let mut both = node(
            "/T/Tex",
            None,
            &[("rgb", "diffuseColor"), ("rgb", "normal")],
        );
        both.uses[1].inseparable = Some("the texture node /T/Tex is outside its material".into());
        let d = decide(&[both]);
        assert_eq!(d.rule(), "conflict");
        assert!(
            d.why().contains("diffuseColor") && d.why().contains("outside its material"),
            "{}",
            d.why()
        );
        let lin = node("/C/Tex", Some("raw"), &[("rgb", "emissiveColor")]);
        let d = decide(&[a, lin]);
        assert_eq!(d.rule(), "conflict", "{d:?}");
        assert!(d.why().contains("two colour spaces"), "{}", d.why());
    }

    #[test]
    fn materialx_names_are_forum_ids() {
        assert_eq!(materialx_space("ACEScg"), Some("lin_ap1_scene"));
        assert_eq!(materialx_space("srgb_texture"), Some("srgb_rec709_scene"));
        assert_eq!(materialx_space("studio:odd"), None);
    }

    #[test]
    fn a_walk_that_gave_up_decides_nothing() {
        let mut n = node("/M/Tex", None, &[("rgb", "diffuseColor")]);
        n.uses.push(Use {
            shader: "/M/Chain/N64".into(),
            input: String::new(),
            through: vec!["/M/Chain/N".into(); 65],
            cut: true,
            ..n.uses[0].clone()
        });
        let d = decide(&[n]);
        assert_eq!(d.rule(), "undecided");
        assert!(
            d.why().contains("gave up at /M/Chain/N64 after 65 nodes"),
            "{}",
            d.why()
        );
    }
}
