//! What every output's header carries of its input and its pixels, written by `convert` and
//! `expand` alike: the data and display windows, and the average (and constant) colour
//! OpenImageIO's texture system reads.

use specconv_exr::{SpectralFile, Windows};

/// The data and display windows an output keeps of its input's level `top`.
pub(crate) fn windows_of(top: &specconv_oiio::Level) -> Windows {
    Windows {
        data_origin: (top.x, top.y),
        display: (
            top.display.x,
            top.display.y,
            top.display.width as usize,
            top.display.height as usize,
        ),
    }
}

/// What OpenImageIO's texture system reports as a texture's average colour.
pub(crate) const AVERAGE: &str = "oiio:AverageColor";
/// What it answers every lookup of a constant texture with.
pub(crate) const CONSTANT: &str = "oiio:ConstantColor";

/// Values as `oiio:AverageColor` lists them, each in 13 characters (`+1.234568e-01`), so that
/// the text's length does not depend on them.
pub(crate) fn average_text(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| {
            if !v.is_finite() {
                return format!("{v:>13}");
            }
            let text = format!("{v:+.6e}");
            let (mantissa, exponent) = text.split_once('e').expect("{:e} has an exponent");
            let exponent: i32 = exponent.parse().expect("{:e}'s exponent is an integer");
            format!(
                "{mantissa}e{}{:02}",
                if exponent < 0 { '-' } else { '+' },
                exponent.abs()
            )
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// The average (and, for a constant texture, the constant) colour attributes of `file`, from
/// the sums of level 0's values (bands, then alpha) over its `pixels`.
pub(crate) fn average_attributes(
    file: &SpectralFile,
    sums: &[f64],
    pixels: u64,
) -> Vec<(String, String)> {
    let mean: Vec<f64> = sums.iter().map(|s| s / pixels as f64).collect();
    let text = average_text(&file.in_channel_order(&mean));
    let constant = file
        .spec()
        .attributes
        .iter()
        .any(|(k, _)| k == CONSTANT)
        .then(|| (CONSTANT.to_string(), text.clone()));
    std::iter::once((AVERAGE.to_string(), text))
        .chain(constant)
        .collect()
}
