//! The scene format of `specconv simulate` (TOML, read with serde) and how a scene file
//! becomes a [`Scene`]: the effect, the materials, the form factors and the lights, each rule
//! of the format checked with an error that says what to write instead.
//!
//! Reading files and converting colours are not this crate's: a [`Resolve`] given by the caller
//! reads measured spectra and turns a colour in a named colour space, or a texture pixel, into
//! XYZ as `convert` would.
//!
//! [`SceneFile`] and the types below it mirror the TOML, one field per key (docs/simulate.md
//! describes the format); [`build`] checks what serde cannot.

use crate::simulate::{self, Effect, Light, Material, Scene};
use serde::Deserialize;
use specconv_colour::{Colorimetry, Illuminant, SpectralTable};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The scene file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `bounces = K`: the series up to K reflections. Exactly one of this and `effect` is given.
    #[serde(default)]
    pub bounces: Option<usize>,
    /// `effect = "direct"` (K = 1) or `"converged"`.
    #[serde(default)]
    pub effect: Option<String>,
    /// `form_factors`: a preset name or a matrix.
    pub form_factors: FormFactors,
    /// Method names, as `--method` takes them.
    #[serde(default)]
    pub methods: Option<Vec<String>>,
    /// A built-in model by name, or a model file relative to the scene; the model in force
    /// (`$SPECCONV_MODEL`, else the built-in default) when absent.
    #[serde(default)]
    pub model: Option<PathBuf>,
    /// The OCIO config for colours and textures: a built-in name or a file relative to the scene.
    #[serde(default)]
    pub ocio: Option<String>,
    /// The `[[lights]]` tables; at least one is needed.
    #[serde(default)]
    pub lights: Vec<LightFile>,
    /// The `[[patches]]` tables; at least one is needed.
    #[serde(default)]
    pub patches: Vec<PatchFile>,
}

/// `form_factors`: a preset or the matrix itself.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum FormFactors {
    /// `"furnace"` (every patch sees only itself) or `"box"` (five walls named floor, ceiling,
    /// back, left, right); see [`simulate::furnace`] and [`simulate::room`].
    Preset(String),
    /// n×n form factors, row i the shares of patch i's light reaching each patch, in the order of
    /// the patches.
    Matrix(Vec<Vec<f64>>),
}

/// One `[[lights]]` table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightFile {
    /// A name for reports; the spectrum's name when `None`.
    #[serde(default)]
    pub name: Option<String>,
    /// Its relative spectral power distribution.
    pub spectrum: SpdFile,
    /// The factor on the spectrum (finite, ≥ 0).
    pub power: f64,
    /// The names of the patches that emit it; every patch when `None`.
    #[serde(default)]
    pub patches: Option<Vec<String>>,
}

/// A light's spectrum: an illuminant by name, or a column of a CSV file.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum SpdFile {
    /// An illuminant as `--illuminant` takes it (`D65`, `A`, `blackbody:5500`, …).
    Named(String),
    /// `{ file = "spd.csv", column = "…" }`: measured power from a spectral table.
    Csv {
        /// The CSV file, relative to the scene.
        file: PathBuf,
        /// The column's name; the first sample column when `None`.
        #[serde(default)]
        column: Option<String>,
    },
}

/// One `[[patches]]` table: a material given by exactly one of `colour`, `spectra` (with
/// `sample` or `samples`) and `texture` (with `pixel`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatchFile {
    /// The patch's name, as lights and the `box` preset refer to it; by default the sample's name,
    /// or the patch's number from 1.
    #[serde(default)]
    pub name: Option<String>,
    /// An RGB colour in `colorspace`, converted to XYZ by the [`Resolve`].
    #[serde(default)]
    pub colour: Option<[f64; 3]>,
    /// The colour space of `colour` or `texture`, as `--colorspace` takes it; the resolver's
    /// default when `None`.
    #[serde(default)]
    pub colorspace: Option<String>,
    /// A CSV file of measured spectra, relative to the scene.
    #[serde(default)]
    pub spectra: Option<PathBuf>,
    /// One sample of `spectra`, by its column name.
    #[serde(default)]
    pub sample: Option<String>,
    /// Several samples of `spectra`, one patch each.
    #[serde(default)]
    pub samples: Option<Samples>,
    /// A texture whose pixel is the colour, relative to the scene.
    #[serde(default)]
    pub texture: Option<PathBuf>,
    /// The pixel `[x, y]` of `texture`, from the top left.
    #[serde(default)]
    pub pixel: Option<[u32; 2]>,
}

/// `samples`: `"all"` or a list of names.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum Samples {
    /// A word; only `"all"` (every column of the table) is accepted.
    All(String),
    /// The names of the columns to take.
    List(Vec<String>),
}

/// An error of the resolver, kept as the cause.
pub type Cause = Box<dyn std::error::Error + Send + Sync>;

/// What a scene needs from outside the science. Paths are already joined to the scene's folder.
pub trait Resolve {
    /// The measured spectra of a CSV file.
    fn spectra(&mut self, path: &Path) -> Result<SpectralTable, Cause>;
    /// XYZ (white Y = 1) of a colour in colour space `space`, or in the default space for
    /// colours when `None`.
    fn colour(&mut self, rgb: [f64; 3], space: Option<&str>) -> Result<[f64; 3], Cause>;
    /// XYZ (white Y = 1) of pixel `[x, y]` of a texture, read as `convert` reads it.
    fn texture_pixel(
        &mut self,
        path: &Path,
        pixel: [u32; 2],
        space: Option<&str>,
    ) -> Result<[f64; 3], Cause>;
}

/// What is wrong with a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Not valid TOML, or not the scene format (unknown key, wrong type).
    #[error(transparent)]
    Syntax(#[from] toml::de::Error),
    /// `bounces` and `effect` both given, or neither.
    #[error("{0}")]
    Effect(&'static str),
    /// An `effect` other than `direct` and `converged`.
    #[error("unknown effect `{0}`; use \"direct\", \"converged\" or `bounces = K`")]
    UnknownEffect(String),
    /// A `[[patches]]` table that breaks a rule of the format.
    #[error("patch {patch}: {problem}")]
    Patch {
        /// The patch's name, or its number from 1.
        patch: String,
        /// What is wrong and what to write instead.
        problem: String,
    },
    /// A patch whose colour or texture pixel the resolver could not turn into XYZ.
    #[error("patch {patch}")]
    PatchSource {
        /// The patch's name, or its number from 1.
        patch: String,
        /// The resolver's error.
        #[source]
        source: Cause,
    },
    /// An unknown preset, or a `box` without its five walls.
    #[error("{0}")]
    FormFactors(String),
    /// A `[[lights]]` table that breaks a rule of the format (unknown column or patch).
    #[error("light {light}: {problem}")]
    Light {
        /// The light's number, from 1.
        light: usize,
        /// What is wrong.
        problem: String,
    },
    /// A CSV file of spectra the resolver could not read.
    #[error("cannot read {}", .path.display())]
    Spectra {
        /// The file, joined to the scene's folder.
        path: PathBuf,
        /// The resolver's error.
        #[source]
        source: Cause,
    },
    /// An unknown illuminant, or spectra that do not cover the grid.
    #[error(transparent)]
    Colour(#[from] specconv_colour::Error),
}

/// Reads a scene file's text.
///
/// ```
/// use specconv_evaluation::scene::{parse, FormFactors, SceneError, SpdFile};
///
/// let file = parse(
///     r#"
///     bounces = 2
///     form_factors = "furnace"
///
///     [[lights]]
///     spectrum = "blackbody:5500"
///     power = 1.0
///
///     [[patches]]
///     name = "grey"
///     colour = [0.5, 0.5, 0.5]
///     "#,
/// )?;
/// assert_eq!(file.bounces, Some(2));
/// assert!(matches!(&file.form_factors, FormFactors::Preset(p) if p == "furnace"));
/// assert!(matches!(&file.lights[0].spectrum, SpdFile::Named(n) if n == "blackbody:5500"));
/// assert_eq!(file.patches[0].colour, Some([0.5; 3]));
///
/// // Unknown keys are refused, not ignored.
/// let typo = parse("bounce = 2\nform_factors = \"box\"");
/// assert!(matches!(typo, Err(SceneError::Syntax(_))));
/// # Ok::<(), SceneError>(())
/// ```
pub fn parse(text: &str) -> Result<SceneFile, SceneError> {
    Ok(toml::from_str(text)?)
}

/// The scene of `file` (whose relative paths are relative to `dir`) on the grid of `a`, and the
/// name of its form factors ("furnace", "box" or "matrix").
pub fn build(
    file: &SceneFile,
    dir: &Path,
    a: &Colorimetry,
    resolve: &mut dyn Resolve,
) -> Result<(Scene, String), SceneError> {
    let effect = effect(file)?;
    let mut tables = Tables {
        dir,
        read: BTreeMap::new(),
    };
    let (mut names, mut materials) = (Vec::new(), Vec::new());
    for (i, p) in file.patches.iter().enumerate() {
        for (name, material) in patch(p, i, a, &mut tables, resolve)? {
            names.push(name);
            materials.push(material);
        }
    }
    let (form_factors, preset) = form_factors(file, &mut names, &mut materials)?;
    let lights = file
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| light(l, i + 1, &names, a, &mut tables, resolve))
        .collect::<Result<_, _>>()?;
    let scene = Scene {
        names,
        materials,
        form_factors,
        lights,
        effect,
    };
    Ok((scene, preset))
}

fn effect(file: &SceneFile) -> Result<Effect, SceneError> {
    match (file.bounces, file.effect.as_deref()) {
        (Some(k), None) => Ok(Effect::Bounces(k)),
        (None, Some("direct")) => Ok(Effect::Bounces(1)),
        (None, Some("converged")) => Ok(Effect::Converged),
        (None, Some(e)) => Err(SceneError::UnknownEffect(e.to_string())),
        (Some(_), Some(_)) => Err(SceneError::Effect(
            "give either `bounces = K` or `effect`, not both",
        )),
        (None, None) => Err(SceneError::Effect(
            "say what to compute: `bounces = K`, `effect = \"direct\"` or `effect = \"converged\"`",
        )),
    }
}

/// The measured-spectra files a scene names, each read once.
struct Tables<'a> {
    dir: &'a Path,
    read: BTreeMap<PathBuf, SpectralTable>,
}

impl Tables<'_> {
    fn get(
        &mut self,
        file: &Path,
        resolve: &mut dyn Resolve,
    ) -> Result<(PathBuf, &SpectralTable), SceneError> {
        let path = self.dir.join(file);
        if !self.read.contains_key(&path) {
            let table = resolve
                .spectra(&path)
                .map_err(|source| SceneError::Spectra {
                    path: path.clone(),
                    source,
                })?;
            self.read.insert(path.clone(), table);
        }
        let table = &self.read[&path];
        Ok((path, table))
    }
}

/// The patches one `[[patches]]` entry makes (several for `samples`), with their names.
fn patch(
    p: &PatchFile,
    i: usize,
    a: &Colorimetry,
    tables: &mut Tables,
    resolve: &mut dyn Resolve,
) -> Result<Vec<(String, Material)>, SceneError> {
    let label = p.name.clone().unwrap_or_else(|| (i + 1).to_string());
    let bad = |problem: String| SceneError::Patch {
        patch: label.clone(),
        problem,
    };
    let failed = |source: Cause| SceneError::PatchSource {
        patch: label.clone(),
        source,
    };
    if let Some(texture) = &p.texture {
        if p.colour.is_some() || p.spectra.is_some() || p.sample.is_some() || p.samples.is_some() {
            return Err(bad("give `texture` alone (with `pixel` and `colorspace`), not with `colour` or `spectra`".into()));
        }
        let pixel = p.pixel.ok_or_else(|| {
            bad("say which pixel of the texture: `pixel = [x, y]` (from the top left)".into())
        })?;
        let xyz = resolve
            .texture_pixel(&tables.dir.join(texture), pixel, p.colorspace.as_deref())
            .map_err(failed)?;
        return Ok(vec![(label.clone(), Material::Colour(xyz))]);
    }
    if p.pixel.is_some() {
        return Err(bad("`pixel` needs `texture = \"FILE\"`".into()));
    }
    match (&p.colour, &p.spectra) {
        (Some(c), None) => {
            if p.sample.is_some() || p.samples.is_some() {
                return Err(bad(
                    "`sample`/`samples` need `spectra = \"FILE.csv\"`".into()
                ));
            }
            let xyz = resolve
                .colour(*c, p.colorspace.as_deref())
                .map_err(failed)?;
            Ok(vec![(label.clone(), Material::Colour(xyz))])
        }
        (None, Some(file)) => {
            let (path, table) = tables.get(file, resolve)?;
            let wanted: Vec<String> = match (&p.sample, &p.samples) {
                (Some(s), None) => vec![s.clone()],
                (None, Some(Samples::List(v))) => v.clone(),
                (None, Some(Samples::All(s))) if s == "all" => table.names.clone(),
                (None, Some(Samples::All(s))) => {
                    return Err(bad(format!("samples = \"{s}\": use \"all\" or a list of names")))
                }
                (None, None) => return Err(bad("name the measured spectra: `sample = \"NAME\"`, `samples = [..]` or `samples = \"all\"`".into())),
                (Some(_), Some(_)) => return Err(bad("give `sample` or `samples`, not both".into())),
            };
            if p.name.is_some() && wanted.len() != 1 {
                return Err(bad(format!(
                    "`name` names one patch, but {} samples are asked for",
                    wanted.len()
                )));
            }
            wanted
                .into_iter()
                .map(|s| {
                    let k =
                        table.names.iter().position(|n| *n == s).ok_or_else(|| {
                            bad(format!(
                            "unknown sample `{s}` in {} (it has {} samples, e.g. {}); check the \
                             name against the CSV header",
                            path.display(),
                            table.names.len(),
                            table.names.iter().take(3).cloned().collect::<Vec<_>>().join(", ")
                        ))
                        })?;
                    let spectrum =
                        a.grid
                            .resample(&table.source, &table.wavelengths, &table.columns[k])?;
                    Ok((p.name.clone().unwrap_or(s), Material::Measured(spectrum)))
                })
                .collect()
        }
        (Some(_), Some(_)) => Err(bad("give `colour` or `spectra`, not both".into())),
        (None, None) => Err(bad(
            "give a material: `colour = [R, G, B]` (with `colorspace`) or `spectra = \"FILE.csv\"`"
                .into(),
        )),
    }
}

/// The form factors, with the patches reordered to the walls of the `box` preset.
fn form_factors(
    file: &SceneFile,
    names: &mut Vec<String>,
    materials: &mut Vec<Material>,
) -> Result<(Vec<Vec<f64>>, String), SceneError> {
    let n = materials.len();
    match &file.form_factors {
        FormFactors::Preset(p) if p == "furnace" => Ok((simulate::furnace(n), "furnace".into())),
        FormFactors::Preset(p) if p == "box" => {
            let walls = simulate::BOX_WALLS.join(", ");
            let order = simulate::BOX_WALLS
                .iter()
                .map(|wall| {
                    names.iter().position(|x| x == wall).ok_or_else(|| {
                        SceneError::FormFactors(format!(
                            "the box preset needs five patches named {walls}; `{wall}` is missing"
                        ))
                    })
                })
                .collect::<Result<Vec<usize>, _>>()?;
            if n != 5 {
                return Err(SceneError::FormFactors(format!(
                    "the box preset has five walls ({walls}), the scene {n} patches"
                )));
            }
            *names = order.iter().map(|&i| names[i].clone()).collect();
            *materials = order.iter().map(|&i| materials[i].clone()).collect();
            Ok((simulate::room(), "box".into()))
        }
        FormFactors::Preset(p) => Err(SceneError::FormFactors(format!(
            "unknown form-factor preset `{p}`; use \"furnace\", \"box\" or a matrix"
        ))),
        FormFactors::Matrix(m) => Ok((m.clone(), "matrix".into())),
    }
}

/// Light `number` (from 1): its spectrum on the grid and the patches that emit it.
fn light(
    l: &LightFile,
    number: usize,
    names: &[String],
    a: &Colorimetry,
    tables: &mut Tables,
    resolve: &mut dyn Resolve,
) -> Result<Light, SceneError> {
    let bad = |problem: String| SceneError::Light {
        light: number,
        problem,
    };
    let (label, spd) = match &l.spectrum {
        SpdFile::Named(s) => {
            let ill: Illuminant = s.parse()?;
            (ill.to_string(), ill.spd(&a.grid)?)
        }
        SpdFile::Csv { file, column } => {
            let (path, t) = tables.get(file, resolve)?;
            let k = match column {
                None => 0,
                Some(c) => t
                    .names
                    .iter()
                    .position(|n| n == c)
                    .ok_or_else(|| bad(format!("no column `{c}` in {}", path.display())))?,
            };
            (
                format!("{}:{}", path.display(), t.names[k]),
                a.grid.resample(&t.source, &t.wavelengths, &t.columns[k])?,
            )
        }
    };
    let patches = match &l.patches {
        None => (0..names.len()).collect(),
        Some(list) => list
            .iter()
            .map(|p| {
                names.iter().position(|x| x == p).ok_or_else(|| {
                    bad(format!(
                        "no patch named `{p}`; patches are {}",
                        names.join(", ")
                    ))
                })
            })
            .collect::<Result<_, _>>()?,
    };
    Ok(Light {
        name: l.name.clone().unwrap_or(label),
        spd,
        power: l.power,
        patches,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::{Grid, Observer};

    /// A resolver with no files: every colour is mid grey, and nothing can be read.
    struct NoFiles;

    impl Resolve for NoFiles {
        fn spectra(&mut self, path: &Path) -> Result<SpectralTable, Cause> {
            Err(format!("no file {} here", path.display()).into())
        }
        fn colour(&mut self, _: [f64; 3], _: Option<&str>) -> Result<[f64; 3], Cause> {
            Ok([0.2, 0.21, 0.23])
        }
        fn texture_pixel(
            &mut self,
            _: &Path,
            _: [u32; 2],
            _: Option<&str>,
        ) -> Result<[f64; 3], Cause> {
            Err("no textures here".into())
        }
    }

    fn built(text: &str) -> Result<(Scene, String), SceneError> {
        let a = Colorimetry::new(Grid::PAPER, Observer::Wyman2013, Illuminant::E).unwrap();
        build(&parse(text)?, Path::new("scenes"), &a, &mut NoFiles)
    }

    #[test]
    fn each_broken_rule_has_its_own_error() {
        let patch =
            "[[lights]]\nspectrum = \"D65\"\npower = 1\n[[patches]]\ncolour = [0.5, 0.5, 0.5]\n";
        let ok = built(&format!("bounces = 2\nform_factors = \"furnace\"\n{patch}")).unwrap();
        assert_eq!((ok.0.names.len(), ok.1.as_str()), (1, "furnace"));
        assert!(matches!(built("bounce = 1\n"), Err(SceneError::Syntax(_))));
        assert!(matches!(
            built("form_factors = \"furnace\"\n"),
            Err(SceneError::Effect(_))
        ));
        assert!(matches!(
            built("effect = \"twice\"\nform_factors = \"furnace\"\n"),
            Err(SceneError::UnknownEffect(e)) if e == "twice"
        ));
        assert!(matches!(
            built(&format!("bounces = 1\nform_factors = \"box\"\n{patch}")),
            Err(SceneError::FormFactors(m)) if m.contains("floor")
        ));
        let e = built(
            "bounces = 1\nform_factors = \"furnace\"\n[[patches]]\nname = \"p\"\npixel = [1, 2]\n",
        )
        .unwrap_err();
        assert!(
            matches!(&e, SceneError::Patch { patch, problem } if patch == "p" && problem.contains("texture"))
        );
        let e = built("bounces = 1\nform_factors = \"furnace\"\n[[patches]]\nspectra = \"m.csv\"\nsample = \"x\"\n")
            .unwrap_err();
        assert!(
            matches!(&e, SceneError::Spectra { path, .. } if path == Path::new("scenes/m.csv"))
        );
        let e = built(&format!("bounces = 1\nform_factors = \"furnace\"\n{patch}[[lights]]\nspectrum = \"E\"\npower = 1\npatches = [\"q\"]\n"))
            .unwrap_err();
        assert!(matches!(&e, SceneError::Light { light: 2, problem } if problem.contains("`q`")));
    }
}
