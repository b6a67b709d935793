//! `specconv asset STAGE -o DIR`: a USD stage's textures, each decided colour or data by the
//! material that reads it (the library's rule, crates/asset), converted as `convert` converts a
//! batch, and a layer over the stage pointing it at the spectral files (docs/assets.md).

use anyhow::{Context, Result};
use specconv_asset::{
    finish, make_folders, member, prepare, unknown_line, unknown_record, with_member, Asset,
    Converters, Decision, Job, Outcomes, Prepared, Reader,
};
use specconv_conversion::record::Record;
use specconv_conversion::Options;
use specconv_convert_cmd::convert::{run_batch, Annotate, BatchArgs, Reporting};
use specconv_convert_cmd::errors::{asset_error, explain, print_error, usage};
use specconv_convert_cmd::exit;
use specconv_flags::defs;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv asset shot.usda -o spectral --dry-run
  specconv asset shot.usda -o spectral -u --json > asset.jsonl
  SPECCONV_USD_PYTHON=/opt/usd/bin/python specconv asset kitchen.usdz -o spectral --data copy
  specconv asset brick.mtlx -o spectral
";

specconv_flags::args! {
    /// Convert the textures a USD stage's (or MaterialX document's) materials read, each as its
    /// material says.
    ///
    /// Opens STAGE (.usda, .usdc, .usd, .usdz) with Pixar's usd-core, composed (references,
    /// payloads, the selected variants, usdz packages), and finds every texture a bound material
    /// reads (a node whose definition has a file input: UsdUVTexture, MaterialX image nodes,
    /// Arnold's image, RenderMan's PxrTexture, PxrMultiTexture, PxrNormalMap, PxrBump). A
    /// MaterialX document (.mtlx), given as STAGE or referenced from the stage, is read with the
    /// MaterialX package (XIncludes, node graphs, fileprefix, colorspace as MaterialX inherits
    /// it); every material of a document given alone is read, and its copy DIR/STEM_spectral.mtlx
    /// takes the layer's place. The material decides what each file is, by the type each input it
    /// feeds has in its shader's definition (usd-core's Sdr, MaterialX's nodedefs, the Arnold and
    /// RenderMan tables): a colour type (diffuseColor, base_color …) makes it colour, in the space
    /// its node declares (sourceColorSpace, MaterialX colorspace, Arnold color_space, PxrTexture
    /// linearize), else the file's own evidence; any other type (roughness, normal …, and
    /// colour-typed quantities held per channel, such as subsurface_radius) data, skipped or
    /// copied as --data says; a file that feeds both is colour where each data use can keep the
    /// original file, else a conflict, named and not converted. A shader with no known definition
    /// that reads a file is reported (--strict: a failure). Outputs go under DIR (the texture's
    /// folder below the stage's, or external/HASH for one outside it), with DIR/STEM_spectral.usda:
    /// a layer over the stage that gives each material reading a colour texture a copy of its
    /// network reading the spectral files, behind UsdShade's render context `spectral`
    /// (outputs:spectral:surface), and each referenced MaterialX document a variant set
    /// spectralTextures (rgb selected; spectral adds its copy), leaving what RGB renderers read as
    /// it was. The stage and its textures are never written. usd-core and MaterialX run in
    /// the Python interpreter $SPECCONV_USD_PYTHON names (else python3):
    /// `python3 -m pip install usd-core MaterialX`.
    /// With -u, up-to-date textures are skipped and the layer is written again; --json's records
    /// are `convert`'s with an `asset` member: the stage, the rule that decided, why, and each
    /// prim and input that reads the texture (docs/assets.md).
    #[derive(Debug)]
    pub struct Args {
        stage: PathBuf = (defs::ASSET_STAGE),
        output: PathBuf = (defs::ASSET_OUTPUT),
        dry_run: bool = (defs::ASSET_DRY_RUN),
        /// The global --ocio (see `specconv --help`).
        pub(crate) ocio: Option<String> = skip,
        /// The options of the conversion, made from the library's definitions (--colorspace is
        /// refused: the material names each texture's).
        pub(crate) conversion: specconv_flags::ConversionArgs = flatten,
        /// -u, --json, --progress, -q, as `convert` takes them.
        batch: BatchArgs = flatten,
        verbose: bool = (defs::ASSET_VERBOSE),
    }
}

/// Reads, plans, converts and writes the layer; returns the exit status (1 when a texture
/// could not be converted: a conflict, a missing file, a failed conversion).
pub fn run(args: Args) -> Result<i32> {
    let mut options = args.conversion.options.clone();
    options.ocio = args.ocio.clone();
    if options.colorspace.is_some() {
        return Err(usage(anyhow::anyhow!(
            "asset takes no --colorspace: the material names each texture's colour space \
             (docs/assets.md); convert the file with `specconv convert --colorspace`"
        )));
    }
    let reader = Reader::from_env().map_err(asset_error)?;
    let Prepared { asset, jobs } = prepare(
        &reader,
        (&args.stage, &args.output),
        &options,
        (args.dry_run, args.batch.update),
    )
    .map_err(asset_error)?;
    let reporting = args.batch.reporting(args.verbose);
    // A shader it does not know reading a file is a warning, as `convert`'s are: `--strict`
    // makes it a failure.
    report_unknown(&asset, args.batch.json, options.strict)?;
    let unknown_fails = options.strict && !asset.unknown.is_empty();
    if asset.textures.is_empty() && !asset.unknown.is_empty() {
        // Reported above: never "nothing to convert".
    } else if asset.textures.is_empty()
        && !args.batch.quiet
        && specconv_asset::is_document(&asset.stage)
    {
        errln!(
            "specconv: note: {}: no material of the document reads an image ({} material(s)); \
             nothing to convert",
            asset.stage.display(),
            asset.materials
        );
    } else if asset.textures.is_empty() && !args.batch.quiet {
        errln!(
            "specconv: note: {}: no bound material reads a texture ({} material(s) bound to \
             {} prim(s)); nothing to convert",
            asset.stage.display(),
            asset.materials,
            asset.bound_prims
        );
    }
    if args.dry_run || args.verbose {
        print_decisions(&asset, &jobs, args.dry_run && args.batch.json)?;
        if args.dry_run {
            let unconverted = asset.textures.iter().any(|t| t.error.is_some());
            return Ok(if unconverted || unknown_fails {
                exit::FAILED
            } else {
                exit::OK
            });
        }
    }
    let code = convert(&reporting, options, &asset, &jobs, &reader)?;
    Ok(if unknown_fails && code == exit::OK {
        exit::FAILED
    } else {
        code
    })
}

/// Each file a shader the reader does not know reads (issue 56, item 2): a warning line, or
/// with --json an object of `convert`'s record form whose status is `unknown-shader`; an
/// error line instead under --strict.
fn report_unknown(asset: &Asset, json: bool, strict: bool) -> Result<()> {
    for u in &asset.unknown {
        if json {
            outln!("{}", unknown_record(asset, u))?;
        }
        match strict {
            true => print_error(&unknown_line(u)),
            false => errln!("specconv: warning: {}", unknown_line(u)),
        }
    }
    Ok(())
}

/// Each texture's decision: a line on standard error, or a JSON object on standard output.
fn print_decisions(asset: &Asset, jobs: &[Job], json: bool) -> Result<()> {
    let mut files = vec![0usize; asset.textures.len()];
    for j in jobs {
        files[j.texture] += 1;
    }
    for (k, t) in asset.textures.iter().enumerate() {
        if json {
            outln!("{}", member(asset, k))?;
            continue;
        }
        let d = &t.texture.decision;
        let what = match d {
            Decision::Colour { .. } => format!(
                "colour, colour space {}",
                t.colorspace
                    .as_deref()
                    .unwrap_or("from the file's evidence")
            ),
            Decision::Data { .. } => "data".into(),
            Decision::Conflict { .. } => "CONFLICT".into(),
            Decision::Undecided { .. } => "UNDECIDED".into(),
            Decision::Missing { .. } => "MISSING".into(),
        };
        let tiles = files[k];
        let to = match (&t.output, d) {
            (_, Decision::Data { .. }) => {
                format!(" ({tiles} file(s): never uplifted, as --data says)")
            }
            (Some(o), _) if t.error.is_none() => format!(" → {} ({tiles} file(s))", o.display()),
            _ => String::new(),
        };
        errln!(
            "{}: {what} [{}]: {}{to}",
            t.texture.file.display(),
            d.rule(),
            t.error.as_deref().unwrap_or(d.why())
        );
    }
    Ok(())
}

/// Converts the jobs (each in its colour space), reports the textures that are not converted
/// as failures, and writes the layer.
fn convert(
    reporting: &Reporting,
    options: Options,
    asset: &Asset,
    jobs: &[Job],
    reader: &Reader,
) -> Result<i32> {
    let converters =
        Converters::new(&options, jobs).map_err(|e| usage(anyhow::anyhow!(explain(&e))))?;
    make_folders(&asset.dir, jobs).map_err(asset_error)?;
    let each = converters.each();
    let pairs: Vec<_> = jobs.iter().map(Job::pair).collect();
    let outcomes = Arc::new(Mutex::new(Outcomes::new(asset, jobs)));
    let members: Vec<String> = (0..asset.textures.len())
        .map(|k| format!("\"asset\":{}", member(asset, k)))
        .collect();
    let annotate: Annotate = {
        let outcomes = Arc::clone(&outcomes);
        Arc::new(move |record: &Record| {
            let k = outcomes
                .lock()
                .ok()?
                .heard(record.input(), record.status())?;
            Some(members[k].clone())
        })
    };
    let reporting = Reporting {
        annotate: Some(annotate),
        ..reporting.clone()
    };
    let unplanned = report_unplanned(&reporting, asset)?;
    let code = run_batch(&reporting, (converters.first(), Some(&each)), &pairs)?;
    if code == exit::INTERRUPTED || code == exit::USAGE {
        return Ok(code);
    }
    let outcomes = outcomes.lock().map(|o| o.clone()).unwrap_or_default();
    let layer = finish(reader, asset, &outcomes)
        .with_context(|| format!("cannot write the layer {}", asset.layer.display()))?;
    if !reporting.quiet {
        errln!("specconv: {}", layer.line());
    }
    if !reporting.quiet {
        errln!("specconv: {}", storage(jobs));
    }
    Ok(if unplanned > 0 { exit::FAILED } else { code })
}

/// The stage-level summary of storage (issue 56, item 5): the bytes of the textures read and
/// of the files written for them (those on disk now: converted, or up to date).
fn storage(jobs: &[Job]) -> String {
    let size = |p: &Path| std::fs::metadata(p).map_or(0, |m| m.len());
    let (inputs, outputs) = jobs.iter().fold((0u64, 0u64), |(i, o), j| {
        (i + size(&j.input), o + size(&j.output))
    });
    let mb = |b: u64| b as f64 / 1e6;
    let ratio = match inputs {
        0 => String::new(),
        _ => format!(" ({:.1}× the textures)", outputs as f64 / inputs as f64),
    };
    format!(
        "storage: {} texture file(s), {:.2} MB read ({inputs} bytes), {:.2} MB written \
         ({outputs} bytes){ratio}",
        jobs.len(),
        mb(inputs),
        mb(outputs)
    )
}

/// The textures that are not converted (a conflict, a missing file, a colour space the config
/// lacks, a UDIM pattern with no tile): a failed record or an error line each; how many.
fn report_unplanned(reporting: &Reporting, asset: &Asset) -> Result<usize> {
    let mut n = 0;
    for (k, t) in asset.textures.iter().enumerate() {
        let Some(why) = &t.error else { continue };
        n += 1;
        let file = &t.texture.file;
        if reporting.json {
            let record = Record::failed(file, Path::new(""), why.clone(), 0.0).to_json();
            outln!("{}", with_member(&record, asset, k))?;
        } else {
            print_error(&format!("{}: {why}", file.display()));
        }
    }
    Ok(n)
}
