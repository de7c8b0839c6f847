//! Stages 6 and 7 of the diagnosis: the baseline's and the extended model's scores on
//! the validation segment, the evidence for the report (residual signatures, order
//! spectra) and the contract's result, the causes ranked with why each was or was not named.

use super::angle_locked::ShaftConstants;
use super::calibration::{Calibration, Relation, Release};
use super::candidates::{Extension, Tested};
use super::decision::{threshold, why_not};
use super::diagnosis::{Cause, Diagnosis, Extended, Fit, Gain};
use super::facts::LogFacts;
use super::findings::{trace_step, traced, traced_all, Analysis};
use super::mechanical::{LineScale, TorqueLine};
use super::predictions::{predict_each, scores, Context, ModelValues};
use super::relations::{Calibrations, Relations};
use super::signatures::{residual_signature, Regressors, ResidualSignature};
use super::spectrum::order_spectrum;
use crate::bench_log::BenchLog;
use plant_model::pump::ripple_order;
use plant_model::Rig;
use std::collections::BTreeMap;
use std::ops::Range;

/// What the predictions left for the evidence: the baseline's whole-log predictions, both
/// models' scores, the extended model's trace and the calibrated values by relation.
pub(super) struct Scored {
    /// Baseline predictions by signal, whole log.
    pub baseline: BTreeMap<&'static str, Vec<f64>>,
    /// The baseline's scores on the validation segment.
    pub base_fit: Fit,
    /// The extended model's scores on the validation segment.
    pub ext_fit: Fit,
    /// The extended model's predictions at the traced rows ([`trace_step`]).
    pub ext_trace: BTreeMap<&'static str, Vec<f64>>,
    /// Each relation's calibrated parameters by name.
    pub calibration: BTreeMap<String, BTreeMap<String, f64>>,
}

/// Stage 7: the evidence for the report (signatures and order spectra of the baseline's
/// residuals, the traces) and the contract's result.
pub(super) fn assemble(
    log: &BenchLog,
    facts: &LogFacts,
    rig: &Rig,
    cal: &Calibrations,
    tested: Vec<Tested>,
    named: Vec<usize>,
    scored: Scored,
) -> Analysis {
    let Scored {
        baseline,
        base_fit,
        ext_fit,
        ext_trace,
        calibration,
    } = scored;
    let signatures = residual_signatures(log, facts, &baseline);
    let spectra = ["p_pa", "speed_rad_s", "iq_a"]
        .iter()
        .filter_map(|name| {
            let y = log.column(crate::bench_log::Signal::from_name(name)?)?;
            let r = super::fit_score::residual(y, baseline.get(name)?);
            Some((*name, order_spectrum(&facts.theta_rad, &r)?))
        })
        .collect();
    let step = trace_step(facts.rows);
    let measured: BTreeMap<&'static str, Vec<f64>> = baseline
        .keys()
        .filter_map(|k| {
            let s = crate::bench_log::Signal::from_name(k)?;
            Some((*k, traced(log.column(s)?, step)))
        })
        .collect();
    let baseline = traced_all(&baseline, step);
    let (hcal, mcal) = (&cal.hydraulic, &cal.mechanical);
    let causes = causes(&tested, &named, &calibration_summary(hcal, mcal, facts));
    let named_effects: Vec<String> = named
        .iter()
        .map(|&i| tested[i].effect.to_string())
        .collect();
    let mut order_idx: Vec<usize> = (0..tested.len()).collect();
    order_idx
        .sort_by(|a, b| rank_key(&tested, &named, *b).total_cmp(&rank_key(&tested, &named, *a)));
    let tested: Vec<Tested> = order_idx.into_iter().map(|i| tested[i].clone()).collect();
    let t = &log.t_s;
    let n = facts.rows;
    let diagnosis = Diagnosis {
        samples: n,
        identification_segment_s: [t[0], t[facts.split - 1]],
        validation_segment_s: [t[facts.split], t[n - 1]],
        gain: Gain {
            fit_points: ext_fit.fit_percent - base_fit.fit_percent,
            rmse_reduction_percent: 100.0 * (1.0 - ext_fit.rmse_pa / base_fit.rmse_pa),
        },
        causes,
        calibration,
        extended: Extended {
            effects: named_effects,
            fit_percent: ext_fit.fit_percent,
            rmse_pa: ext_fit.rmse_pa,
            fit_percent_by_signal: ext_fit.fit_percent_by_signal,
            noise_ratio_by_signal: ext_fit.noise_ratio_by_signal,
        },
        baseline: base_fit,
    };
    Analysis {
        diagnosis,
        t_s: traced(t, step),
        measured,
        baseline,
        extended: ext_trace,
        spectra,
        signatures,
        candidate_orders: candidate_orders(rig),
        tested,
        contributions: Vec::new(),
    }
}

/// Each relation's calibrated parameters by name, for the JSON.
pub(super) fn calibration_values(
    rel: &Relations<'_>,
    cal: &Calibrations,
) -> BTreeMap<String, BTreeMap<String, f64>> {
    [
        (
            "hydraulic",
            Some((&cal.hydraulic, rel.hydraulic.specs(Release::Nothing))),
        ),
        (
            "mechanical",
            Some((&cal.mechanical, rel.mechanical.specs(Release::Nothing))),
        ),
        (
            "electrical",
            cal.electrical
                .as_ref()
                .zip(rel.electrical.as_ref().map(|r| r.specs(Release::Nothing))),
        ),
        (
            "cylinder",
            cal.cylinder
                .as_ref()
                .zip(rel.cylinder.as_ref().map(|r| r.specs(Release::Nothing))),
        ),
    ]
    .into_iter()
    .filter_map(|(name, c)| {
        let (cal, specs) = c?;
        Some((
            name.to_string(),
            specs
                .iter()
                .zip(&cal.fitted.values)
                .map(|(s, v)| (s.name.to_string(), *v))
                .collect(),
        ))
    })
    .collect()
}

/// The sort key that ranks the tested effects: the named ones first, in their order, then
/// by Λ over its threshold.
fn rank_key(tested: &[Tested], named: &[usize], i: usize) -> f64 {
    if let Some(k) = named.iter().position(|&j| j == i) {
        return f64::MAX - k as f64 * 1e300;
    }
    tested[i].lambda / threshold(tested[i].dof)
}

/// A line on the calibrated nominal model for `none`'s evidence.
fn calibration_summary(h: &Calibration, m: &Calibration, facts: &LogFacts) -> String {
    let unseen = if facts.piston_unseen {
        " (the piston moves and x_m is not logged: the hydraulic effects were not tested)"
    } else {
        ""
    };
    format!(
        "the nominal model calibrated within its tolerances (hydraulic relation: residual \
         variance {:.1}× the noise per independent sample; mechanical: {:.1}×) leaves nothing \
         an effect of the catalogue explains significantly beyond its tolerance band{unseen}",
        h.scale, m.scale
    )
}

/// The contract's ranked causes: the named effects (or `none`) first, then every other
/// effect once, by strength, each with why it was not named.
fn causes(tested: &[Tested], named: &[usize], none_why: &str) -> Vec<Cause> {
    let cause = |t: &Tested, note: Option<String>| Cause {
        effect: t.effect.to_string(),
        score: t.lambda,
        parameters: t
            .parameters
            .iter()
            .map(|(k, v)| (k.to_string(), *v))
            .collect(),
        standard_errors: t
            .standard_errors
            .iter()
            .map(|(k, v)| (k.to_string(), *v))
            .collect(),
        evidence: match note {
            Some(n) => format!("{}; {n}", t.evidence),
            None => t.evidence.clone(),
        },
        ambiguous_with: t.ambiguous_with.iter().map(|s| s.to_string()).collect(),
    };
    let none = |score: f64, why: String| Cause {
        effect: "none".into(),
        score,
        parameters: BTreeMap::new(),
        standard_errors: BTreeMap::new(),
        evidence: why,
        ambiguous_with: Vec::new(),
    };
    let mut out: Vec<Cause> = named.iter().map(|&i| cause(&tested[i], None)).collect();
    if named.is_empty() {
        out.push(none(0.0, none_why.to_string()));
    }
    let mut rest: Vec<usize> = (0..tested.len()).filter(|i| !named.contains(i)).collect();
    rest.sort_by(|a, b| rank_key(tested, named, *b).total_cmp(&rank_key(tested, named, *a)));
    for i in rest {
        if out.iter().any(|c| c.effect == tested[i].effect) {
            continue;
        }
        out.push(cause(&tested[i], why_not(&tested[i])));
    }
    if !named.is_empty() {
        out.push(none(0.0, "the named effects qualify".into()));
    }
    out
}

/// The model values extended by a named effect's `extension`.
pub(super) fn extended_values(
    base: &ModelValues,
    extension: &Extension,
    rig: &Rig,
    shaft: ShaftConstants,
) -> ModelValues {
    let mut m = base.clone();
    match extension {
        Extension::Hydraulic(v) => m.hydraulic = v.clone(),
        Extension::Mechanical(v) => m.mechanical = v.clone(),
        Extension::Electrical(v) => m.electrical = Some(v.clone()),
        Extension::Cylinder(v) => m.cylinder = Some(v.clone()),
        Extension::TorqueLine(f) => {
            use super::angle_locked::LineEffect;
            let scale = match f.effect {
                LineEffect::CurrentOffset | LineEffect::Cogging(_) => LineScale::Constant,
                LineEffect::FluxHarmonics => LineScale::Electromagnetic,
                LineEffect::PistonRipple(z) => LineScale::PressureDifference(
                    super::mechanical::ripple_fundamental_per_ratio(rig, z) * shaft.d_per_rad,
                ),
            };
            m.lines.push(TorqueLine {
                order: f.effect.order(rig),
                amplitude: f.amplitude,
                scale,
            });
        }
        Extension::CurrentLines(_) => {}
    }
    m
}

/// The contract's fit of `predicted` over `rows`.
pub(super) fn fit_of(
    log: &BenchLog,
    facts: &LogFacts,
    predicted: &BTreeMap<&'static str, Vec<f64>>,
    rows: Range<usize>,
) -> Fit {
    let (by, ratios) = scores(log, facts, predicted, rows.clone());
    let rmse = predicted.get("p_pa").map_or(f64::NAN, |p| {
        let y = &log.p_pa[rows.clone()];
        (y.iter()
            .zip(&p[rows])
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / y.len().max(1) as f64)
            .sqrt()
    });
    Fit {
        fit_percent: by.get("p_pa").copied().unwrap_or(f64::NAN),
        rmse_pa: rmse,
        fit_percent_by_signal: by,
        noise_ratio_by_signal: ratios,
    }
}

/// The contract's fit over `rows` of the model `values`, its signals predicted and scored
/// one at a time, and each signal's trace at every `step`-th row.
pub(super) fn fit_each(
    ctx: &Context<'_>,
    values: &ModelValues,
    rows: Range<usize>,
    step: usize,
) -> (Fit, BTreeMap<&'static str, Vec<f64>>) {
    let mut fit = Fit {
        fit_percent: f64::NAN,
        rmse_pa: f64::NAN,
        fit_percent_by_signal: BTreeMap::new(),
        noise_ratio_by_signal: BTreeMap::new(),
    };
    let mut trace = BTreeMap::new();
    predict_each(ctx, values, &mut |name, v| {
        let one = BTreeMap::from([(name, v)]);
        let f = fit_of(ctx.log, ctx.facts, &one, rows.clone());
        if name == "p_pa" {
            (fit.fit_percent, fit.rmse_pa) = (f.fit_percent, f.rmse_pa);
        }
        fit.fit_percent_by_signal.extend(f.fit_percent_by_signal);
        fit.noise_ratio_by_signal.extend(f.noise_ratio_by_signal);
        trace.insert(name, traced(&one[name], step));
    });
    (fit, trace)
}

/// The time-domain signatures of every baseline residual, the model's own predictions of
/// the other signals as regressors where it made them.
fn residual_signatures(
    log: &BenchLog,
    facts: &LogFacts,
    baseline: &BTreeMap<&'static str, Vec<f64>>,
) -> Vec<ResidualSignature> {
    let with = Regressors {
        speed_rad_s: predicted_or(baseline, "speed_rad_s", &log.speed_rad_s),
        p_pa: predicted_or(baseline, "p_pa", &log.p_pa),
        iq_a: predicted_or(baseline, "iq_a", &log.iq_a),
    };
    baseline
        .iter()
        .filter_map(|(name, b)| {
            let y = log.column(crate::bench_log::Signal::from_name(name)?)?;
            residual_signature(name, facts.period_s, y, b, &with)
        })
        .collect()
}

/// The whole-log prediction of `name` in `predicted`, or `logged` when there is none.
fn predicted_or<'a>(
    predicted: &'a BTreeMap<&'static str, Vec<f64>>,
    name: &str,
    logged: &'a [f64],
) -> &'a [f64] {
    match predicted.get(name) {
        Some(v) if v.len() == logged.len() => v,
        _ => logged,
    }
}

/// The angle-locked orders each effect would show at.
fn candidate_orders(rig: &Rig) -> Vec<(u32, &'static str)> {
    let pp = rig.motor.pole_pairs;
    vec![
        (pp, "current_sensor_offset"),
        (6 * pp, "flux_harmonics"),
        (ripple_order(rig.pump.pistons), "piston_ripple"),
        (rig.motor.cogging_fundamental_order(), "cogging_torque"),
    ]
}
