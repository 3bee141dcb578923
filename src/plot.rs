//! Figures as SVG or PNG (plotters): log-log convergence plots (error
//! against samples per pixel or time, with 1/sqrt(N) and 1/N guides) for
//! the README and `tracelab bench`, and the Monte Carlo lab's curves,
//! scatter plots and histograms.

use crate::error::{Error, Result};
use crate::image::write_atomically;
use plotters::coord::Shift;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// Size of a plot in pixels (PNG) or user units (SVG).
const SIZE: (u32, u32) = (820, 520);

/// How a figure's axes scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axes {
    /// Both logarithmic (errors against N); zero and negative values are skipped.
    LogLog,
    /// Both linear, over the given ranges (point sets, functions).
    Linear { x: (f64, f64), y: (f64, f64) },
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A line through the points with markers.
    Line,
    /// Markers only (a scatter of a point set).
    Points,
    /// A thin grey guide (1/√N).
    Guide,
}

/// One named set of (x, y) points.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub style: SeriesStyle,
    /// Palette index, so a sampler has one colour in every figure.
    pub color: usize,
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// A series named `name` of `points`.
    pub fn new(name: &str, style: SeriesStyle, color: usize, points: &[(f64, f64)]) -> Series {
        Series {
            name: name.into(),
            style,
            color,
            points: points.to_vec(),
        }
    }
}

/// A grid of values in [0, 1] drawn from black (0) to white (1) (histograms,
/// spectra), row 0 at the bottom.
#[derive(Clone, Debug)]
pub struct Heatmap {
    pub width: usize,
    pub height: usize,
    pub values: Vec<f64>,
}

/// A figure: curves, scatter or a heatmap, with its axes.
#[derive(Clone, Debug)]
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub axes: Axes,
    pub series: Vec<Series>,
    pub heatmap: Option<Heatmap>,
}

impl Figure {
    /// A log-log figure of error curves.
    pub fn log_log(title: impl Into<String>, x: &str, y: &str, series: Vec<Series>) -> Figure {
        Figure {
            title: title.into(),
            x_label: x.into(),
            y_label: y.into(),
            axes: Axes::LogLog,
            series,
            heatmap: None,
        }
    }

    /// A linear figure over `x` × `y`.
    pub fn linear(
        title: impl Into<String>,
        labels: (&str, &str),
        x: (f64, f64),
        y: (f64, f64),
        series: Vec<Series>,
    ) -> Figure {
        Figure {
            title: title.into(),
            x_label: labels.0.into(),
            y_label: labels.1.into(),
            axes: Axes::Linear { x, y },
            series,
            heatmap: None,
        }
    }

    /// A short name for file names: lower case, words joined by '-'.
    pub fn slug(&self) -> String {
        let mut slug = String::new();
        for word in self
            .title
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|w| !w.is_empty())
            .take(5)
        {
            if !slug.is_empty() {
                slug.push('-');
            }
            slug.push_str(&word.to_ascii_lowercase());
        }
        slug
    }
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
    let mut figure = Figure::log_log(title, x_label, y_label, series.to_vec());
    if let Some(&(gx, gy)) = series.first().and_then(|s| s.points.first()) {
        let x1 = series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0))
            .fold(gx, f64::max);
        for (name, slope) in [("1/sqrt(N)", -0.5), ("1/N", -1.0)] {
            figure.series.push(Series::new(
                name,
                SeriesStyle::Guide,
                7,
                &[(gx, gy), (x1, gy * (x1 / gx).powf(slope))],
            ));
        }
    }
    write_figure(path, &figure)
}

/// Writes `figure` to `path`, as SVG or PNG by its extension.
pub fn write_figure(path: &Path, figure: &Figure) -> Result<()> {
    let range = figure
        .range()
        .ok_or_else(|| Error::at(path, None, "nothing to plot"))?;
    let format = PlotFormat::of(path)?;
    register_font();
    write_atomically(path, |tmp| {
        match format {
            PlotFormat::Svg => draw(
                figure,
                range,
                SVGBackend::new(tmp, SIZE).into_drawing_area(),
            ),
            PlotFormat::Png => write_png(figure, range, tmp),
        }
        .map_err(|e| e.to_string())
    })
}

impl Figure {
    /// The axes' ranges: given (linear), or around the positive points (log-log).
    fn range(&self) -> Option<(f64, f64, f64, f64)> {
        match self.axes {
            Axes::Linear { x, y } => Some((x.0, x.1, y.0, y.1)),
            Axes::LogLog => {
                let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
                for (x, y) in self.series.iter().flat_map(|s| s.points.iter()) {
                    if *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite() {
                        x0 = x0.min(*x);
                        x1 = x1.max(*x);
                        y0 = y0.min(*y);
                        y1 = y1.max(*y);
                    }
                }
                (x0 <= x1).then_some((x0 / 1.2, x1 * 1.2, y0 / 1.5, y1 * 1.5))
            }
        }
    }
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

type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

/// Renders the figure into an RGB buffer and encodes it as PNG at `path`.
fn write_png(figure: &Figure, range: (f64, f64, f64, f64), path: &Path) -> DrawResult {
    let (width, height) = SIZE;
    let mut pixels = vec![0u8; width as usize * height as usize * 3];
    draw(
        figure,
        range,
        BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area(),
    )?;
    let image = image::RgbImage::from_raw(width, height, pixels).ok_or("plot buffer size")?;
    image.save_with_format(path, image::ImageFormat::Png)?;
    Ok(())
}

/// Draws a figure on any plotters backend.
fn draw<DB: DrawingBackend>(
    figure: &Figure,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    root: DrawingArea<DB, Shift>,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&figure.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64);
    match figure.axes {
        Axes::LogLog => {
            let chart = builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
            draw_contents(figure, chart)?;
        }
        Axes::Linear { .. } => {
            let chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
            draw_contents(figure, chart)?;
        }
    }
    root.present()?;
    Ok(())
}

/// Axes, heatmap, series and legend, on linear or logarithmic coordinates.
fn draw_contents<'a, DB, X, Y>(
    figure: &Figure,
    mut chart: ChartContext<'a, DB, Cartesian2d<X, Y>>,
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(figure.x_label.as_str())
        .y_desc(figure.y_label.as_str())
        .x_label_formatter(&|v| format_number(*v))
        .y_label_formatter(&|v| format_number(*v))
        .draw()?;
    if let (Some(map), Axes::Linear { x, y }) = (&figure.heatmap, figure.axes) {
        let (w, h) = (
            (x.1 - x.0) / map.width as f64,
            (y.1 - y.0) / map.height as f64,
        );
        chart.draw_series((0..map.width * map.height).map(|k| {
            let (i, j) = ((k % map.width) as f64, (k / map.width) as f64);
            let level = (255.0 * map.values[k].clamp(0.0, 1.0)) as u8;
            Rectangle::new(
                [
                    (x.0 + i * w, y.0 + j * h),
                    (x.0 + (i + 1.0) * w, y.0 + (j + 1.0) * h),
                ],
                RGBColor(level, level, level).filled(),
            )
        }))?;
    }
    let mut legend = false;
    for s in &figure.series {
        let color = match s.style {
            SeriesStyle::Guide => RGBColor(150, 150, 150),
            _ => PALETTE[s.color % PALETTE.len()],
        };
        let points = s.points.iter().copied().filter(|(x, y)| {
            x.is_finite()
                && y.is_finite()
                && (figure.axes != Axes::LogLog || (*x > 0.0 && *y > 0.0))
        });
        let width = match s.style {
            SeriesStyle::Line => 2,
            _ => 1,
        };
        if s.style == SeriesStyle::Points {
            chart
                .draw_series(points.map(|p| Circle::new(p, 2, color.filled())))?
                .label(s.name.as_str())
                .legend(move |(x, y)| Circle::new((x + 9, y), 3, color.filled()));
        } else {
            chart
                .draw_series(LineSeries::new(
                    points.clone(),
                    ShapeStyle::from(&color).stroke_width(width),
                ))?
                .label(s.name.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(
                        vec![(x, y), (x + 18, y)],
                        ShapeStyle::from(&color).stroke_width(width),
                    )
                });
            if s.style == SeriesStyle::Line {
                chart.draw_series(points.map(|p| Circle::new(p, 3, color.filled())))?;
            }
        }
        legend = true;
    }
    if legend && figure.heatmap.is_none() {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    Ok(())
}

fn format_number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
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
        vec![Series::new(
            "path:sobol",
            SeriesStyle::Line,
            0,
            &[(1.0, 0.2), (4.0, 0.05), (16.0, 0.011)],
        )]
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
