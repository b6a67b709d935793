//! How the spectra are stored ([`Storage`]), and the channels and attributes of a compact
//! file.

use crate::{Options, Rounding};
use specconv_exr::{Kind, Sample};
use specconv_spectral::compact::{Compact, Precision};
use specconv_spectral::stack::Stack;

/// How the spectra are stored, as the options and the method stack decide it together
/// ([`Storage::of`]): everything a job needs beyond the options themselves.
#[derive(Debug, Clone)]
pub struct Storage {
    /// Reflectance (`T.` channels) or emission (`S0.` channels with their units).
    pub kind: Kind,
    /// Per band, the weights of X, Y and Z with which the spectra will be read back (the
    /// method's colorimetry): half samples are rounded to keep that colour
    /// ([`specconv_exr::quantize`]); `None` rounds to nearest.
    pub xyz_weights: Option<[Vec<f64>; 3]>,
    /// The range a filter with negative lobes
    /// ([`Filter::has_negative_lobes`](crate::filter::Kernel::has_negative_lobes)) keeps the
    /// bands it makes in: [0, 1] for bounded reflectance. Alpha is kept in [0, 1].
    pub band_range: (f32, f32),
    /// The compact layout's encoder: texels of [`COMPACT_CHANNELS`] instead of bands.
    pub compact: Option<Compact>,
    /// How a compact texel's colour and u are stored (`--data-type`: half as maketx stores
    /// colour, u as half where exact enough; float32 throughout).
    pub precision: Precision,
}

impl Storage {
    /// What `options` make of `stack`'s spectra, with the compact layout's encoder when it
    /// is the layout.
    pub fn of(options: &Options, stack: &Stack, compact: Option<Compact>) -> Storage {
        let precision = match options.sample {
            Sample::Half => Precision::Half,
            Sample::Float => Precision::Float,
        };
        if let Some(compact) = compact {
            // Colours and dual unknowns, rounded by `Compact::store`: no range but a number's.
            let float = |name: &str| precision == Precision::Float || name.starts_with("UF.");
            let channels = COMPACT_CHANNELS.map(|name| {
                let sample = if float(name) {
                    Sample::Float
                } else {
                    Sample::Half
                };
                (name.to_string(), sample)
            });
            return Storage {
                kind: specconv_exr::Kind::Named(channels.to_vec()),
                xyz_weights: None,
                band_range: (f32::NEG_INFINITY, f32::INFINITY),
                compact: Some(compact),
                precision,
            };
        }
        let by_colour = options.rounding_in_effect() == Rounding::Colour;
        Storage {
            kind: crate::layout::bands(options.emission),
            xyz_weights: by_colour.then(|| match stack.emission() {
                Some(e) => e.emission.weights.clone(),
                None => stack.colorimetry().weights.clone(),
            }),
            // What a filter's negative lobes may not push a band beyond: a bounded reflectance
            // stays in [0, 1]; nothing physical is negative.
            band_range: if options.bounded && options.emission.is_none() {
                (0.0, 1.0)
            } else {
                (0.0, f32::INFINITY)
            },
            compact: None,
            precision,
        }
    }

    /// Values a pixel holds beside alpha: the `bands` of the spectra, or a compact texel's.
    pub fn values(&self, bands: usize) -> usize {
        match self.compact {
            Some(_) => specconv_spectral::compact::STORED,
            None => bands,
        }
    }
}

/// A compact texel's channels as a file stores them, in the order of its values
/// ([`specconv_spectral::compact::Compact::store`]): the colour in the working space (so that
/// any viewer shows the texture), u as half, u as float32.
pub const COMPACT_CHANNELS: [&str; specconv_spectral::compact::STORED] =
    ["R", "G", "B", "U.0", "U.1", "U.2", "UF.0", "UF.1", "UF.2"];

/// The attribute that names a compact file's layout and version (`compact 2`).
pub const LAYOUT_ATTRIBUTE: &str = "specconvLayout";
/// The attribute that holds a compact file's model and decoding rule (docs/compact.md).
pub const COMPACT_ATTRIBUTE: &str = "specconvCompact";
/// The attribute that holds how `specconv expand` stores the spectra (`expand::settings`).
pub const EXPAND_ATTRIBUTE: &str = "specconvExpand";
