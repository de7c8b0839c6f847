//! Each named effect's contribution on the signals it acts on: the fit (MATLAB's
//! `compare` measure, per signal, on the validation segment) gained as the named effects
//! join the calibrated model one by one in their rank, the strongest first. The last step
//! is the extended model itself, so the contributions add up to the gain the diagnosis
//! reports; an effect that acts on one signal moves only its column.

use super::angle_locked::ShaftConstants;
use super::candidates::Tested;
use super::diagnosis::Fit;
use super::facts::LogFacts;
use super::findings::Contributions;
use super::predictions::{Context, ModelValues};
use super::result::{extended_values, fit_each};
use plant_model::Rig;

/// The contributions of `named` (indices into `tested`) from the calibrated `base`
/// values, whose fit is `base_fit`, to the extended model, whose fit is `ext_fit`.
pub(super) fn contributions(
    ctx: &Context<'_>,
    (facts, rig, shaft): (&LogFacts, &Rig, ShaftConstants),
    (tested, named): (&[Tested], &[usize]),
    base: &ModelValues,
    (base_fit, ext_fit): (&Fit, &Fit),
) -> Contributions {
    let val = facts.validation();
    let mut before = base_fit.fit_percent_by_signal.clone();
    let mut values = base.clone();
    let mut out = Contributions::new();
    for (k, &i) in named.iter().enumerate() {
        values = extended_values(&values, &tested[i].extension, rig, shaft);
        let after = if k + 1 == named.len() {
            ext_fit.fit_percent_by_signal.clone()
        } else {
            fit_each(ctx, &values, val.clone(), usize::MAX)
                .0
                .fit_percent_by_signal
        };
        let gained = after
            .iter()
            .filter_map(|(s, f)| Some((s.clone(), f - before.get(s)?)))
            .collect();
        out.push((tested[i].effect.to_string(), gained));
        before = after;
    }
    out
}
