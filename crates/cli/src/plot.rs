//! The report's plot: accuracy against time per colour, one labelled point per method and
//! setting, both axes logarithmic.

use plotters::prelude::*;

pub struct Point {
    pub label: String,
    pub ns: f64,
    pub delta_e: f64,
}

/// The SVG text of the plot. `threads` is only for the caption.
pub fn accuracy_against_time(points: &[Point], _threads: usize) -> String {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        // Drawing into a string cannot fail for I/O; errors would be plotters' own bugs, and the
        // plot is an extra: draw what can be drawn.
        let _ = draw(&root, points);
        let _ = root.present();
    }
    svg
}

fn draw(
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    points: &[Point],
) -> Result<(), Box<dyn std::error::Error>> {
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
            ("sans-serif", 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(range(&xs).log_scale(), range(&ys).log_scale())?;
    chart
        .configure_mesh()
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
            ("sans-serif", 12).into_font().color(&c),
        )))?;
    }
    Ok(())
}
