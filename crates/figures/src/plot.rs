//! The report's plot: accuracy against time per colour, one labelled point per method and
//! setting, both axes logarithmic.

use crate::error::Result;
use crate::picture::{drawing_failed, DrawResult};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One method in one setting.
pub struct Point {
    /// Written beside the point.
    pub label: String,
    /// Nanoseconds per colour.
    pub ns: f64,
    /// Mean reconstruction error (ΔE).
    pub delta_e: f64,
}

const SIZE: (u32, u32) = (900, 600);

/// The SVG text of the plot.
pub fn svg(points: &[Point]) -> Result<String> {
    crate::font::ensure()?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw(&root, points).map_err(drawing_failed)?;
        root.present().map_err(drawing_failed)?;
    }
    Ok(svg)
}

/// The PNG bytes of the plot.
pub fn png(points: &[Point]) -> Result<Vec<u8>> {
    crate::picture::render_png(SIZE, |root| draw(root, points))
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, points: &[Point]) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let finite = |v: f64| v.is_finite() && v > 0.0;
    let xs: Vec<f64> = points.iter().map(|p| p.ns).filter(|&v| finite(v)).collect();
    let ys: Vec<f64> = points
        .iter()
        .map(|p| p.delta_e)
        .filter(|&v| finite(v))
        .collect();
    let range = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        if lo.is_finite() {
            (lo / 2.0)..(hi * 2.0)
        } else {
            1.0..10.0
        }
    };
    let (xr, yr) = (range(&xs), range(&ys));
    let (xt, yt) = (log_ticks(xr.start, xr.end), log_ticks(yr.start, yr.end));
    let mut chart = ChartBuilder::on(root)
        .caption(
            "Accuracy against cost (f32 uplift, one thread)",
            (crate::font::FAMILY, 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(
            xr.log_scale().with_key_points(xt),
            yr.log_scale().with_key_points(yt),
        )?;
    chart
        .configure_mesh()
        .x_label_formatter(&|v| short(*v))
        .y_label_formatter(&|v| short(*v))
        .x_desc("nanoseconds per colour")
        .y_desc("mean Δe = ‖s − r‖²")
        .draw()?;
    let colour = |label: &str| {
        if label.starts_with("otsu2018") {
            RED
        } else if label.starts_with("pca") {
            MAGENTA
        } else if label.starts_with("meng") {
            GREEN
        } else if label.starts_with("jakob") {
            BLUE
        } else {
            BLACK
        }
    };
    let shown: Vec<&Point> = points
        .iter()
        .filter(|p| finite(p.ns) && finite(p.delta_e))
        .collect();
    let font = (crate::font::FAMILY, 12).into_font();
    let at: Vec<(i32, i32)> = shown
        .iter()
        .map(|p| chart.backend_coord(&(p.ns, p.delta_e)))
        .collect();
    let sizes = shown
        .iter()
        .map(|p| root.estimate_text_size(&p.label, &TextStyle::from(font.clone())))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let (x, y) = chart.plotting_area().get_pixel_range();
    let labels = place_labels(&at, &sizes, (x.start, y.start, x.end, y.end));
    for ((p, &point), label) in shown.iter().zip(&at).zip(labels) {
        let c = colour(&p.label);
        root.draw(&Circle::new(point, 4, c.filled()))?;
        root.draw(&Text::new(p.label.clone(), label, font.clone().color(&c)))?;
    }
    Ok(())
}

/// Ticks of a logarithmic axis from `lo` to `hi`: 1, 2 and 5 of each decade (every whole
/// mantissa where that gives fewer than four), exact decimals, so that every decade the
/// points reach is labelled.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let decades = lo.log10().floor() as i32..=hi.log10().ceil() as i32;
    let ticks = |mantissas: &[u32]| -> Vec<f64> {
        decades
            .clone()
            .flat_map(|d| mantissas.iter().map(move |m| format!("{m}e{d}")))
            .filter_map(|t| t.parse::<f64>().ok())
            .filter(|t| (lo..=hi).contains(t))
            .collect()
    };
    let coarse = ticks(&[1, 2, 5]);
    if coarse.len() >= 4 {
        coarse
    } else {
        ticks(&[1, 2, 3, 4, 5, 6, 7, 8, 9])
    }
}

/// Where each label's top-left corner goes: beside its point (`at`), on the first side (right,
/// left, above, below, then stepped up and down from right and left) where its box (`sizes`)
/// stays inside `area` (left, top, right, bottom) and meets no label placed before it and no
/// point; to the right when no side is free.
fn place_labels(
    at: &[(i32, i32)],
    sizes: &[(u32, u32)],
    area: (i32, i32, i32, i32),
) -> Vec<(i32, i32)> {
    type Rect = (i32, i32, i32, i32);
    let meets = |a: Rect, b: Rect| a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
    let dots: Vec<Rect> = at
        .iter()
        .map(|&(x, y)| (x - 5, y - 5, x + 5, y + 5))
        .collect();
    let mut placed: Vec<Rect> = Vec::new();
    let mut corners = Vec::with_capacity(at.len());
    for (&(x, y), &(w, h)) in at.iter().zip(sizes) {
        let (w, h) = (w as i32, h as i32);
        let (right, left) = (x + 7, x - 7 - w);
        let mut candidates = vec![
            (right, y - h / 2),
            (left, y - h / 2),
            (x - w / 2, y - 7 - h),
            (x - w / 2, y + 7),
        ];
        for step in 1..=8 {
            for dy in [step * (h + 2), -step * (h + 2)] {
                candidates.push((right, y - h / 2 + dy));
                candidates.push((left, y - h / 2 + dy));
            }
        }
        let free = |&(cx, cy): &(i32, i32)| {
            let b = (cx, cy, cx + w, cy + h);
            b.0 >= area.0
                && b.1 >= area.1
                && b.2 <= area.2
                && b.3 <= area.3
                && !placed.iter().chain(&dots).any(|&o| meets(b, o))
        };
        let corner = candidates
            .iter()
            .copied()
            .find(free)
            .unwrap_or(candidates[0]);
        placed.push((corner.0, corner.1, corner.0 + w, corner.1 + h));
        corners.push(corner);
    }
    corners
}

/// A tick's value in at most three significant digits, without trailing zeros (`0.05`,
/// `0.3`, `1000`): log-scale ticks are not round in binary.
fn short(v: f64) -> String {
    let decimals = (2.0 - v.abs().log10().floor()).clamp(0.0, 9.0) as usize;
    let s = format!("{v:.decimals$}");
    match s.contains('.') {
        true => s.trim_end_matches('0').trim_end_matches('.').to_string(),
        false => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every decade the points reach has ticks, below 0.1 too, labelled in short decimals.
    #[test]
    fn log_ticks_label_every_decade() {
        for (lo, hi, want) in [
            (
                0.004,
                0.9,
                &["0.005", "0.01", "0.02", "0.05", "0.1", "0.2", "0.5"][..],
            ),
            (
                0.0301,
                0.0802,
                &["0.04", "0.05", "0.06", "0.07", "0.08"][..],
            ),
            (
                5.0,
                2000.0,
                &["5", "10", "20", "50", "100", "200", "500", "1000", "2000"][..],
            ),
        ] {
            let got: Vec<String> = log_ticks(lo, hi).into_iter().map(short).collect();
            assert_eq!(got, want, "{lo}..{hi}");
        }
    }

    /// Labels of points close together (a model's cluster counts, as in docs/report-*.svg)
    /// are placed so that no two meet and none covers a point, whatever their order.
    #[test]
    fn labels_do_not_overlap() {
        let area = (90, 50, 880, 530);
        for n in [2, 5, 8, 12] {
            for spread in [0, 3, 8, 15] {
                let at: Vec<(i32, i32)> = (0..n)
                    .map(|i| (240 + spread * i, 420 + (i % 3) * spread / 2))
                    .collect();
                let sizes = vec![(110, 12); n as usize];
                let corners = place_labels(&at, &sizes, area);
                let boxes: Vec<_> = corners
                    .iter()
                    .zip(&sizes)
                    .map(|(&(x, y), &(w, h))| (x, y, x + w as i32, y + h as i32))
                    .collect();
                for (i, a) in boxes.iter().enumerate() {
                    for b in &boxes[i + 1..] {
                        let meet = a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
                        assert!(!meet, "{n} points {spread} px apart: {a:?} meets {b:?}");
                    }
                    for &(x, y) in &at {
                        assert!(
                            !(a.0 < x + 5 && x - 5 < a.2 && a.1 < y + 5 && y - 5 < a.3),
                            "{n} points {spread} px apart: {a:?} covers the point {x},{y}"
                        );
                    }
                }
            }
        }
    }
}
