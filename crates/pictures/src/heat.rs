//! Heat maps: values from black through red and yellow to white, with a colour bar.

use crate::font::FAMILY;
use crate::picture;
use crate::Result;
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

/// The PNG of `values` (row-major, `w × h`) as heat from 0 to `scale`, with a colour bar, its
/// scale and `title` to the right.
pub fn heat_map(
    (w, h): (usize, usize),
    values: &[f64],
    scale: f64,
    title: &str,
) -> Result<Vec<u8>> {
    let (width, height) = (w as u32 + BAR, (h as u32).max(200));
    let mut rgb = picture::render((width, height), |root| {
        root.fill(&WHITE)?;
        let (x0, top, bottom) = (w as i32 + 12, 24, height as i32 - 12);
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
    for y in 0..h {
        for x in 0..w {
            let i = 3 * (y * width as usize + x);
            rgb[i..i + 3].copy_from_slice(&heat(values[y * w + x] / scale));
        }
    }
    picture::encode_png(&rgb, width, height)
}
