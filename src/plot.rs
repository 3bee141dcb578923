//! Log-log line plots as SVG or PNG (plotters), for convergence figures in
//! the README: error against samples per pixel or time, with 1/sqrt(N) and
//! 1/N guide lines.

use crate::error::{Error, Result};
use crate::image::write_atomically;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// Size of a plot in pixels (PNG) or user units (SVG).
const SIZE: (u32, u32) = (820, 520);

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

/// The file formats a plot can be written in, by the path's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotFormat {
    Svg,
    Png,
}

impl PlotFormat {
    /// The format `path` asks for, or an error naming the file.
    pub fn of(path: &Path) -> Result<Self> {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match extension.as_deref() {
            Some("svg") => Ok(PlotFormat::Svg),
            Some("png") => Ok(PlotFormat::Png),
            _ => Err(Error::at(
                path,
                None,
                "a plot is written as .svg or .png: name the file with one of those extensions",
            )),
        }
    }
}

/// Writes a log-log plot of `series` to `path`, as SVG or PNG by its
/// extension. Guides of slope -1/2 and -1 start at the first point of the
/// first series.
pub fn log_log_plot(
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
    let format = PlotFormat::of(path)?;
    register_font();
    let plot = Plot {
        title,
        x_label,
        y_label,
        series,
        range: (x0, x1, y0, y1),
        guides,
    };
    write_atomically(path, |tmp| {
        match format {
            PlotFormat::Svg => plot.draw(SVGBackend::new(tmp, SIZE).into_drawing_area()),
            PlotFormat::Png => write_png(&plot, tmp),
        }
        .map_err(|e| e.to_string())
    })
}

/// Plotters looks fonts up by family name; text is laid out (SVG) and
/// rasterised (PNG) with this one, so no system font is needed.
fn register_font() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        // The embedded font is valid TrueType; were it not, plotters would
        // fail to draw text and say so through `draw`'s error.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

/// Renders the plot into an RGB buffer and encodes it as PNG at `path`.
fn write_png(plot: &Plot, path: &Path) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let (width, height) = SIZE;
    let mut pixels = vec![0u8; width as usize * height as usize * 3];
    plot.draw(BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area())?;
    let image = image::RgbImage::from_raw(width, height, pixels).ok_or("plot buffer size")?;
    image.save_with_format(path, image::ImageFormat::Png)?;
    Ok(())
}

/// What a plot shows; drawn the same on any plotters backend.
struct Plot<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    series: &'a [Series],
    range: (f64, f64, f64, f64),
    guides: Option<(f64, f64)>,
}

impl Plot<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), Box<dyn std::error::Error>>
    where
        DB::ErrorType: 'static,
    {
        let (x0, x1, y0, y1) = self.range;
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(self.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(self.x_label)
            .y_desc(self.y_label)
            .x_label_formatter(&|v| format_number(*v))
            .y_label_formatter(&|v| format_number(*v))
            .draw()?;
        if let Some((gx, gy)) = self.guides {
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
        for (i, s) in self.series.iter().enumerate() {
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
}

fn format_number(v: f64) -> String {
    if (1e-3..1e5).contains(&v.abs()) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series() -> Vec<Series> {
        vec![Series {
            name: "path:sobol".into(),
            points: vec![(1.0, 0.2), (4.0, 0.05), (16.0, 0.011)],
        }]
    }

    #[test]
    fn png_plots_are_png_images_with_the_curves_and_text() {
        let dir = std::env::temp_dir().join(format!("tracelab-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("rmse.png");
        log_log_plot(
            &path,
            "RMSE against the reference",
            "spp",
            "RMSE",
            &series(),
        )
        .unwrap();
        let image = image::open(&path).unwrap().to_rgb8();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(image.dimensions(), SIZE);
        let count =
            |wanted: fn(&image::Rgb<u8>) -> bool| image.pixels().filter(|p| wanted(p)).count();
        // The first series' colour, exactly, along its line and markers.
        let curve = count(|p| p.0 == [31, 119, 180]);
        assert!(curve > 500, "{curve} pixels of the curve");
        // The title is the only thing drawn in the top rows: its glyphs.
        let title = (0..SIZE.0)
            .flat_map(|x| (0..30).map(move |y| (x, y)))
            .filter(|&(x, y)| image.get_pixel(x, y).0.iter().all(|&c| c < 128))
            .count();
        assert!(title > 50, "{title} dark pixels of the title");
    }

    #[test]
    fn svg_plots_are_svg_and_other_extensions_are_refused() {
        let dir = std::env::temp_dir().join(format!("tracelab-svg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let svg = dir.join("rmse.svg");
        log_log_plot(&svg, "RMSE", "spp", "RMSE", &series()).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        let jpg = dir.join("rmse.jpg");
        let refused = log_log_plot(&jpg, "RMSE", "spp", "RMSE", &series());
        let left = std::fs::read_dir(&dir).unwrap().count();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(text.starts_with("<svg"), "{}", &text[..40.min(text.len())]);
        assert!(text.contains("path:sobol"));
        let message = refused.unwrap_err().to_string();
        assert!(
            message.contains("rmse.jpg") && message.contains(".png"),
            "{message}"
        );
        assert_eq!(left, 1, "only the SVG is written");
    }
}
