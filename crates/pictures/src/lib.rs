//! The pictures specconv draws: the accuracy-against-cost plot ([`plot`]), sheets of colour
//! swatches ([`swatches`]), heat maps with a colour bar ([`heat`]), and the rendering and PNG
//! encoding under them ([`picture`]), all in memory so that the caller writes the file
//! atomically. Text needs a font registered at run time ([`font`]).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod font;
pub mod heat;
pub mod picture;
pub mod plot;
pub mod swatches;

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
