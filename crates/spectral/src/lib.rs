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
//! - [`stack`]: the one builder of what a command uplifts with, from a spec of its
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
mod error;
pub mod key_hash;
pub mod method;
pub mod otsu2018;
pub mod resample;
pub mod stack;

pub use error::Error;
pub use method::Method;
pub use otsu2018::model::Model;
pub use otsu2018::runtime::Uplifter;
pub use otsu2018::train::{train, Part, TrainOptions, TrainingSet};
