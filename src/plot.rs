//! Log-log line plots as SVG (plotters), for convergence figures in the
//! README: error against samples per pixel or time, with 1/sqrt(N) and 1/N
//! guide lines.

use crate::error::{Error, Result};
use crate::image::write_atomically;
use plotters::prelude::*;
use std::path::Path;

/// One named curve of (x, y) points, both positive.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Writes a log-log plot of `series` to `path` (SVG). Guides of slope -1/2
/// and -1 start at the first point of the first series.
pub fn log_log_svg(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<()> {
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .collect();
    if all.is_empty() {
        return Err(Error::at(path, None, "nothing to plot"));
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in &all {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    let (x0, x1, y0, y1) = (x0 / 1.2, x1 * 1.2, y0 / 1.5, y1 * 1.5);
    let guides = series.first().and_then(|s| s.points.first().copied());
    write_atomically(path, |tmp| {
        draw(
            tmp,
            title,
            x_label,
            y_label,
            series,
            (x0, x1, y0, y1),
            guides,
        )
        .map_err(|e| e.to_string())
    })
}

fn draw(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    guides: Option<(f64, f64)>,
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (820, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| format_number(*v))
        .y_label_formatter(&|v| format_number(*v))
        .draw()?;
    if let Some((gx, gy)) = guides {
        for (name, slope) in [("1/sqrt(N)", -0.5), ("1/N", -1.0)] {
            let end = (x1, gy * (x1 / gx).powf(slope));
            chart
                .draw_series(LineSeries::new(
                    [(gx, gy), end],
                    ShapeStyle::from(&RGBColor(170, 170, 170)).stroke_width(1),
                ))?
                .label(name)
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], RGBColor(170, 170, 170))
                });
        }
    }
    for (i, s) in series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        chart
            .draw_series(LineSeries::new(
                s.points.iter().copied(),
                ShapeStyle::from(&color).stroke_width(2),
            ))?
            .label(s.name.as_str())
            .legend(move |(x, y)| {
                PathElement::new(
                    vec![(x, y), (x + 18, y)],
                    ShapeStyle::from(&color).stroke_width(2),
                )
            });
        chart.draw_series(s.points.iter().map(|p| Circle::new(*p, 3, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

fn format_number(v: f64) -> String {
    if (1e-3..1e5).contains(&v.abs()) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}
