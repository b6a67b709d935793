//! The errors of the C++ libraries, wrapped: OpenImageIO's and OpenColorIO's error types are
//! no part of this crate's API (a front-end never names an FFI crate), yet their messages and
//! causes are kept as they are (each wrapper is transparent).

/// An image could not be opened or read (OpenImageIO's message).
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct ImageError(pub specconv_oiio::Error);

/// Colour management failed: the OCIO config, a colour space, a processor (OpenColorIO's
/// message).
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct ColourError(pub specconv_ocio::Error);

impl ColourError {
    /// Whether the colour space is a data space (it holds numbers, not colour).
    pub fn is_data_space(&self) -> bool {
        matches!(self.0, specconv_ocio::Error::DataColorSpace { .. })
    }
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_oiio::Error> for ImageError {
    fn from(e: specconv_oiio::Error) -> ImageError {
        ImageError(e)
    }
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_ocio::Error> for ColourError {
    fn from(e: specconv_ocio::Error) -> ColourError {
        ColourError(e)
    }
}
