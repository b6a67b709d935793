//! The rule: what a texture is, decided by the material inputs it feeds (docs/assets.md). The
//! material is the strongest evidence of colour there is (docs/colour.md): it outranks every
//! row of the precedence table; where it says "colour" without a space, the table decides the
//! space from the file.

use crate::stage::{Node, Use};
use serde::Serialize;
use std::path::PathBuf;

/// Inputs that take a colour (UsdPreviewSurface; MaterialX standard_surface, open_pbr_surface,
/// gltf_pbr): a texture whose colour channels feed one is colour.
pub const COLOUR_INPUTS: &[&str] = &[
    "diffuseColor",
    "emissiveColor",
    "specularColor",
    "base_color",
    "specular_color",
    "transmission_color",
    "subsurface_color",
    "sheen_color",
    "coat_color",
    "emission_color",
    "fuzz_color",
    "emissive",
    "attenuation_color",
];

/// Inputs that take numbers, not colour: a texture feeding one is data.
pub const DATA_INPUTS: &[&str] = &[
    "roughness",
    "metallic",
    "normal",
    "occlusion",
    "opacity",
    "opacityThreshold",
    "displacement",
    "clearcoat",
    "clearcoatRoughness",
    "ior",
    "base",
    "base_weight",
    "diffuse_roughness",
    "metalness",
    "specular",
    "specular_weight",
    "specular_roughness",
    "specular_IOR",
    "specular_ior",
    "specular_anisotropy",
    "specular_rotation",
    "specular_roughness_anisotropy",
    "transmission",
    "transmission_weight",
    "transmission_depth",
    "subsurface",
    "subsurface_weight",
    "subsurface_scale",
    "sheen",
    "sheen_roughness",
    "coat",
    "coat_weight",
    "coat_roughness",
    "coat_IOR",
    "coat_ior",
    "coat_normal",
    "fuzz_weight",
    "fuzz_roughness",
    "thin_film_thickness",
    "emission",
    "emission_luminance",
    "geometry_normal",
    "geometry_coat_normal",
    "geometry_opacity",
    "tangent",
    "alpha",
    "alpha_cutoff",
];

/// Every input a use ends at (the reader follows a texture's output through other nodes until
/// it reaches one of these, or a node nothing reads on).
pub fn final_inputs() -> Vec<&'static str> {
    COLOUR_INPUTS.iter().chain(DATA_INPUTS).copied().collect()
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
/// beside a colour output, they leave the texture colour (issue 56, item 2).
pub const ALPHA_OUTPUTS: [&str; 2] = ["a", "outa"];

fn says(u: &Use) -> Says {
    if ALPHA_OUTPUTS.contains(&u.output.as_str()) {
        Says::Alpha
    } else if COLOUR_INPUTS.contains(&u.input.as_str()) {
        Says::Colour
    } else if DATA_INPUTS.contains(&u.input.as_str()) {
        Says::Data
    } else {
        Says::Unknown
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
    if let (Some(c), Some(d)) = (colour.first(), data.first()) {
        return Decision::Conflict {
            why: format!(
                "colour in one use and data in another: {} (colour), {} (data)",
                describe(c.0, c.1),
                describe(d.0, d.1)
            ),
        };
    }
    if let Some(&(first, u)) = colour.first() {
        return colour_decision(&colour, first, u, &alpha);
    }
    if let Some(&(n, u)) = data.first() {
        let more = match data.len() {
            1 => String::new(),
            k => format!(" (and {} more data uses)", k - 1),
        };
        return Decision::Data {
            rule: "data-input",
            why: format!("{} takes data{more}", describe(n, u)),
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
            "{}: an input specconv does not know as colour or data; the file's evidence decides",
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
    alpha: &[(&Node, &Use)],
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
    let with_alpha = match alpha.first() {
        Some(&(n, a)) => format!(", with alpha ({})", describe(n, a)),
        None => String::new(),
    };
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
        why: format!("{} takes colour{of_space}{with_alpha}", describe(first, u)),
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
        Space::Named(n) => format!("MaterialX colorspace '{n}'"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(path: &str, scs: Option<&str>, uses: &[(&str, &str)]) -> Node {
        Node {
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
                    output: (*output).into(),
                    through: vec![],
                    cut: false,
                })
                .collect(),
        }
    }

    #[test]
    fn every_input_is_in_one_list() {
        for c in COLOUR_INPUTS {
            assert!(!DATA_INPUTS.contains(c), "{c}");
        }
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
        let d = decide(&[node(
            "/M/Base",
            None,
            &[("outcolor", "base_color"), ("outa", "alpha")],
        )]);
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

    #[test]
    fn colour_and_data_uses_of_one_file_are_a_conflict_naming_both() {
        let a = node("/A/Tex", Some("sRGB"), &[("rgb", "diffuseColor")]);
        let b = node("/B/Tex", Some("raw"), &[("rgb", "normal")]);
        let d = decide(&[a.clone(), b]);
        assert_eq!(d.rule(), "conflict");
        assert!(
            d.why().contains("/A/Tex") && d.why().contains("/B/Tex"),
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
