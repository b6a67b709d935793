//! The model a conversion uplifts with: the built-in one or a file from `specconv train`.

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
}

/// The largest model file read: 1024 clusters on 1 nm bands would be ≈64 MB of JSON (scaled
/// from the built-in model: 45 KB for 8 clusters on 36 bands).
pub const MODEL_LIMIT: u64 = 256 << 20;

/// The model of `path`, or the built-in one.
pub fn load(path: Option<&Path>) -> Result<Model, ModelError> {
    let Some(path) = path else {
        return Ok(Model::builtin().clone());
    };
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

/// A model's one-line description, as outputs record it (`specconvModel`) and reports show it.
pub fn describe(path: Option<&Path>, m: &Model) -> String {
    format!(
        "{} ({} clusters, {}, {}, {} nm, trained on {} spectra from {})",
        path.map_or_else(|| "built-in".to_string(), |p| p.display().to_string()),
        m.leaves.len(),
        m.observer,
        m.illuminant,
        m.grid,
        m.training.count,
        m.training.sources.join(", ")
    )
}
