//! `eha diagnose --report DIR`: a short markdown report with SVG plots — measured against
//! simulated before and after the extension on the leading cause's signals, the residual
//! order spectra with the candidates' orders marked, and the ranking with its evidence.
//!
//! The folder is one output of the command's transaction ([`crate::output::Outputs`]): its
//! files are written into a staging folder that replaces DIR whole at the end, so a
//! failure leaves DIR as it was and no file of an earlier log stays beside the new ones.

use super::diagnosis::Diagnosis;
use super::findings::Analysis;
use super::spectrum::OrderSpectrum;
use crate::output::{CliError, StagedFolder};
use crate::plots::{line_chart, png, stacked_chart, Figure, Marker, Panel, Series};
use std::fmt::Write as _;
use std::path::Path;

/// The files a report folder holds.
pub const FILES: &[&str] = &[
    "report.md",
    "trace_*.svg",
    "trace_*.png",
    "residual_spectrum_*.svg",
    "residual_spectrum_*.png",
];

/// The points of a trace (the analysis keeps at most about
/// [`super::findings::TRACE_POINTS`] rows of each, so the SVG stays small on long logs).
fn decimated(t: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    t.iter().zip(y).map(|(a, b)| (*a, *b)).collect()
}

/// Links a figure in the report (its PNG, readable in any viewer, and the SVG).
fn figure(md: &mut String, what: &str, svg: &str) {
    let png = png::beside(Path::new(svg)).display().to_string();
    let _ = writeln!(md, "![{what}]({png}) ([SVG]({svg}))\n");
}

/// A signal's figure: measured, nominal and extended model above; beneath, on its own
/// scale, the residual of each model (measured − model). `[y, b, e]` are the measured,
/// nominal and extended series over `t`; the validation segment starts at `t_val`.
fn trace_figure(
    signal: &str,
    t: &[f64],
    [y, b, e]: [&Vec<f64>; 3],
    t_val: f64,
) -> Result<Figure, String> {
    // Pressures read in MPa: a 5 MPa axis in pascals is seven digits a tick.
    let (scale, unit) = display_unit(unit_of(signal));
    let shown = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| x * scale).collect() };
    let (y, b, e) = (&shown(y), &shown(b), &shown(e));
    let residual = |m: &[f64]| -> Vec<f64> { y.iter().zip(m).map(|(y, m)| y - m).collect() };
    let traces = [
        Series {
            name: "measured",
            points: decimated(t, y),
        },
        Series {
            name: "nominal model",
            points: decimated(t, b),
        },
        Series {
            name: "extended model",
            points: decimated(t, e),
        },
    ];
    let residuals = [
        Series {
            name: "measured - nominal",
            points: decimated(t, &residual(b)),
        },
        Series {
            name: "measured - extended",
            points: decimated(t, &residual(e)),
        },
    ];
    let validation = [Marker {
        x: t_val,
        label: "validation →",
    }];
    let signal_label = format!("{signal} [{unit}]");
    let residual_label = format!("residual [{unit}]");
    stacked_chart(
        &format!("{signal}: measured, nominal model, extended model; the residuals beneath"),
        "t [s]",
        &[
            Panel::new(&signal_label, &traces)
                .markers(&validation)
                .weight(3)
                .robust()
                .measured_first(),
            Panel::new(&residual_label, &residuals).weight(2).robust(),
        ],
    )
}

/// The scale and unit a figure shows a signal of `unit` in: pascals as megapascals.
fn display_unit(unit: &'static str) -> (f64, &'static str) {
    match unit {
        "Pa" => (1e-6, "MPa"),
        u => (1.0, u),
    }
}

/// The unit a bench-log column's name ends in.
fn unit_of(signal: &str) -> &'static str {
    crate::bench_log::Signal::from_name(signal)
        .map_or("", |s| crate::bench_log::limits::physical_range(s).2)
}

fn failed(what: &str, e: impl std::fmt::Display) -> CliError {
    CliError::Failed(format!("report: {what}: {e}"))
}

/// Writes the report of `analysis` (of the log at `log_path`) into the staged folder `d`:
/// the markdown's sections in order, the figures they link, then `report.md`.
pub fn write_report(out: &StagedFolder, log_path: &Path, a: &Analysis) -> Result<(), CliError> {
    let mut md = String::new();
    summary_section(&mut md, log_path, &a.diagnosis);
    ranking_section(&mut md, &a.diagnosis);
    contributions_section(&mut md, a);
    signatures_section(&mut md, a);
    trace_section(out, &mut md, a)?;
    spectrum_section(out, &mut md, a)?;
    out.file("report.md", md.as_bytes())
}

/// The title, what is named and each named cause with its evidence, the segments, the
/// per-signal fit table (baseline against extended, on the validation segment) and the
/// pressure RMSE.
fn summary_section(md: &mut String, log_path: &Path, d: &Diagnosis) {
    let _ = writeln!(md, "# Diagnosis of `{}`\n", log_path.display());
    let _ = writeln!(md, "**Named: `{}`**\n", d.named_label());
    for c in d.named_causes() {
        let _ = writeln!(md, "- **Cause: `{}`** — {}", c.effect, c.evidence_in_full());
    }
    let _ = writeln!(
        md,
        "\n{} samples; identification segment {:.3}–{:.3} s (the fit), \
         validation segment {:.3}–{:.3} s (the scores below; the fit never saw it).\n",
        d.samples,
        d.identification_segment_s[0],
        d.identification_segment_s[1],
        d.validation_segment_s[0],
        d.validation_segment_s[1]
    );
    let _ = writeln!(
        md,
        "| signal | residual/noise, baseline | residual/noise, extended | baseline fit [%] | extended fit [%] |\n|---|---|---|---|---|"
    );
    let f = |m: &std::collections::BTreeMap<String, f64>, s: &str| {
        m.get(s).map_or("—".to_string(), |v| format!("{v:.2}"))
    };
    for s in d.baseline.fit_percent_by_signal.keys() {
        let _ = writeln!(
            md,
            "| `{s}` | {} | {} | {} | {} |",
            f(&d.baseline.noise_ratio_by_signal, s),
            f(&d.extended.noise_ratio_by_signal, s),
            f(&d.baseline.fit_percent_by_signal, s),
            f(&d.extended.fit_percent_by_signal, s)
        );
    }
    let _ = writeln!(
        md,
        "\nPressure RMSE: {:.0} Pa → {:.0} Pa ({:+.1} % reduction).\n",
        d.baseline.rmse_pa, d.extended.rmse_pa, d.gain.rmse_reduction_percent
    );
}

/// The ranking: every cause with its score, fitted parameters and evidence.
fn ranking_section(md: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        md,
        "## Ranking\n\n| rank | effect | score | parameters | evidence |\n|---|---|---|---|---|"
    );
    for (k, c) in d.causes.iter().enumerate() {
        let params: Vec<String> = c
            .parameters
            .iter()
            .map(|(n, v)| format!("{n} = {}", super::candidates::short(*v)))
            .collect();
        let _ = writeln!(
            md,
            "| {} | `{}` | {:.3} | {} | {} |",
            k + 1,
            c.effect,
            c.score,
            params.join(", "),
            c.evidence
        );
    }
}

/// Each named effect's fit points gained per signal as it joins the model.
fn contributions_section(md: &mut String, a: &Analysis) {
    let Some((_, first)) = a.contributions.first() else {
        return;
    };
    let signals: Vec<&String> = first.keys().collect();
    let _ = writeln!(
        md,
        "## Contributions\n\nFit points on the validation segment each named effect gains \
         per signal as it joins the model, the strongest first (the last row ends at the \
         extended model).\n\n| effect | {} |\n|---|{}",
        signals
            .iter()
            .map(|s| format!("`{s}`"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(signals.len())
    );
    for (effect, gained) in &a.contributions {
        let cells: Vec<String> = signals
            .iter()
            .map(|s| gained.get(*s).map_or("—".into(), |g| format!("{g:+.1}")))
            .collect();
        let _ = writeln!(md, "| `{effect}` | {} |", cells.join(" | "));
    }
    md.push('\n');
}

/// The baseline residuals' time-domain signatures, when there are any.
fn signatures_section(md: &mut String, a: &Analysis) {
    if a.signatures.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Residual signatures (baseline, measured − simulated)\n\n\
         | signal | RMS | Ljung–Box Q ({} lags) | p (white) | corr. speed | corr. pressure | \
         corr. q current | lag [ms] | standstill / running RMS |\n|---|---|---|---|---|---|---|---|---|",
        super::signatures::WHITENESS_LAGS
    );
    for g in &a.signatures {
        let _ = writeln!(
            md,
            "| `{}` | {:.4e} | {:.0} | {:.3} | {:+.2} | {:+.2} | {:+.2} | {:.1} | {} |",
            g.signal,
            g.rms,
            g.ljung_box_q,
            g.white_p,
            g.corr_speed,
            g.corr_pressure,
            g.corr_current,
            1e3 * g.lag_s,
            g.standstill_ratio
                .map_or("—".to_string(), |k| format!("{k:.2}"))
        );
    }
}

/// One trace figure ([`trace_figure`]) per predicted signal that was also measured,
/// written into `d` and linked from the report.
fn trace_section(d: &StagedFolder, md: &mut String, a: &Analysis) -> Result<(), CliError> {
    let signals: Vec<&'static str> = a.baseline.keys().copied().collect();
    let _ = writeln!(md, "\n## Measured and simulated\n");
    for s in signals {
        let (Some(y), Some(b), Some(e)) = (a.measured.get(s), a.baseline.get(s), a.extended.get(s))
        else {
            continue;
        };
        let file = format!("trace_{s}.svg");
        trace_figure(s, &a.t_s, [y, b, e], a.diagnosis.validation_segment_s[0])
            .map_err(|e| failed(&file, e))?
            .write_into(d, &file)?;
        figure(md, s, &file);
    }
    Ok(())
}

/// One residual order spectrum figure per spectrum of the analysis, the candidates'
/// orders marked, written into `d` and linked from the report.
fn spectrum_section(d: &StagedFolder, md: &mut String, a: &Analysis) -> Result<(), CliError> {
    let _ = writeln!(md, "## Residual order spectra (nominal model)\n");
    let labels: Vec<String> = a
        .candidate_orders
        .iter()
        .map(|(k, name)| format!("{k}: {name}"))
        .collect();
    let markers: Vec<Marker> = a
        .candidate_orders
        .iter()
        .zip(&labels)
        .map(|((k, _), l)| Marker {
            x: *k as f64,
            label: l,
        })
        .collect();
    for (s, spec) in &a.spectra {
        let file = format!("residual_spectrum_{s}.svg");
        spectrum_figure(s, spec, &markers)
            .map_err(|e| failed(&file, e))?
            .write_into(d, &file)?;
        figure(md, &format!("{s} residual spectrum"), &file);
    }
    Ok(())
}

/// A residual's order spectrum over orders 1–200 with `markers` at the candidates' orders.
fn spectrum_figure(
    signal: &str,
    spec: &OrderSpectrum,
    markers: &[Marker<'_>],
) -> Result<Figure, String> {
    let points: Vec<(f64, f64)> = spec
        .amplitude
        .iter()
        .enumerate()
        .skip(1)
        .take(200)
        .map(|(k, v)| (k as f64, *v))
        .collect();
    line_chart(
        &format!(
            "{signal} residual against shaft angle ({} revolutions)",
            spec.revolutions
        ),
        "order [cycles per revolution]",
        "amplitude",
        &[Series {
            name: "residual",
            points,
        }],
        markers,
        true,
    )
}

#[cfg(test)]
mod tests {
    use super::super::candidates::short;

    #[test]
    fn small_and_large_parameters_keep_their_digits_in_the_ranking() {
        // A dead time of about a microsecond and a leakage of 1e-13 m³/(s·Pa) were printed
        // as 0.0000 with four decimals; a count of pistons as 9.0000.
        assert_eq!(short(1.063e-6), "1.063e-6");
        assert_eq!(short(9.886e-13), "9.886e-13");
        assert_eq!(short(4.599e6), "4.599e6");
        assert_eq!(short(0.0397), "0.0397");
        assert_eq!(short(-3.0364), "-3.0364");
        assert_eq!(short(72.0), "72");
        assert_eq!(short(0.0), "0");
    }
}
