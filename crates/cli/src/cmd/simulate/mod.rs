//! `specconv simulate`: the colour shift of interreflection in a small declarative scene.

use crate::{files, methods};
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use specconv_colour::rgb;
use specconv_colour::rgb::RgbSpace;
use specconv_colour::{Colorimetry, Illuminant};
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::Stack;
use specconv_spectral::{Method, Model};
use specconv_study::simulate;
use specconv_study::simulate::{Effect, Light, Material, Outcome, Scene};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod drawing;
mod texture;

/// Shown after `--help` and as the man page's EXAMPLES: a scene that runs as it is (a test
/// runs it), its alternatives commented out.
pub const EXAMPLES: &str = "\
Scene (save the lines below as scene.toml; paths in it are relative to it):

  bounces = 8                     # or: effect = \"direct\" | \"converged\"
  form_factors = \"furnace\"        # or \"box\", or a matrix [[F11, F12, …], …]
  methods = [\"otsu2018\", \"smits1999\", \"meng2015\"]
  # ocio = \"config.ocio\"          # for textures (default: $OCIO, else aces)

  [[lights]]
  spectrum = \"blackbody:5500\"     # a CIE illuminant, blackbody:K, or { file = \"spd.csv\" }
  power = 1.0                     # patches = [\"red\"]: which patches emit it (all)

  [[patches]]
  name = \"red\"
  colour = [0.8, 0.1, 0.1]
  colorspace = \"sRGB\"             # or Linear Rec.709, Linear Rec.2020, ACEScg, CIE-XYZ-D65

  [[patches]]
  name = \"green\"
  colour = [0.2, 0.6, 0.2]
  colorspace = \"sRGB\"

  # [[patches]]                   # measured spectra, the reference for every method:
  # spectra = \"munsell.csv\"       # samples = \"all\" | [\"5R 4/14\", …], or sample = \"5R 4/14\"

  # [[patches]]                   # a pixel of a texture, read as `convert` reads it
  # name = \"brick\"                # (x, y from the top left; colorspace as --colorspace)
  # texture = \"albedo.png\"
  # pixel = [120, 40]

Examples:
  specconv simulate --scene scene.toml
  specconv simulate --scene scenes/furnace_5500k.toml --image furnace.png --patch \"5R 4/14\"
";

/// Simulate light bouncing between patches, once per uplift method and once with the measured
/// spectra, and report how far each method's colour drifts from the measured one.
///
/// The scene (TOML) names lights, patches and their form factors, and the effect wanted. Each
/// patch's material is stored as a texture would store it: a colour (in sRGB, Linear Rec.709,
/// Linear Rec.2020, ACEScg or CIE-XYZ-D65), the colour of a measured spectrum from a CSV file,
/// or a pixel of a texture.
/// Every method uplifts that colour; the simulator solves the spectral radiosity
/// B = E + ρ·F·B per wavelength, truncated after K bounces or converged, and converts each
/// patch's radiance to XYZ, CIELAB (white: the same scene with white patches) and display sRGB.
/// The report gives the CIEDE2000 difference of each method from the measured reference (when
/// every patch is measured) and from plain RGB multiplication (`rgb`, an RGB renderer's
/// answer). The scene below (`--help`) runs as it is; scenes/ in the repository has more.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The scene (TOML); relative paths in it are relative to its directory.
    #[arg(long, value_name = "SCENE.toml")]
    scene: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Report every patch, not only the means (the default for scenes of up to 16 patches).
    #[arg(long)]
    per_patch: bool,
    /// Report (and draw) only this patch; repeat for several. Means stay over all patches.
    #[arg(long, value_name = "NAME")]
    patch: Vec<String>,
    /// Also draw the report as a PNG: one block per patch (at most 16: choose with --patch),
    /// one row per rendering (the measured reference, each method, `rgb` multiplication), one
    /// column per bounce count; each swatch in display sRGB (the white scene's Y as 1) with its
    /// CIEDE2000 from the measured reference under it (from `rgb` where the scene has no
    /// measured spectra). Text needs DejaVu Sans (fonts-dejavu-core) or $SPECCONV_FONT.
    #[arg(long, value_name = "OUT.png")]
    image: Option<PathBuf>,
    /// Replace an existing --image file.
    #[arg(long, requires = "image")]
    force: bool,
    /// Uplift method to compare, instead of the scene's `methods`; repeat for several:
    /// otsu2018, pca, smits1999, meng2015, meng2015-bounded or jakob2019. Each is built as
    /// `convert` builds it, with the options below and their defaults.
    #[arg(long = "method", value_name = "NAME")]
    methods: Vec<MethodName>,
    /// The method options of `convert`, with its defaults; --model replaces the scene's `model`.
    #[command(flatten)]
    pub(crate) stack: methods::StackArgs,
}

/// The scene file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    #[serde(default)]
    bounces: Option<usize>,
    #[serde(default)]
    effect: Option<String>,
    form_factors: FormFactors,
    #[serde(default)]
    methods: Option<Vec<String>>,
    #[serde(default)]
    model: Option<PathBuf>,
    #[serde(default)]
    ocio: Option<String>,
    #[serde(default)]
    lights: Vec<LightFile>,
    #[serde(default)]
    patches: Vec<PatchFile>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum FormFactors {
    Preset(String),
    Matrix(Vec<Vec<f64>>),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LightFile {
    #[serde(default)]
    name: Option<String>,
    spectrum: SpdFile,
    power: f64,
    #[serde(default)]
    patches: Option<Vec<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum SpdFile {
    Named(String),
    Csv {
        file: PathBuf,
        #[serde(default)]
        column: Option<String>,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PatchFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    colour: Option<[f64; 3]>,
    #[serde(default)]
    colorspace: Option<String>,
    #[serde(default)]
    spectra: Option<PathBuf>,
    #[serde(default)]
    sample: Option<String>,
    #[serde(default)]
    samples: Option<Samples>,
    #[serde(default)]
    texture: Option<PathBuf>,
    #[serde(default)]
    pixel: Option<[u32; 2]>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Samples {
    All(String),
    List(Vec<String>),
}

pub fn run(args: Args) -> Result<()> {
    if let Some(p) = &args.image {
        crate::checks::output_dir(p)?;
    }
    let text = std::fs::read_to_string(&args.scene)
        .with_context(|| format!("cannot read scene {}", args.scene.display()))?;
    let file: SceneFile = toml::from_str(&text)
        .with_context(|| format!("{} is not a valid scene", args.scene.display()))?;
    let dir = args.scene.parent().unwrap_or(Path::new("."));
    let model_path = match &args.stack.model {
        Some(p) => Some(p.clone()),
        None => file.model.as_ref().map(|p| dir.join(p)),
    };
    let model = files::load_model(model_path.as_deref())?;
    // Every method's output shares the grid, observer and illuminant of the model.
    let (a, _) = args.description(MethodName::Otsu2018).output(&model)?;
    let (scene, preset) = build(&file, dir, &a).with_context(|| {
        format!(
            "in scene {}; see `specconv simulate --help`",
            args.scene.display()
        )
    })?;
    let stacks = stacks(&args, &file, &model)?;
    let selected = select(&args.patch, &scene.names)?;
    if let Some(path) = &args.image {
        drawing::check(
            path,
            args.force,
            selected.as_ref().map_or(scene.names.len(), Vec::len),
        )?;
    }
    let named: Vec<(&str, &dyn Method)> = stacks
        .iter()
        .map(|(name, s)| (name.as_str(), s.method()))
        .collect();
    let out = simulate::simulate(&scene, &a, &named)?;
    let per_patch: Vec<usize> = match selected {
        Some(s) => s,
        None if args.per_patch || args.image.is_some() || scene.names.len() <= 16 => {
            (0..scene.names.len()).collect()
        }
        None => Vec::new(),
    };
    let mut report = report(&args.scene, &scene, &preset, &out, &a, &per_patch);
    if let Some(path) = &args.image {
        report.image = Some(drawing::write(path, &report, &[args.scene.as_path()])?);
    }
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

impl Args {
    /// The method stack of `method` with these options.
    pub(crate) fn description(&self, method: MethodName) -> specconv_spectral::stack::Description {
        self.stack.describe(method)
    }
}

/// The methods to compare (--method, else the scene's `methods`, else otsu2018, smits1999
/// and meng2015), each built as `convert` builds it, with its name.
fn stacks(args: &Args, file: &SceneFile, model: &Model) -> Result<Vec<(MethodName, Stack)>> {
    let names: Vec<MethodName> = if !args.methods.is_empty() {
        args.methods.clone()
    } else if let Some(names) = &file.methods {
        names
            .iter()
            .map(|n| n.parse())
            .collect::<Result<_, _>>()
            .context("in the scene's `methods`")?
    } else {
        vec![
            MethodName::Otsu2018,
            MethodName::Smits1999,
            MethodName::Meng2015,
        ]
    };
    names
        .into_iter()
        .map(|m| {
            let stack = methods::build(&args.description(m), model)
                .with_context(|| format!("cannot build {m}"))?;
            Ok((m, stack))
        })
        .collect()
}

/// The library scene from the file: materials resolved, lights sampled, presets expanded.
fn build(file: &SceneFile, dir: &Path, a: &Colorimetry) -> Result<(Scene, String)> {
    let effect = match (file.bounces, file.effect.as_deref()) {
        (Some(k), None) => Effect::Bounces(k),
        (None, Some("direct")) => Effect::Bounces(1),
        (None, Some("converged")) => Effect::Converged,
        (None, Some(e)) => {
            bail!("unknown effect `{e}`; use \"direct\", \"converged\" or `bounces = K`")
        }
        (Some(_), Some(_)) => bail!("give either `bounces = K` or `effect`, not both"),
        (None, None) => bail!(
            "say what to compute: `bounces = K`, `effect = \"direct\"` or `effect = \"converged\"`"
        ),
    };
    let mut names = Vec::new();
    let mut materials = Vec::new();
    let mut tables: BTreeMap<PathBuf, specconv_colour::SpectralTable> = BTreeMap::new();
    // Loaded for the first texture patch only.
    let mut config = None;
    for (i, p) in file.patches.iter().enumerate() {
        let which = || {
            format!(
                "patch {}",
                p.name.clone().unwrap_or_else(|| (i + 1).to_string())
            )
        };
        if let Some(texture) = &p.texture {
            if p.colour.is_some()
                || p.spectra.is_some()
                || p.sample.is_some()
                || p.samples.is_some()
            {
                bail!("{}: give `texture` alone (with `pixel` and `colorspace`), not with `colour` or `spectra`", which());
            }
            let pixel = p.pixel.ok_or_else(|| {
                anyhow!(
                    "{}: say which pixel of the texture: `pixel = [x, y]` (from the top left)",
                    which()
                )
            })?;
            if config.is_none() {
                config = Some(ocio_config(file.ocio.as_deref(), dir)?);
            }
            let config = config.as_ref().expect("loaded above");
            let xyz =
                texture::pixel_xyz(&dir.join(texture), pixel, p.colorspace.as_deref(), config)
                    .with_context(which)?;
            materials.push(Material::Colour(xyz));
            names.push(p.name.clone().unwrap_or_else(|| (i + 1).to_string()));
            continue;
        }
        if p.pixel.is_some() {
            bail!("{}: `pixel` needs `texture = \"FILE\"`", which());
        }
        match (&p.colour, &p.spectra) {
            (Some(c), None) => {
                if p.sample.is_some() || p.samples.is_some() {
                    bail!("{}: `sample`/`samples` need `spectra = \"FILE.csv\"`", which());
                }
                let space = p.colorspace.as_deref().unwrap_or("sRGB");
                materials.push(Material::Colour(colour_xyz(*c, space, a).with_context(which)?));
                names.push(p.name.clone().unwrap_or_else(|| (i + 1).to_string()));
            }
            (None, Some(path)) => {
                let path = dir.join(path);
                if !tables.contains_key(&path) {
                    tables.insert(path.clone(), files::read_spectra(&path)?);
                }
                let table = &tables[&path];
                let wanted: Vec<String> = match (&p.sample, &p.samples) {
                    (Some(s), None) => vec![s.clone()],
                    (None, Some(Samples::List(v))) => v.clone(),
                    (None, Some(Samples::All(s))) if s == "all" => table.names.clone(),
                    (None, Some(Samples::All(s))) => {
                        bail!("{}: samples = \"{s}\": use \"all\" or a list of names", which())
                    }
                    (None, None) => bail!(
                        "{}: name the measured spectra: `sample = \"NAME\"`, `samples = [..]` or `samples = \"all\"`",
                        which()
                    ),
                    (Some(_), Some(_)) => bail!("{}: give `sample` or `samples`, not both", which()),
                };
                if p.name.is_some() && wanted.len() != 1 {
                    bail!("{}: `name` names one patch, but {} samples are asked for", which(), wanted.len());
                }
                for s in wanted {
                    let k = table.names.iter().position(|n| *n == s).ok_or_else(|| {
                        anyhow!(
                            "{}: unknown sample `{s}` in {} (it has {} samples, e.g. {}); check the \
                             name against the CSV header",
                            which(),
                            path.display(),
                            table.names.len(),
                            table.names.iter().take(3).cloned().collect::<Vec<_>>().join(", ")
                        )
                    })?;
                    let spectrum = a
                        .grid
                        .resample(&table.source, &table.wavelengths, &table.columns[k])?;
                    materials.push(Material::Measured(spectrum));
                    names.push(p.name.clone().unwrap_or(s));
                }
            }
            (Some(_), Some(_)) => bail!("{}: give `colour` or `spectra`, not both", which()),
            (None, None) => bail!(
                "{}: give a material: `colour = [R, G, B]` (with `colorspace`) or `spectra = \"FILE.csv\"`",
                which()
            ),
        }
    }
    let n = materials.len();
    let (form_factors, preset) = match &file.form_factors {
        FormFactors::Preset(p) if p == "furnace" => (simulate::furnace(n), "furnace".to_string()),
        FormFactors::Preset(p) if p == "box" => {
            // Reorder the patches to the walls of the preset.
            let mut order = Vec::new();
            for wall in simulate::BOX_WALLS {
                let at = names.iter().position(|x| x == wall).ok_or_else(|| {
                    anyhow!(
                        "the box preset needs five patches named {}; `{wall}` is missing",
                        simulate::BOX_WALLS.join(", ")
                    )
                })?;
                order.push(at);
            }
            if n != 5 {
                bail!(
                    "the box preset has five walls ({}), the scene {n} patches",
                    simulate::BOX_WALLS.join(", ")
                );
            }
            names = order.iter().map(|&i| names[i].clone()).collect();
            materials = order.iter().map(|&i| materials[i].clone()).collect();
            (simulate::room(), "box".to_string())
        }
        FormFactors::Preset(p) => {
            bail!("unknown form-factor preset `{p}`; use \"furnace\", \"box\" or a matrix")
        }
        FormFactors::Matrix(m) => (m.clone(), "matrix".to_string()),
    };
    let mut lights = Vec::new();
    for (i, l) in file.lights.iter().enumerate() {
        let (label, spd) = match &l.spectrum {
            SpdFile::Named(s) => {
                let ill: Illuminant = s.parse()?;
                (ill.to_string(), ill.spd(&a.grid)?)
            }
            SpdFile::Csv { file, column } => {
                let path = dir.join(file);
                let t = files::read_spectra(&path)?;
                let k = match column {
                    None => 0,
                    Some(c) => t.names.iter().position(|n| n == c).ok_or_else(|| {
                        anyhow!("light {}: no column `{c}` in {}", i + 1, path.display())
                    })?,
                };
                (
                    format!("{}:{}", path.display(), t.names[k]),
                    a.grid.resample(&t.source, &t.wavelengths, &t.columns[k])?,
                )
            }
        };
        let patches = match &l.patches {
            None => (0..n).collect(),
            Some(list) => list
                .iter()
                .map(|p| {
                    names.iter().position(|x| x == p).ok_or_else(|| {
                        anyhow!(
                            "light {}: no patch named `{p}`; patches are {}",
                            i + 1,
                            names.join(", ")
                        )
                    })
                })
                .collect::<Result<_>>()?,
        };
        lights.push(Light {
            name: l.name.clone().unwrap_or(label),
            spd,
            power: l.power,
            patches,
        });
    }
    Ok((
        Scene {
            names,
            materials,
            form_factors,
            lights,
            effect,
        },
        preset,
    ))
}

/// The scene's `ocio` (a built-in name such as `aces` or `ocio://default`, or a config file
/// relative to the scene), else as `convert` without --ocio: $OCIO, else the built-in ACES
/// config.
fn ocio_config(ocio: Option<&str>, dir: &Path) -> Result<specconv_ocio::Config> {
    let path = ocio.map(|o| {
        if specconv_ocio::is_builtin_name(o) {
            o.to_string()
        } else {
            dir.join(o).display().to_string()
        }
    });
    Ok(specconv_ocio::Config::resolve(path.as_deref())?)
}

/// XYZ (white Y = 1, the model's white) of a colour in a named RGB space or XYZ.
fn colour_xyz(c: [f64; 3], space: &str, a: &Colorimetry) -> Result<[f64; 3]> {
    let rgb_space =
        |s: &RgbSpace, rgb: [f64; 3]| specconv_colour::mat3::mul_vec(&s.to_xyz(a.white_xyz()), rgb);
    Ok(match space.to_ascii_lowercase().as_str() {
        "srgb" | "srgb - texture" | "srgb texture" => {
            rgb_space(&rgb::SRGB, c.map(rgb::srgb_decode))
        }
        "linear rec.709 (srgb)" | "linear rec.709" | "lin_rec709" => rgb_space(&rgb::SRGB, c),
        "linear rec.2020" | "lin_rec2020" => rgb_space(&rgb::REC2020, c),
        "acescg" => rgb_space(&rgb::ACESCG, c),
        "cie-xyz-d65" | "xyz" => c,
        _ => bail!(
            "colour space `{space}` is not one simulate knows; use sRGB, Linear Rec.709 (sRGB), \
             Linear Rec.2020, ACEScg or CIE-XYZ-D65"
        ),
    })
}

#[derive(Serialize)]
struct Report {
    scene: String,
    form_factors: String,
    patches: usize,
    lights: Vec<String>,
    /// Bounce counts, or "converged".
    counts: Vec<String>,
    methods: Vec<String>,
    /// Per method, per count: mean CIEDE2000 from the measured reference (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_delta_e: Option<BTreeMap<String, Vec<f64>>>,
    /// Per method, per count: mean CIEDE2000 from plain RGB multiplication.
    mean_delta_e_rgb: BTreeMap<String, Vec<f64>>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    per_patch: Vec<PatchReport>,
    /// With --image: where it was written and where each swatch is in it.
    #[serde(skip_serializing_if = "Option::is_none")]
    image: Option<drawing::Written>,
}

#[derive(Serialize)]
struct PatchReport {
    name: String,
    /// Per method (and `measured`, `rgb`), per count.
    colours: BTreeMap<String, Vec<Cell>>,
}

#[derive(Serialize)]
struct Cell {
    xyz: [f64; 3],
    lab: [f64; 3],
    /// Display sRGB, clipped to [0, 1], the white scene's Y as 1.
    srgb: [f64; 3],
    #[serde(skip_serializing_if = "Option::is_none")]
    delta_e: Option<f64>,
    delta_e_rgb: f64,
}

fn report(
    path: &Path,
    scene: &Scene,
    preset: &str,
    out: &Outcome,
    a: &Colorimetry,
    per_patch: &[usize],
) -> Report {
    let methods: Vec<String> = out.renderings.iter().map(|r| r.method.clone()).collect();
    let mean = |reference: &str| {
        methods
            .iter()
            .filter(|m| m.as_str() != reference && m.as_str() != "measured")
            .filter_map(|m| Some((m.clone(), out.mean_delta_e(m, reference)?)))
            .collect::<BTreeMap<_, _>>()
    };
    let rgb = out.rendering("rgb").expect("always rendered");
    let reference = out.has_reference.then(|| &out.renderings[0]);
    let per_patch = per_patch
        .iter()
        .map(|&p| PatchReport {
            name: scene.names[p].clone(),
            colours: out
                .renderings
                .iter()
                .map(|r| {
                    let cells = (0..out.counts.len())
                        .map(|c| Cell {
                            xyz: r.xyz[c][p],
                            lab: out.lab(r, c, p),
                            srgb: out.display_rgb(r, c, p, a),
                            delta_e: reference.map(|m| out.delta_e(r, m, c, p)),
                            delta_e_rgb: out.delta_e(r, rgb, c, p),
                        })
                        .collect();
                    (r.method.clone(), cells)
                })
                .collect(),
        })
        .collect();
    Report {
        scene: path.display().to_string(),
        form_factors: preset.to_string(),
        patches: scene.names.len(),
        lights: scene
            .lights
            .iter()
            .map(|l| format!("{} × {}", l.name, l.power))
            .collect(),
        counts: out
            .counts
            .iter()
            .map(|c| c.map_or("converged".into(), |k| k.to_string()))
            .collect(),
        mean_delta_e: out.has_reference.then(|| mean("measured")),
        mean_delta_e_rgb: mean("rgb"),
        methods,
        per_patch,
        image: None,
    }
}

/// The patches named by --patch, in the order given; `None` when none is named.
fn select(wanted: &[String], names: &[String]) -> Result<Option<Vec<usize>>> {
    if wanted.is_empty() {
        return Ok(None);
    }
    wanted
        .iter()
        .map(|w| {
            names.iter().position(|n| n == w).ok_or_else(|| {
                anyhow!(
                    "--patch {w}: the scene has no patch of that name (it has {}: {}{})",
                    names.len(),
                    names.iter().take(5).cloned().collect::<Vec<_>>().join(", "),
                    if names.len() > 5 { ", …" } else { "" }
                )
            })
        })
        .collect::<Result<_>>()
        .map(Some)
}

fn print_text(r: &Report) {
    println!(
        "scene {}: {} patches, form factors {}, lights {}",
        r.scene,
        r.patches,
        r.form_factors,
        r.lights.join(", ")
    );
    let table = |title: &str, rows: &BTreeMap<String, Vec<f64>>| {
        println!("\n{title}");
        print!("{:<18}", "bounces");
        for c in &r.counts {
            print!("{c:>10}");
        }
        println!();
        // Methods in the scene's order, then rgb.
        for m in r.methods.iter().filter_map(|m| rows.get_key_value(m)) {
            print!("{:<18}", m.0);
            for v in m.1 {
                print!("{v:>10.4}");
            }
            println!();
        }
    };
    if let Some(m) = &r.mean_delta_e {
        table("mean CIEDE2000 from the measured reference", m);
    }
    table(
        "mean CIEDE2000 from plain RGB multiplication",
        &r.mean_delta_e_rgb,
    );
    for p in &r.per_patch {
        println!(
            "\npatch {}: sRGB hex and CIEDE2000 (from measured / from rgb)",
            p.name
        );
        for m in &r.methods {
            let cells = &p.colours[m];
            print!("  {m:<16}");
            for c in cells {
                let hex: String = c
                    .srgb
                    .iter()
                    .map(|v| format!("{:02x}", (v * 255.0).round() as u8))
                    .collect();
                match c.delta_e {
                    Some(d) => print!(" #{hex} {d:>6.3}/{:<6.3}", c.delta_e_rgb),
                    None => print!(" #{hex} {:>6.3}", c.delta_e_rgb),
                }
            }
            println!();
        }
    }
}
