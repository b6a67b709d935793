//! Transfer functions from stored values to linear: what a declaration (a PNG chunk, an ICC
//! curve, a Color Interop Forum ID) says a file's values are, before its primaries apply.

use specconv_colour::rgb;

/// A transfer function from stored values to linear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Decode {
    /// Stored values are linear.
    Linear,
    /// linear = stored^exponent (PNG `gAMA` g: exponent 1/g).
    Power(f64),
    /// IEC 61966-2-1.
    Srgb,
}

impl Decode {
    pub(crate) fn apply(self, v: f32) -> f32 {
        match self {
            Decode::Linear => v,
            // Odd extension below 0, as OCIO's ExponentTransform mirrors negative values.
            Decode::Power(e) => (v.abs() as f64).powf(e).copysign(v as f64) as f32,
            Decode::Srgb => (rgb::srgb_decode(v.abs() as f64) as f32).copysign(v),
        }
    }
}
