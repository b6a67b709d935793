//! The model a conversion uplifts with: a built-in one by name (`extended`, the default; `paper`, `broad`, `open`:
//! [`specconv_spectral::otsu2018::model::BUILTIN`]) or a file from `specconv train`.

use specconv_spectral::otsu2018::model::BUILTIN;
use specconv_spectral::Model;
use std::path::Path;

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
    /// A bare name (no directory, no extension) that is neither a built-in model nor a file.
    #[error("no built-in model is called '{name}' and there is no such file; the built-in models are {}; a model file ends in .json", names())]
    UnknownBuiltin {
        /// The name given.
        name: String,
    },
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

/// The model of `path`: a built-in one by name ([`builtin_name`]), a file, or without a path
/// the built-in default.
pub fn load(path: Option<&Path>) -> Result<Model, ModelError> {
    let Some(path) = path else {
        return Ok(Model::builtin().clone());
    };
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

/// A model's one-line description, as outputs record it (`specconvModel`) and reports show
/// it: which model, its setting, and the data it was trained on with their weights and terms.
/// ASCII only: readers of EXR text attributes differ on anything else (colour-science 0.4.7's
/// fails on a non-ASCII byte), so other characters of a file name or licence become `?`.
pub fn describe(path: Option<&Path>, m: &Model) -> String {
    let name = match path {
        None => format!("built-in {}", BUILTIN[0].name),
        Some(p) => match builtin_name(p) {
            Some(name) => format!("built-in {name}"),
            None => p.display().to_string(),
        },
    };
    let text = format!(
        "{name} ({} clusters, {}, {}, {} nm, trained on {} spectra from {})",
        m.leaves.len(),
        m.observer,
        m.illuminant,
        m.grid,
        m.training.count,
        sources(m)
    );
    text.chars()
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
