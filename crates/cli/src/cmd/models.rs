//! `specconv models`: the models a conversion may use, with their data, terms, credits and
//! notices, and which one is in force.

use anyhow::Result;
use specconv_conversion::models;
use specconv_convert_cmd::errors::usage;
use specconv_flags::defs;
use specconv_spectral::otsu2018::model::BUILTIN;
use specconv_spectral::otsu2018::terms::Notice;
use specconv_spectral::Model;
use std::path::{Path, PathBuf};

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv models
  specconv models studio.json
  SPECCONV_MODEL=/studio/models/paint.json specconv models
  specconv models --json | jq '.models[] | {name, commercial}'
";

specconv_flags::args! {
    /// List the built-in models (and model files named here) with the data each was trained on,
    /// its terms, the credits it asks for and the notices that must ship with it; and say which
    /// model a conversion uses when none is named, and why.
    ///
    /// When no --model is given, every command, the Python package, farm tasks and the Mitsuba
    /// plugins use the site's default model, $SPECCONV_MODEL (a built-in name or a model file), or
    /// else the built-in default (the first listed). A model may be used commercially only when
    /// every set it was trained on may; each output records the answer (`specconvCommercialUse`).
    #[derive(Debug)]
    pub struct Args {
        models: Vec<PathBuf> = (defs::MODELS_NAMES),
        json: bool = (defs::MODELS_JSON),
    }
}

#[derive(serde::Serialize)]
struct Listed {
    name: String,
    builtin: bool,
    default: bool,
    summary: String,
    commercial: String,
    clusters: usize,
    sets: Vec<specconv_spectral::otsu2018::model::SetRecord>,
    notices: Vec<&'static str>,
}

pub fn run(args: Args) -> Result<()> {
    let (_, origin) = models::in_force(None);
    let in_force = models::load(None).map_err(usage)?;
    let name = shown(&models::pinned(None));
    let mut listed: Vec<Listed> = BUILTIN
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let m = Model::builtin_named(b.name).expect("built in");
            listing(b.name, true, k == 0, b.summary, m)
        })
        .collect();
    let mut files = Vec::new();
    for p in &args.models {
        if models::builtin_name(p).is_none() {
            let m = crate::files::load_model(Some(p))?;
            listed.push(listing(&shown(p), false, false, "", &m));
            files.push(m);
        }
    }
    let mut notices: Vec<Notice> = Vec::new();
    for m in BUILTIN
        .iter()
        .map(|b| Model::builtin_named(b.name).expect("built in"))
        .chain(&files)
    {
        for n in m.training.notices() {
            if !notices.contains(&n) {
                notices.push(n);
            }
        }
    }
    if args.json {
        let v = serde_json::json!({
            "in_force": {
                "model": name,
                "origin": origin.word(),
                "commercial": in_force.training.commercial().to_string(),
            },
            "models": listed,
            "notices": notices.iter().map(|n| serde_json::json!({"title": n.title, "text": n.text})).collect::<Vec<_>>(),
        });
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
        return Ok(());
    }
    outln!(
        "in force: {name} ({}; commercial use: {})",
        origin.describe(),
        in_force.training.commercial()
    )?;
    for l in &listed {
        outln!()?;
        let what = match (l.builtin, l.default) {
            (true, true) => "built in, the default",
            (true, false) => "built in",
            _ => "model file",
        };
        outln!("{} ({what}): commercial use: {}", l.name, l.commercial)?;
        if !l.summary.is_empty() {
            outln!("  {}", l.summary)?;
        }
        outln!("  {} clusters, trained on:", l.clusters)?;
        for s in &l.sets {
            let weight = if s.weight == 1.0 {
                String::new()
            } else {
                format!(", weight {:.3}", s.weight)
            };
            outln!(
                "    {} ({} spectra{weight}): {}; commercial use: {}",
                s.source,
                s.count,
                s.licence,
                s.commercial
            )?;
            for a in &s.attribution {
                outln!("      credit: {a}")?;
            }
        }
        if l.sets.is_empty() {
            outln!("    (its sets and their terms are not recorded)")?;
        }
        for n in &l.notices {
            outln!("  ships with the notice for {n} (below)")?;
        }
    }
    // The notices the models' data ship under (docs/licences.md), verbatim, each once.
    for n in notices {
        outln!("\nnotice for {}:\n{}", n.title, n.text.trim_end())?;
    }
    Ok(())
}

fn listing(name: &str, builtin: bool, default: bool, summary: &str, m: &Model) -> Listed {
    Listed {
        name: name.to_string(),
        builtin,
        default,
        summary: summary.to_string(),
        commercial: m.training.commercial().to_string(),
        clusters: m.leaves.len(),
        sets: m.training.sets.clone(),
        notices: m.training.notices().iter().map(|n| n.title).collect(),
    }
}

/// A model's name or path on one line: control characters escaped, so that a value cannot
/// break a line or imitate another.
fn shown(p: &Path) -> String {
    p.display().to_string().escape_debug().to_string()
}

/// `--version`'s one line: the version, the model in force and whether its outputs may be used
/// commercially. A site default that cannot be loaded is said, not hidden.
pub fn version_line() -> String {
    let (_, origin) = models::in_force(None);
    let name = shown(&models::pinned(None));
    let from = match origin {
        models::Origin::Site => format!(" from ${}", models::MODEL_ENV),
        _ => String::new(),
    };
    let terms = match models::load(None) {
        Ok(m) => format!("commercial use: {}", m.training.commercial()),
        Err(_) => "cannot be loaded: see `specconv models`".into(),
    };
    format!(
        "{}; default model: {name}{from} ({terms}); `specconv models` lists the models and their terms",
        env!("CARGO_PKG_VERSION")
    )
}
