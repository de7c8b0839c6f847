//! Trend figures (`eha fleet`): per parameter a panel with each log's estimate and its
//! error bar, the fitted line with its ±2σ band, the limit, and where the line crosses
//! it with the crossing time's ±2σ interval. Rendered into a [`Figure`] (SVG and PNG), which
//! the command's staged output folder writes ([`Figure::write_into`]).

use super::{png, Figure, MAX_SPAN};
use plotters::prelude::*;

/// One panel: one parameter over time. x in years (decimal), y in the panel's unit.
pub struct TrendPanel {
    /// The y axis's label (with its unit).
    pub y_label: String,
    /// Estimates: (x, y, standard error).
    pub points: Vec<(f64, f64, f64)>,
    /// The fitted line, its low and high 2σ edges: (x, centre, low, high).
    pub line: Vec<(f64, f64, f64, f64)>,
    /// The limit, if any. [the panel's unit]
    pub limit: Option<f64>,
    /// Crossing: (x, 2σ before, 2σ after) and its legend text.
    pub crossing: Option<((f64, f64, f64), String)>,
}

/// An axis's range: (low, high).
type Span = (f64, f64);

const POINTS: RGBColor = RGBColor(31, 119, 180);
const LINE: RGBColor = RGBColor(44, 160, 44);
const LIMIT: RGBColor = RGBColor(214, 39, 40);
const WIDTH: u32 = 960;
const PANEL_HEIGHT: u32 = 320;

fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return None;
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        lo.abs().max(1.0) * 1e-3
    };
    Some((lo - pad, hi + pad))
}

/// The panel's x and y ranges: the estimates, the fitted line with its band, the crossing
/// and the limit, padded; refused when there is nothing to draw or the span is too wide.
fn panel_range(p: &TrendPanel) -> Result<(Span, Span), String> {
    let xs = p
        .points
        .iter()
        .map(|q| q.0)
        .chain(p.line.iter().map(|q| q.0))
        .chain(p.crossing.iter().flat_map(|((_, lo, hi), _)| [*lo, *hi]));
    // The estimates, the band and the limit set the y range; an error bar longer than
    // that is cut at the frame (a log whose parameter it could not tell apart can have a
    // standard error of 1e100 and would otherwise flatten every other point).
    let ys = p
        .points
        .iter()
        .map(|q| q.1)
        .chain(p.line.iter().flat_map(|q| [q.2, q.3]))
        .chain(p.limit);
    let ((x0, x1), (y0, y1)) = match (bounds(xs), bounds(ys)) {
        (Some(x), Some(y)) => (x, y),
        _ => return Err("nothing to draw".into()),
    };
    if !(x1 - x0 <= MAX_SPAN && y1 - y0 <= MAX_SPAN) {
        return Err(format!(
            "the data span {:e} by {:e}, too wide to draw",
            x1 - x0,
            y1 - y0
        ));
    }
    Ok(((x0, x1), (y0, y1)))
}

/// Renders `panels` stacked under `title`; `name` (the figure's file name) names it in
/// errors.
pub fn trend_chart(name: &str, title: &str, panels: &[TrendPanel]) -> Result<Figure, String> {
    let err = |e: &dyn std::fmt::Display| format!("plot `{name}`: {e}");
    let height = 60 + PANEL_HEIGHT * panels.len().max(1) as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let body = root
            .titled(title, ("sans-serif", 20))
            .map_err(|e| err(&e))?;
        let areas = body.split_evenly((panels.len().max(1), 1));
        for (p, area) in panels.iter().zip(&areas) {
            draw(area, p).map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    let png = png::render(&svg).map_err(|e| err(&e))?;
    Ok(Figure { svg, png })
}

fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    p: &TrendPanel,
) -> Result<(), String> {
    let ((x0, x1), (y0, y1)) = panel_range(p)?;
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(90)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("year")
        .y_desc(p.y_label.as_str())
        .draw()
        .map_err(e)?;
    if !p.line.is_empty() {
        let band: Vec<(f64, f64)> = p
            .line
            .iter()
            .map(|q| (q.0, q.2))
            .chain(p.line.iter().rev().map(|q| (q.0, q.3)))
            .collect();
        chart
            .draw_series(std::iter::once(Polygon::new(band, LINE.mix(0.15))))
            .map_err(e)?
            .label("fitted line ±2σ")
            .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 18, y + 5)], LINE.mix(0.3).filled()));
        chart
            .draw_series(LineSeries::new(
                p.line.iter().map(|q| (q.0, q.1)),
                LINE.stroke_width(2),
            ))
            .map_err(e)?;
    }
    chart
        .draw_series(p.points.iter().map(|q| {
            PathElement::new(
                vec![
                    (q.0, (q.1 - q.2).clamp(y0, y1)),
                    (q.0, (q.1 + q.2).clamp(y0, y1)),
                ],
                POINTS.stroke_width(1),
            )
        }))
        .map_err(e)?;
    chart
        .draw_series(
            p.points
                .iter()
                .map(|q| Circle::new((q.0, q.1), 3, POINTS.filled())),
        )
        .map_err(e)?
        .label("log's estimate ±1 s.e.")
        .legend(|(x, y)| Circle::new((x + 9, y), 3, POINTS.filled()));
    if let Some(l) = p.limit {
        chart
            .draw_series(LineSeries::new([(x0, l), (x1, l)], LIMIT.stroke_width(2)))
            .map_err(e)?
            .label("limit")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], LIMIT.stroke_width(2)));
        if let Some(((_, lo, hi), label)) = &p.crossing {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(*lo, l), (*hi, l)],
                    BLACK.stroke_width(5),
                )))
                .map_err(e)?
                .label(label.as_str())
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(5))
                });
        }
    }
    // The corner the data leave free: a falling trend starts high on the left, a
    // rising one low.
    let falling = p
        .line
        .first()
        .zip(p.line.last())
        .is_some_and(|(a, b)| b.1 < a.1);
    chart
        .configure_series_labels()
        .position(if falling {
            SeriesLabelPosition::LowerLeft
        } else {
            SeriesLabelPosition::UpperLeft
        })
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    Ok(())
}
