//! The pictures specconv draws: the accuracy-against-cost plot ([`plot`]), sheets of colour
//! swatches ([`swatches`]), heat maps with a colour bar ([`heat`]), and the rendering and PNG
//! encoding under them ([`picture`]), all in memory so that the caller writes the file
//! atomically. Text needs a font registered at run time ([`font`]).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod error;
pub mod font;
pub mod heat;
pub mod picture;
pub mod plot;
pub mod swatches;

pub use error::{Error, Result};
