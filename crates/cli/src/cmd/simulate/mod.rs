//! `specconv simulate`: the colour shift of interreflection in a small declarative scene.

use crate::{files, methods};
use anyhow::{anyhow, Context, Result};
use serde::Serialize;
use specconv_colour::Colorimetry;
use specconv_convert_cmd::stdio::StdoutFailed;
use specconv_evaluation::scene::{self, SceneFile};
use specconv_evaluation::simulate;
use specconv_evaluation::simulate::{Outcome, Scene};
use specconv_flags::defs;
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::Stack;
use specconv_spectral::{Method, Model};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod drawing;
mod resources;

/// Shown after `--help` and as the man page's EXAMPLES: a scene that runs as it is (a test
/// runs it), its alternatives commented out.
pub const EXAMPLES: &str = "\
Scene (save the lines below as scene.toml; paths in it are relative to it):

  bounces = 8                     # or: effect = \"direct\" | \"converged\"
  form_factors = \"furnace\"        # or \"box\", or a matrix [[F11, F12, …], …]
  methods = [\"otsu2018\", \"smits1999\", \"meng2015\"]
  # ocio = \"config.ocio\"          # for colours and textures (default: $OCIO, else aces)

  [[lights]]
  spectrum = \"blackbody:5500\"     # a CIE illuminant, blackbody:K, or { file = \"spd.csv\" }
  power = 1.0                     # patches = [\"red\"]: which patches emit it (all)

  [[patches]]
  name = \"red\"
  colour = [0.8, 0.1, 0.1]
  colorspace = \"sRGB - Texture\"   # a colour space of the OCIO config, as --colorspace

  [[patches]]
  name = \"green\"
  colour = [0.2, 0.6, 0.2]         # no colorspace: the config's sRGB texture space

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

specconv_flags::args! {
    /// Simulate light bouncing between patches, once per uplift method and once with the measured
    /// spectra, and report how far each method's colour drifts from the measured one.
    ///
    /// The scene (TOML) names lights, patches and their form factors, and the effect wanted. Each
    /// patch's material is stored as a texture would store it: a colour in a colour space of the
    /// scene's OCIO config (converted as `convert` converts pixels), the colour of a measured
    /// spectrum from a CSV file, or a pixel of a texture.
    /// Every method uplifts that colour; the simulator solves the spectral radiosity
    /// B = E + ρ·F·B per wavelength, truncated after K bounces or converged, and converts each
    /// patch's radiance to XYZ, CIELAB (white: the same scene with white patches) and display sRGB.
    /// The report gives the CIEDE2000 difference of each method from the measured reference (when
    /// every patch is measured) and from plain RGB multiplication (`rgb`, an RGB renderer's
    /// answer). The scene below (`--help`) runs as it is; scenes/ in the repository has more.
    #[derive(Debug)]
    pub struct Args {
        scene: PathBuf = (defs::SIMULATE_SCENE),
        json: bool = (defs::JSON_INSTEAD_OF_TEXT),
        per_patch: bool = (defs::SIMULATE_PER_PATCH),
        patch: Vec<String> = (defs::SIMULATE_PATCH),
        image: Option<PathBuf> = (defs::SIMULATE_IMAGE),
        force: bool = (defs::SIMULATE_FORCE),
        methods: Vec<MethodName> = (defs::SIMULATE_METHODS),
        /// The method options of `convert`, with its defaults; --model replaces the scene's `model`.
        pub(crate) stack: methods::StackArgs = flatten,
    }
}

/// The largest scene file read (a scene is a few hundred lines of TOML).
const SCENE_LIMIT: u64 = 16 << 20;

pub fn run(args: Args) -> Result<()> {
    let text = specconv_atomic_file::read_bounded(&args.scene, SCENE_LIMIT, "scene")?;
    let text = String::from_utf8(text)
        .with_context(|| format!("scene {} is not UTF-8 text", args.scene.display()))?;
    let file = scene::parse(&text)
        .with_context(|| format!("{} is not a valid scene", args.scene.display()))?;
    let dir = args.scene.parent().unwrap_or(Path::new("."));
    let model_path = match &args.stack.options.model {
        Some(p) => Some(p.clone()),
        // A built-in model by name, unless a file of that name sits beside the scene.
        None => file.model.as_ref().map(|p| {
            let beside = dir.join(p);
            match specconv_conversion::models::builtin_name(p) {
                Some(name) if !beside.exists() => PathBuf::from(name),
                _ => beside,
            }
        }),
    };
    let model = files::load_model(model_path.as_deref())?;
    // Every method's output shares the grid, observer and illuminant of the model.
    let (a, _) = args.stack_spec(MethodName::Otsu2018).output(&model)?;
    let mut resources = resources::Resources::new(file.ocio.as_deref(), dir);
    let (scene, preset) = scene::build(&file, dir, &a, &mut resources).with_context(|| {
        format!(
            "in scene {}; see `specconv simulate --help`",
            args.scene.display()
        )
    })?;
    let stacks = stacks(&args, &file, &model)?;
    let selected = select(&args.patch, &scene.names)?;
    // Every file the scene read, which --image may never replace.
    let mut read: Vec<&Path> = vec![args.scene.as_path()];
    read.extend(model_path.as_deref());
    read.extend(resources.read.iter().map(PathBuf::as_path));
    if let Some(path) = &args.image {
        drawing::check(
            path,
            (&read, specconv_atomic_file::Replace::when(args.force)),
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
        report.image = Some(drawing::write(
            path,
            &report,
            (&read, specconv_atomic_file::Replace::when(args.force)),
        )?);
    }
    if args.json {
        outln!("{}", serde_json::to_string(&report)?)?;
    } else {
        print_text(&report)?;
    }
    Ok(())
}

impl Args {
    /// The method stack of `method` with these options.
    pub(crate) fn stack_spec(&self, method: MethodName) -> specconv_spectral::stack::StackSpec {
        methods::describe(&self.stack, method)
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
            let stack = methods::build(&args.stack_spec(m), model)
                .with_context(|| format!("cannot build {m}"))?;
            Ok((m, stack))
        })
        .collect()
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

fn print_text(r: &Report) -> Result<(), StdoutFailed> {
    outln!(
        "scene {}: {} patches, form factors {}, lights {}",
        r.scene,
        r.patches,
        r.form_factors,
        r.lights.join(", ")
    )?;
    let table = |title: &str, rows: &BTreeMap<String, Vec<f64>>| {
        outln!("\n{title}")?;
        out!("{:<18}", "bounces")?;
        for c in &r.counts {
            out!("{c:>10}")?;
        }
        outln!()?;
        // Methods in the scene's order, then rgb.
        for m in r.methods.iter().filter_map(|m| rows.get_key_value(m)) {
            out!("{:<18}", m.0)?;
            for v in m.1 {
                out!("{v:>10.4}")?;
            }
            outln!()?;
        }
        Ok(())
    };
    if let Some(m) = &r.mean_delta_e {
        table("mean CIEDE2000 from the measured reference", m)?;
    }
    table(
        "mean CIEDE2000 from plain RGB multiplication",
        &r.mean_delta_e_rgb,
    )?;
    for p in &r.per_patch {
        outln!(
            "\npatch {}: sRGB hex and CIEDE2000 (from measured / from rgb)",
            p.name
        )?;
        for m in &r.methods {
            let cells = &p.colours[m];
            out!("  {m:<16}")?;
            for c in cells {
                let hex: String = c
                    .srgb
                    .iter()
                    .map(|v| format!("{:02x}", (v * 255.0).round() as u8))
                    .collect();
                match c.delta_e {
                    Some(d) => out!(" #{hex} {d:>6.3}/{:<6.3}", c.delta_e_rgb)?,
                    None => out!(" #{hex} {:>6.3}", c.delta_e_rgb)?,
                }
            }
            outln!()?;
        }
    }
    Ok(())
}
