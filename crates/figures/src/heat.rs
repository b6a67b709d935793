//! Heat maps: values from black through red and yellow to white, with a colour bar.

use crate::error::Result;
use crate::font::FAMILY;
use crate::picture;
use plotters::prelude::*;

/// Black → red → yellow → white as ΔE goes from 0 to 1 (of the scale): readable in grey too.
pub fn heat(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let c = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    [c(3.0 * t), c(3.0 * t - 1.0), c(3.0 * t - 2.0)]
}

/// Width of the bar and its scale, pixels.
const BAR: u32 = 110;

/// The least height of a heat map: room for the title, the bar and its scale.
const MIN_HEIGHT: usize = 200;
/// The widest a small image is magnified to.
const MAX_WIDTH: usize = 4096;

/// How many times a `w × h` image is magnified (each value a k×k block) so that the map is at
/// least [`MIN_HEIGHT`] high, as the bar is, leaving no blank band under it; never wider than
/// [`MAX_WIDTH`] (a very wide, short image keeps a band).
fn magnification(w: usize, h: usize) -> usize {
    MIN_HEIGHT
        .div_ceil(h.max(1))
        .min((MAX_WIDTH / w.max(1)).max(1))
}

/// The PNG of `values` (row-major, `w × h`) as heat from 0 to `scale`, with a colour bar, its
/// scale and `title` to the right; an image under 200 rows is magnified by a whole factor
/// (up to 4096 pixels wide) so that the map fills the picture's height.
pub fn heat_map(
    (w, h): (usize, usize),
    values: &[f64],
    scale: f64,
    title: &str,
) -> Result<Vec<u8>> {
    let k = magnification(w, h);
    let (mw, mh) = (w * k, h * k);
    let (width, height) = (mw as u32 + BAR, (mh.max(MIN_HEIGHT)) as u32);
    let mut rgb = picture::render((width, height), |root| {
        root.fill(&WHITE)?;
        let (x0, top, bottom) = (mw as i32 + 12, 24, height as i32 - 12);
        let style = |size| (FAMILY, size).into_font().color(&BLACK);
        root.draw(&Text::new(title, (x0, 4), style(12.0)))?;
        for y in top..=bottom {
            let t = f64::from(bottom - y) / f64::from(bottom - top);
            let [r, g, b] = heat(t);
            root.draw(&Rectangle::new(
                [(x0, y), (x0 + 18, y + 1)],
                RGBColor(r, g, b).filled(),
            ))?;
        }
        for (t, y) in [(1.0, top), (0.5, (top + bottom) / 2), (0.0, bottom - 10)] {
            root.draw(&Text::new(
                format!("{:.2}", t * scale),
                (x0 + 24, y),
                style(12.0),
            ))?;
        }
        Ok(())
    })?;
    for y in 0..mh {
        for x in 0..mw {
            let i = 3 * (y * width as usize + x);
            rgb[i..i + 3].copy_from_slice(&heat(values[(y / k) * w + x / k] / scale));
        }
    }
    picture::encode_png(&rgb, width, height)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The map fills the picture's height, whatever the image's size: no row of the map's
    /// columns is left white (the values are 0: black), for images short, tall, wide and one
    /// pixel.
    #[test]
    fn a_heat_map_leaves_no_blank_band() {
        for (w, h) in [
            (64, 64),
            (1, 1),
            (300, 7),
            (13, 199),
            (50, 200),
            (20, 450),
            (5000, 3),
        ] {
            let png = heat_map((w, h), &vec![0.0; w * h], 1.0, "ΔE00").unwrap();
            let img = image::load_from_memory(&png).unwrap().to_rgb8();
            let (width, height) = img.dimensions();
            let rgb = img.into_raw();
            let k = magnification(w, h);
            assert_eq!(width as usize, w * k + BAR as usize, "{w}×{h}");
            let map_rows = (0..height as usize)
                .filter(|&y| {
                    let row = &rgb[3 * y * width as usize..][..3 * w * k];
                    row.iter().all(|&v| v == 0)
                })
                .count();
            if h * k >= MIN_HEIGHT {
                assert_eq!(map_rows, height as usize, "{w}×{h}: a blank band");
            } else {
                // Capped by the width: the widest magnification, still under the bar.
                assert_eq!(w * k, w * (MAX_WIDTH / w).max(1), "{w}×{h}");
                assert_eq!(map_rows, h * k, "{w}×{h}");
            }
        }
    }
}
