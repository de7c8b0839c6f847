//! The terminal view of `eha watch` (ratatui on crossterm): a status block (source, time,
//! the drive's mode and latched fault by the firmware's names, the counts, the log), the
//! pulsation over the last second, then one panel of rolling traces per signal group, each
//! trace drawn as its envelope (minimum and maximum per screen column, so a pulsation too
//! fast for the screen still shows its band). Keys are read from the terminal itself, so
//! the stream can come on standard input.

use super::running::{Stream, Watch};
use super::session::{Pulsation, Session};
use crate::output::{interrupt, CliError};
use firmware::TelemetryFrame;
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType, Paragraph};
use ratatui::Frame;
use std::time::Duration;

/// How long the view waits for lines between two drawings (about 20 per second).
const FRAME: Duration = Duration::from_millis(50);
/// Trace colours, in panel order.
const COLOURS: [Color; 4] = [Color::Cyan, Color::Yellow, Color::Magenta, Color::Green];

/// Runs the view until the user quits (q, Esc, Ctrl-C) or a signal asks to stop.
pub fn run(watch: &mut Watch, panels: &[Vec<&'static str>]) -> Result<(), CliError> {
    let mut terminal = ratatui::try_init()
        .map_err(|e| CliError::Failed(format!("cannot start the terminal view: {e}")))?;
    let result = (|| loop {
        watch.pump(FRAME)?;
        terminal
            .draw(|f| draw(f, watch, panels))
            .map_err(|e| CliError::Failed(format!("terminal: {e}")))?;
        if quit_pressed()? || interrupt::stop_requested() {
            return Ok(());
        }
    })();
    ratatui::restore();
    result
}

/// Takes the keys waiting; true when one of them quits.
fn quit_pressed() -> Result<bool, CliError> {
    let failed = |e: std::io::Error| CliError::Failed(format!("terminal: {e}"));
    while event::poll(Duration::ZERO).map_err(failed)? {
        if let Event::Key(k) = event::read().map_err(failed)? {
            let ctrl_c =
                k.code == KeyCode::Char('c') && k.modifiers.contains(KeyModifiers::CONTROL);
            if k.kind == KeyEventKind::Press
                && (ctrl_c || matches!(k.code, KeyCode::Char('q') | KeyCode::Esc))
            {
                return Ok(true);
            }
        }
    }
    Ok(false)
}

/// Draws the whole screen.
pub fn draw(f: &mut Frame, watch: &Watch, panels: &[Vec<&'static str>]) {
    let mut rows = vec![Constraint::Length(5), Constraint::Length(1)];
    rows.extend(panels.iter().map(|_| Constraint::Fill(1)));
    let areas = Layout::vertical(rows).split(f.area());
    f.render_widget(status(watch), areas[0]);
    f.render_widget(Paragraph::new(pulsation_line(&watch.session)), areas[1]);
    for (panel, area) in panels.iter().zip(areas.iter().skip(2)) {
        draw_panel(f, &watch.session, panel, *area);
    }
}

/// The status block: what, where, mode, fault, counts, log.
fn status(watch: &Watch) -> Paragraph<'static> {
    let s = &watch.session;
    let bold = Style::default().add_modifier(Modifier::BOLD);
    let mode = s.mode().map_or("—", firmware::Mode::name);
    let fault = match s.fault() {
        Some(fc) => Span::styled(fc.to_string(), bold.fg(Color::Red)),
        None => Span::styled("none", Style::default().fg(Color::Green)),
    };
    let t = s
        .latest()
        .map_or("—".to_string(), |f| format!("{:.3} s", f.t_s));
    let stream = match watch.stream {
        Stream::Open => "reading".to_string(),
        Stream::Ended => match &watch.failure {
            Some(why) => format!("stream failed: {why}"),
            None => "stream ended".to_string(),
        },
    };
    let line1 = Line::from(vec![
        Span::styled("mode ", bold),
        Span::raw(format!("{mode}   ")),
        Span::styled("fault ", bold),
        fault,
        Span::raw(format!("   t {t}   {stream}")),
    ]);
    let mut counts = format!(
        "frames {}   other lines {}   malformed {}",
        s.frames, s.skipped, s.malformed
    );
    if let Some((line, what)) = &s.first_malformed {
        counts.push_str(&format!(" (first: line {line}, {what})"));
    }
    if s.resets > 0 {
        counts.push_str(&format!("   controller resets {}", s.resets));
    }
    let log = match (watch.open_log(), &watch.log_result) {
        (Some(l), _) => format!("log {}: {} rows, writing", l.path().display(), l.rows()),
        (None, Some(Ok((p, n)))) => format!("log {}: {n} rows, written", p.display()),
        (None, Some(Err(why))) => why.clone(),
        (None, None) => "no log (--out LOG.csv writes one)".to_string(),
    };
    let title = format!(" eha watch — {} — q quits ", watch.source.name());
    Paragraph::new(vec![line1, Line::raw(counts), Line::raw(log)])
        .block(Block::bordered().title(title))
}

/// The pulsation over the last second, in words.
fn pulsation_line(s: &Session) -> Line<'static> {
    let Some(p) = s.pulsation() else {
        return Line::raw(" pulsation (last 1 s): waiting for a second of telemetry");
    };
    Line::from(vec![
        Span::styled(
            " pulsation (last 1 s) ",
            Style::default().add_modifier(Modifier::BOLD),
        ),
        Span::raw(describe(&p)),
    ])
}

/// `12.3 kPa p-p; dominant 36.0 Hz = order 18.0 (piston ripple) at 2.00 rev/s`.
pub fn describe(p: &Pulsation) -> String {
    let mut text = format!("{:.2} kPa p-p", p.peak_to_peak_pa / 1e3);
    match (p.line, p.order()) {
        (Some((f, a)), Some(order)) => {
            text.push_str(&format!(
                "; dominant {f:.1} Hz ({:.2} kPa) = order {order:.1}",
                a / 1e3
            ));
            if let Some(src) = p.source {
                text.push_str(&format!(" ({})", src.cause));
            }
            text.push_str(&format!(" at {:.2} rev/s", p.shaft_rev_per_s));
        }
        (Some((f, a)), None) => {
            text.push_str(&format!(
                "; dominant {f:.1} Hz ({:.2} kPa), shaft at rest",
                a / 1e3
            ));
        }
        _ => {}
    }
    text
}

/// The value of a telemetry column in a frame.
pub fn value(f: &TelemetryFrame, name: &str) -> f64 {
    let k = firmware::telemetry::COLUMNS
        .iter()
        .position(|c| *c == name)
        .unwrap_or(0);
    crate::ingest::frame_values(f)[k]
}

/// The unit a column's name ends in, and the scale it is shown at.
fn shown_unit(name: &str) -> (&'static str, f64) {
    match name.rsplit('_').next() {
        Some("pa") => ("MPa", 1e-6),
        Some("s") => ("rad/s", 1.0),
        Some("rad") => ("rad", 1.0),
        Some("a") => ("A", 1.0),
        Some("v") => ("V", 1.0),
        _ => ("", 1.0),
    }
}

/// One panel: the signals' envelopes over the window.
fn draw_panel(f: &mut Frame, s: &Session, names: &[&'static str], area: Rect) {
    let window = s.window();
    let (Some(first), Some(last)) = (window.front(), window.back()) else {
        f.render_widget(
            Block::bordered().title(format!(" {} ", names.join(" + "))),
            area,
        );
        return;
    };
    // The window rolls once it is full; until then it spans what has arrived.
    let t1 = last.t_s;
    let t0 = (t1 - s.window_s()).max(first.t_s);
    let columns = usize::from(area.width.saturating_sub(10)).max(10);
    let traces: Vec<Vec<(f64, f64)>> = names
        .iter()
        .map(|n| {
            let scale = shown_unit(n).1;
            envelope(
                window.iter().map(|fr| (fr.t_s, value(fr, n) * scale)),
                t0,
                t1,
                columns,
            )
        })
        .collect();
    let (lo, hi) = bounds(traces.iter().flatten().map(|p| p.1));
    let unit = shown_unit(names[0]).0;
    let latest: Vec<String> = names
        .iter()
        .map(|n| format!("{n} {:.4}", value(last, n) * shown_unit(n).1))
        .collect();
    let datasets: Vec<Dataset> = traces
        .iter()
        .zip(names)
        .enumerate()
        .map(|(k, (pts, n))| {
            Dataset::default()
                .name(*n)
                .marker(Marker::Braille)
                .graph_type(GraphType::Scatter)
                .style(Style::default().fg(COLOURS[k % COLOURS.len()]))
                .data(pts)
        })
        .collect();
    let x_axis = Axis::default()
        .bounds([t0, t1])
        .labels([format!("{t0:.1} s"), format!("{t1:.1} s")]);
    let y_axis = Axis::default()
        .bounds([lo, hi])
        .labels([format!("{lo:.3}"), format!("{hi:.3}")]);
    let chart = Chart::new(datasets)
        .block(Block::bordered().title(format!(" [{unit}]  {} ", latest.join("   "))))
        .x_axis(x_axis)
        .y_axis(y_axis);
    f.render_widget(chart, area);
}

/// The minimum and maximum of `points` per column of `columns` over [t0, t1].
pub fn envelope(
    points: impl Iterator<Item = (f64, f64)>,
    t0: f64,
    t1: f64,
    columns: usize,
) -> Vec<(f64, f64)> {
    let width = (t1 - t0).max(f64::MIN_POSITIVE);
    let mut lo = vec![f64::INFINITY; columns];
    let mut hi = vec![f64::NEG_INFINITY; columns];
    for (t, v) in points {
        if t < t0 || !v.is_finite() {
            continue;
        }
        let k = (((t - t0) / width) * columns as f64) as usize;
        let k = k.min(columns - 1);
        lo[k] = lo[k].min(v);
        hi[k] = hi[k].max(v);
    }
    let dt = width / columns as f64;
    let mut out = Vec::with_capacity(2 * columns);
    for k in 0..columns {
        if lo[k] <= hi[k] {
            let t = t0 + (k as f64 + 0.5) * dt;
            out.push((t, lo[k]));
            if hi[k] > lo[k] {
                out.push((t, hi[k]));
            }
        }
    }
    out
}

/// The y range of the values, widened a little (and around a constant).
fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05)
        .max(hi.abs().max(lo.abs()) * 1e-6)
        .max(1e-9);
    (lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_envelope_keeps_a_fast_ripples_band() {
        // 1000 samples of a ±1 ripple much faster than 10 columns: every column spans it.
        let pts = (0..1000).map(|i| (i as f64 * 1e-3, if i % 2 == 0 { 1.0 } else { -1.0 }));
        let e = envelope(pts, 0.0, 1.0, 10);
        assert_eq!(e.len(), 20);
        assert!(e.chunks(2).all(|c| c[0].1 == -1.0 && c[1].1 == 1.0));
    }
}
