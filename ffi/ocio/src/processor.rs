//! A colour conversion OpenColorIO built, ready to apply from any thread, and the way it
//! reaches CIE XYZ.

use std::fmt;
use std::ptr::NonNull;

use ocio_sys as sys;

use crate::error::{Error, Result};
use crate::shim::last_error;

/// How a processor reaches CIE XYZ.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum XyzRoute {
    /// Not an XYZ processor: straight to this colour space.
    Direct(String),
    /// Through the `cie_xyz_d65_interchange` role (this colour space).
    CieXyzD65Interchange(String),
    /// Through the `aces_interchange` role (this colour space) and OCIO's built-in
    /// Bradford-adapted AP0-to-XYZ-D65 transform.
    AcesInterchange(String),
}

/// A colour conversion, ready to apply. Immutable; share it between worker threads.
pub struct Processor {
    pub(crate) raw: NonNull<sys::specconv_ocio_processor>,
    pub(crate) src: String,
    pub(crate) route: XyzRoute,
}

// SAFETY: OCIO processors and CPU processors are immutable and documented as safe to
// apply from several threads at once.
unsafe impl Send for Processor {}
unsafe impl Sync for Processor {}

impl Drop for Processor {
    fn drop(&mut self) {
        // SAFETY: raw came from the shim and is freed exactly once, here.
        unsafe { sys::specconv_ocio_processor_free(self.raw.as_ptr()) }
    }
}

impl fmt::Debug for Processor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Processor")
            .field("src", &self.src)
            .field("route", &self.route)
            .finish()
    }
}

impl Processor {
    /// The source colour space (canonical name).
    pub fn src(&self) -> &str {
        &self.src
    }

    /// The destination and, for a processor to CIE XYZ, the role it goes through.
    pub fn route(&self) -> &XyzRoute {
        &self.route
    }

    /// Converts interleaved RGB pixels in place.
    pub fn apply_rgb(&self, rgb: &mut [f32]) -> Result<()> {
        self.apply(rgb, 3)
    }

    /// Converts interleaved RGBA pixels in place; alpha is left as it is.
    pub fn apply_rgba(&self, rgba: &mut [f32]) -> Result<()> {
        self.apply(rgba, 4)
    }

    /// Converts one RGB triple.
    pub fn convert(&self, rgb: [f32; 3]) -> Result<[f32; 3]> {
        let mut px = rgb;
        self.apply_rgb(&mut px)?;
        Ok(px)
    }

    fn apply(&self, data: &mut [f32], channels: usize) -> Result<()> {
        if !data.len().is_multiple_of(channels) {
            return Err(Error::Argument(format!(
                "{} values are not whole {channels}-channel pixels",
                data.len()
            )));
        }
        // SAFETY: live processor; data holds len/channels whole pixels of `channels` f32
        // each, the size given to the shim.
        let status = unsafe {
            sys::specconv_ocio_processor_apply(
                self.raw.as_ptr(),
                data.as_mut_ptr(),
                data.len() / channels,
                channels as i32,
            )
        };
        if status as u32 == sys::SPECCONV_OCIO_OK {
            Ok(())
        } else {
            Err(Error::Processor {
                src: self.src.clone(),
                dst: match &self.route {
                    XyzRoute::Direct(d) => d.clone(),
                    _ => "CIE XYZ (D65)".into(),
                },
                message: last_error(),
            })
        }
    }
}
