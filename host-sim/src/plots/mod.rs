//! Plots (plotters' SVG, and a PNG of it, [`png`]): time traces, spectra with the physical
//! orders marked, sweep curves, and figures of panels stacked over one time axis (a signal
//! above, its residual or its measured reading beneath, each on its own scale). A plot is
//! rendered into memory as a [`Figure`]; the command's output folder writes it
//! ([`Figure::write_into`]), so plots are outputs of its transaction like any file.
//!
//! Order markers are labelled at the top of their panel in as many rows as it takes for no
//! label to cover another. Points that are not finite are left out, and the axes span at
//! most [`MAX_SPAN`]: a range beyond it (values near ±1e308, whose difference overflows)
//! would leave plotters' tick search without end.

pub mod png;
pub mod trend;

/// Widest axis span drawn (a plot of wider data is refused, not drawn). [axis unit]
pub const MAX_SPAN: f64 = 1e100;

use crate::output::{CliError, StagedFolder};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// A rendered plot: the SVG and the PNG of it.
pub struct Figure {
    /// The SVG document.
    pub svg: String,
    /// The PNG rendered from it.
    pub png: Vec<u8>,
}

impl Figure {
    /// Writes the figure into the staged folder `d` as `svg_name` (`NAME.svg`) and the PNG
    /// beside it (`NAME.png`).
    pub fn write_into(&self, d: &StagedFolder, svg_name: &str) -> Result<(), CliError> {
        d.file(svg_name, self.svg.as_bytes())?;
        let png = png::beside(Path::new(svg_name));
        d.file(&png.to_string_lossy(), &self.png)
    }
}

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

/// One panel of a figure: its lines and markers on its own y axis.
pub struct Panel<'a> {
    /// The y axis's label.
    pub y_label: &'a str,
    /// The lines.
    pub series: &'a [Series<'a>],
    /// The vertical markers.
    pub markers: &'a [Marker<'a>],
    /// Whether y is on a log scale.
    pub log_y: bool,
    /// Share of the figure's height (relative to the other panels').
    pub weight: u32,
    /// The y range from the bulk of the points (0.5 % to 99.5 %) when a few outliers (a
    /// start-up transient) would squeeze the rest into a line; they run off the panel.
    pub robust: bool,
    /// The first series is a measurement drawn in grey behind the others (models).
    pub measured_first: bool,
}

impl<'a> Panel<'a> {
    /// A linear panel of `series`, no markers, weight 1.
    pub fn new(y_label: &'a str, series: &'a [Series<'a>]) -> Panel<'a> {
        Panel {
            y_label,
            series,
            markers: &[],
            log_y: false,
            weight: 1,
            robust: false,
            measured_first: false,
        }
    }

    /// With vertical markers.
    pub fn markers(mut self, markers: &'a [Marker<'a>]) -> Panel<'a> {
        self.markers = markers;
        self
    }

    /// With a share of the figure's height.
    pub fn weight(mut self, weight: u32) -> Panel<'a> {
        self.weight = weight;
        self
    }

    /// With the y range of the bulk of the points.
    pub fn robust(mut self) -> Panel<'a> {
        self.robust = true;
        self
    }

    /// With the first series drawn as a measurement behind the others.
    pub fn measured_first(mut self) -> Panel<'a> {
        self.measured_first = true;
        self
    }
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// A measurement behind model lines.
const MEASURED: RGBColor = RGBColor(170, 170, 170);

/// The figure's size. [px]
const SIZE: (u32, u32) = (960, 540);
/// Marker labels' font size, the pixels a character takes at it, a row's height. [px]
const LABEL_FONT: u32 = 13;
const LABEL_CHAR_PX: f64 = 7.0;
const LABEL_ROW_PX: i32 = 15;

fn x_bounds(panels: &[Panel]) -> (f64, f64) {
    let mut b = (f64::MAX, f64::MIN);
    for p in panels {
        for q in p.series.iter().flat_map(|s| &s.points) {
            if drawable(q, p.log_y) {
                b = (b.0.min(q.0), b.1.max(q.0));
            }
        }
    }
    if b.0 > b.1 {
        return (0.0, 1.0);
    }
    if b.1 == b.0 {
        b.1 = b.0 + 1.0;
    }
    b
}

/// The y range of a panel's points within [x0, x1], padded; on a log scale with
/// `headroom` decades (linear: that share of the span) above for the marker labels.
fn y_bounds(p: &Panel, x0: f64, x1: f64, headroom: f64) -> (f64, f64) {
    let mut ys: Vec<f64> = p
        .series
        .iter()
        .flat_map(|s| &s.points)
        .filter(|q| drawable(q, p.log_y) && q.0 >= x0 && q.0 <= x1)
        .map(|q| q.1)
        .collect();
    if ys.is_empty() {
        return (0.0, 1.0);
    }
    ys.sort_by(f64::total_cmp);
    let mut b = (ys[0], ys[ys.len() - 1]);
    if p.robust && !p.log_y {
        let q = |f: f64| ys[((ys.len() - 1) as f64 * f).round() as usize];
        let (lo, hi) = (q(0.005), q(0.995));
        // Only when the outliers would take most of the panel.
        if b.1 - b.0 > 2.0 * (hi - lo) {
            let pad = 0.25 * (hi - lo);
            b = ((lo - pad).max(b.0), (hi + pad).min(b.1));
        }
    }
    if b.1 <= b.0 {
        let m = b.0.abs().max(1.0) * 1e-3;
        b = (b.0 - m, b.1 + m);
    }
    if p.log_y {
        // Whole decades, so the axis has a labelled tick at each end.
        let (lo, hi) = (
            b.0.log10().floor(),
            b.1.log10().ceil().max(b.0.log10().floor() + 1.0),
        );
        (10f64.powf(lo), 10f64.powf(hi + headroom))
    } else {
        let pad = 0.05 * (b.1 - b.0);
        (b.0 - pad, b.1 + pad + headroom * (b.1 - b.0))
    }
}

/// Whether a point can be drawn: finite, and positive on a log scale.
fn drawable(p: &(f64, f64), log_y: bool) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0)
}

/// A line chart written to `path` (SVG, and a PNG beside it). `log_y` plots y on a log
/// scale.
pub fn line_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    markers: &[Marker],
    log_y: bool,
) -> Result<Figure, String> {
    let panel = Panel {
        log_y,
        ..Panel::new(y_label, series).markers(markers)
    };
    stacked_chart(title, x_label, &[panel])
}

/// Panels stacked over one x axis, rendered.
pub fn stacked_chart(title: &str, x_label: &str, panels: &[Panel]) -> Result<Figure, String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let (x0, x1) = x_bounds(panels);
    let span_ok = |s: f64| s.is_finite() && s <= MAX_SPAN;
    for p in panels {
        let (y0, y1) = y_bounds(p, x0, x1, 0.0);
        if !(span_ok(x1 - x0) && span_ok(y1 - y0)) {
            return Err(err(&format_args!(
                "the data span {:e} by {:e}, too wide to draw",
                x1 - x0,
                y1 - y0
            )));
        }
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let body = root
            .titled(title, ("sans-serif", 20))
            .map_err(|e| err(&e))?;
        let total: u32 = panels.iter().map(|p| p.weight.max(1)).sum();
        let height = body.dim_in_pixel().1 as f64;
        let mut breaks = Vec::new();
        let mut acc = 0;
        for p in &panels[..panels.len().saturating_sub(1)] {
            acc += p.weight.max(1);
            breaks.push((height * f64::from(acc) / f64::from(total)) as i32);
        }
        let areas = body.split_by_breakpoints(Vec::<i32>::new(), breaks);
        for (k, (p, area)) in panels.iter().zip(&areas).enumerate() {
            let last = k + 1 == panels.len();
            draw_panel(area, p, (x0, x1), if last { x_label } else { "" }, last)
                .map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    let png = png::render(&svg)?;
    Ok(Figure { svg, png })
}

/// Rows of marker labels: for each marker (in x order) its row, so that no label overlaps
/// another in its row; `px` maps x to pixels, `right` is the plot's right edge. Returns
/// (marker index, row, left pixel of the label).
fn label_rows(markers: &[Marker], px: impl Fn(f64) -> i32, right: i32) -> Vec<(usize, i32, i32)> {
    let mut order: Vec<usize> = (0..markers.len()).collect();
    order.sort_by(|a, b| markers[*a].x.total_cmp(&markers[*b].x));
    let mut row_ends: Vec<i32> = Vec::new();
    let mut out = Vec::new();
    for k in order {
        let m = &markers[k];
        let width = (m.label.chars().count() as f64 * LABEL_CHAR_PX).ceil() as i32;
        let at = px(m.x);
        // Right of the line, or left of it where the plot ends.
        let left = if at + 3 + width <= right {
            at + 3
        } else {
            at - 3 - width
        };
        let row = match row_ends.iter().position(|end| *end + 6 <= left) {
            Some(r) => r,
            None => {
                row_ends.push(i32::MIN);
                row_ends.len() - 1
            }
        };
        row_ends[row] = left + width;
        out.push((k, row as i32, left));
    }
    out
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
    (x0, x1): (f64, f64),
    x_label: &str,
    last: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    // Room for the marker labels' rows above the data: estimated from a first layout at
    // the panel's width.
    let width = f64::from(area.dim_in_pixel().0.saturating_sub(100)).max(1.0);
    let visible: Vec<&Marker> = p
        .markers
        .iter()
        .filter(|m| m.x >= x0 && m.x <= x1)
        .collect();
    let probe: Vec<Marker> = visible
        .iter()
        .map(|m| Marker {
            x: m.x,
            label: m.label,
        })
        .collect();
    let rows = label_rows(
        &probe,
        |x| ((x - x0) / (x1 - x0) * width) as i32,
        width as i32,
    )
    .iter()
    .map(|r| r.1 + 1)
    .max()
    .unwrap_or(0);
    let plot_px = f64::from(area.dim_in_pixel().1.saturating_sub(60)).max(1.0);
    let share = (f64::from(rows * LABEL_ROW_PX + 4) / plot_px).min(0.6);
    let (y0, y1) = if rows == 0 {
        y_bounds(p, x0, x1, 0.0)
    } else if p.log_y {
        let (a, b) = y_bounds(p, x0, x1, 0.0);
        let decades = (b / a).log10().max(0.1);
        y_bounds(p, x0, x1, decades * share / (1.0 - share))
    } else {
        y_bounds(p, x0, x1, share / (1.0 - share))
    };
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(10)
        .x_label_area_size(if last { 40 } else { 22 })
        .y_label_area_size(80);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(p.y_label)
                .draw()?;
            for (i, s) in p.series.iter().enumerate() {
                let c = match (p.measured_first, i) {
                    (true, 0) => MEASURED,
                    (true, _) => COLOURS[(i - 1) % COLOURS.len()],
                    _ => COLOURS[i % COLOURS.len()],
                };
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|q| drawable(q, p.log_y))
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts, c.stroke_width(1)))?
                    .label(s.name)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c));
            }
            for m in &visible {
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(m.x, y0), (m.x, y1)],
                    BLACK.mix(0.35),
                )))?;
            }
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            let origin = (xr.start, yr.start);
            let px = |x: f64| chart.backend_coord(&(x, y0)).0;
            for (k, row, left) in label_rows(&probe, px, xr.end) {
                let y = origin.1 + 3 + row * LABEL_ROW_PX;
                area.draw(&Text::new(
                    probe[k].label.to_string(),
                    (left - area.get_base_pixel().0, y - area.get_base_pixel().1),
                    ("sans-serif", LABEL_FONT),
                ))?;
            }
            let _ = origin;
            if p.series.len() > 1 {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::LowerRight)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()?;
            }
        }};
    }
    if p.log_y {
        draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?);
    } else {
        draw!(builder.build_cartesian_2d(x0..x1, y0..y1)?);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extreme_and_non_finite_points_end_quickly() {
        let wild = Series {
            name: "wild",
            points: vec![
                (0.0, 1e308),
                (1.0, -1e308),
                (2.0, f64::NAN),
                (3.0, f64::INFINITY),
            ],
        };
        let e = line_chart("t", "x", "y", &[wild], &[], false)
            .err()
            .unwrap();
        assert!(e.contains("too wide"), "{e}");
        let tame = Series {
            name: "tame",
            points: vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)],
        };
        let f = line_chart("t", "x", "y", &[tame], &[], false).unwrap();
        assert!(f.svg.starts_with("<svg"), "{}", &f.svg[..40]);
        // The PNG: a PNG signature and the SVG's size in its header.
        let png = f.png;
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
        let h = u32::from_be_bytes(png[20..24].try_into().unwrap());
        assert_eq!((w, h), SIZE);
    }

    #[test]
    fn close_marker_labels_take_separate_rows() {
        // Labels 70 px wide at 10 px from each other cannot share a row; one far away can.
        let m = |x: f64, label| Marker { x, label };
        let markers = [
            m(10.0, "ten chars."),
            m(20.0, "ten chars."),
            m(30.0, "ten chars."),
            m(500.0, "ten chars."),
        ];
        let rows = label_rows(&markers, |x| x as i32, 1000);
        let row_of = |k: usize| rows.iter().find(|r| r.0 == k).unwrap().1;
        assert_eq!([row_of(0), row_of(1), row_of(2)], [0, 1, 2]);
        assert_eq!(row_of(3), 0);
        // Within a row no two labels overlap.
        for a in &rows {
            for b in &rows {
                if a.0 < b.0 && a.1 == b.1 {
                    assert!((a.2 - b.2).abs() >= 70, "{a:?} {b:?}");
                }
            }
        }
        // At the right edge a label goes left of its line.
        let edge = label_rows(&[m(995.0, "ten chars.")], |x| x as i32, 1000);
        assert!(edge[0].2 + 70 <= 995, "{edge:?}");
    }
}
