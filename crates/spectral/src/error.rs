//! What can go wrong in the uplift: this crate's error, with what to do about it in the message.

/// Everything that can go wrong in the uplift, with what to do about it in the message.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Colour data that cannot be used: a grid, an observer or illuminant table, a CSV table.
    #[error(transparent)]
    Colour(#[from] specconv_colour::Error),
    /// A grid a method cannot work on: the method's and the colorimetry's grids differ, too few
    /// bands (Meng 2015 needs 4, Jakob 2019 3), a grid that sees no light or cannot tell X, Y and Z
    /// apart, or a Jakob 2019 table resolution outside 4–256.
    #[error("bad wavelength grid {0}")]
    Grid(String),
    /// An unknown method name, with the names to choose from (or a basis spectrum missing from an
    /// embedded table).
    #[error("unknown {0}")]
    Unknown(String),
    /// A model file (or a Jakob 2019 table) that cannot be used: not a model, another version,
    /// malformed, inconsistent with its colorimetry, or built for another setting.
    #[error("{file}: {msg}")]
    Model {
        /// The file, as the caller named it (`built-in model`, `jakob2019 table`, a path).
        file: String,
        /// What is wrong with it and what to do.
        msg: String,
    },
    /// Training data or options that cannot make a model (see
    /// [`otsu2018::train`](crate::otsu2018::train)'s table).
    #[error("cannot train: {0}")]
    Training(String),
    /// A blend width that is not finite, or outside the allowed range
    /// ([`otsu2018::blend`](crate::otsu2018::blend)).
    #[error("bad blend width {0}")]
    Blend(String),
    /// `pca` asked of a model with several clusters.
    #[error(
        "pca is the clustered PCA with one cluster, and the model has {clusters}: it needs a \
         one-cluster model"
    )]
    NeedsOneCluster {
        /// The model's clusters.
        clusters: usize,
    },
}
