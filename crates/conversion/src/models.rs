//! The model a conversion uplifts with: a built-in one by name
//! ([`specconv_spectral::otsu2018::model::BUILTIN`], the default first) or a file from
//! `specconv train`; when none is named, the site's default ([`MODEL_ENV`]), else the built-in
//! default ([`in_force`]). Every front-end (CLI, Python, farm tasks, Mitsuba's plugins) reaches
//! a model through [`load`], so a studio pins its model everywhere with one variable.

use specconv_spectral::otsu2018::model::BUILTIN;
use specconv_spectral::{Model, Part, TrainOptions, TrainingSet};
use std::path::{Path, PathBuf};

/// The environment variable that names a site's default model: a built-in name or a model file,
/// used whenever no model is named (empty: unset).
pub const MODEL_ENV: &str = "SPECCONV_MODEL";

/// Why the model in force is the one it is ([`in_force`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// Named by the caller (`--model`, `model=`).
    Named,
    /// The site's default, [`MODEL_ENV`].
    Site,
    /// Nothing named: the built-in default.
    Default,
}

impl Origin {
    /// One word for machines (`specconv models --json`): `named`, `site` or `built-in default`.
    pub fn word(self) -> &'static str {
        match self {
            Origin::Named => "named",
            Origin::Site => "site",
            Origin::Default => "built-in default",
        }
    }

    /// In words, for `specconv models` and errors.
    pub fn describe(self) -> String {
        match self {
            Origin::Named => "named by --model".into(),
            Origin::Site => format!("the site default, ${MODEL_ENV}"),
            Origin::Default => format!("the built-in default (${MODEL_ENV} is not set)"),
        }
    }
}

/// The model in force when `named` is the caller's choice: `named`, else [`MODEL_ENV`]'s value,
/// else `None` (the built-in default, [`BUILTIN`]'s first); and why.
pub fn in_force(named: Option<&Path>) -> (Option<PathBuf>, Origin) {
    if let Some(p) = named {
        return (Some(p.to_path_buf()), Origin::Named);
    }
    match std::env::var_os(MODEL_ENV) {
        Some(v) if !v.is_empty() => (Some(PathBuf::from(v)), Origin::Site),
        _ => (None, Origin::Default),
    }
}

/// Why a model file cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// It cannot be read: missing, not a file, too large, unreadable.
    #[error("cannot read model file {}", path.display())]
    Read {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        source: specconv_atomic_file::ReadError,
    },
    /// It is not UTF-8 text.
    #[error("model file {} is not UTF-8 text (JSON)", path.display())]
    NotText {
        /// The file.
        path: std::path::PathBuf,
    },
    /// It is not a model.
    #[error(transparent)]
    Invalid(#[from] specconv_spectral::Error),
    /// It may not be written ([`save`]): another kind of file's name, an input, a special
    /// file, an existing file not to be replaced; or writing failed.
    #[error(transparent)]
    Save(specconv_atomic_file::WriteError),
    /// A spectra table (CSV) cannot be read.
    #[error("cannot read spectra file {}: {why}", path.display())]
    Spectra {
        /// The file.
        path: std::path::PathBuf,
        /// Why, in words.
        why: String,
    },
    /// A set read again for a model (`train --with`) that is not the set the model records:
    /// other spectra under its file name.
    #[error(transparent)]
    SetDiffers(Box<SetDiffers>),
    /// A model to train on top of records no sets.
    #[error("{model} does not record the sets it was trained on, so no model can be trained on top of it; give its sets with --spectra instead")]
    NoRecordedSets {
        /// The model, described.
        model: String,
    },
    /// A bare name (no directory, no extension) that is neither a built-in model nor a file.
    #[error("no built-in model is called '{name}' and there is no such file; the built-in models are {}; a model file ends in .json", names())]
    UnknownBuiltin {
        /// The name given.
        name: String,
    },
    /// The site default ([`MODEL_ENV`]) names a model that cannot be used.
    #[error("${MODEL_ENV} (the site's default model) is '{}', which cannot be used; set it to a built-in model ({}) or a model file, or unset it for the built-in default", value.display(), names())]
    Site {
        /// The variable's value.
        value: PathBuf,
        /// Why it cannot be used.
        source: Box<ModelError>,
    },
}

/// A set read again for a model (`train --with`) that is not the set the model records
/// ([`ModelError::SetDiffers`]).
#[derive(Debug, thiserror::Error)]
#[error("{} is not the set {model} was trained on: the model records {source_name} as {count} spectra with SHA-256 {recorded}, and this file holds {found_count} spectra with SHA-256 {found}; give --with-data the folder that holds the recorded file (../shared/spectra for the built-in models), or train on this file as your own data with --spectra and state its --licence and --commercial", path.display())]
pub struct SetDiffers {
    /// The file read.
    pub path: PathBuf,
    /// The model, described.
    pub model: String,
    /// The recorded set's file name.
    pub source_name: String,
    /// The spectra the model records of it.
    pub count: usize,
    /// The hash the model records of it ("not recorded" in older models).
    pub recorded: String,
    /// The spectra the file holds.
    pub found_count: usize,
    /// The file's hash.
    pub found: String,
}

fn names() -> String {
    BUILTIN
        .iter()
        .map(|b| b.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The built-in model a `--model` value names: a bare word (no directory, no extension) that
/// is one of [`BUILTIN`]'s names, unless a file of that name exists.
pub fn builtin_name(path: &Path) -> Option<&'static str> {
    let word = path.to_str()?;
    let b = BUILTIN.iter().find(|b| b.name == word)?;
    (!path.exists()).then_some(b.name)
}

/// The largest model file read: 1024 clusters on 1 nm bands would be ≈64 MB of JSON (scaled
/// from the built-in model: 45 KB for 8 clusters on 36 bands).
pub const MODEL_LIMIT: u64 = 256 << 20;

/// The model in force for `named` as a name or path that means it anywhere, whatever the
/// environment there: what a farm job records at submit, as it records the OCIO config.
pub fn pinned(named: Option<&Path>) -> PathBuf {
    in_force(named).0.unwrap_or_else(|| BUILTIN[0].name.into())
}

/// The model in force for `path` ([`in_force`]): a built-in one by name ([`builtin_name`]), a
/// file, the site default, or the built-in default.
pub fn load(path: Option<&Path>) -> Result<Model, ModelError> {
    match in_force(path) {
        (None, _) => Ok(Model::builtin().clone()),
        (Some(p), Origin::Site) => load_named(&p).map_err(|e| ModelError::Site {
            value: p,
            source: Box::new(e),
        }),
        (Some(p), _) => load_named(&p),
    }
}

/// The model a name or path gives.
fn load_named(path: &Path) -> Result<Model, ModelError> {
    if let Some(name) = builtin_name(path) {
        return Ok(Model::builtin_named(name).expect("a built-in name").clone());
    }
    let bare = path.extension().is_none() && path.components().count() == 1;
    if bare && !path.exists() {
        return Err(ModelError::UnknownBuiltin {
            name: path.display().to_string(),
        });
    }
    let bytes =
        specconv_atomic_file::read_bounded(path, MODEL_LIMIT, "model").map_err(|source| {
            ModelError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
    let text = String::from_utf8(bytes).map_err(|_| ModelError::NotText {
        path: path.to_path_buf(),
    })?;
    Ok(Model::from_json(&path.display().to_string(), &text)?)
}

/// The largest spectra table read: 64× the largest measured set the project uses (3.7 MB).
pub const SPECTRA_LIMIT: u64 = 256 << 20;

/// Reads a spectra CSV file; the table is named by the file's name (as models record it).
pub fn read_spectra(path: &Path) -> Result<specconv_colour::SpectralTable, ModelError> {
    Ok(read_set(path)?.0)
}

/// Reads a spectra CSV file as [`read_spectra`] does, with the SHA-256 of its bytes
/// ([`specconv_spectral::otsu2018::terms::content_hash`]): what a model records of a set
/// it is trained on, and what known terms are found by.
pub fn read_set(path: &Path) -> Result<(specconv_colour::SpectralTable, String), ModelError> {
    let bad = |why: String| ModelError::Spectra {
        path: path.to_path_buf(),
        why,
    };
    let bytes = specconv_atomic_file::read_bounded(path, SPECTRA_LIMIT, "spectra table")
        .map_err(|e| bad(e.to_string()))?;
    let sha256 = specconv_spectral::otsu2018::terms::content_hash(&bytes);
    let text = String::from_utf8(bytes).map_err(|_| bad("it is not UTF-8 text".into()))?;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    // A table that is not one says where (file, line), as any other bad table does.
    let table = specconv_colour::SpectralTable::parse(&name, &text)
        .map_err(|e| ModelError::Invalid(specconv_spectral::Error::Colour(e)))?;
    Ok((table, sha256))
}

/// The model file that [`load`] reads for `path`; `None` for a built-in model. What a command
/// that reads a model counts among its inputs, which `--force` never replaces.
pub fn file_read(path: Option<&Path>) -> Option<PathBuf> {
    in_force(path).0.filter(|p| builtin_name(p).is_none())
}

/// A model's sets read again ([`recorded_parts`]).
#[derive(Debug)]
pub struct Recorded {
    /// Each set with its recorded weight and terms.
    pub parts: Vec<Part>,
    /// Sets whose record has no hash (models written before sets' hashes were recorded):
    /// their recorded terms are not inherited, each is taken under the terms its content
    /// is known by, else unknown terms. One line each, to be shown as a warning.
    pub unverified: Vec<String>,
}

/// The files of `m`'s recorded sets in the folder `dir` (../shared/spectra for the built-in
/// models): what [`recorded_parts`] reads, and a command's inputs that `--force` never replaces.
pub fn recorded_files(named: &Path, m: &Model, dir: &Path) -> Result<Vec<PathBuf>, ModelError> {
    if m.training.sets.is_empty() {
        return Err(ModelError::NoRecordedSets {
            model: name_of(Some(named)),
        });
    }
    m.training
        .sets
        .iter()
        .map(|r| {
            // A recorded source is a file name, never a path: nothing outside `dir` is read.
            let file = Path::new(&r.source);
            if file.components().count() != 1 || file.file_name().is_none() {
                return Err(ModelError::Spectra {
                    path: file.to_path_buf(),
                    why: "a model's recorded set must be a plain file name".into(),
                });
            }
            Ok(dir.join(file))
        })
        .collect()
}

/// The sets `m` was trained on, read again from the folder `dir` that holds its recorded files
/// ([`recorded_files`]; `named` is how the model was named, for messages), each with its recorded weight, on `m`'s grid: what a studio's own
/// sets join to make a model it owns (`train --with`, Python's `Model.train(with_model=…)`,
/// joined by [`TrainingSet::on_top`]). Trained alone with [`recorded_options`] they give `m`
/// back bit for bit.
///
/// A set is trusted by its content, never its name: a file whose hash (or, where none is
/// recorded, spectra count) is not the record's is refused ([`ModelError::SetDiffers`]). Its
/// terms are those its content is known by
/// ([`specconv_spectral::otsu2018::terms::Terms::of_content`]), else the recorded ones when
/// the hash matches; a record without a hash passes no terms on ([`Recorded::unverified`]).
pub fn recorded_parts(named: &Path, m: &Model, dir: &Path) -> Result<Recorded, ModelError> {
    use specconv_spectral::otsu2018::terms::Terms;
    let mut out = Recorded {
        parts: Vec::with_capacity(m.training.sets.len()),
        unverified: Vec::new(),
    };
    for (r, path) in m.training.sets.iter().zip(recorded_files(named, m, dir)?) {
        let (table, sha256) = read_set(&path)?;
        let set = TrainingSet::from_file(&table, &sha256, &m.grid, r.held_ends)?;
        let found_count = set.spectra.len();
        let same = match &r.sha256 {
            Some(h) => *h == sha256,
            None => found_count == r.count,
        };
        if !same {
            return Err(ModelError::SetDiffers(Box::new(SetDiffers {
                path,
                model: name_of(Some(named)),
                source_name: r.source.clone(),
                count: r.count,
                recorded: r.sha256.clone().unwrap_or_else(|| "not recorded".into()),
                found_count,
                found: sha256,
            })));
        }
        let terms = match (&r.sha256, Terms::is_known(&sha256)) {
            (Some(_), false) => r.terms(),
            (None, false) => {
                out.unverified.push(unverified(named, &r.source));
                Terms::of_content(None)
            }
            (_, true) => Terms::of_content(Some(&sha256)),
        };
        out.parts.push(Part {
            set,
            weight: r.weight,
            terms,
        });
    }
    Ok(out)
}

/// Why a set without a recorded hash is taken under unknown terms.
fn unverified(named: &Path, source: &str) -> String {
    format!(
        "{} records no hash of {source} (it was written before models recorded them), so its data cannot be checked: its recorded terms are not inherited and it is taken under unknown terms; give it with --spectra and state its --licence and --commercial, or retrain that model to record the hashes",
        name_of(Some(named))
    )
}

/// The options `m` was trained with.
pub fn recorded_options(m: &Model) -> TrainOptions {
    TrainOptions {
        clusters: m.training.clusters_requested,
        min_cluster_size: m.training.min_cluster_size,
        max_condition: m.training.max_condition,
    }
}

/// The extension of a model file: JSON, what [`save`] writes and [`load`] reads.
pub const EXTENSIONS: &[&str] = &["json"];

/// Writes `model` to `path` as JSON (what [`load`] reads), under the rules of every output:
/// a name ending in .json ([`EXTENSIONS`]: a texture is never replaced by a model), never one
/// of `inputs` or a special file, an existing file only when `replace` allows, and whole or
/// not at all (a temporary file renamed into place). `specconv train -o` and Python's
/// `Model.save` write through it.
pub fn save(
    model: &Model,
    path: &Path,
    inputs: &[&Path],
    replace: specconv_atomic_file::Replace,
) -> Result<(), ModelError> {
    use specconv_atomic_file::WriteError;
    specconv_atomic_file::check_extension(path, EXTENSIONS, "a model file is JSON")
        .map_err(|e| ModelError::Save(WriteError::Plan(e)))?;
    let json = model.to_json();
    specconv_atomic_file::write_checked(path, json.as_bytes(), inputs, replace)
        .map_err(ModelError::Save)
}

/// The model in force for `path` by name: `built-in NAME` or the file's path.
pub fn name_of(path: Option<&Path>) -> String {
    match in_force(path).0.as_deref() {
        None => format!("built-in {}", BUILTIN[0].name),
        Some(p) => match builtin_name(p) {
            Some(name) => format!("built-in {name}"),
            None => p.display().to_string(),
        },
    }
}

/// A model's one-line description, as outputs record it (`specconvModel`) and reports show
/// it: which model (`path` as [`load`] takes it: `None` is the model in force), its setting,
/// the data it was trained on with their weights and terms, and whether the model may be used
/// commercially (only when every set may).
/// ASCII only: readers of EXR text attributes differ on anything else (colour-science 0.4.7's
/// fails on a non-ASCII byte), so other characters of a file name or licence become `?`.
pub fn describe(path: Option<&Path>, m: &Model) -> String {
    let name = name_of(path);
    let text = format!(
        "{name} ({} clusters, {}, {}, {} nm, trained on {} spectra from {}; commercial use: {})",
        m.leaves.len(),
        m.observer,
        m.illuminant,
        m.grid,
        m.training.count,
        sources(m),
        m.training.commercial()
    );
    ascii(&text)
}

/// What a user of the model's data must credit, one line per source (each once), as outputs
/// record it (`specconvModelAttribution`); `None` when no set asks for any.
pub fn attribution(m: &Model) -> Option<String> {
    let mut lines: Vec<&str> = Vec::new();
    for line in m.training.sets.iter().flat_map(|s| &s.attribution) {
        if !lines.contains(&line.as_str()) {
            lines.push(line);
        }
    }
    (!lines.is_empty()).then(|| ascii(&lines.join("; ")))
}

/// ASCII only (see [`describe`]), on one line ([`specconv_atomic_file::shown::escaped`]):
/// no licence or file name can pass for another attribute's line.
fn ascii(text: &str) -> String {
    specconv_atomic_file::shown::escaped(text)
        .chars()
        .map(|c| if c.is_ascii() { c } else { '?' })
        .collect()
}

/// The data a model was trained on: each source with its weight (when not 1) and licence.
pub fn sources(m: &Model) -> String {
    if m.training.sets.is_empty() {
        return format!("{}; licences not recorded", m.training.sources.join(", "));
    }
    let sets: Vec<String> = m
        .training
        .sets
        .iter()
        .map(|s| {
            let weight = if s.weight == 1.0 {
                String::new()
            } else {
                format!(", weight {:.3}", s.weight)
            };
            format!("{} ({}{weight}; {})", s.source, s.count, s.licence)
        })
        .collect();
    sets.join(", ")
}
