//! An asset's plan: each texture file once, what it is, where its output goes under DIR, the
//! colour space its conversion is given, and the layer that points the stage at the outputs.

use crate::decide::{decide, materialx_space, takes_colour, takes_data, Decision, Space, Texture};
use crate::error::Error;
use crate::stage::{MtlxReference, Node, Stage};
use serde::Serialize;
use sha2::{Digest, Sha256};
use specconv_atomic_file::outputs::Holds;
use specconv_atomic_file::udim;
use specconv_conversion::{ColourConfig, Options};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};

/// A texture with its plan.
#[derive(Debug, Clone, Serialize)]
pub struct Planned {
    /// The texture, its nodes and the decision.
    #[serde(flatten)]
    pub texture: Texture,
    /// Its output under DIR (a UDIM pattern keeps `<UDIM>`); `None` when it is not converted.
    pub output: Option<PathBuf>,
    /// The colour space its conversion is given (the config's name: a data texture's is the
    /// config's data space); `None`: the file's own evidence decides.
    pub colorspace: Option<String>,
    /// Why it is not converted (a conflict, a missing file, a colour space the config lacks).
    pub error: Option<String>,
}

/// The plan of one stage.
#[derive(Debug, Clone, Serialize)]
pub struct Asset {
    /// The stage, absolute.
    pub stage: PathBuf,
    /// The output directory.
    pub dir: PathBuf,
    /// The layer written over the stage: `DIR/STEM_spectral.usda`.
    pub layer: PathBuf,
    /// Bound materials, and prims bound to one.
    pub materials: usize,
    /// Prims with a bound material.
    pub bound_prims: usize,
    /// Every texture file once, in the order of its first node's path.
    pub textures: Vec<Planned>,
    /// The stage's references to MaterialX documents that MaterialX read.
    pub references: Vec<MtlxReference>,
    /// Every file the stage composed or read but its textures ([`Stage::read_files`]).
    #[serde(skip)]
    pub read_files: Vec<PathBuf>,
    /// Files read by shaders the reader does not know ([`crate::stage::UnknownRead`]).
    #[serde(skip)]
    pub unknown: Vec<crate::stage::UnknownRead>,
    /// Every file the run may write (the layer, document copies, the jobs' outputs), set by
    /// [`crate::prepare`] and stamped in the record ([`crate::record`]) once written.
    #[serde(skip)]
    pub writes: Vec<PathBuf>,
}

/// One conversion: a file (or one UDIM tile) of texture `texture`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    /// Its index in [`Asset::textures`].
    pub texture: usize,
    /// The file.
    pub input: PathBuf,
    /// Its output.
    pub output: PathBuf,
    /// The colour space the conversion is given.
    pub colorspace: Option<String>,
}

impl Job {
    /// Its input and output as a batch plans them: the asset names a data texture's output
    /// itself, so a pair has one name.
    pub fn pair(&self) -> specconv_conversion::plan::Pair {
        specconv_conversion::plan::Pair::new(&self.input, &self.output)
    }
}

/// The layer of overrides ([`crate::Reader::write_layer`]), as the reader script takes it.
#[derive(Debug, Clone, Serialize)]
pub struct LayerPlan {
    /// Where it is written.
    pub layer: PathBuf,
    /// The stage it sublayers, relative to the layer ([`anchored`]): the layer and the stage
    /// move together.
    pub sublayer: String,
    /// The stage, as the run named it (absolute): what the layer is made of.
    pub stage: PathBuf,
    /// One per texture node (a USD prim) of a converted colour texture.
    pub overrides: Vec<Override>,
    /// The override copies of MaterialX documents whose nodes read converted colour
    /// textures (the document given, or those the stage references).
    pub documents: Vec<DocumentPlan>,
    /// The stage's references to those documents, pointed at their copies in the layer.
    pub references: Vec<Retarget>,
    /// UsdShade's render context of the spectral networks ([`RENDER_CONTEXT`]).
    pub render_context: &'static str,
    /// The variant set that switches a referenced document to its copy ([`VARIANT_SET`]).
    pub variant_set: &'static str,
}

/// UsdShade's render context behind which the layer gives spectral renderers the spectral
/// files (`outputs:spectral:surface`): the one name the writer and the messages use.
pub const RENDER_CONTEXT: &str = "spectral";

/// The variant set on a prim referencing a MaterialX document, `rgb` selected, whose other
/// choice, named as the render context ([`RENDER_CONTEXT`]), adds the document's copy.
pub const VARIANT_SET: &str = "spectralTextures";

impl LayerPlan {
    /// What the layer (or a document's copy) gives spectral renderers, in a line.
    pub fn line(&self) -> String {
        let in_copies: usize = self.documents.iter().map(|d| d.overrides.len()).sum();
        if crate::file_names::is_document(&self.stage) {
            return format!(
                "copy {} of {}: {in_copies} image node(s) pointed at spectral files",
                self.layer.display(),
                self.stage.display()
            );
        }
        let copies = match self.documents.len() {
            0 => String::new(),
            1 => format!(", and {in_copies} image node(s) in a MaterialX copy"),
            n => format!(", and {in_copies} image node(s) in {n} MaterialX copies"),
        };
        let variant = match self.documents.is_empty() {
            true => String::new(),
            false => format!(" (variant {} = {})", self.variant_set, self.render_context),
        };
        format!(
            "layer {} over {}: {} texture node(s) given spectral files in the render context \
             `{}`{copies}{variant}",
            self.layer.display(),
            self.stage.display(),
            self.overrides.len(),
            self.render_context
        )
    }
}

/// A MaterialX document's override copy: the document with its XIncludes written in, its
/// filenames absolute, and its nodes' file inputs pointed at spectral files
/// (docs/assets.md).
#[derive(Debug, Clone, Serialize)]
pub struct DocumentPlan {
    /// The original document.
    pub source: PathBuf,
    /// The copy: `DIR/STEM_spectral.mtlx`.
    pub layer: PathBuf,
    /// Its nodes' overrides (`node` is the element's name path).
    pub overrides: Vec<Override>,
}

/// A reference to a MaterialX document, deleted in the layer and replaced by one to the
/// document's copy.
#[derive(Debug, Clone, Serialize)]
pub struct Retarget {
    /// The reference.
    #[serde(flatten)]
    pub reference: MtlxReference,
    /// The copy, relative to the layer.
    pub file: String,
}

/// `inputs:file` of one node, pointed at a spectral file (in the copy of its network that the
/// layer makes for the render context `spectral`).
#[derive(Debug, Clone, Serialize)]
pub struct Override {
    /// The node's prim path.
    pub node: String,
    /// The spectral file, relative to the layer (`./tex/rock_albedo_spectral.exr`).
    pub file: String,
    /// `inputs:file` as the stage wrote it.
    pub original: Option<String>,
    /// As it resolved.
    pub original_resolved: Option<PathBuf>,
    /// The node's input that names the file (`file`, `filename`).
    pub file_input: String,
    /// The node's data uses: in the spectral choice, each still reads the original file (the
    /// USD copy's input connected to the original network; in a MaterialX copy, to a copy of
    /// the image that keeps it).
    pub keep: Vec<Kept>,
    /// How the copy reads the spectral file as written (`sourceColorSpace` `raw` for a
    /// UsdUVTexture): the spectra are linear ([`crate::stage::Node::raw_input`]).
    pub raw_input: Option<serde_json::Value>,
    /// The `colorSpace` the stage gave `inputs:file` (MaterialX's `colorspace`): the layer sets
    /// it to `raw` (the spectral file is read as written, like `sourceColorSpace` `raw`) and
    /// records this one.
    pub original_colorspace: Option<String>,
}

/// A data use that keeps the original file: the input `input` of the shader `shader` (a prim
/// path, or a MaterialX element's name path).
#[derive(Debug, Clone, Serialize)]
pub struct Kept {
    /// The shader.
    pub shader: String,
    /// Its input.
    pub input: String,
}

/// Where the packaged textures of `stage` are copied out to, under `dir`.
pub fn extract_dir(stage: &Path, dir: &Path) -> PathBuf {
    let mut name = stage.file_stem().unwrap_or_default().to_os_string();
    name.push("_usdz");
    dir.join(name)
}

/// The layer's path: `DIR/STEM_spectral.usda`; for a MaterialX document, its override copy
/// `DIR/STEM_spectral.mtlx`.
pub fn layer_path(stage: &Path, dir: &Path) -> PathBuf {
    let mut name = stage.file_stem().unwrap_or_default().to_os_string();
    name.push(match crate::file_names::is_document(stage) {
        true => "_spectral.mtlx",
        false => "_spectral.usda",
    });
    dir.join(name)
}

impl Asset {
    /// The plan of `stage` (as [`crate::Reader::read`] gave it) into `dir`, the colour spaces
    /// named in `config`, each file seen as a conversion with `options` reads it (its
    /// subimage and channels). A stage that did not compose is refused whole: a texture may
    /// be missing from it.
    pub fn new(
        stage: Stage,
        dir: &Path,
        (config, options): (&ColourConfig, &Options),
    ) -> Result<Asset, Error> {
        if let Some(first) = stage.composition_errors.first() {
            return Err(Error::Composition {
                stage: stage.stage.clone(),
                first: first.clone(),
                more: stage.composition_errors.len() - 1,
            });
        }
        let stage_dir = stage.stage.parent().unwrap_or(Path::new("/")).to_path_buf();
        let mut textures: Vec<Planned> = group(stage.textures)
            .into_iter()
            .map(|(file, nodes)| planned(file, nodes, (&stage_dir, dir), (config, options)))
            .collect();
        disambiguate(&mut textures, &stage.read_files);
        Ok(Asset {
            layer: layer_path(&stage.stage, dir),
            stage: stage.stage,
            dir: dir.to_path_buf(),
            materials: stage.materials,
            bound_prims: stage.bound_prims,
            textures,
            references: stage.references,
            read_files: stage.read_files,
            unknown: stage.unknown,
            writes: Vec::new(),
        })
    }

    /// The conversions, UDIM patterns expanded into the tiles that exist; textures that cannot
    /// be planned (a pattern with no tile) get their error instead. Folders are not looked
    /// at: the batch checks the whole plan before its first write.
    pub fn jobs(&mut self) -> Vec<Job> {
        let mut jobs = Vec::new();
        for (k, t) in self.textures.iter_mut().enumerate() {
            let Some(output) = t.output.clone() else {
                continue;
            };
            let input = t.texture.file.clone();
            let job = |input: PathBuf, output: PathBuf| Job {
                texture: k,
                input,
                output,
                colorspace: t.colorspace.clone(),
            };
            match udim::expand(&input) {
                Ok(None) => jobs.push(job(input, output)),
                Ok(Some(tiles)) => jobs.extend(
                    tiles
                        .into_iter()
                        .map(|tile| job(tile.path, udim::substitute(&output, tile.number))),
                ),
                Err(e) => t.error = Some(e.to_string()),
            }
        }
        self.conflicting_reads(&mut jobs);
        jobs
    }

    /// One file read by two textures (a UDIM pattern's tile and the tile by its own name, or
    /// two patterns) that are decided differently (colour and data, two colour spaces) is a
    /// conflict, as two uses of one file are (issue 57, item 6): neither texture is converted,
    /// and each says why.
    fn conflicting_reads(&mut self, jobs: &mut Vec<Job>) {
        let mut readers: std::collections::BTreeMap<&Path, Vec<usize>> = Default::default();
        for j in jobs.iter() {
            let ks = readers.entry(j.input.as_path()).or_default();
            if !ks.contains(&j.texture) {
                ks.push(j.texture);
            }
        }
        let role = |k: usize| {
            let t = &self.textures[k];
            (t.texture.decision.rule(), t.colorspace.clone())
        };
        let mut errors: Vec<(usize, String)> = Vec::new();
        for (file, ks) in &readers {
            let Some(&first) = ks.first() else { continue };
            if ks.iter().all(|&k| role(k) == role(first)) {
                continue;
            }
            let each: Vec<String> = ks
                .iter()
                .map(|&k| {
                    let t = &self.textures[k];
                    format!(
                        "{} ({})",
                        t.texture.file.display(),
                        t.texture.decision.rule()
                    )
                })
                .collect();
            let why = format!(
                "not converted: {} is read as {} (make the material say one thing)",
                file.display(),
                each.join(" and as ")
            );
            errors.extend(ks.iter().map(|&k| (k, why.clone())));
        }
        for (k, why) in errors {
            self.textures[k].error.get_or_insert(why);
        }
        // Linear in the jobs: 3,000 UDIM tiles are a normal asset.
        let failed: Vec<bool> = self.textures.iter().map(|t| t.error.is_some()).collect();
        jobs.retain(|j| !failed[j.texture]);
    }

    /// With `--data fail`: texture `k`, when it is data, becomes a failure (its error says
    /// why); whether it did.
    pub fn fail_data(&mut self, k: usize) -> bool {
        let t = &mut self.textures[k];
        let Decision::Data { why, .. } = &t.texture.decision else {
            return false;
        };
        t.error = Some(format!(
            "a data texture ({why}), never uplifted; the data policy fail counts it as a failure"
        ));
        true
    }

    /// The layer pointing every node of each colour texture for which `done` holds at its
    /// output: USD prims in the layer, MaterialX nodes in their documents' copies.
    pub fn layer_plan(&self, done: impl Fn(usize) -> bool) -> LayerPlan {
        let mut overrides = Vec::new();
        let mut documents: Vec<DocumentPlan> = Vec::new();
        for (k, t) in self.textures.iter().enumerate() {
            let colour = matches!(t.texture.decision, Decision::Colour { .. });
            let Some(output) = t.output.as_ref().filter(|_| colour && done(k)) else {
                continue;
            };
            let rel = output.strip_prefix(&self.dir).unwrap_or(output);
            for n in &t.texture.nodes {
                // A node that only feeds data keeps its file: its material is not touched.
                if !n.uses.iter().any(takes_colour) && n.uses.iter().any(takes_data) {
                    continue;
                }
                let keep = n
                    .uses
                    .iter()
                    .filter(|u| takes_data(u))
                    .map(|u| Kept {
                        shader: u.shader.clone(),
                        input: u.input.clone(),
                    })
                    .collect();
                let o = Override {
                    keep,
                    node: n.node.clone(),
                    file: format!("./{}", rel.to_string_lossy()),
                    original: n.authored.clone(),
                    original_resolved: n.resolved.clone(),
                    file_input: n.file_input.clone(),
                    raw_input: n.raw_input.clone(),
                    original_colorspace: n.colorspace.clone(),
                };
                match &n.document {
                    None => overrides.push(o),
                    Some(doc) => self.document_of(&mut documents, doc).overrides.push(o),
                }
            }
        }
        let references = self
            .references
            .iter()
            .filter_map(|r| {
                let d = documents.iter().find(|d| d.source == r.resolved)?;
                let name = d.layer.file_name()?.to_string_lossy();
                Some(Retarget {
                    reference: r.clone(),
                    file: format!("./{name}"),
                })
            })
            .collect();
        let layer_dir = self.layer.parent().unwrap_or(&self.dir);
        LayerPlan {
            layer: self.layer.clone(),
            sublayer: anchored(layer_dir, &self.stage),
            stage: self.stage.clone(),
            overrides,
            documents,
            references,
            render_context: RENDER_CONTEXT,
            variant_set: VARIANT_SET,
        }
    }

    /// The copy of document `doc` in `documents`, added if missing: the layer itself for the
    /// document given, else `DIR/STEM_spectral.mtlx` (`STEM_HASH_spectral.mtlx` where two
    /// referenced documents share a stem).
    fn document_of<'a>(
        &self,
        documents: &'a mut Vec<DocumentPlan>,
        doc: &Path,
    ) -> &'a mut DocumentPlan {
        if let Some(k) = documents.iter().position(|d| d.source == doc) {
            return &mut documents[k];
        }
        let layer = if doc == self.stage {
            self.layer.clone()
        } else {
            let plain = layer_path(doc, &self.dir);
            let taken = |p: &Path| p == self.layer || documents.iter().any(|d| d.layer == p);
            if taken(&plain) {
                let hash = Sha256::digest(doc.as_os_str().as_encoded_bytes());
                let hex: String = hash[..4].iter().map(|b| format!("{b:02x}")).collect();
                let stem = doc.file_stem().unwrap_or_default().to_string_lossy();
                self.dir.join(format!("{stem}_{hex}_spectral.mtlx"))
            } else {
                plain
            }
        };
        documents.push(DocumentPlan {
            source: doc.to_path_buf(),
            layer,
            overrides: Vec::new(),
        });
        documents.last_mut().expect("just pushed")
    }
}

/// The nodes of each file, files in the order of their first node; a node whose file does not
/// resolve is its own (missing) texture.
fn group(nodes: Vec<Node>) -> Vec<(Option<PathBuf>, Vec<Node>)> {
    let mut order: Vec<(Option<PathBuf>, Vec<Node>)> = Vec::new();
    let mut index: BTreeMap<PathBuf, usize> = BTreeMap::new();
    for n in nodes {
        match n.resolved.clone() {
            Some(file) => match index.get(&file) {
                Some(&k) => order[k].1.push(n),
                None => {
                    index.insert(file.clone(), order.len());
                    order.push((Some(file), vec![n]));
                }
            },
            None => order.push((None, vec![n])),
        }
    }
    order
}

/// One file's decision, output and colour space.
fn planned(
    file: Option<PathBuf>,
    nodes: Vec<Node>,
    (stage_dir, dir): (&Path, &Path),
    (config, options): (&ColourConfig, &Options),
) -> Planned {
    let Some(file) = file else {
        let n = &nodes[0];
        let authored = n.authored.as_deref().unwrap_or("");
        let written = n
            .layer
            .as_ref()
            .map(|l| format!(" (written in {})", l.display()))
            .unwrap_or_default();
        let why = if authored.to_ascii_lowercase().contains("<uvtile>") {
            // Mudbox's tile names (u1_v1): not read; said by name (issue 56, item 4).
            format!(
                "the texture '{authored}' that {} reads{written} names its tiles with \
                 <UVTILE> (u1_v1, u2_v1, …), which specconv asset does not read: name the \
                 tiles by UDIM number and the file with <UDIM> (wood.1001.png, \
                 wood.<UDIM>.png)",
                n.node
            )
        } else {
            let at = n
                .looked_for
                .as_ref()
                .map(|p| format!(" (looked for at {})", p.display()))
                .unwrap_or_default();
            format!(
                "the texture '{authored}'{at} that {} reads does not exist{}",
                n.node,
                n.layer
                    .as_ref()
                    .map(|l| format!(
                        " (written in {}; fix the path or add the file)",
                        l.display()
                    ))
                    .unwrap_or_default()
            )
        };
        let texture = Texture {
            file: PathBuf::from(n.authored.clone().unwrap_or_default()),
            decision: Decision::Missing { why: why.clone() },
            nodes,
        };
        return not_converted(texture, why);
    };
    let mut decision = decide(&nodes);
    let grey = grey_colour(&decision, &file, (config, options));
    if let (Decision::Colour { why, .. }, Some(space)) = (&mut decision, &grey) {
        why.push_str(&format!(
            "; one channel, which the data-map rule alone would take as data: the material \
             calls it colour, so it is uplifted as grey in {space}, the space the file's \
             evidence gives"
        ));
    }
    let texture = Texture {
        file: file.clone(),
        nodes,
        decision,
    };
    let space = match &texture.decision {
        Decision::Colour { .. } if grey.is_some() => Ok(grey),
        Decision::Colour { space, .. } => colour_space(space, config),
        Decision::Data { .. } => named(config, "data"),
        Decision::Conflict { why } => {
            let why = format!("not converted: {why} (make the material say one thing)");
            return not_converted(texture, why);
        }
        Decision::Missing { why } | Decision::Undecided { why } => {
            let why = format!("not converted: {why}");
            return not_converted(texture, why);
        }
    };
    match space {
        Ok(colorspace) => Planned {
            output: Some(output_for(stage_dir, dir, &file, holds(&texture.decision))),
            colorspace,
            error: None,
            texture,
        },
        Err(why) => not_converted(texture, why),
    }
}

/// For a colour texture whose space the file decides, and whose file is one channel that the
/// data-map rule of docs/colour.md would make data: the space rows 4 to 6 give it. The material
/// is stronger evidence than that rule (it says colour), so the texture is uplifted as grey,
/// in that space, named to the conversion. `None` otherwise (or when the file cannot be read:
/// the conversion says why).
fn grey_colour(
    decision: &Decision,
    file: &Path,
    (config, options): (&ColourConfig, &Options),
) -> Option<String> {
    let Decision::Colour {
        space: Space::File, ..
    } = decision
    else {
        return None;
    };
    // A UDIM pattern: its first tile speaks for the set.
    let tile = match udim::expand(file) {
        Ok(Some(tiles)) => tiles.into_iter().next()?.path,
        Ok(None) => file.to_path_buf(),
        Err(_) => return None,
    };
    let described = specconv_conversion::describe(config, &tile, options).ok()?;
    match described.colour {
        Ok(specconv_conversion::ReadAs::Data { rule, .. }) => {
            rule.colour_after_all().map(str::to_string)
        }
        _ => None,
    }
}

/// What a texture's output holds: a data texture's copy is named as data, as `convert` names
/// it (`specconv_atomic_file::outputs::Holds`).
fn holds(decision: &Decision) -> Holds {
    match decision {
        Decision::Data { .. } => Holds::Data,
        _ => Holds::Spectral,
    }
}

fn not_converted(texture: Texture, why: String) -> Planned {
    Planned {
        texture,
        output: None,
        colorspace: None,
        error: Some(why),
    }
}

/// The config's name for a declared space; `None`: the file decides.
fn colour_space(space: &Space, config: &ColourConfig) -> Result<Option<String>, String> {
    match space {
        Space::File => Ok(None),
        Space::Srgb => match config.srgb_texture() {
            Ok(Some(name)) => Ok(Some(name)),
            _ => Err("sourceColorSpace sRGB, and the config has no sRGB texture space".into()),
        },
        Space::Linear => named(config, "lin_rec709_scene"),
        Space::Named(name) => match config.named_space(name) {
            Ok(Some(Ok(found))) => Ok(Some(found)),
            _ => match materialx_space(name) {
                Some(id) => named(config, id),
                None => Err(format!(
                    "the colour space '{name}' the material names is neither a colour space of the config \
                     nor a MaterialX name (docs/assets.md lists them)"
                )),
            },
        },
    }
}

/// The config's space for a name or Color Interop Forum ID.
fn named(config: &ColourConfig, id: &str) -> Result<Option<String>, String> {
    match config.named_space(id) {
        Ok(Some(Ok(name))) => Ok(Some(name)),
        Ok(Some(Err(why))) => Err(why),
        Ok(None) => Ok(None),
        Err(e) => Err(e.to_string()),
    }
}

/// `DIR/SUB/STEM_spectral.exr` (`STEM_data.exr` for a data texture): SUB is the file's folder
/// below the stage's (or below DIR, for a texture copied out of a usdz), else `external/HASH`
/// of its folder; never outside DIR.
pub fn output_for(stage_dir: &Path, dir: &Path, file: &Path, holds: Holds) -> PathBuf {
    let folder = file.parent().unwrap_or(Path::new(""));
    let below = |root: &Path| {
        folder
            .strip_prefix(root)
            .ok()
            .filter(|r| r.components().all(|c| matches!(c, Component::Normal(_))))
            .map(Path::to_path_buf)
    };
    let sub = below(dir).or_else(|| below(stage_dir)).unwrap_or_else(|| {
        let hash = Sha256::digest(folder.as_os_str().as_encoded_bytes());
        let hex: String = hash[..4].iter().map(|b| format!("{b:02x}")).collect();
        Path::new("external").join(hex)
    });
    dir.join(sub).join(output_name(file, Distinct::Stem, holds))
}

/// How much of a texture's own path its output's name carries.
#[derive(Clone, Copy, PartialEq)]
enum Distinct {
    /// The stem: `STEM_spectral.exr`.
    Stem,
    /// The extension too (two textures of one stem): `STEM_EXT_spectral.exr`.
    Extension,
    /// And a hash of the texture's path, where names still meet: `STEM_EXT_HASH_spectral.exr`.
    Path,
}

/// `STEM_spectral.exr`, `STEM_spectral.<UDIM>.exr` for a pattern, with the extension and the
/// path's hash as `distinct` says; `data` for `spectral` when it holds data.
fn output_name(file: &Path, distinct: Distinct, holds: Holds) -> String {
    let word = holds.word();
    let name = file.file_name().unwrap_or_default().to_string_lossy();
    let (base, extension) = match name.rfind('.') {
        Some(i) if i > 0 => (&name[..i], &name[i + 1..]),
        _ => (&name[..], ""),
    };
    let with_ext = |stem: &str| {
        let mut stem = stem.to_owned();
        if distinct != Distinct::Stem && !extension.is_empty() {
            stem = format!("{stem}_{extension}");
        }
        if distinct == Distinct::Path {
            let hash = Sha256::digest(file.as_os_str().as_encoded_bytes());
            let hex: String = hash[..4].iter().map(|b| format!("{b:02x}")).collect();
            stem = format!("{stem}_{hex}");
        }
        stem
    };
    match base.to_ascii_lowercase().find("<udim>") {
        Some(i) => {
            let stem = base[..i].trim_end_matches(['.', '_']);
            format!("{}_{word}.<UDIM>.exr", with_ext(stem))
        }
        None => format!("{}_{word}.exr", with_ext(base)),
    }
}

/// `path` as a path relative to folder `from` that USD anchors to the layer (`./s.usda`,
/// `../shot/s.usda`): a relative path that starts with neither `./` nor `../` is a search
/// path to USD's resolver. Both absolute; compared by their components, as written.
pub fn anchored(from: &Path, path: &Path) -> String {
    let (a, b): (Vec<_>, Vec<_>) = (from.components().collect(), path.components().collect());
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..a.len() {
        out.push("..");
    }
    for c in &b[common..] {
        out.push(c);
    }
    let text = out.to_string_lossy().into_owned();
    match text.starts_with("../") {
        true => text,
        false => format!("./{text}"),
    }
}

/// Makes every output name its own (issue 57, item 11): two textures of one folder and stem
/// (`a.png`, `a.tx`) get their extensions in the name; where names still meet (`a.png` and
/// `a_png.png`), or an output would be a file the asset reads (`tex/a.png` beside
/// `tex/a_spectral.exr`), the texture's path's hash too. Names depend on the paths alone, so
/// a run again gives the same ones, and the record (`record.rs`) holds them.
fn disambiguate(textures: &mut [Planned], read: &[PathBuf]) {
    for distinct in [Distinct::Extension, Distinct::Path] {
        let mut seen: BTreeMap<PathBuf, usize> = BTreeMap::new();
        for t in textures.iter() {
            if let Some(o) = &t.output {
                *seen.entry(o.clone()).or_default() += 1;
            }
        }
        let inputs: BTreeSet<PathBuf> = textures
            .iter()
            .map(|t| t.texture.file.clone())
            .chain(read.iter().cloned())
            .collect();
        for t in textures.iter_mut() {
            let clash = |o: &PathBuf| seen.get(o) > Some(&1) || inputs.contains(o);
            if let Some(o) = t.output.as_mut().filter(|o| clash(o)) {
                *o = o.with_file_name(output_name(
                    &t.texture.file,
                    distinct,
                    holds(&t.texture.decision),
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_stay_inside_dir() {
        let named = |f: &str, h| output_for(Path::new("/s"), Path::new("/out"), Path::new(f), h);
        let out = |f: &str| named(f, Holds::Spectral);
        assert_eq!(out("/s/tex/a.png"), Path::new("/out/tex/a_spectral.exr"));
        // A data texture written through is named as data, as `convert -o DIR` names it.
        assert_eq!(
            named("/s/tex/a.<UDIM>.png", Holds::Data),
            Path::new("/out/tex/a_data.<UDIM>.exr")
        );
        assert_eq!(
            out("/s/tex/wood.<UDIM>.png"),
            Path::new("/out/tex/wood_spectral.<UDIM>.exr")
        );
        assert_eq!(
            out("/out/x_usdz/0/a.png"),
            Path::new("/out/x_usdz/0/a_spectral.exr")
        );
        for outside in ["/etc/hostname", "/s/../etc/a.png", "/dev/zero"] {
            let o = out(outside);
            assert!(o.starts_with("/out/external/"), "{}", o.display());
            assert!(o.components().all(|c| c != Component::ParentDir));
        }
    }

    /// Issue 57, item 11: outputs that would meet after the extension is added, or land on a
    /// file the asset reads, get the path's hash; every name is then its own, and the same on
    /// a second plan.
    #[test]
    fn every_output_name_is_its_own_and_never_a_file_read() {
        let plan = || {
            let mut textures: Vec<Planned> = ["a.png", "a.tif", "a_png.png", "b.png", "c.png"]
                .iter()
                .map(|name| {
                    let file = Path::new("/s/tex").join(name);
                    Planned {
                        output: Some(output_for(
                            Path::new("/s"),
                            Path::new("/s"),
                            &file,
                            Holds::Spectral,
                        )),
                        texture: Texture {
                            file,
                            nodes: vec![],
                            decision: Decision::Colour {
                                space: Space::File,
                                rule: "test",
                                why: String::new(),
                            },
                        },
                        colorspace: None,
                        error: None,
                    }
                })
                .collect();
            disambiguate(&mut textures, &["/s/tex/b_spectral.exr".into()]);
            textures
                .into_iter()
                .map(|t| t.output.unwrap())
                .collect::<Vec<PathBuf>>()
        };
        let outputs = plan();
        let names: BTreeSet<&PathBuf> = outputs.iter().collect();
        assert_eq!(names.len(), outputs.len(), "{outputs:?}");
        assert!(!outputs.contains(&PathBuf::from("/s/tex/b_spectral.exr")));
        assert_eq!(outputs[1], Path::new("/s/tex/a_tif_spectral.exr"));
        assert_eq!(outputs[4], Path::new("/s/tex/c_spectral.exr"));
        // a.png and a_png.png met at a_png_spectral.exr: each gets its path's hash.
        for (o, stem) in [(&outputs[0], "a_png_"), (&outputs[2], "a_png_png_")] {
            let name = o.file_name().unwrap().to_string_lossy();
            let hash = name
                .strip_prefix(stem)
                .and_then(|n| n.strip_suffix("_spectral.exr"));
            assert!(
                hash.is_some_and(|h| h.len() == 8 && h.bytes().all(|b| b.is_ascii_hexdigit())),
                "{name}"
            );
        }
        assert_eq!(plan(), outputs);
    }

    #[test]
    fn a_path_relative_to_the_layer_is_anchored() {
        let a = |from: &str, to: &str| anchored(Path::new(from), Path::new(to));
        assert_eq!(a("/s/out", "/s/shot.usda"), "../shot.usda");
        assert_eq!(a("/s", "/s/shot.usda"), "./shot.usda");
        assert_eq!(a("/s/out", "/s/out/tex/a.exr"), "./tex/a.exr");
        assert_eq!(a("/x/y", "/s/shot.usda"), "../../s/shot.usda");
    }

    fn node(path: &str, document: Option<&str>) -> Node {
        Node {
            node: path.into(),
            node_id: Some("ND_image_color3".into()),
            file_input: "file".into(),
            raw_input: None,
            looked_for: None,
            source_color_space: None,
            colorspace: Some("srgb_texture".into()),
            authored: Some("tex/a.png".into()),
            resolved: Some("/s/tex/a.png".into()),
            layer: None,
            package: None,
            uses: vec![],
            document: document.map(PathBuf::from),
        }
    }

    #[test]
    fn materialx_nodes_go_to_their_documents_copies_and_one_stem_twice_is_told_apart() {
        let reference = |doc: &str| MtlxReference {
            prim: "/World/Looks/Brick".into(),
            arc: "references".into(),
            asset: "./brick.mtlx".into(),
            resolved: doc.into(),
            target: "/MaterialX/Materials/M".into(),
            offset: 0.0,
            scale: 1.0,
        };
        let texture = Texture {
            file: "/s/tex/a.png".into(),
            nodes: vec![
                node("/World/Looks/Rock/Albedo", None),
                node("NG/img", Some("/s/a/brick.mtlx")),
                node("img", Some("/s/b/brick.mtlx")),
            ],
            decision: Decision::Colour {
                space: Space::Named("srgb_texture".into()),
                rule: "materialx-colorspace",
                why: String::new(),
            },
        };
        let mut asset = Asset {
            stage: "/s/shot.usda".into(),
            dir: "/out".into(),
            layer: layer_path(Path::new("/s/shot.usda"), Path::new("/out")),
            materials: 2,
            bound_prims: 1,
            textures: vec![Planned {
                texture,
                output: Some("/out/tex/a_spectral.exr".into()),
                colorspace: None,
                error: None,
            }],
            references: vec![reference("/s/a/brick.mtlx"), reference("/s/c/other.mtlx")],
            read_files: Vec::new(),
            unknown: Vec::new(),
            writes: Vec::new(),
        };
        let plan = asset.layer_plan(|_| true);
        assert_eq!(plan.overrides.len(), 1);
        let layers: Vec<&Path> = plan.documents.iter().map(|d| d.layer.as_path()).collect();
        assert_eq!(layers[0], Path::new("/out/brick_spectral.mtlx"));
        let second = layers[1].to_string_lossy();
        assert!(second.starts_with("/out/brick_") && second.ends_with("_spectral.mtlx"));
        assert_ne!(layers[0], layers[1]);
        assert_eq!(plan.documents[1].overrides[0].file, "./tex/a_spectral.exr");
        // Only a reference to a document with a copy is retargeted.
        assert_eq!(plan.references.len(), 1);
        assert_eq!(plan.references[0].file, "./brick_spectral.mtlx");
        // A document given alone: its copy is the layer; nothing is done when nothing is.
        asset.stage = "/s/brick.mtlx".into();
        asset.layer = layer_path(&asset.stage, &asset.dir);
        assert_eq!(asset.layer, Path::new("/out/brick_spectral.mtlx"));
        assert!(asset.layer_plan(|_| false).documents.is_empty());
    }
}
