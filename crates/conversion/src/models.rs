//! The model a conversion uplifts with: the built-in one or a file from `specconv train`.

use specconv_spectral::Model;
use std::path::Path;

/// Why a model file cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// It cannot be read.
    #[error("cannot read model file {}", path.display())]
    Read {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// It is not a model.
    #[error(transparent)]
    Invalid(#[from] specconv_spectral::Error),
}

/// The model of `path`, or the built-in one.
pub fn load(path: Option<&Path>) -> Result<Model, ModelError> {
    let Some(path) = path else {
        return Ok(Model::builtin().clone());
    };
    let text = std::fs::read_to_string(path).map_err(|source| ModelError::Read {
        path: path.to_path_buf(),
        source,
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
