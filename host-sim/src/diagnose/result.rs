//! Stages 6 and 7 of the diagnosis: the baseline's and the extended model's scores on
//! the validation segment, the evidence for the report (residual signatures, order
//! spectra) and the contract's result, the causes ranked with why each was or was not named.

use super::angle_locked::ShaftConstants;
use super::calibration::{Calibration, Relation, Release};
use super::candidates::{Extension, Tested};
use super::decision::{threshold, why_not};
use super::diagnosis::{Cause, Diagnosis, Extended, Fit, Gain};
use super::facts::LogFacts;
use super::findings::Analysis;
use super::mechanical::{LineScale, TorqueLine};
use super::predictions::{scores, ModelValues};
use super::relations::{Calibrations, Relations};
use super::signatures::{residual_signature, Regressors, ResidualSignature};
use super::spectrum::order_spectrum;
use crate::bench_log::BenchLog;
use plant_model::pump::ripple_order;
use plant_model::Rig;
use std::collections::BTreeMap;
use std::ops::Range;

/// Stages 6 and 7: the scores on the validation segment, the evidence for the report and
/// the contract's result.
#[allow(clippy::too_many_arguments)]
pub(super) fn assemble(
    log: &BenchLog,
    facts: &LogFacts,
    rel: &Relations<'_>,
    cal: &Calibrations,
    tested: Vec<Tested>,
    named: Vec<usize>,
    baseline: BTreeMap<&'static str, Vec<f64>>,
    extended: BTreeMap<&'static str, Vec<f64>>,
) -> Analysis {
    let rig = rel.hydraulic.rig;
    let val = facts.validation();
    let base_fit = fit_of(log, facts, &baseline, val.clone());
    let ext_fit = fit_of(log, facts, &extended, val.clone());
    let measured: BTreeMap<&'static str, Vec<f64>> = baseline
        .keys()
        .filter_map(|k| {
            let s = crate::bench_log::Signal::from_name(k)?;
            Some((*k, log.column(s)?.to_vec()))
        })
        .collect();
    let signatures = residual_signatures(log, facts, &measured, &baseline);
    let spectra = ["p_pa", "speed_rad_s", "iq_a"]
        .iter()
        .filter_map(|name| {
            let y = measured.get(name)?;
            let r = super::fit_score::residual(y, baseline.get(name)?);
            Some((*name, order_spectrum(&facts.theta_rad, &r)?))
        })
        .collect();
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
        calibration: calibration_values(rel, cal),
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
        t_s: t.clone(),
        measured,
        baseline,
        extended,
        spectra,
        signatures,
        candidate_orders: candidate_orders(rig),
        tested,
        contributions: Vec::new(),
    }
}

/// Each relation's calibrated parameters by name, for the JSON.
fn calibration_values(
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

/// The time-domain signatures of every baseline residual.
fn residual_signatures(
    log: &BenchLog,
    facts: &LogFacts,
    measured: &BTreeMap<&'static str, Vec<f64>>,
    baseline: &BTreeMap<&'static str, Vec<f64>>,
) -> Vec<ResidualSignature> {
    let point = |name: &str, logged: &'static str| -> Vec<f64> {
        baseline
            .get(name)
            .cloned()
            .unwrap_or_else(|| measured.get(logged).cloned().unwrap_or_default())
    };
    let speed = point("speed_rad_s", "speed_rad_s");
    let p = point("p_pa", "p_pa");
    let iq = point("iq_a", "iq_a");
    let with = Regressors {
        speed_rad_s: if speed.len() == facts.rows {
            &speed
        } else {
            &log.speed_rad_s
        },
        p_pa: if p.len() == facts.rows { &p } else { &log.p_pa },
        iq_a: if iq.len() == facts.rows {
            &iq
        } else {
            &log.iq_a
        },
    };
    measured
        .iter()
        .filter_map(|(name, y)| {
            residual_signature(name, facts.period_s, y, baseline.get(name)?, &with)
        })
        .collect()
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
