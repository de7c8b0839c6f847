//! What one diagnosis computed, gathered for the contract's JSON and the markdown report:
//! the result, the measured signals beside the baseline and extended predictions, the
//! baseline residuals' order spectra and signatures, and every tested effect with its
//! contributions.

use super::candidates::Tested;
use super::diagnosis::Diagnosis;
use super::signatures::ResidualSignature;
use super::spectrum::OrderSpectrum;
use std::collections::BTreeMap;

/// Fit points each named effect gains per signal, in the order they join the model.
pub type Contributions = Vec<(String, BTreeMap<String, f64>)>;

/// Everything the diagnosis computed, for the JSON and the report.
pub struct Analysis {
    /// The contract's result.
    pub diagnosis: Diagnosis,
    /// The log's time. [s]
    pub t_s: Vec<f64>,
    /// Measured signals by name (those the models predict).
    pub measured: BTreeMap<&'static str, Vec<f64>>,
    /// Baseline (calibrated nominal) predictions by signal, whole log.
    pub baseline: BTreeMap<&'static str, Vec<f64>>,
    /// Extended predictions by signal, whole log (the baseline's when nothing was named).
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
