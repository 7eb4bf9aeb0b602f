//! Log-log plots of error curves, one line per method, as PNG and SVG (plotters).
//!
//! The PNG is drawn into a memory buffer and encoded with `image`, so plotters needs neither
//! its own image encoder nor the system's fonts: text is laid out and rasterised with
//! `ab_glyph` from a subset of DejaVu Sans compiled into the binary
//! (`crates/experiment/assets/fonts/`, Bitstream Vera licence). The SVG names the `sans-serif` family and lets
//! the viewer draw the text.

use crate::error::{ExperimentError, Result};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// The bundled font.
const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans-ascii.ttf");

/// Plot size in pixels (SVG user units).
const SIZE: (u32, u32) = (760, 520);

/// Line colours: the Tableau 10 palette, distinguishable and printable.
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// One curve.
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points, sorted by x; non-positive values cannot be shown on log axes and are skipped.
    pub points: Vec<(f64, f64)>,
}

/// What to draw.
pub struct Chart<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// X axis label.
    pub x_label: &'a str,
    /// Y axis label.
    pub y_label: &'a str,
    /// Tick spacing of the x axis: 2 for sample counts, 10 otherwise.
    pub x_base: f64,
    /// The curves.
    pub series: &'a [Series],
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is compiled in and known to parse (a test draws with it).
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Writes the chart as a PNG and an SVG, each atomically.
pub fn write(chart: &Chart<'_>, png: &Path, svg: &Path) -> Result<()> {
    write_scaled(chart, png, svg, false)
}

/// Writes the chart with a linear x axis (frame numbers; `x_base` unused) and a log y axis,
/// as a PNG and an SVG, each atomically.
pub fn write_linear_x(chart: &Chart<'_>, png: &Path, svg: &Path) -> Result<()> {
    write_scaled(chart, png, svg, true)
}

fn write_scaled(chart: &Chart<'_>, png: &Path, svg: &Path, linear_x: bool) -> Result<()> {
    register_font();
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        if linear_x {
            draw_linear_x(&root, chart).map_err(plot_error(png))?;
        } else {
            draw(&root, chart).map_err(plot_error(png))?;
        }
        root.present().map_err(plot_error(png))?;
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &rgb,
        w,
        h,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(plot_error(png))?;
    rt_film::write_bytes_atomic(png, &bytes)?;

    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
        if linear_x {
            draw_linear_x(&root, chart).map_err(plot_error(svg))?;
        } else {
            draw(&root, chart).map_err(plot_error(svg))?;
        }
        root.present().map_err(plot_error(svg))?;
    }
    Ok(rt_film::write_bytes_atomic(svg, text.as_bytes())?)
}

/// An [`ExperimentError::Plot`] about `path`.
fn plot_error<E: std::fmt::Display>(path: &Path) -> impl FnOnce(E) -> ExperimentError + '_ {
    move |e| ExperimentError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Tick labels: plain decimals where they are short, powers of ten elsewhere.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        let e = a.log10().round() as i32;
        if (a / 10f64.powi(e) - 1.0).abs() < 1e-6 {
            format!("1e{e}")
        } else {
            format!("{v:.1e}")
        }
    }
}

/// The smallest and largest positive values, widened by a margin so points do not sit on the
/// frame.
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (0.1, 10.0);
    }
    if lo == hi {
        return (lo / 2.0, hi * 2.0);
    }
    let m = (hi / lo).powf(0.06);
    (lo / m, hi * m)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart<'_>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let keep = |p: &(f64, f64)| p.0 > 0.0 && p.1 > 0.0;
    let pts = || {
        chart
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| keep(p))
    };
    let (x0, x1) = span(pts().map(|p| p.0));
    let (y0, y1) = span(pts().map(|p| p.1));
    let c = builder(root, chart).build_cartesian_2d(
        (x0..x1).log_scale().base(chart.x_base),
        (y0..y1).log_scale(),
    )?;
    finish(c, chart, keep, true)
}

/// [`draw`] with a linear x axis: error over frames. Points with a non-positive y are left out
/// (log y axis); lines have no markers (sequences have many points).
fn draw_linear_x<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart<'_>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let keep = |p: &(f64, f64)| p.0.is_finite() && p.1 > 0.0 && p.1.is_finite();
    let pts = || {
        chart
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| keep(p))
    };
    let (x0, x1) = pts().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p.0), hi.max(p.0))
    });
    let (x0, x1) = if x0 < x1 {
        (x0, x1)
    } else if x0.is_finite() {
        (x0 - 1.0, x0 + 1.0)
    } else {
        (0.0, 1.0)
    };
    let (y0, y1) = span(pts().map(|p| p.1));
    let c = builder(root, chart).build_cartesian_2d(x0..x1, (y0..y1).log_scale())?;
    finish(c, chart, keep, false)
}

/// The chart's frame: caption, margins and label areas.
fn builder<'a, 'b, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    chart: &Chart<'_>,
) -> ChartBuilder<'a, 'b, DB> {
    let mut b = ChartBuilder::on(root);
    b.caption(chart.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(70);
    b
}

/// Grid, axis labels, one line per series (points where `keep`, with markers if asked) and
/// the legend, on either kind of x axis.
fn finish<'a, DB, X, Y>(
    mut c: ChartContext<'a, DB, Cartesian2d<X, Y>>,
    chart: &Chart<'_>,
    keep: impl Fn(&(f64, f64)) -> bool,
    markers: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    c.configure_mesh()
        .x_desc(chart.x_label)
        .y_desc(chart.y_label)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(200, 200, 200))
        .draw()?;
    for (i, s) in chart.series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let points: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| keep(p)).collect();
        c.draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(s.name.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 22, y)], colour.stroke_width(2))
            });
        if markers {
            c.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
        }
    }
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick(1.0), "1");
        assert_eq!(tick(0.25), "0.25");
        assert_eq!(tick(64.0), "64");
        assert_eq!(tick(1e-5), "1e-5");
        assert_eq!(tick(3e-6), "3.0e-6");
        assert_eq!(tick(1e6), "1e6");
    }

    #[test]
    fn plots_have_text_and_lines() {
        let dir = tempfile::tempdir().unwrap();
        let (png, svg) = (dir.path().join("p.png"), dir.path().join("p.svg"));
        let series = [
            Series {
                name: "path".into(),
                points: vec![(0.1, 1.0), (0.2, 0.5), (0.4, 0.25)],
            },
            Series {
                name: "path-bsdf".into(),
                points: vec![(0.1, 2.0), (0.2, 1.1), (0.4, 0.0)],
            },
        ];
        let chart = Chart {
            title: "cornell",
            x_label: "seconds",
            y_label: "relMSE",
            x_base: 10.0,
            series: &series,
        };
        write(&chart, &png, &svg).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for needle in ["cornell", "relMSE", "seconds", "path-bsdf", "<polyline"] {
            assert!(text.contains(needle), "{needle} missing from the SVG");
        }
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        // Both line colours are there, and the title (the only thing drawn in the top 30
        // rows) has dark pixels: text was rasterised.
        let has = |c: RGBColor| img.pixels().any(|p| p.0 == [c.0, c.1, c.2]);
        assert!(has(COLOURS[0]) && has(COLOURS[1]));
        let title_ink = (0..30)
            .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&v| v < 100))
            .count();
        assert!(
            title_ink > 30,
            "{title_ink} dark pixels in the title area: no text?"
        );
    }
}
