//! SVG plots (plotters): time traces, spectra with the physical orders marked, sweep curves.
//!
//! Points that are not finite are left out, and the axes span at most [`MAX_SPAN`]: a
//! range beyond it (values near ±1e308, whose difference overflows) would leave plotters'
//! tick search without end.

/// Widest axis span drawn (a plot of wider data is refused, not drawn). [axis unit]
pub const MAX_SPAN: f64 = 1e100;

use plotters::prelude::*;
use std::path::Path;

/// One named line.
pub struct Series<'a> {
    /// Legend text.
    pub name: &'a str,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
}

/// A vertical marker with a label (a physical order in a spectrum).
pub struct Marker<'a> {
    /// Where. [x unit]
    pub x: f64,
    /// Label.
    pub label: &'a str,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

fn bounds(series: &[Series], log_y: bool) -> (f64, f64, f64, f64) {
    let mut b = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in series.iter().flat_map(|s| &s.points) {
        if !drawable(p, log_y) {
            continue;
        }
        b = (b.0.min(p.0), b.1.max(p.0), b.2.min(p.1), b.3.max(p.1));
    }
    if b.0 > b.1 {
        return (0.0, 1.0, 0.0, 1.0);
    }
    if b.1 == b.0 {
        b.1 = b.0 + 1.0;
    }
    if b.3 <= b.2 {
        let m = b.2.abs().max(1.0) * 1e-3;
        b = (b.0, b.1, b.2 - m, b.3 + m);
    }
    if !log_y {
        let pad = 0.05 * (b.3 - b.2);
        b.2 -= pad;
        b.3 += pad;
    }
    b
}

/// Whether a point can be drawn: finite, and positive on a log scale.
fn drawable(p: &(f64, f64), log_y: bool) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0)
}

/// A line chart written to `path` (SVG). `log_y` plots y on a log scale.
pub fn line_chart(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    markers: &[Marker],
    log_y: bool,
) -> Result<(), String> {
    // Named by its file name: the folder may be a staging folder the user never sees.
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let err = |e: &dyn std::fmt::Display| format!("plot `{name}`: {e}");
    let (x0, x1, y0, y1) = bounds(series, log_y);
    let span_ok = |s: f64| s.is_finite() && s <= MAX_SPAN;
    if !(span_ok(x1 - x0) && span_ok(y1 - y0)) {
        return Err(err(&format_args!(
            "the data span {:e} by {:e}, too wide to draw",
            x1 - x0,
            y1 - y0
        )));
    }
    let root = SVGBackend::new(path, (960, 540)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(80);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(y_label)
                .draw()
                .map_err(|e| err(&e))?;
            for (i, s) in series.iter().enumerate() {
                let c = COLOURS[i % COLOURS.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|p| drawable(p, log_y))
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts, c.stroke_width(1)))
                    .map_err(|e| err(&e))?
                    .label(s.name)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c));
            }
            for m in markers.iter().filter(|m| m.x >= x0 && m.x <= x1) {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(m.x, y0), (m.x, y1)],
                        BLACK.mix(0.35),
                    )))
                    .map_err(|e| err(&e))?;
                chart
                    .draw_series(std::iter::once(Text::new(
                        m.label.to_string(),
                        (m.x, y1),
                        ("sans-serif", 13),
                    )))
                    .map_err(|e| err(&e))?;
            }
            if series.len() > 1 {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()
                    .map_err(|e| err(&e))?;
            }
        }};
    }
    if log_y {
        draw!(builder
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(|e| err(&e))?);
    } else {
        draw!(builder
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(&e))?);
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extreme_and_non_finite_points_end_quickly() {
        let dir = std::env::temp_dir().join(format!("eha-plots-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.svg");
        let wild = Series {
            name: "wild",
            points: vec![
                (0.0, 1e308),
                (1.0, -1e308),
                (2.0, f64::NAN),
                (3.0, f64::INFINITY),
            ],
        };
        let e = line_chart(&path, "t", "x", "y", &[wild], &[], false).unwrap_err();
        assert!(e.contains("too wide"), "{e}");
        let tame = Series {
            name: "tame",
            points: vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)],
        };
        line_chart(&path, "t", "x", "y", &[tame], &[], false).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
