//! What every front-end does with an asset, in order: [`prepare`] (read and plan),
//! [`Converters`] (one per colour space), the batch (the front-end's, with
//! [`specconv_conversion::Batch::each_input`]), [`Outcomes`], [`finish`] (the layer).

use crate::error::Error;
use crate::plan::{extract_dir, Asset, Job, LayerPlan};
use crate::reader::check_stage;
use crate::{record, Reader};
use specconv_conversion::{ColourConfig, Converter, DataPolicy, Options};
use std::path::{Path, PathBuf};

/// A stage read and planned: every texture's decision and output, the jobs.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The plan.
    pub asset: Asset,
    /// The conversions (UDIM tiles one each).
    pub jobs: Vec<Job>,
}

/// Reads `stage` and plans it into `dir` for a conversion with `options` (their config names
/// the colour spaces; with `data` fail a data texture is a failure, not a job). Unless
/// `dry_run`, `dir` is made and a usdz's textures are copied out into it. The plan is refused
/// when an output is a file the stage reads or one no asset run wrote ([`record::check`]),
/// and when the layer exists, unless `update` or `overwrite`; then it is claimed in the
/// record. Nothing else is written.
pub fn prepare(
    reader: &Reader,
    (stage, dir): (&Path, &Path),
    options: &Options,
    (dry_run, update): (bool, bool),
) -> Result<Prepared, Error> {
    let replace = update || options.overwrite;
    check_stage(stage)?;
    let stage = absolute(stage)?;
    if !dry_run {
        std::fs::create_dir_all(dir).map_err(|e| Error::Io(dir.to_path_buf(), e))?;
    }
    let dir = absolute(dir)?;
    let extract = (!dry_run).then(|| extract_dir(&stage, &dir));
    // A usdz's copy-outs replace only the asset's own files; once made, they are its own.
    let own = match &extract {
        Some(folder) => record::own_under(&dir, folder)?,
        None => Vec::new(),
    };
    let read = reader.read(&stage, extract.as_deref().map(|d| (d, own.as_slice())))?;
    let copied: Vec<PathBuf> = read
        .textures
        .iter()
        .filter(|t| t.package.is_some())
        .filter_map(|t| t.resolved.clone())
        .collect();
    // A dry run copies nothing out, and writes no record.
    if !dry_run && !copied.is_empty() {
        record::stamp(&dir, &copied)?;
    }
    let config =
        ColourConfig::resolve(options.ocio.as_deref()).map_err(|e| Error::Config(Box::new(e)))?;
    let mut asset = Asset::new(read, &dir, (&config, options))?;
    let mut jobs = asset.jobs();
    if options.data == DataPolicy::Fail {
        jobs.retain(|j| !asset.fail_data(j.texture));
    }
    // The whole plan is checked before the first write, and claimed (crate::record).
    let documents = asset.layer_plan(|_| true).documents;
    asset.writes = std::iter::once(asset.layer.clone())
        .chain(documents.into_iter().map(|d| d.layer))
        .chain(jobs.iter().map(|j| j.output.clone()))
        .collect();
    let reads: Vec<PathBuf> = std::iter::once(asset.stage.clone())
        .chain(asset.read_files.iter().cloned())
        .chain(asset.textures.iter().map(|t| t.texture.file.clone()))
        .chain(jobs.iter().map(|j| j.input.clone()))
        .collect();
    record::check(&dir, &asset.writes, &reads)?;
    if !dry_run && !replace && std::fs::symlink_metadata(&asset.layer).is_ok() {
        return Err(Error::LayerExists {
            layer: asset.layer.clone(),
        });
    }
    if !dry_run {
        record::claim(&dir, &asset.writes)?;
    }
    Ok(Prepared { asset, jobs })
}

/// `p` absolute, `.` and `..` taken out by name (as the resolver's paths are), so that a DIR
/// given as `../spectral` is compared with them as the folder it names.
fn absolute(p: &Path) -> Result<PathBuf, Error> {
    let abs = std::path::absolute(p).map_err(|e| Error::Io(p.to_path_buf(), e))?;
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    Ok(out)
}

/// One converter per colour space the jobs are given: `options` with that space.
pub struct Converters {
    list: Vec<(Option<String>, Converter)>,
    of_job: Vec<usize>,
}

impl Converters {
    /// The converters of `jobs`, each checked as `Converter::new` checks; with no job, one of
    /// `options` as they are (the batch needs one).
    pub fn new(options: &Options, jobs: &[Job]) -> Result<Converters, specconv_conversion::Error> {
        Converters::of_spaces(options, jobs.iter().map(|j| j.colorspace.as_deref()))
    }

    /// The converters of inputs given these colour spaces in turn (a farm task's files, as the
    /// manifest carries the asset's decisions): one per space, `options` with that space.
    pub fn of_spaces<'a>(
        options: &Options,
        spaces: impl IntoIterator<Item = Option<&'a str>>,
    ) -> Result<Converters, specconv_conversion::Error> {
        let mut list: Vec<(Option<String>, Converter)> = Vec::new();
        let mut of_job = Vec::new();
        for space in spaces {
            let space = space.map(str::to_string);
            let k = match list.iter().position(|(s, _)| *s == space) {
                Some(k) => k,
                None => {
                    let mut o = options.clone();
                    o.colorspace = space.clone();
                    list.push((space, Converter::new(o)?));
                    list.len() - 1
                }
            };
            of_job.push(k);
        }
        if list.is_empty() {
            list.push((None, Converter::new(options.clone())?));
        }
        Ok(Converters { list, of_job })
    }

    /// The batch's converter.
    pub fn first(&self) -> &Converter {
        &self.list[0].1
    }

    /// Job k's converter, for [`specconv_conversion::Batch::each_input`].
    pub fn each(&self) -> Vec<&Converter> {
        self.of_job.iter().map(|&k| &self.list[k].1).collect()
    }
}

/// Makes the folders under `dir` (the asset's DIR) the jobs' outputs go to, once no folder
/// on the way is a symbolic link: nothing is written outside DIR.
pub fn make_folders(dir: &Path, jobs: &[Job]) -> Result<(), Error> {
    for j in jobs {
        if let Some(link) = specconv_atomic_file::link_below(dir, &j.output) {
            return Err(Error::LinkBelowDir {
                link,
                dir: dir.to_path_buf(),
            });
        }
        if let Some(parent) = j.output.parent() {
            std::fs::create_dir_all(parent).map_err(|e| Error::Io(parent.to_path_buf(), e))?;
        }
    }
    Ok(())
}

/// What became of each texture's jobs (the statuses of their records: `ok`, `clipped`,
/// `skipped`, `data`, `copied`, `failed`).
#[derive(Debug, Clone, Default)]
pub struct Outcomes {
    statuses: Vec<Vec<&'static str>>,
    jobs: Vec<usize>,
    texture_of: std::collections::HashMap<PathBuf, usize>,
}

impl Outcomes {
    /// Nothing heard yet of the `jobs` of `asset`.
    pub fn new(asset: &Asset, jobs: &[Job]) -> Outcomes {
        let mut counts = vec![0; asset.textures.len()];
        for j in jobs {
            counts[j.texture] += 1;
        }
        Outcomes {
            statuses: vec![Vec::new(); asset.textures.len()],
            jobs: counts,
            texture_of: jobs.iter().map(|j| (j.input.clone(), j.texture)).collect(),
        }
    }

    /// The texture of the job whose input is `input`.
    pub fn texture_of(&self, input: &Path) -> Option<usize> {
        self.texture_of.get(input).copied()
    }

    /// Hears the status of the record of `input`; its texture.
    pub fn heard(&mut self, input: &Path, status: &'static str) -> Option<usize> {
        let k = self.texture_of(input)?;
        self.statuses[k].push(status);
        Some(k)
    }

    /// Every job of texture `k` converted or up to date.
    pub fn done(&self, k: usize) -> bool {
        let s = &self.statuses[k];
        s.len() == self.jobs[k]
            && !s.is_empty()
            && s.iter().all(|s| matches!(*s, "ok" | "clipped" | "skipped"))
    }
}

/// Whether a fresh plan's `jobs` are exactly a farm job's `files` (input, output, colour space
/// given), in any order: the stage still says what the job converted. `Err`: the first
/// difference, in words.
pub fn same_jobs(jobs: &[Job], files: &[(PathBuf, PathBuf, Option<String>)]) -> Result<(), String> {
    let now: std::collections::BTreeSet<(&Path, &Path, Option<&str>)> = jobs
        .iter()
        .map(|j| {
            (
                j.input.as_path(),
                j.output.as_path(),
                j.colorspace.as_deref(),
            )
        })
        .collect();
    let then: std::collections::BTreeSet<(&Path, &Path, Option<&str>)> = files
        .iter()
        .map(|(i, o, c)| (i.as_path(), o.as_path(), c.as_deref()))
        .collect();
    let say = |(i, o, c): &(&Path, &Path, Option<&str>)| {
        format!(
            "{} → {} (colour space {})",
            i.display(),
            o.display(),
            c.unwrap_or("from the file")
        )
    };
    if let Some(gone) = then.difference(&now).next() {
        return Err(format!(
            "the job converts {}, which the stage no longer plans",
            say(gone)
        ));
    }
    if let Some(new) = now.difference(&then).next() {
        return Err(format!(
            "the stage now plans {}, which the job does not convert",
            say(new)
        ));
    }
    Ok(())
}

/// One file of a farm job of a stage, as its manifest and its logs say: input, output, the
/// colour space its conversion was given, and whether it is done.
pub type FarmFile = (PathBuf, PathBuf, Option<String>, bool);

/// The layer of a farm job of `stage` into `dir` (`farm collect`): the stage read and planned
/// again with `options`; written, over the colour textures whose files are all done, only when
/// that plan is exactly the job's `files` ([`same_jobs`]). `Err`: why no layer was written.
pub fn farm_layer(
    reader: &Reader,
    (stage, dir): (&Path, &Path),
    options: &Options,
    files: &[FarmFile],
) -> Result<LayerPlan, String> {
    let Prepared { asset, jobs } =
        prepare(reader, (stage, dir), options, (false, true)).map_err(|e| e.to_string())?;
    let planned: Vec<_> = files
        .iter()
        .map(|(i, o, c, _)| (i.clone(), o.clone(), c.clone()))
        .collect();
    same_jobs(&jobs, &planned).map_err(|why| {
        format!("{why} (the stage changed since the job was submitted, or the manifest was edited)")
    })?;
    let done: std::collections::HashSet<&Path> = files
        .iter()
        .filter(|f| f.3)
        .map(|f| f.0.as_path())
        .collect();
    let layer = asset.layer_plan(|k| {
        let mut of = jobs.iter().filter(|j| j.texture == k).peekable();
        of.peek().is_some() && of.all(|j| done.contains(j.input.as_path()))
    });
    reader.write_layer(&layer).map_err(|e| e.to_string())?;
    record::stamp(&asset.dir, &asset.writes).map_err(|e| e.to_string())?;
    Ok(layer)
}

/// Writes the layer: every colour texture that is done given its spectral file in the render
/// context `spectral` (a copy of its material network).
pub fn finish(reader: &Reader, asset: &Asset, outcomes: &Outcomes) -> Result<LayerPlan, Error> {
    let layer = asset.layer_plan(|k| outcomes.done(k));
    reader.write_layer(&layer)?;
    record::stamp(&asset.dir, &asset.writes)?;
    Ok(layer)
}

/// A texture's `asset` member of its records (docs/assets.md): the stage, the layer, the
/// rule, why, the colour space given, the output, and each use.
pub fn member(asset: &Asset, k: usize) -> serde_json::Value {
    let t = &asset.textures[k];
    let uses: Vec<serde_json::Value> = t
        .texture
        .nodes
        .iter()
        .flat_map(|n| {
            n.uses.iter().map(move |u| {
                serde_json::json!({
                    "prim": n.node, "node_id": n.node_id, "material": u.material,
                    "shader": u.shader, "input": u.input, "output": u.output,
                    "input_type": u.input_type, "defined_by": u.defined_by,
                    "file_input": n.file_input,
                    "through": u.through, "source_color_space": n.source_color_space,
                    "colorspace": n.colorspace, "authored": n.authored,
                    "document": n.document,
                })
            })
        })
        .collect();
    serde_json::json!({
        "stage": asset.stage, "layer": asset.layer, "texture": t.texture.file,
        "decision": &t.texture.decision, "rule": t.texture.decision.rule(),
        "why": t.error.as_deref().unwrap_or(t.texture.decision.why()),
        "colorspace_given": t.colorspace, "output": t.output, "uses": uses,
    })
}

/// A file a shader this reader does not know reads, in words (issue 56, item 2): a warning,
/// or under `--strict` (`strict`) an error.
pub fn unknown_line(u: &crate::stage::UnknownRead) -> String {
    format!(
        "unknown shader {} at {} reads {} (its input {}, material {}): not converted; \
         no definition specconv knows has this shader (it reads USD's own, MaterialX's, \
         Arnold's and RenderMan's: docs/assets.md, \"Roles from shader definitions\")",
        u.node_id.as_deref().unwrap_or("(no info:id)"),
        u.node,
        u.file,
        u.input,
        u.material
    )
}

/// The same as a record of `convert --json`'s form: status `unknown-shader`, no output, the
/// shader, prim, input, file and material in its `asset` member.
pub fn unknown_record(asset: &Asset, u: &crate::stage::UnknownRead) -> serde_json::Value {
    serde_json::json!({
        "input": u.resolved.as_deref().unwrap_or(&u.file),
        "output": "",
        "status": "unknown-shader",
        "asset": {
            "stage": asset.stage, "node": u.node,
            "shader": u.node_id.as_deref().unwrap_or("(no info:id)"), "input": u.input,
            "file": u.file, "material": u.material,
            "why": "a shader specconv asset does not know reads it: not converted",
        },
    })
}

/// A record (`convert --json`'s, one JSON object) with the `asset` member of texture `k`.
pub fn with_member(record: &str, asset: &Asset, k: usize) -> String {
    let members = record.trim_end().strip_suffix('}').unwrap_or(record);
    format!("{members},\"asset\":{}}}", member(asset, k))
}
