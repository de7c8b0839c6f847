//! What one diagnosis computed, gathered for the contract's JSON and the markdown report:
//! the result, the measured signals beside the baseline and extended predictions, the
//! baseline residuals' order spectra and signatures, and every tested effect with its
//! contributions.

use super::candidates::Tested;
use super::diagnosis::Diagnosis;
use super::signatures::ResidualSignature;
use super::spectrum::OrderSpectrum;
use std::collections::BTreeMap;

/// Rows a trace of the report keeps, about: a figure shows no more, and the diagnosis does
/// not hold a whole log's predictions once it has scored them.
pub const TRACE_POINTS: usize = 4000;

/// Every how many rows a trace of a log of `rows` rows keeps one.
pub fn trace_step(rows: usize) -> usize {
    (rows / TRACE_POINTS).max(1)
}

/// Every `step`-th value of `v`, from the first.
pub fn traced(v: &[f64], step: usize) -> Vec<f64> {
    v.iter().step_by(step.max(1)).copied().collect()
}

/// Every `step`-th value of each series of `by_signal`.
pub fn traced_all(
    by_signal: &BTreeMap<&'static str, Vec<f64>>,
    step: usize,
) -> BTreeMap<&'static str, Vec<f64>> {
    by_signal
        .iter()
        .map(|(k, v)| (*k, traced(v, step)))
        .collect()
}

/// Fit points each named effect gains per signal, in the order they join the model.
pub type Contributions = Vec<(String, BTreeMap<String, f64>)>;

/// Everything the diagnosis computed, for the JSON and the report.
pub struct Analysis {
    /// The contract's result.
    pub diagnosis: Diagnosis,
    /// The log's time at the traced rows (every [`trace_step`]-th row). [s]
    pub t_s: Vec<f64>,
    /// Measured signals by name (those the models predict), at the traced rows.
    pub measured: BTreeMap<&'static str, Vec<f64>>,
    /// Baseline (calibrated nominal) predictions by signal, at the traced rows.
    pub baseline: BTreeMap<&'static str, Vec<f64>>,
    /// Extended predictions by signal, at the traced rows (the baseline's when nothing was
    /// named).
    pub extended: BTreeMap<&'static str, Vec<f64>>,
    /// Order spectra of the baseline residuals (pressure, speed, q current).
    pub spectra: Vec<(&'static str, OrderSpectrum)>,
    /// Time-domain signatures of the baseline residuals.
    pub signatures: Vec<ResidualSignature>,
    /// Orders the candidates point at, for the plots: (order, effect).
    pub candidate_orders: Vec<(u32, &'static str)>,
    /// Every tested effect, most likely first.
    pub tested: Vec<Tested>,
    /// Fit points each named effect gains per signal as it joins the model in rank order.
    pub contributions: Contributions,
}
