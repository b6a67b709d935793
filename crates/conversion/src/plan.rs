//! Which file each input of a batch becomes, and whether the batch may write them: the rules
//! every front-end plans by (the command line's `INPUT OUTPUT`, `-o DIR`, templates and
//! `--shard`; the Python package's `outputs` and `output_template`).
//!
//! A plan is made in three steps, each owning its rules:
//!
//! 1. [`Plan::new`]: inputs (UDIM patterns expanded to the tiles that exist, in tile order) and
//!    an [`Outputs`] give the pairs. Refused here, for the **whole** plan: an output that is
//!    not OpenEXR, a pattern whose output does not name its tiles, an output that is an input
//!    (as files: links, hard links, `./` and `..` spellings are seen through), and two inputs
//!    that would write one file (both inputs named).
//! 2. [`Plan::shard`]: the inputs one of N runs converts, split by pixel count
//!    (`specconv_atomic_file::shards`, the split the farm plans its tasks with). Every run of
//!    a sharded batch makes the same whole plan and refuses the same mistakes.
//! 3. [`Plan::check_existing`]: outputs that exist, on the pairs this run converts only, so
//!    runs of other shards, side by side or earlier, never stop this one.
//!
//! [`check_plan`] is step 1's checks of files and step 3, on pairs made elsewhere; a [`crate::Batch`]
//! runs it again before its first write. Planning is linear in the number of inputs: files are
//! compared through hash maps of their identities, each directory is looked at once.
//!
//! ```no_run
//! use specconv_conversion::plan::{Outputs, Plan};
//! let inputs = vec!["wood.<UDIM>.png".into(), "brick.1001.png".into()];
//! let outputs = Outputs::template("spectral/{stem}_spectral.{udim}.exr")?;
//! let plan = Plan::new(inputs, &outputs)?.shard(0, 2)?;
//! plan.check_existing(false, false)?;
//! for pair in plan.pairs() {
//!     println!("{} → {}", pair.input.display(), pair.output.display());
//! }
//! # Ok::<(), specconv_conversion::plan::Error>(())
//! ```

use crate::provenance::recorded;
use specconv_atomic_file::outputs::{self as naming, Holds, Template, TemplateError};
use specconv_atomic_file::udim::{self, UdimError};
use specconv_atomic_file::{plan as files, Places, PlanError};
use std::path::{Path, PathBuf};

/// The extensions a spectral output may have (OpenEXR's): every front-end checks names by it.
pub const SPECTRAL_EXTENSIONS: &[&str] = specconv_exr::EXTENSIONS;

/// Where the outputs of a batch go.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Outputs {
    /// One output per input, in order. The output of a UDIM pattern names its tiles with the
    /// same token (`wood.<UDIM>.png` → `wood_spectral.<UDIM>.exr`), one file per tile.
    Files(Vec<PathBuf>),
    /// Every output in this directory, which exists, as `STEM_spectral.exr` (`STEM_data.exr`
    /// for a data texture written through).
    Directory(PathBuf),
    /// Each output by a template ([`Template`]: `{dir}`, `{stem}`, `{name}`, `{ext}`, `{udim}`,
    /// `{tile}`, `{role}`).
    Template(Template),
}

/// One input of a plan and where it goes: `output` when it is uplifted, and `data` when the
/// naming gives a data texture written through a name of its own ([`Holds`]). Which one is
/// written is known only once the input is read, so a plan checks both.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Pair {
    /// The input texture (a UDIM tile, never a pattern).
    pub input: PathBuf,
    /// Its spectral (or compact) output.
    pub output: PathBuf,
    /// Its data copy's output, when not `output`.
    pub data: Option<PathBuf>,
}

impl Pair {
    /// `input` into `output`, whatever it holds.
    pub fn new(input: impl Into<PathBuf>, output: impl Into<PathBuf>) -> Pair {
        Pair {
            input: input.into(),
            output: output.into(),
            data: None,
        }
    }

    /// The output written when the input holds `holds`.
    pub fn output(&self, holds: Holds) -> &Path {
        match (holds, &self.data) {
            (Holds::Data, Some(data)) => data,
            _ => &self.output,
        }
    }

    /// Every file this input may write: its output, then its data copy's when apart.
    pub fn outputs(&self) -> impl Iterator<Item = &Path> {
        std::iter::once(self.output.as_path()).chain(self.data.as_deref())
    }
}

impl Outputs {
    /// Outputs named by the template `text`, refused before any input is looked at when it
    /// cannot name one (an unknown field, an unclosed brace).
    pub fn template(text: &str) -> Result<Outputs, Error> {
        Ok(Outputs::Template(Template::parse(text)?))
    }
}

/// Why a batch may not start: nothing has been read or written. Messages name no option of any
/// front-end; [`crate::Error::remedy`] says which setting would fix it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Not one output per input.
    #[error(
        "{} and {}: give one output per input, a directory that exists or an output template",
        count(*inputs, "input"),
        match one { Some(o) => format!("one output {}, which is not a directory", o.display()), None => count(*outputs, "output") }
    )]
    OutputCount {
        /// Inputs given (UDIM patterns counted once).
        inputs: usize,
        /// Outputs given.
        outputs: usize,
        /// The output, when there is one.
        one: Option<PathBuf>,
    },
    /// A UDIM pattern whose output is one file: every tile would be written over it.
    #[error(
        "{} is a UDIM pattern ({}): name the output with the token too (such as {})",
        input.display(), count(*tiles, "tile"), suggestion.display()
    )]
    PatternIntoOneFile {
        /// The pattern.
        input: PathBuf,
        /// Its output.
        output: PathBuf,
        /// How many tiles it has.
        tiles: usize,
        /// The output with the token.
        suggestion: PathBuf,
    },
    /// An output with a UDIM token for an input that is no pattern.
    #[error(
        "the output {} has a UDIM token but the input {} is no UDIM pattern",
        output.display(), input.display()
    )]
    TokenWithoutPattern {
        /// The output.
        output: PathBuf,
        /// The input.
        input: PathBuf,
    },
    /// An output that is not an OpenEXR file name (or is `-`).
    #[error(
        "{}: specconv writes spectral OpenEXR; give an output file ending in .exr",
        if output.as_os_str() == "-" {
            "'-' is not a file (nothing is written to standard output)".to_string()
        } else {
            format!("the output {} has the wrong extension", output.display())
        }
    )]
    NotExr {
        /// The output.
        output: PathBuf,
    },
    /// An output directory that does not exist (outputs are never given new directories).
    #[error("the output directory {} does not exist; create it first", dir.display())]
    NoDirectory {
        /// The directory.
        dir: PathBuf,
    },
    /// An output directory that exists and is not a directory.
    #[error(
        "the output directory {} exists and is not a directory; give a directory",
        dir.display()
    )]
    NotADirectory {
        /// The path.
        dir: PathBuf,
    },
    /// An output directory that could not be made.
    #[error("cannot make the output directory {}: {source}", dir.display())]
    MakeDirectory {
        /// The directory.
        dir: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A template that cannot name an output.
    #[error(transparent)]
    Template(#[from] TemplateError),
    /// A UDIM pattern that names no tiles, or that cannot be read.
    #[error(transparent)]
    Udim(#[from] UdimError),
    /// Two inputs whose outputs are one file.
    #[error(
        "{}; give each input its own output",
        shared(first, second, first_output, second_output)
    )]
    SharedOutput {
        /// The first input.
        first: PathBuf,
        /// The second input.
        second: PathBuf,
        /// The first input's output.
        first_output: PathBuf,
        /// The second input's output: the same file.
        second_output: PathBuf,
    },
    /// An output that may not be written: an input, not a file, in no directory, a name too
    /// long, or one that exists and may not be replaced.
    #[error(transparent)]
    Files(#[from] PlanError),
    /// Existing files at outputs' paths that specconv did not make: updating replaces only
    /// specconv's own outputs.
    #[error("{} exists and is not a specconv output{}, which updating never replaces", output.display(), if *more > 0 { format!(" (and {more} more)") } else { String::new() })]
    NotMadeBySpecconv {
        /// The first such output.
        output: PathBuf,
        /// How many more.
        more: usize,
    },
    /// A shard that is not one of the plan's.
    #[error("{}", match count {
        0 => "a plan is split into at least one shard".to_string(),
        n => format!("shard {index} of {n} does not exist: shards count from 0 to {}", n - 1),
    })]
    NoShard {
        /// The shard asked for.
        index: usize,
        /// How many there are.
        count: usize,
    },
}

/// `1 input`, `2 inputs`.
fn count(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}

/// Two inputs and the one file they would write.
fn shared(first: &Path, second: &Path, a: &Path, b: &Path) -> String {
    let target = if a == b {
        a.display().to_string()
    } else {
        format!("{} and {}, one file", a.display(), b.display())
    };
    if first == second {
        format!(
            "{} is given twice, which would write {target} twice",
            first.display()
        )
    } else {
        format!(
            "{} and {} would both write {target}{}",
            first.display(),
            second.display(),
            separating(first, second, a).map_or(String::new(), |(field, example)| format!(
                " (an output template with {field} separates them, such as {example})"
            ))
        )
    }
}

/// The template field that tells two inputs apart, and an output template with it beside
/// `output`: `{ext}` (or `{name}`) for one stem with two extensions, `{dir}` for one name in
/// two directories, `{stem}` otherwise.
fn separating(first: &Path, second: &Path, output: &Path) -> Option<(&'static str, String)> {
    let dir = output
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .map_or(String::new(), |d| format!("{}/", d.display()));
    if first.file_name() == second.file_name() {
        return (first.parent() != second.parent())
            .then(|| ("{dir}", "{dir}/{stem}_spectral.exr".to_string()));
    }
    Some(if first.file_stem() == second.file_stem() {
        (
            "{ext} or {name}",
            format!("{dir}{{stem}}_{{ext}}_spectral.exr"),
        )
    } else {
        ("{stem}", format!("{dir}{{stem}}_spectral.exr"))
    })
}

/// The inputs of a batch and the output of each, checked as a whole ([`Plan::new`]), or the
/// shard of such a plan that one run converts ([`Plan::shard`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    pairs: Vec<Pair>,
}

impl Plan {
    /// [`Plan::new`], and where `outputs` is a directory that does not exist, that directory
    /// made (with the folders above it that are missing), as `asset -o` makes its own (issue
    /// 56, item 6): once the plan is accepted; a plan refused after all takes the folders it
    /// made away again.
    pub fn new_making_directory(inputs: Vec<PathBuf>, outputs: &Outputs) -> Result<Plan, Error> {
        let dir = match outputs {
            Outputs::Directory(dir) if !dir.is_dir() => dir,
            _ => return Plan::new(inputs, outputs),
        };
        if dir.exists() {
            return Err(Error::NotADirectory { dir: dir.clone() });
        }
        // Refused for what `new` finds before it looks at the directory (the count of
        // outputs, a UDIM pattern): nothing is made.
        match Plan::new(inputs.clone(), outputs) {
            Err(Error::NoDirectory { dir: d }) if d == *dir => {}
            other => return other,
        }
        let mut top = dir.clone();
        while let Some(parent) = top
            .parent()
            .filter(|p| !p.as_os_str().is_empty() && !p.exists())
        {
            top = parent.to_path_buf();
        }
        std::fs::create_dir_all(dir).map_err(|source| Error::MakeDirectory {
            dir: dir.clone(),
            source,
        })?;
        Plan::new(inputs, outputs).inspect_err(|_| {
            // Each folder made, from the deepest, only while empty.
            for made in dir.ancestors().take_while(|a| a.starts_with(&top)) {
                if std::fs::remove_dir(made).is_err() {
                    break;
                }
            }
        })
    }

    /// The pairs of `inputs` (paths, or UDIM patterns standing for the tiles that exist, in
    /// tile order) and `outputs`, once the plan's files allow them: every output OpenEXR, none
    /// an input (as files), no two one file. Existing outputs are not looked at here
    /// ([`Plan::check_existing`]). Linear in the number of inputs.
    pub fn new(inputs: Vec<PathBuf>, outputs: &Outputs) -> Result<Plan, Error> {
        if let Outputs::Files(files) = outputs {
            if files.len() != inputs.len() {
                return Err(Error::OutputCount {
                    inputs: inputs.len(),
                    outputs: files.len(),
                    one: (files.len() == 1).then(|| files[0].clone()),
                });
            }
        }
        // Patterns first, each into its tiles: the given input's position and the tile's number.
        let mut expanded: Vec<(usize, PathBuf, Option<u32>)> = Vec::with_capacity(inputs.len());
        for (k, input) in inputs.iter().enumerate() {
            match udim::expand(input)? {
                Some(tiles) => {
                    expanded.extend(tiles.into_iter().map(|t| (k, t.path, Some(t.number))))
                }
                None => expanded.push((k, input.clone(), None)),
            }
        }
        let named: Vec<(PathBuf, Option<PathBuf>)> = match outputs {
            Outputs::Files(files) => {
                for (k, (input, output)) in inputs.iter().zip(files).enumerate() {
                    let tiles = expanded.iter().filter(|(j, _, _)| *j == k).count();
                    pattern_and_output(input, output, tiles)?;
                }
                expanded
                    .iter()
                    .map(|(k, _, tile)| match tile {
                        Some(n) => (udim::substitute(&files[*k], *n), None),
                        None => (files[*k].clone(), None),
                    })
                    .collect()
            }
            Outputs::Directory(dir) => {
                if !dir.is_dir() {
                    return Err(Error::NoDirectory { dir: dir.clone() });
                }
                expanded
                    .iter()
                    .map(|(_, i, _)| {
                        let [spectral, data] = Holds::ALL.map(|h| naming::in_directory(dir, i, h));
                        (spectral, Some(data))
                    })
                    .collect()
            }
            Outputs::Template(t) => expanded
                .iter()
                .map(|(_, i, _)| {
                    let spectral = t.apply(i, Holds::Spectral)?;
                    let data = t.apply(i, Holds::Data)?;
                    Ok((spectral.clone(), (data != spectral).then_some(data)))
                })
                .collect::<Result<_, TemplateError>>()?,
        };
        let pairs: Vec<Pair> = expanded
            .into_iter()
            .zip(named)
            .map(|((_, input, _), (output, data))| Pair {
                input,
                output,
                data,
            })
            .collect();
        if let Some(o) = pairs.iter().flat_map(Pair::outputs).find(|o| !is_exr(o)) {
            return Err(Error::NotExr {
                output: o.to_path_buf(),
            });
        }
        check_files(&pairs, &[])?;
        Ok(Plan { pairs })
    }

    /// The shard `index` of `count` (from 0): the inputs one of `count` runs converts, split by
    /// pixel count ([`weight`]) as every other run of the same plan splits it, in plan order.
    /// The same whole plan gives each input to exactly one shard.
    pub fn shard(self, index: usize, count: usize) -> Result<Plan, Error> {
        if index >= count {
            return Err(Error::NoShard { index, count });
        }
        if count == 1 {
            // One shard holds it all: no input need be read to weigh it.
            return Ok(self);
        }
        let inputs: Vec<&Path> = self.pairs.iter().map(|p| p.input.as_path()).collect();
        let weights = weights(&inputs);
        let mine = specconv_atomic_file::shards::split(&weights, count).swap_remove(index);
        let mut pairs: Vec<Option<Pair>> = self.pairs.into_iter().map(Some).collect();
        Ok(Plan {
            pairs: mine.into_iter().filter_map(|k| pairs[k].take()).collect(),
        })
    }

    /// Refuses outputs that exist, on this plan's pairs alone: without `overwrite` or `update`,
    /// any; with `update`, files specconv did not make (its own out-of-date outputs are
    /// replaced, up-to-date ones skipped); with `overwrite`, none (and nothing is looked
    /// at). The outputs are looked at now, one `lstat` each.
    pub fn check_existing(&self, overwrite: bool, update: bool) -> Result<(), Error> {
        if overwrite {
            // Nothing to refuse: no name need be looked at.
            return Ok(());
        }
        let taken = per_output(&self.pairs, |o| std::fs::symlink_metadata(o).is_ok());
        check_existing(&self.pairs, &taken, overwrite, update)
    }

    /// The inputs and their outputs, in order.
    pub fn pairs(&self) -> &[Pair] {
        &self.pairs
    }

    /// The inputs and their outputs, in order.
    pub fn into_pairs(self) -> Vec<Pair> {
        self.pairs
    }

    /// How many inputs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// Whether there are no inputs (an empty list).
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }
}

/// The weight of an input in a split: the pixels of all its levels; 0 when it cannot be read
/// (it fails fast wherever it lands). `farm submit` records the same for its tasks.
pub fn weight(input: &Path) -> u64 {
    specconv_oiio::ImageReader::open(input).map_or(0, |reader| {
        reader
            .info()
            .levels
            .iter()
            .map(|l| u64::from(l.width) * u64::from(l.height))
            .sum()
    })
}

/// The weights ([`weight`]) of `inputs`, in order, read side by side on rayon's shared pool:
/// reading a header mostly waits for the disk (or a network file system), and a plan may weigh
/// 100,000 inputs.
pub fn weights<P: AsRef<Path> + Sync>(inputs: &[P]) -> Vec<u64> {
    use rayon::prelude::*;
    inputs.par_iter().map(|p| weight(p.as_ref())).collect()
}

/// The output of a given input names its tiles exactly when the input is a UDIM pattern.
fn pattern_and_output(input: &Path, output: &Path, tiles: usize) -> Result<(), Error> {
    match (udim::is_pattern(input), udim::is_pattern(output)) {
        (true, false) => {
            let mut suggestion = output.with_extension("").into_os_string();
            suggestion.push(".<UDIM>.exr");
            Err(Error::PatternIntoOneFile {
                input: input.to_path_buf(),
                output: output.to_path_buf(),
                tiles,
                suggestion: suggestion.into(),
            })
        }
        (false, true) => Err(Error::TokenWithoutPattern {
            output: output.to_path_buf(),
            input: input.to_path_buf(),
        }),
        _ => Ok(()),
    }
}

/// Whether `path` names an OpenEXR file (`.exr`, any case).
fn is_exr(path: &Path) -> bool {
    specconv_atomic_file::has_extension(path, SPECTRAL_EXTENSIONS)
}

/// The rules of a batch's plan, checked before anything is written: no output is any input or
/// file in `read` (as files: links, `..` and bind mounts are seen through), no two inputs share an output, every
/// output's directory is there, and an existing output may be replaced ([`Plan::check_existing`]).
/// Inputs that are missing or not files fail on their own when their turn comes.
pub fn check_plan(
    pairs: &[Pair],
    read: &[PathBuf],
    overwrite: bool,
    update: bool,
) -> Result<(), Error> {
    let taken = check_files(pairs, read)?;
    check_existing(pairs, &taken, overwrite, update)
}

/// Outputs' names, directories and kinds, then outputs that are inputs (or other files the
/// command reads, `read`: a model, a config), then inputs that share an output: the checks of
/// the whole plan. Answers, per pair, whether each output's name is taken (one `lstat` an
/// output for all of it).
pub(crate) fn check_files(pairs: &[Pair], read: &[PathBuf]) -> Result<Vec<[bool; 2]>, Error> {
    let inputs: Vec<&Path> = pairs
        .iter()
        .map(|p| p.input.as_path())
        .chain(read.iter().map(PathBuf::as_path))
        .collect();
    // Every file an input may write (both names of each), and whose it is.
    let (owner, outputs): (Vec<usize>, Vec<&Path>) = pairs
        .iter()
        .enumerate()
        .flat_map(|(k, p)| p.outputs().map(move |o| (k, o)))
        .unzip();
    let mut known = Places::default();
    let places = files::output_places(&outputs, &mut known)?;
    if let Some((o, i)) = files::output_is_input(&inputs, &places, &mut known) {
        return Err(PlanError::OutputIsInput {
            output: outputs[o].to_path_buf(),
            input: inputs[i].to_path_buf(),
        }
        .into());
    }
    if let Some((a, b)) = files::shared_output(&places) {
        // An input's two names are one file only through links: its own choice.
        return Err(Error::SharedOutput {
            first: inputs[owner[a]].to_path_buf(),
            second: inputs[owner[b]].to_path_buf(),
            first_output: outputs[a].to_path_buf(),
            second_output: outputs[b].to_path_buf(),
        });
    }
    let mut places = places.iter();
    Ok(per_output(pairs, |_| {
        places.next().is_some_and(files::Target::is_taken)
    }))
}

/// `f` of each pair's outputs, in [`Pair::outputs`]'s order (at most two a pair).
fn per_output(pairs: &[Pair], mut f: impl FnMut(&Path) -> bool) -> Vec<[bool; 2]> {
    pairs
        .iter()
        .map(|p| {
            let mut each = [false; 2];
            for (slot, o) in each.iter_mut().zip(p.outputs()) {
                *slot = f(o);
            }
            each
        })
        .collect()
}

/// [`Plan::check_existing`] on pairs, whose outputs' names are `taken` (per pair, in
/// [`Pair::outputs`]'s order): a plan's check ([`check_plan`]) takes that from the look
/// [`check_files`] has just taken, so each output is looked at once.
fn check_existing(
    pairs: &[Pair],
    taken: &[[bool; 2]],
    overwrite: bool,
    update: bool,
) -> Result<(), Error> {
    if overwrite {
        return Ok(());
    }
    let existing: Vec<&Path> = pairs
        .iter()
        .zip(taken)
        .flat_map(|(p, t)| p.outputs().zip(t).filter_map(|(o, &t)| t.then_some(o)))
        .collect();
    if !update {
        return match existing.first() {
            Some(first) => Err(PlanError::Exists {
                output: first.to_path_buf(),
                more: existing.len() - 1,
            }
            .into()),
            None => Ok(()),
        };
    }
    // A file at an output's path that specconv did not make is never replaced by an update.
    let foreign: Vec<&&Path> = existing.iter().filter(|o| recorded(o).is_none()).collect();
    match foreign.first() {
        Some(first) => Err(Error::NotMadeBySpecconv {
            output: first.to_path_buf(),
            more: foreign.len() - 1,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("conversion-plan-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn files(d: &Path, names: &[&str]) -> Vec<PathBuf> {
        names
            .iter()
            .map(|n| {
                let p = d.join(n);
                std::fs::write(&p, b"not an image").unwrap();
                p
            })
            .collect()
    }

    #[test]
    fn a_data_copys_name_is_planned_and_checked_as_an_output() {
        let d = scratch("data-names");
        let inputs = files(&d, &["t.png", "u.png"]);
        let plan = Plan::new(inputs.clone(), &Outputs::Directory(d.clone())).unwrap();
        let t = &plan.pairs()[0];
        assert_eq!(t.output(Holds::Spectral), d.join("t_spectral.exr"));
        assert_eq!(t.output(Holds::Data), d.join("t_data.exr"));
        // Without {role} a template names one file for both; with it, two.
        let one = Plan::new(
            inputs.clone(),
            &Outputs::template("{dir}/{stem}.exr").unwrap(),
        );
        assert_eq!(one.unwrap().pairs()[0].data, None);
        let two = Outputs::template("{dir}/{stem}.{role}.exr").unwrap();
        let plan = Plan::new(inputs.clone(), &two).unwrap();
        assert_eq!(plan.pairs()[1].data, Some(d.join("u.data.exr")));
        // A data name that exists is refused as an output is, or that is another input.
        std::fs::write(d.join("u.data.exr"), b"theirs").unwrap();
        assert!(matches!(
            plan.check_existing(false, false),
            Err(Error::Files(PlanError::Exists { .. }))
        ));
        assert!(matches!(
            plan.check_existing(false, true),
            Err(Error::NotMadeBySpecconv { .. })
        ));
        // A batch's own check sees the same, from its one look at each output.
        assert!(matches!(
            check_plan(plan.pairs(), &[], false, false),
            Err(Error::Files(PlanError::Exists { more: 0, .. }))
        ));
        assert!(check_plan(plan.pairs(), &[], true, false).is_ok());
        let mut with_input = inputs.clone();
        with_input.extend(files(&d, &["t_data.exr"]));
        let e = Plan::new(with_input, &Outputs::Directory(d.clone())).unwrap_err();
        assert!(e.to_string().contains("t_data.exr"), "{e}");
        // Another input's data name: both named.
        let clash = Outputs::template("{dir}/x{role}.exr").unwrap();
        let e = Plan::new(inputs, &clash).unwrap_err();
        assert!(matches!(e, Error::SharedOutput { .. }), "{e}");
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn two_inputs_into_one_output_are_both_named() {
        let d = scratch("collide");
        let inputs = files(&d, &["brick.png", "brick.tx"]);
        let out = d.join("conv");
        std::fs::create_dir_all(&out).unwrap();
        let e = Plan::new(inputs.clone(), &Outputs::Directory(out.clone())).unwrap_err();
        let text = e.to_string();
        assert!(matches!(e, Error::SharedOutput { .. }), "{text}");
        assert_eq!(
            text,
            format!(
                "{} and {} would both write {} (an output template with {{ext}} or {{name}} \
                 separates them, such as {}/{{stem}}_{{ext}}_spectral.exr); give each input its \
                 own output",
                inputs[0].display(),
                inputs[1].display(),
                out.join("brick_spectral.exr").display(),
                out.display()
            )
        );
        // The same input twice says so.
        let twice = vec![inputs[0].clone(), inputs[0].clone()];
        let e = Plan::new(twice, &Outputs::Directory(out)).unwrap_err();
        assert!(e.to_string().contains("is given twice"), "{e}");
        // Spelled apart, one file: both spellings named.
        let e = Plan::new(
            inputs.clone(),
            &Outputs::Files(vec![d.join("conv/x.exr"), d.join("conv/../conv/x.exr")]),
        )
        .unwrap_err();
        assert!(e.to_string().contains("x.exr, one file"), "{e}");
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn outputs_are_openexr_and_patterns_name_their_tiles() {
        let d = scratch("names");
        let inputs = files(&d, &["a.png", "wood.1001.png", "wood.1002.png"]);
        let e = Plan::new(
            vec![inputs[0].clone()],
            &Outputs::Files(vec![d.join("a.tif")]),
        );
        assert!(matches!(e, Err(Error::NotExr { .. })), "{e:?}");
        let e = Plan::new(vec![inputs[0].clone()], &Outputs::Files(vec!["-".into()]));
        assert!(e.unwrap_err().to_string().starts_with("'-' is not a file"));
        let upper = Plan::new(
            vec![inputs[0].clone()],
            &Outputs::Files(vec![d.join("A.EXR")]),
        );
        assert!(upper.is_ok(), "{upper:?}");
        let pattern = d.join("wood.<UDIM>.png");
        let e = Plan::new(
            vec![pattern.clone()],
            &Outputs::Files(vec![d.join("w.exr")]),
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("UDIM pattern (2 tiles)")
                && e.to_string().contains("w.<UDIM>.exr"),
            "{e}"
        );
        let e = Plan::new(
            vec![inputs[0].clone()],
            &Outputs::Files(vec![d.join("a.<UDIM>.exr")]),
        );
        assert!(matches!(e, Err(Error::TokenWithoutPattern { .. })), "{e:?}");
        let plan = Plan::new(
            vec![pattern.clone()],
            &Outputs::Files(vec![d.join("w_spectral.<UDIM>.exr")]),
        )
        .unwrap();
        assert_eq!(
            plan.pairs(),
            [
                Pair::new(&inputs[1], d.join("w_spectral.1001.exr")),
                Pair::new(&inputs[2], d.join("w_spectral.1002.exr"))
            ]
        );
        let e = Plan::new(
            vec![pattern, inputs[0].clone()],
            &Outputs::Files(vec![d.join("o.exr")]),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "2 inputs and one output {}, which is not a directory: give one output per \
                 input, a directory that exists or an output template",
                d.join("o.exr").display()
            )
        );
        let e = Plan::new(vec![], &Outputs::Directory(d.join("none"))).unwrap_err();
        assert!(matches!(e, Error::NoDirectory { .. }), "{e}");
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn shards_partition_the_plan_and_existing_outputs_count_only_in_their_own() {
        let d = scratch("shards");
        let names: Vec<String> = (0..7).map(|k| format!("in{k}.png")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let inputs = files(&d, &names);
        let out = d.join("out");
        std::fs::create_dir_all(&out).unwrap();
        let whole = Plan::new(inputs.clone(), &Outputs::Directory(out.clone())).unwrap();
        let mut seen = Vec::new();
        for i in 0..3 {
            let shard = whole.clone().shard(i, 3).unwrap();
            shard.check_existing(false, false).unwrap();
            // This shard's outputs appear: the next shards still start.
            for p in shard.pairs() {
                std::fs::write(&p.output, b"done").unwrap();
            }
            // (These files are no images: weightless, they all fall in the first shard.)
            assert_eq!(
                shard.check_existing(false, false).is_err(),
                !shard.is_empty()
            );
            seen.extend(shard.into_pairs());
        }
        seen.sort();
        assert_eq!(seen, whole.pairs());
        assert!(matches!(
            whole.clone().shard(3, 3),
            Err(Error::NoShard { index: 3, count: 3 })
        ));
        assert!(whole.shard(0, 0).is_err());
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn an_output_that_is_an_input_under_any_name_is_refused() {
        let d = scratch("identity");
        let inputs = files(&d, &["x.png", "y.png"]);
        std::os::unix::fs::symlink(&inputs[0], d.join("link.exr")).unwrap();
        std::fs::hard_link(&inputs[1], d.join("hard.exr")).unwrap();
        for output in ["link.exr", "hard.exr"] {
            let e = Plan::new(
                inputs.clone(),
                &Outputs::Files(vec![d.join("other.exr"), d.join(output)]),
            )
            .unwrap_err();
            assert!(
                matches!(e, Error::Files(PlanError::OutputIsInput { .. })),
                "{output}: {e}"
            );
        }
        // An input named like another's output, in `./` spelling, before that output exists.
        let later = d.join("x_spectral.exr");
        let e = Plan::new(
            vec![inputs[0].clone(), d.join(".").join("x_spectral.exr")],
            &Outputs::Files(vec![later, d.join("z.exr")]),
        )
        .unwrap_err();
        assert!(e.to_string().contains("is the input"), "{e}");
        std::fs::remove_dir_all(d).unwrap();
    }
}
