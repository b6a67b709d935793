//! The uplift of specconv: turning tristimulus colours into spectral reflectances, with the
//! clustered PCA of Otsu, Yamamoto and Hachisuka, "Reproducing Spectral Reflectances from
//! Tristimulus Colors" (CGF 2018) and the baselines. Equation numbers in comments are the
//! paper's. The colour basics (grids, observers, colorimetry, CIELAB, the object-colour solid)
//! are in `specconv_colour`, below this crate.
//!
//! - [`Method`]: one way of turning XYZ into spectra; every method and adapter implements it.
//! - [`otsu2018`]: the clustered PCA: the tree on xy ([`otsu2018::tree`]), per-cluster PCA
//!   (Eq. 5–8, [`otsu2018::pca`]), greedy training (Eq. 10–13, [`train`]), the [`Model`] and
//!   its file, the runtime [`Uplifter`] (r = T·c + o per pixel), hard inputs, blending.
//! - [`baselines`]: Smits 1999, Meng et al. 2015, Jakob & Hanika 2019 behind the same trait.
//! - Adapters: [`resample`] (another grid), [`bounded`] (reflectances in [0, 1]),
//!   [`emission`] (emission spectra of any brightness).
//! - [`compact`]: the texel form of the clustered method's spectra, six numbers per texel.
//! - [`stack`]: the one builder of what a command uplifts with, from a description of its
//!   options (method, model, blend, grid, bounded, emissive) to the method and its counters.
//!
//! This crate knows nothing of images, threads or FFI. It touches files in one place, the Jakob
//! 2019 table cache ([`baselines::jakob_cache`]): a pure function of its key, kept once.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod baselines;
pub mod bounded;
pub mod c_header;
pub mod compact;
pub mod emission;
pub mod key_hash;
pub mod method;
pub mod otsu2018;
pub mod resample;
pub mod stack;

pub use method::Method;
pub use otsu2018::model::Model;
pub use otsu2018::runtime::Uplifter;
pub use otsu2018::train::{train, Part, TrainOptions, TrainingSet};

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
    /// Training data or options that cannot make a model (see [`otsu2018::train`]'s table).
    #[error("cannot train: {0}")]
    Training(String),
    /// A blend width that is not finite, or outside the allowed range ([`otsu2018::blend`]).
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
