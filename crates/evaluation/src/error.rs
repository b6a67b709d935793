//! What can go wrong in a study: this crate's error, with what to do about it in the message.

/// What can go wrong in a study, with what to do about it in the message.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Colour data that cannot be used (a grid, an observer or illuminant table, a CSV table).
    #[error(transparent)]
    Colour(#[from] specconv_colour::Error),
    /// An uplift method or its training failed (e.g. too few spectra for cross-validation).
    #[error(transparent)]
    Spectral(#[from] specconv_spectral::Error),
    /// A scene that cannot be simulated as asked (bad form factors, lights or materials, a
    /// diverging series, too many bounces or patches), with what to ask for instead.
    #[error("bad scene: {0}")]
    Scene(String),
}
