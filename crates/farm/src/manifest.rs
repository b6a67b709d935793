//! The job directory: `manifest.json` (inputs, outputs, settings, the tasks of every round) and
//! one folder per round (`round-0` for the submission, then one per retry) holding the sbatch
//! script, each task's input list, its log of JSON lines and its standard error.
//!
//! The directory is input like any other: [`Manifest::load`] checks that every path the
//! manifest names is one the job owns (outputs inside its output directory, rounds planning
//! only listed files) and refuses files over [`MAX_FILE_BYTES`] before reading them.

use crate::error::Error;
use serde::{Deserialize, Serialize};
use specconv_atomic_file::outputs;
use std::path::{Component, Path, PathBuf};

/// Version of the manifest's layout.
pub const FORMAT: u32 = 3;

/// The largest manifest or task log read: a manifest of 100 000 files (paths of about 60
/// characters) measured 18.8 MB, so this holds some 350 000; far less than a damaged or
/// hostile file could hold.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// `manifest.json`, the job directory's record of a job: what to convert, how, and every round
/// submitted. The fields are its JSON, written by serde (docs/farm.md describes the directory).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Manifest {
    /// The layout version the file was written in; [`Manifest::load`] refuses any but [`FORMAT`].
    pub format: u32,
    /// The specconv binary every task runs (on the shared file system).
    pub specconv: PathBuf,
    /// The directory tasks run in (where relative paths in `options` mean something).
    pub workdir: PathBuf,
    /// The OCIO config `submit` checked (an absolute file path or a built-in name), passed to
    /// every task as `--ocio`, so the nodes' `$OCIO` does not matter.
    pub ocio: String,
    /// Where outputs go: every [`File::output`] must follow it.
    pub outputs: Outputs,
    /// The conversion's options every task converts with, by the conversion library's names
    /// and in its text (`specconv_conversion::Key`, `Options::text`): those that differ from
    /// the defaults. The farm sets the rest itself: the config ([`Manifest::ocio`]), the threads
    /// (`--cpus-per-task`) and the up-to-date check (always on).
    pub options: std::collections::BTreeMap<String, String>,
    /// Every input of the job; rounds refer to them by index.
    pub files: Vec<File>,
    /// What each task asks of Slurm, the same in every round.
    pub request: Request,
    /// The rounds, in order: the submission first, then each retry.
    pub rounds: Vec<Round>,
    /// A stage submitted (`farm submit STAGE`): its textures are the files, each with the
    /// colour space the asset's rule gave it ([`File::colorspace`]); absent for a job of files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub asset: Option<AssetJob>,
}

/// What a job of a stage adds (docs/farm.md, docs/assets.md): the stage, and the layer `collect`
/// writes over it once a fresh read of the stage plans exactly the job's files.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct AssetJob {
    /// The stage, an absolute path.
    pub stage: PathBuf,
    /// The layer over it, `DIR/STEM_spectral.usda`, directly in the job's output directory.
    pub layer: PathBuf,
}

/// Where a job's outputs go, as `submit` was told.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outputs {
    /// `-o DIR` (absolute): every output directly inside it.
    Directory(PathBuf),
    /// `--output-template`, as given (relative to [`Manifest::workdir`] when relative): every
    /// output is what it gives for its input.
    Template(String),
    /// A stage's `-o DIR` (absolute): every output anywhere below it, where the asset's plan
    /// puts it (`DIR/tex/…`, `DIR/external/HASH/…`), never through `..`.
    Tree(PathBuf),
}

/// One input and where its output goes.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct File {
    /// The input texture, an absolute path.
    pub input: PathBuf,
    /// Where its spectral EXR goes (absolute, as [`Manifest::outputs`] says).
    pub output: PathBuf,
    /// Where it goes when it is a data texture written through, when that is another file
    /// (`-o DIR`'s `STEM_data.exr`, a template's `{role}`); absent in older manifests.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<PathBuf>,
    /// Pixels over all levels when planned (0 when the input could not be read then).
    pub pixels: u64,
    /// The colour space this file's conversion is given (the config's name), as the asset's
    /// rule decided it at submit (a texture's material names it; a data texture's is the
    /// config's data space); absent: the job's options and the file's own evidence decide.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colorspace: Option<String>,
}

impl File {
    /// The files its conversion may write: the file is done only when one exists.
    pub fn outputs(&self) -> impl Iterator<Item = &Path> {
        std::iter::once(self.output.as_path()).chain(self.data.as_deref())
    }
}

/// What each array task asks of Slurm.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Request {
    /// `--partition`; `None` leaves Slurm's default.
    pub partition: Option<String>,
    /// `--time`, as sbatch reads it (`30`, `2:00:00`, `1-0`); `None` leaves the partition's limit.
    pub time: Option<String>,
    /// `--cpus-per-task`, also the threads each conversion uses (`-j`).
    pub cpus_per_task: usize,
    /// Memory per task in MiB.
    pub mem_mib: u64,
    /// At most this many tasks at once (`--array=…%K`).
    pub limit: Option<usize>,
}

/// One round: an array whose task `t` converts the files `tasks[t]` (indices into
/// [`Manifest::files`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Round {
    /// The array job's id, as sbatch printed it; `None` while the round is written but not
    /// submitted (recorded before sbatch runs, so an interrupted submit shows as such).
    pub job_id: Option<String>,
    /// Per array task, the indices of its files.
    pub tasks: Vec<Vec<usize>>,
}

impl Manifest {
    /// `JOBDIR/manifest.json`.
    pub fn path(job_dir: &Path) -> PathBuf {
        job_dir.join("manifest.json")
    }

    /// Reads and checks the manifest of a job directory: [`Error::NotAJobFile`] when it is
    /// missing (not a job directory) or no regular file, [`Error::Io`] when it cannot be read,
    /// [`Error::TooLarge`], [`Error::Manifest`] when it does not parse or
    /// has another [`FORMAT`], [`Error::Untrusted`] when it names what the job does not own
    /// ([`Manifest::check`]).
    pub fn load(job_dir: &Path) -> Result<Manifest, Error> {
        let path = Manifest::path(job_dir);
        let text = read_bounded(&path).map_err(|e| match e {
            Error::Io(what, e) => Error::Io(
                format!("{what} (is this a job directory of `specconv farm submit`?)"),
                e,
            ),
            e => e,
        })?;
        let m: Manifest = serde_json::from_str(&text)
            .map_err(|e| Error::Manifest(format!("{}: {e}", path.display())))?;
        if m.format != FORMAT {
            return Err(Error::Manifest(format!(
                "{} has layout {} where this specconv reads {FORMAT}; use the specconv that submitted it",
                path.display(),
                m.format
            )));
        }
        m.check(job_dir)?;
        Ok(m)
    }

    /// Checks that the manifest names only what the job owns: absolute paths; every output
    /// where [`Manifest::outputs`] puts its input's; every round planning listed files, each
    /// once; every round folder a real folder of the job directory.
    pub fn check(&self, job_dir: &Path) -> Result<(), Error> {
        let untrusted = |named: &dyn std::fmt::Display, why: String| Error::Untrusted {
            manifest: Manifest::path(job_dir),
            named: named.to_string(),
            why,
        };
        for p in [&self.specconv, &self.workdir] {
            if !p.is_absolute() {
                return Err(untrusted(&p.display(), "not an absolute path".into()));
            }
        }
        if let Outputs::Directory(dir) | Outputs::Tree(dir) = &self.outputs {
            if !dir.is_absolute() {
                return Err(untrusted(&dir.display(), "not an absolute path".into()));
            }
        }
        self.check_asset()
            .map_err(|(named, why)| untrusted(&named, why))?;
        for f in &self.files {
            if !f.input.is_absolute() {
                return Err(untrusted(&f.input.display(), "not an absolute path".into()));
            }
            for (output, holds) in f.outputs().zip(outputs::Holds::ALL) {
                self.outputs
                    .check(&self.workdir, &f.input, output, holds)
                    .map_err(|why| untrusted(&output.display(), why))?;
            }
        }
        for (r, round) in self.rounds.iter().enumerate() {
            let mut seen = vec![false; self.files.len()];
            for &i in round.tasks.iter().flatten() {
                match seen.get_mut(i) {
                    Some(s) if !*s => *s = true,
                    Some(_) => {
                        return Err(untrusted(
                            &format!("file {i}"),
                            format!("planned twice in round {r}"),
                        ))
                    }
                    None => {
                        return Err(untrusted(
                            &format!("file {i}"),
                            format!("in round {r}, where {} files are listed", self.files.len()),
                        ))
                    }
                }
            }
            own_folder(&round_dir(job_dir, r))
                .map_err(|why| untrusted(&round_dir(job_dir, r).display(), why))?;
        }
        Ok(())
    }

    /// A stage's job: the stage absolute, the layer a `.usda` directly in its output tree, and
    /// outputs of a tree only with a stage (`Err`: what is named, and why not).
    fn check_asset(&self) -> Result<(), (String, String)> {
        match (&self.asset, &self.outputs) {
            (None, Outputs::Tree(dir)) => Err((
                dir.display().to_string(),
                "an output tree, which only a stage's job has".into(),
            )),
            (None, _) => Ok(()),
            (Some(a), Outputs::Tree(dir)) => {
                if !a.stage.is_absolute() {
                    return Err((a.stage.display().to_string(), "not an absolute path".into()));
                }
                let named = a.layer.file_name().map(Path::new);
                let usda = named.and_then(Path::extension) == Some("usda".as_ref());
                if a.layer.parent() == Some(dir.as_path()) && usda {
                    Ok(())
                } else {
                    Err((
                        a.layer.display().to_string(),
                        format!("not a .usda layer directly in {}", dir.display()),
                    ))
                }
            }
            (Some(a), _) => Err((
                a.stage.display().to_string(),
                "a stage, whose job must have an output tree".into(),
            )),
        }
    }

    /// Writes the manifest atomically (temporary file, then rename).
    pub fn save(&self, job_dir: &Path) -> Result<(), Error> {
        let path = Manifest::path(job_dir);
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::Manifest(format!("cannot write {}: {e}", path.display())))?;
        specconv_atomic_file::write(&path, (text + "\n").as_bytes())
            .map_err(|e| Error::Io(format!("cannot write {}", path.display()), e))
    }

    /// The directories outputs go into, sorted, each once (a stage's: its output directory,
    /// which holds the folders below it).
    pub fn output_dirs(&self) -> Vec<PathBuf> {
        if let Outputs::Tree(dir) = &self.outputs {
            return vec![dir.clone()];
        }
        let dirs: std::collections::BTreeSet<PathBuf> = self
            .files
            .iter()
            .filter_map(|f| f.output.parent().map(Path::to_path_buf))
            .collect();
        dirs.into_iter().collect()
    }

    /// The (input, output) files task `task` of round `round` converts, in order.
    pub fn task_files(&self, round: usize, task: usize) -> Result<Vec<&File>, Error> {
        let files = self
            .rounds
            .get(round)
            .and_then(|r| r.tasks.get(task))
            .ok_or(Error::NoSuchTask { round, task })?;
        files
            .iter()
            .map(|&i| self.files.get(i).ok_or(Error::NoSuchTask { round, task }))
            .collect()
    }
}

impl Outputs {
    /// Whether `output` is where these rules put `input`'s output when it holds `holds`
    /// (`Err`: why not, in words).
    pub fn check(
        &self,
        workdir: &Path,
        input: &Path,
        output: &Path,
        holds: outputs::Holds,
    ) -> Result<(), String> {
        if !output.is_absolute() {
            return Err("not an absolute path".into());
        }
        match self {
            Outputs::Directory(dir) => {
                let inside = output.parent() == Some(dir.as_path())
                    && matches!(output.components().next_back(), Some(Component::Normal(_)));
                if inside {
                    Ok(())
                } else {
                    Err(format!(
                        "outside the job's output directory {}",
                        dir.display()
                    ))
                }
            }
            Outputs::Tree(dir) => {
                let below = output.strip_prefix(dir).ok().filter(|rest| {
                    rest.components().next().is_some()
                        && rest.components().all(|c| matches!(c, Component::Normal(_)))
                });
                match (below, specconv_atomic_file::link_below(dir, output)) {
                    (None, _) => Err(format!("outside the job's output tree {}", dir.display())),
                    (Some(_), Some(link)) => Err(format!(
                        "through the symbolic link {} below the job's output tree {}",
                        link.display(),
                        dir.display()
                    )),
                    (Some(_), None) => Ok(()),
                }
            }
            Outputs::Template(t) => {
                let planned = outputs::from_template(t, input, holds).map_err(|e| e.to_string())?;
                let want = lexical(&workdir.join(planned));
                if lexical(output) == want {
                    Ok(())
                } else {
                    Err(format!(
                        "not where the job's output template {t:?} puts {} ({})",
                        input.display(),
                        want.display()
                    ))
                }
            }
        }
    }
}

/// A path with `.` components and repeated separators dropped, as `std::path::absolute` leaves
/// it (`..` kept: no symlink is resolved).
fn lexical(p: &Path) -> PathBuf {
    p.components()
        .filter(|c| !matches!(c, Component::CurDir))
        .collect()
}

/// A folder of the job directory: absent (not written yet), or a real folder, not a link to
/// somewhere else.
fn own_folder(p: &Path) -> Result<(), String> {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => Err("not a folder of the job directory (a link or a file)".into()),
        Err(_) => Ok(()),
    }
}

/// A file of the job directory as text: a regular file (not a FIFO, device or link, opened so
/// that none can block) of at most [`MAX_FILE_BYTES`].
pub fn read_bounded(path: &Path) -> Result<String, Error> {
    use specconv_atomic_file::ReadError;
    let cannot = |e| Error::Io(format!("cannot read {}", path.display()), e);
    // A link is not the job's own file, whatever it leads to.
    let bytes =
        specconv_atomic_file::read_bounded_own(path, MAX_FILE_BYTES, "job file").map_err(|e| {
            match e {
                ReadError::TooLarge { .. } => Error::TooLarge {
                    path: path.to_path_buf(),
                    limit: MAX_FILE_BYTES,
                },
                ReadError::NotAFile { path, kind } => Error::NotAJobFile { path, kind },
                ReadError::Io { source, .. } => cannot(source),
            }
        })?;
    String::from_utf8(bytes).map_err(|_| cannot(std::io::Error::other("not UTF-8 text")))
}

/// The folder of round `r`.
pub fn round_dir(job_dir: &Path, round: usize) -> PathBuf {
    job_dir.join(format!("round-{round}"))
}

/// Task `t`'s list of inputs, its log (JSON lines, standard output) and its standard error.
pub fn task_inputs(round_dir: &Path, task: usize) -> PathBuf {
    round_dir.join(format!("task-{task}.inputs"))
}

/// `task-T.jsonl`: the task's log, its standard output.
pub fn task_log(round_dir: &Path, task: usize) -> PathBuf {
    round_dir.join(format!("task-{task}.jsonl"))
}

/// A path as an sbatch filename pattern (`--output`, `--error`) that means the path itself:
/// `%` doubled (sbatch expands `%j`, `%A`, `%a`…). sbatch drops backslashes and disables
/// patterns where it sees one, and the script names the folder in a comment, so paths with a
/// backslash or a line break, or that are not UTF-8, are refused ([`Error::JobDir`]).
pub fn sbatch_pattern(p: &Path) -> Result<String, Error> {
    let refuse = |why: &str| Error::JobDir {
        dir: p.to_path_buf(),
        why: why.to_string(),
    };
    let s = p.to_str().ok_or_else(|| refuse("not UTF-8"))?;
    if s.contains('\\') {
        return Err(refuse(
            "a backslash, which sbatch drops from log file names",
        ));
    }
    if s.contains(['\n', '\r']) {
        return Err(refuse("a line break"));
    }
    Ok(s.replace('%', "%%"))
}

/// The sbatch options of a round: one array of `tasks` tasks, its logs in `round_dir`.
pub fn sbatch_options(m: &Manifest, round_dir: &Path, tasks: usize) -> Result<Vec<String>, Error> {
    let r = &m.request;
    let mut o = vec![
        "--parsable".to_string(),
        "--job-name=specconv".to_string(),
        format!(
            "--array=0-{}{}",
            tasks - 1,
            r.limit.map_or(String::new(), |k| format!("%{k}"))
        ),
        format!("--cpus-per-task={}", r.cpus_per_task),
        format!("--mem={}M", r.mem_mib),
        // --chdir takes no patterns (sbatch 22.05).
        format!("--chdir={}", m.workdir.display()),
        format!("--output={}/task-%a.jsonl", sbatch_pattern(round_dir)?),
        format!("--error={}/task-%a.err", sbatch_pattern(round_dir)?),
    ];
    if let Some(p) = &r.partition {
        o.push(format!("--partition={p}"));
    }
    if let Some(t) = &r.time {
        o.push(format!("--time={t}"));
    }
    Ok(o)
}

/// The command line a task runs, `specconv farm task JOBDIR --round R --task T`: made here
/// only, and read only by the `farm task` command. The conversion's options are not on it:
/// the task reads them from the manifest.
pub fn task_command(m: &Manifest, job_dir: &Path, round: usize, task: &str) -> Vec<String> {
    vec![
        m.specconv.display().to_string(),
        "farm".into(),
        "task".into(),
        job_dir.display().to_string(),
        "--round".into(),
        round.to_string(),
        "--task".into(),
        task.into(),
    ]
}

/// The batch script every task runs: `farm task` on its files ([`task_command`]), one JSON line
/// per file on standard output (the task's log), framed by start and end events that carry the
/// time and the exit code.
pub fn script(m: &Manifest, job_dir: &Path, round: usize) -> String {
    let command: Vec<String> = task_command(m, job_dir, round, "T")
        .iter()
        .map(|w| match w.as_str() {
            "T" => "\"$t\"".to_string(),
            w => quote(w),
        })
        .collect();
    format!(
        r#"#!/bin/bash
# specconv farm: one task of a job array converts its files of round {round} (task-N.inputs lists
# them). Written by `specconv farm`; its manifest is {manifest}.
t=$SLURM_ARRAY_TASK_ID
echo "{{\"event\":\"start\",\"task\":$t,\"unix\":$(date +%s.%N)}}"
# In the background, so that a SIGTERM (scancel, time limit) reaching this shell is passed on
# and waited for: the conversion stops between windows and removes its temporary file.
{command} < /dev/null &
pid=$!
trap 'kill -TERM $pid 2>/dev/null' TERM INT
wait $pid
code=$?
while kill -0 $pid 2>/dev/null; do wait $pid; code=$?; done
echo "{{\"event\":\"end\",\"task\":$t,\"unix\":$(date +%s.%N),\"exit\":$code}}"
exit $code
"#,
        manifest = Manifest::path(job_dir).display(),
        command = command.join(" "),
    )
}

/// Quotes a word for bash (single quotes unless it is plainly safe).
pub fn quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// A manifest for the crate's tests: these outputs and (input, output) files, one pixel each,
/// and these rounds.
#[cfg(test)]
pub(crate) fn example(
    outputs: Outputs,
    files: Vec<(PathBuf, PathBuf)>,
    rounds: Vec<Round>,
) -> Manifest {
    Manifest {
        format: FORMAT,
        specconv: "/bin/specconv".into(),
        workdir: "/work".into(),
        ocio: "aces".into(),
        outputs,
        options: Default::default(),
        files: files
            .into_iter()
            .map(|(input, output)| File {
                input,
                output,
                data: None,
                pixels: 1,
                colorspace: None,
            })
            .collect(),
        request: Request {
            partition: None,
            time: None,
            cpus_per_task: 1,
            mem_mib: 100,
            limit: None,
        },
        rounds,
        asset: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use outputs::Holds::{self, Spectral};

    #[test]
    fn words_are_quoted_for_bash() {
        assert_eq!(quote("-o"), "-o");
        assert_eq!(quote("/a b/c"), "'/a b/c'");
        assert_eq!(quote("it's"), r"'it'\''s'");
        assert_eq!(quote(""), "''");
    }

    #[test]
    fn percent_signs_reach_sbatch_literally_and_backslashes_are_refused() {
        assert_eq!(
            sbatch_pattern(Path::new("/a%j/b%%")).unwrap(),
            "/a%%j/b%%%%"
        );
        assert_eq!(
            sbatch_pattern(Path::new("/plain/dir")).unwrap(),
            "/plain/dir"
        );
        for bad in ["/a\\b", "/a\nb"] {
            let e = sbatch_pattern(Path::new(bad)).unwrap_err().to_string();
            assert!(e.contains("--job-dir"), "{e}");
        }
        let m = manifest(Outputs::Directory("/out".into()), vec![]);
        let o = sbatch_options(&m, Path::new("/jobs/%A_%a/round-0"), 2).unwrap();
        assert!(
            o.contains(&"--output=/jobs/%%A_%%a/round-0/task-%a.jsonl".to_string()),
            "{o:?}"
        );
        assert!(
            o.contains(&"--error=/jobs/%%A_%%a/round-0/task-%a.err".to_string()),
            "{o:?}"
        );
    }

    fn manifest(outputs: Outputs, files: Vec<(&str, &str)>) -> Manifest {
        let files = files
            .into_iter()
            .map(|(i, o)| (i.into(), o.into()))
            .collect();
        example(
            outputs,
            files,
            vec![Round {
                job_id: None,
                tasks: vec![vec![0]],
            }],
        )
    }

    #[test]
    fn outputs_are_confined_to_the_output_directory() {
        let dir = Outputs::Directory("/out".into());
        let ok = |o: &str| {
            dir.check(
                Path::new("/w"),
                Path::new("/in/a.png"),
                Path::new(o),
                Spectral,
            )
        };
        assert!(ok("/out/a_spectral.exr").is_ok());
        for outside in [
            "/etc/passwd",
            "/out/sub/a.exr",
            "/out/../etc/a.exr",
            "/out/..",
            "/out",
            "out/a.exr",
            "/outside/a.exr",
        ] {
            let e = ok(outside).unwrap_err();
            assert!(
                e.contains("outside the job's output directory /out") || e.contains("absolute"),
                "{outside}: {e}"
            );
        }
        // A manifest naming one is refused as edited or damaged, naming the path.
        let jobs = std::env::temp_dir().join(format!("farm-confine-{}", std::process::id()));
        let m = manifest(dir.clone(), vec![("/in/a.png", "/victim/a.exr")]);
        let e = m.check(&jobs).unwrap_err().to_string();
        assert!(
            e.contains("/victim/a.exr") && e.contains("edited or damaged"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
        let mut m = manifest(dir, vec![("/in/a.png", "/out/a.exr")]);
        assert!(m.check(&jobs).is_ok());
        m.rounds[0].tasks = vec![vec![0], vec![1]];
        assert!(m.check(&jobs).unwrap_err().to_string().contains("file 1"));
        m.rounds[0].tasks = vec![vec![0], vec![0]];
        assert!(m.check(&jobs).unwrap_err().to_string().contains("twice"));
    }

    /// A stage's job: outputs anywhere below DIR, never out of it; the layer directly in DIR;
    /// a manifest of files (no `asset`, no `colorspace`) reads as before.
    #[test]
    fn a_stages_outputs_stay_in_its_tree_and_its_layer_in_dir() {
        let tree = Outputs::Tree("/out".into());
        let at = |o: &str| {
            tree.check(
                Path::new("/w"),
                Path::new("/s/a.png"),
                Path::new(o),
                Spectral,
            )
        };
        assert!(at("/out/tex/a_spectral.exr").is_ok());
        assert!(at("/out/external/0a1b2c3d/a_spectral.exr").is_ok());
        for outside in [
            "/out/../etc/a.exr",
            "/out",
            "/outx/a.exr",
            "/etc/a.exr",
            "out/a.exr",
        ] {
            let e = at(outside).unwrap_err();
            assert!(
                e.contains("output tree") || e.contains("absolute"),
                "{outside}: {e}"
            );
        }
        // A folder below the tree that is a link (made after submit, say) is out of it.
        let real = std::env::temp_dir().join(format!("farm-tree-link-{}", std::process::id()));
        std::fs::create_dir_all(real.join("out/tex")).unwrap();
        std::os::unix::fs::symlink("/tmp", real.join("out/away")).unwrap();
        let linked = Outputs::Tree(real.join("out"));
        let at = |o: &str| {
            linked.check(
                Path::new("/w"),
                Path::new("/s/a.png"),
                &real.join(o),
                Spectral,
            )
        };
        assert!(at("out/tex/a_spectral.exr").is_ok());
        let e = at("out/away/a_spectral.exr").unwrap_err();
        assert!(e.contains("symbolic link") && e.contains("away"), "{e}");
        std::fs::remove_dir_all(&real).unwrap();
        let jobs = std::env::temp_dir().join(format!("farm-tree-{}", std::process::id()));
        let mut m = manifest(tree, vec![("/s/tex/a.png", "/out/tex/a_spectral.exr")]);
        let e = m.check(&jobs).unwrap_err().to_string();
        assert!(e.contains("only a stage's job"), "{e}");
        m.asset = Some(AssetJob {
            stage: "/s/shot.usda".into(),
            layer: "/out/shot_spectral.usda".into(),
        });
        assert!(m.check(&jobs).is_ok());
        for layer in [
            "/etc/shot_spectral.usda",
            "/out/tex/shot_spectral.usda",
            "/out/x.exr",
        ] {
            let mut bad = m.clone();
            bad.asset.as_mut().unwrap().layer = layer.into();
            let e = bad.check(&jobs).unwrap_err().to_string();
            assert!(e.contains(layer) && e.contains("edited or damaged"), "{e}");
        }
        let mut files = m.clone();
        files.outputs = Outputs::Directory("/out".into());
        files.files[0].output = "/out/a_spectral.exr".into();
        assert!(files
            .check(&jobs)
            .unwrap_err()
            .to_string()
            .contains("output tree"));
        // What a submit of files wrote before stages were: read, with no stage and no spaces.
        let mut old = serde_json::to_value(example(
            Outputs::Directory("/out".into()),
            vec![("/in/a.png".into(), "/out/a.exr".into())],
            vec![],
        ))
        .unwrap();
        old.as_object_mut().unwrap().remove("asset");
        let text = old.to_string();
        assert!(
            !text.contains("colorspace") && !text.contains("asset"),
            "{text}"
        );
        let read: Manifest = serde_json::from_str(&text).unwrap();
        assert!(read.asset.is_none() && read.files[0].colorspace.is_none());
    }

    #[test]
    fn template_outputs_must_be_what_the_template_gives_their_input() {
        let t = Outputs::Template("{dir}/../spectral/{stem}.exr".into());
        let w = Path::new("/w");
        let input = Path::new("/lib/wood/a.png");
        assert!(t
            .check(w, input, Path::new("/lib/wood/../spectral/a.exr"), Spectral)
            .is_ok());
        assert!(t
            .check(
                w,
                input,
                Path::new("/lib/wood/./../spectral//a.exr"),
                Spectral
            )
            .is_ok());
        assert!(t
            .check(w, input, Path::new("/lib/spectral/b.exr"), Spectral)
            .is_err());
        assert!(t
            .check(w, input, Path::new("/etc/a.exr"), Spectral)
            .is_err());
        // Relative templates mean what they meant where submit ran.
        let r = Outputs::Template("out/{name}.exr".into());
        assert!(r
            .check(w, input, Path::new("/w/out/a.png.exr"), Spectral)
            .is_ok());
        assert!(r
            .check(w, input, Path::new("/elsewhere/out/a.png.exr"), Spectral)
            .is_err());
        // UDIM tiles: the command line's names, by the same rule.
        let u = Outputs::Template("{dir}/{stem}_spectral.{udim}.exr".into());
        let tile = Path::new("/lib/wood.1012.png");
        assert!(u
            .check(w, tile, Path::new("/lib/wood_spectral.1012.exr"), Spectral)
            .is_ok());
        let e = u
            .check(w, input, Path::new("/lib/wood/a.exr"), Spectral)
            .unwrap_err();
        assert!(e.contains("no tile number"), "{e}");
        // A manifest edited to a template with an unknown field is refused, not followed.
        let typo = Outputs::Template("{dir}/{stme}.exr".into());
        let e = typo
            .check(w, input, Path::new("/lib/wood/a.exr"), Spectral)
            .unwrap_err();
        assert!(e.contains("unknown field {stme}"), "{e}");
        // A data copy's name, by the template's {role}, and a manifest edited to point it away.
        let roles = Outputs::Template("{dir}/{stem}_{role}.exr".into());
        let data = Path::new("/lib/wood/a_data.exr");
        assert!(roles.check(w, input, data, Holds::Data).is_ok());
        assert!(roles.check(w, input, data, Spectral).is_err());
        let jobs = std::env::temp_dir().join(format!("farm-role-{}", std::process::id()));
        let mut m = manifest(roles, vec![("/lib/wood/a.png", "/lib/wood/a_spectral.exr")]);
        m.files[0].data = Some(data.into());
        assert!(m.check(&jobs).is_ok());
        m.files[0].data = Some("/victim/a_data.exr".into());
        let e = m.check(&jobs).unwrap_err().to_string();
        assert!(e.contains("/victim/a_data.exr"), "{e}");
    }

    #[test]
    fn job_directory_files_are_read_only_up_to_the_limit() {
        let d = std::env::temp_dir().join(format!("farm-bounded-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let small = d.join("small");
        std::fs::write(&small, "{}").unwrap();
        assert_eq!(read_bounded(&small).unwrap(), "{}");
        let big = d.join("big");
        let f = std::fs::File::create(&big).unwrap();
        f.set_len(MAX_FILE_BYTES + 1).unwrap();
        let e = read_bounded(&big).unwrap_err().to_string();
        assert!(e.contains("67108864"), "{e}");
        assert!(read_bounded(&d).is_err(), "a folder is not read");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
