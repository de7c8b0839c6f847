//! SVG plots (plotters): time traces, spectra with the physical orders marked, sweep curves.

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
        if log_y && p.1 <= 0.0 {
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
    let err = |e: &dyn std::fmt::Display| format!("plot `{}`: {e}", path.display());
    let root = SVGBackend::new(path, (960, 540)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (x0, x1, y0, y1) = bounds(series, log_y);
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
                    .filter(|p| !log_y || p.1 > 0.0)
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
