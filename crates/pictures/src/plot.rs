//! The report's plot: accuracy against time per colour, one labelled point per method and
//! setting, both axes logarithmic.

use crate::picture::{drawing_failed, DrawResult};
use crate::Result;
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
    let mut chart = ChartBuilder::on(root)
        .caption(
            "Accuracy against cost (f32 uplift, one thread)",
            (crate::font::FAMILY, 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(range(&xs).log_scale(), range(&ys).log_scale())?;
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
    for p in points.iter().filter(|p| finite(p.ns) && finite(p.delta_e)) {
        let c = colour(&p.label);
        chart.draw_series(std::iter::once(Circle::new(
            (p.ns, p.delta_e),
            4,
            c.filled(),
        )))?;
        chart.draw_series(std::iter::once(Text::new(
            p.label.clone(),
            (p.ns, p.delta_e),
            (crate::font::FAMILY, 12).into_font().color(&c),
        )))?;
    }
    Ok(())
}

/// Three significant digits: log-scale ticks are not round in binary.
fn short(v: f64) -> String {
    let decimals = (2.0 - v.abs().log10().floor()).clamp(0.0, 9.0) as usize;
    format!("{v:.decimals$}")
}
