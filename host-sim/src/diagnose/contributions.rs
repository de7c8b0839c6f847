//! Each named effect's contribution on the signals it acts on: the fit (MATLAB's
//! `compare` measure, per signal, on the validation segment) gained as the named effects
//! join the calibrated model one by one in their rank, the strongest first. The last step
//! is the extended model itself, so the contributions add up to the gain the diagnosis
//! reports; an effect that acts on one signal moves only its column.

use super::angle_locked::ShaftConstants;
use super::candidates::Tested;
use super::facts::LogFacts;
use super::findings::Contributions;
use super::predictions::{predict, Context, ModelValues};
use super::result::{extended_values, fit_of};
use crate::bench_log::BenchLog;
use plant_model::Rig;
use std::collections::BTreeMap;

/// Predictions by signal, whole log.
type Predicted = BTreeMap<&'static str, Vec<f64>>;

/// The contributions of `named` (indices into `tested`) from the calibrated `base`
/// values and predictions `baseline` to the `extended` predictions.
#[allow(clippy::too_many_arguments)]
pub(super) fn contributions(
    ctx: &Context<'_>,
    log: &BenchLog,
    facts: &LogFacts,
    rig: &Rig,
    shaft: ShaftConstants,
    (tested, named): (&[Tested], &[usize]),
    base: &ModelValues,
    (baseline, extended): (&Predicted, &Predicted),
) -> Contributions {
    let val = facts.validation();
    let mut before = fit_of(log, facts, baseline, val.clone()).fit_percent_by_signal;
    let mut values = base.clone();
    let mut out = Contributions::new();
    for (k, &i) in named.iter().enumerate() {
        values = extended_values(&values, &tested[i].extension, rig, shaft);
        let after = if k + 1 == named.len() {
            fit_of(log, facts, extended, val.clone())
        } else {
            fit_of(log, facts, &predict(ctx, &values), val.clone())
        }
        .fit_percent_by_signal;
        let gained = after
            .iter()
            .filter_map(|(s, f)| Some((s.clone(), f - before.get(s)?)))
            .collect();
        out.push((tested[i].effect.to_string(), gained));
        before = after;
    }
    out
}
