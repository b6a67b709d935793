//! What usd-core (and MaterialX, for `.mtlx` documents) says of a stage: the texture nodes
//! bound materials read, and their uses, as the reader (`specconv._asset_reader.stage`) gives them.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The composed stage, as far as textures go.
#[derive(Debug, Clone, Deserialize, Serialize)]
pub struct Stage {
    /// The stage's file, absolute.
    pub stage: PathBuf,
    /// Materials bound to some prim.
    pub materials: usize,
    /// Prims with a bound material.
    pub bound_prims: usize,
    /// What composition could not do (a reference cycle, a layer that cannot be read).
    pub composition_errors: Vec<String>,
    /// Every texture node the bound materials read, in path order.
    pub textures: Vec<Node>,
    /// The references and payloads to MaterialX documents that were read by the MaterialX
    /// package (usd-core without its MaterialX file format), each used by a binding.
    #[serde(default)]
    pub references: Vec<MtlxReference>,
    /// Every layer the stage composed and every MaterialX document and XInclude read
    /// (absolute): files no output may be.
    #[serde(default)]
    pub read_files: Vec<PathBuf>,
    /// Files read by shaders that are no texture node this reader knows (Arnold's `image`,
    /// RenderMan's `PxrTexture`, …): reported, never converted (issue 56, item 2).
    #[serde(default)]
    pub unknown: Vec<UnknownRead>,
}

/// A file an unknown shader reads.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
pub struct UnknownRead {
    /// The shader's prim.
    pub node: String,
    /// Its `info:id` (or prim type).
    pub node_id: Option<String>,
    /// The input that names the file.
    pub input: String,
    /// The file as written.
    pub file: String,
    /// As usd-core resolved it.
    pub resolved: Option<String>,
    /// The bound material whose network it is in.
    pub material: String,
}

/// A prim's reference (or payload) to a MaterialX document.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
pub struct MtlxReference {
    /// The referencing prim.
    pub prim: String,
    /// `references` or `payload`.
    pub arc: String,
    /// The document's path as written.
    pub asset: String,
    /// Anchored to the layer that wrote it (as composition compares references).
    pub resolved: PathBuf,
    /// The prim of the document it names (`/MaterialX/Materials/M`), empty for the default.
    pub target: String,
    /// Its layer offset.
    pub offset: f64,
    /// Its layer scale.
    pub scale: f64,
}

/// A texture node (UsdUVTexture, a MaterialX image node) and what it reads.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq, Eq)]
pub struct Node {
    /// Its prim path.
    pub node: String,
    /// Its shader id (`UsdUVTexture`, `ND_image_color3`).
    pub node_id: Option<String>,
    /// Its `inputs:sourceColorSpace` (`sRGB`, `raw`, `auto`), if authored.
    pub source_color_space: Option<String>,
    /// The `colorSpace` of its `inputs:file` (MaterialX's `colorspace`), if authored.
    pub colorspace: Option<String>,
    /// The input that names the file (`file`; Arnold's and RenderMan's `filename`,
    /// PxrMultiTexture's `filename0`…): a node with several gives one [`Node`] for each.
    #[serde(default = "file_input")]
    pub file_input: String,
    /// How its copy is told to read the spectral file as written, `[input, type, value]`
    /// (`["sourceColorSpace", "token", "raw"]`), from the reader's table of texture nodes.
    #[serde(default)]
    pub raw_input: Option<serde_json::Value>,
    /// `inputs:file` as written.
    pub authored: Option<String>,
    /// `inputs:file` resolved by usd-core's asset resolver (a UDIM pattern keeps `<UDIM>`);
    /// `None` when it resolves to nothing (a missing file).
    pub resolved: Option<PathBuf>,
    /// The layer that wrote `inputs:file`.
    pub layer: Option<PathBuf>,
    /// Where the file was looked for (anchored to its layer or document, with MaterialX's
    /// `fileprefix`), said when it is missing.
    #[serde(default)]
    pub looked_for: Option<PathBuf>,
    /// The usdz package the file is in, if it is in one.
    pub package: Option<Package>,
    /// Which of its outputs feeds which input.
    pub uses: Vec<Use>,
    /// The MaterialX document it is a node of (its `node` is then the element's name path,
    /// `NG_brick/image_color`); `None`: a USD prim.
    #[serde(default)]
    pub document: Option<PathBuf>,
}

/// A file inside a usdz package.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq, Eq)]
pub struct Package {
    /// The package.
    pub file: PathBuf,
    /// The member's name inside it.
    pub member: String,
}

/// One output of a texture node feeding one input, in the end (through the nodes between).
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq, Eq)]
pub struct Use {
    /// The bound material it is in.
    pub material: String,
    /// The node whose input it feeds (the surface shader).
    pub shader: String,
    /// That node's shader id.
    pub shader_id: Option<String>,
    /// The input (`diffuseColor`, `roughness`, `base_color`).
    pub input: String,
    /// Its type in the definition of the node it is an input of (`color3`, `color3f`, `RGB`,
    /// `float`, `normal3f`), which decides its role; `None`: no definition is known.
    #[serde(default)]
    pub input_type: Option<String>,
    /// The definition: where it comes from, and its name.
    #[serde(default)]
    pub defined_by: Option<String>,
    /// The texture's output (`rgb`, `r`, `g`, `b`, `a`, MaterialX's `out`).
    pub output: String,
    /// The nodes between (a normal-map node), in order.
    pub through: Vec<String>,
    /// Why this use could not keep reading the original file while the node's colour uses
    /// read the spectral one (a USD texture node outside its material, which no render
    /// context reaches; a MaterialX use through nodes between); `None`: it can.
    #[serde(default)]
    pub inseparable: Option<String>,
    /// The reader's walk gave up at `shader` after this many nodes between (a chain past its
    /// depth): what the texture feeds there is not known.
    #[serde(default)]
    pub cut: bool,
}

/// The file input a reader that names none meant: `file` (UsdUVTexture's, MaterialX's).
fn file_input() -> String {
    "file".to_owned()
}
