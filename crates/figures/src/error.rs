//! Why a picture could not be made: this crate's error and result.

/// Why a picture could not be made.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The font for the text cannot be had (the text says what to do).
    #[error("{0}")]
    Font(String),
    /// plotters failed (the font or the backend, never the data).
    #[error("drawing failed: {0}")]
    Drawing(String),
    /// The PNG encoder failed.
    #[error("cannot encode the PNG: {0}")]
    Png(String),
}

/// Pictures' results.
pub type Result<T> = std::result::Result<T, Error>;
