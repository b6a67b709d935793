//! Embedded ICC profiles, converted through Little CMS (Debian's liblcms2, through the
//! `lcms2` crate).
//!
//! [`Profile::to_pcs`] makes a transform from the profile's RGB (or grey) to its profile
//! connection space, CIE XYZ relative to the D50 PCS white (0.9642, 1, 0.8249), with the
//! relative colorimetric intent: the media white maps to the PCS white. Adapting that to a
//! D65 white is colour science, done above this crate (the pipeline applies a Bradford
//! matrix after the transform).
//!
//! The transforms are built in a per-object Little CMS context without cache, so they are
//! `Send + Sync` and shared by the pipeline's worker threads.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

use lcms2::{
    ColorSpaceSignature, DisallowCache, Flags, InfoType, Intent, Locale, PixelFormat,
    ThreadContext, Transform,
};

/// What can go wrong reading an ICC profile or making its transform to XYZ.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Little CMS cannot parse the profile's bytes ([`Profile::new`]); holds its message.
    #[error("the embedded ICC profile cannot be read by Little CMS: {0}")]
    Parse(String),
    /// The profile's data colour space is neither RGB nor grey ([`Profile::to_pcs`]); holds
    /// that colour space's signature.
    #[error("the embedded ICC profile describes {0:?} data, not RGB or grey")]
    Unsupported(ColorSpaceSignature),
    /// Little CMS cannot make the transform from the profile to PCS XYZ
    /// ([`Profile::to_pcs`]).
    #[error("Little CMS cannot convert the embedded ICC profile '{name}' to XYZ: {message}")]
    Transform {
        /// The profile's description ([`Profile::description`]).
        name: String,
        /// Little CMS's message.
        message: String,
    },
}

/// A result whose error is, by default, this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// The D50 white of the ICC profile connection space (ICC.1:2022, 7.2.16), Y = 1.
pub const PCS_WHITE: [f64; 3] = [0.9642, 1.0, 0.8249];

/// A parsed ICC profile.
pub struct Profile {
    profile: lcms2::Profile<ThreadContext>,
    context: ThreadContext,
}

impl std::fmt::Debug for Profile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Profile")
            .field("description", &self.description())
            .finish()
    }
}

impl Profile {
    /// Parses the bytes of a profile (as embedded in PNG `iCCP`, JPEG APP2 or TIFF tag 34675).
    pub fn new(bytes: &[u8]) -> Result<Profile> {
        let context = ThreadContext::new();
        let profile = lcms2::Profile::new_icc_context(&context, bytes)
            .map_err(|e| Error::Parse(e.to_string()))?;
        Ok(Profile { profile, context })
    }

    /// The profile's description tag ("Adobe RGB (1998)", "Display P3"...), or "unnamed".
    pub fn description(&self) -> String {
        self.profile
            .info(InfoType::Description, Locale::none())
            .map(|s| s.trim().to_owned())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "unnamed".into())
    }

    /// A transform from the profile's RGB (or grey) to PCS XYZ (D50 white, Y = 1), relative
    /// colorimetric. It keeps the profile's Little CMS context alive, which it was made in.
    pub fn to_pcs(self) -> Result<ToPcs> {
        let grey = match self.profile.color_space() {
            ColorSpaceSignature::RgbData => false,
            ColorSpaceSignature::GrayData => true,
            other => return Err(Error::Unsupported(other)),
        };
        let xyz = lcms2::Profile::new_xyz_context(&self.context);
        let fail = |e: lcms2::Error| Error::Transform {
            name: self.description(),
            message: e.to_string(),
        };
        let transform = if grey {
            Pcs::Grey(
                Transform::new_flags_context(
                    &self.context,
                    &self.profile,
                    PixelFormat::GRAY_FLT,
                    &xyz,
                    PixelFormat::XYZ_FLT,
                    Intent::RelativeColorimetric,
                    Flags::NO_CACHE,
                )
                .map_err(fail)?,
            )
        } else {
            Pcs::Rgb(
                Transform::new_flags_context(
                    &self.context,
                    &self.profile,
                    PixelFormat::RGB_FLT,
                    &xyz,
                    PixelFormat::XYZ_FLT,
                    Intent::RelativeColorimetric,
                    Flags::NO_CACHE,
                )
                .map_err(fail)?,
            )
        };
        let name = self.description();
        let Profile { profile, context } = self;
        drop(xyz);
        drop(profile);
        Ok(ToPcs {
            transform,
            name,
            context: std::sync::Mutex::new(context),
        })
    }
}

enum Pcs {
    Rgb(Transform<[f32; 3], [f32; 3], ThreadContext, DisallowCache>),
    Grey(Transform<f32, [f32; 3], ThreadContext, DisallowCache>),
}

/// Profile RGB to PCS XYZ; immutable and shared between threads.
pub struct ToPcs {
    // Dropped first: the transform was made in `context`.
    transform: Pcs,
    name: String,
    /// Never locked: held so that the context outlives the transform (a Mutex makes the
    /// Send-only context Sync).
    #[allow(dead_code)]
    context: std::sync::Mutex<ThreadContext>,
}

impl std::fmt::Debug for ToPcs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ToPcs")
            .field("profile", &self.name)
            .finish()
    }
}

impl ToPcs {
    /// The profile's description.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Converts interleaved RGB triples (profile encoding, 0–1) to PCS XYZ in place. A grey
    /// profile reads the first value of each triple (the image's grey, repeated).
    pub fn apply_rgb(&self, rgb: &mut [f32]) {
        let pixels: Vec<[f32; 3]> = rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let mut xyz = vec![[0.0f32; 3]; pixels.len()];
        match &self.transform {
            Pcs::Rgb(t) => t.transform_pixels(&pixels, &mut xyz),
            Pcs::Grey(t) => {
                let grey: Vec<f32> = pixels.iter().map(|p| p[0]).collect();
                t.transform_pixels(&grey, &mut xyz);
            }
        }
        for (out, v) in rgb.chunks_exact_mut(3).zip(&xyz) {
            out.copy_from_slice(v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Little CMS's own sRGB profile: its white lands on the PCS white, and its red primary
    /// on the Bradford-adapted sRGB red of IEC 61966-2-1 Annex (0.4360, 0.2225, 0.0139).
    #[test]
    fn srgb_white_is_the_pcs_white_and_red_is_the_adapted_primary() {
        let bytes = lcms2::Profile::new_srgb().icc().unwrap();
        let profile = Profile::new(&bytes).unwrap();
        let t = profile.to_pcs().unwrap();
        let mut px = [1.0, 1.0, 1.0, 1.0, 0.0, 0.0];
        t.apply_rgb(&mut px);
        for k in 0..3 {
            assert!((px[k] as f64 - PCS_WHITE[k]).abs() < 2e-4, "{px:?}");
        }
        let red = [0.4361, 0.2225, 0.0139];
        for k in 0..3 {
            assert!((px[3 + k] as f64 - red[k]).abs() < 2e-4, "{px:?}");
        }
    }

    #[test]
    fn garbage_is_an_error_not_a_crash() {
        let err = Profile::new(b"not an ICC profile").unwrap_err();
        assert!(err.to_string().contains("cannot be read"), "{err}");
    }
}
