//! What `eha diagnose` finds, in the shape of the contract's JSON
//! (`shared/contracts/eha-cli.md`): the segments, the baseline and extended fits on the
//! validation segment, the ranked causes with their fitted parameters and evidence, and the
//! gain.

use serde::Serialize;
use std::collections::BTreeMap;

/// The diagnosis of one bench log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Data rows of the log.
    pub samples: usize,
    /// Where the candidates' parameters were fitted. [s]
    pub identification_segment_s: [f64; 2],
    /// Where both models are scored; the fit never saw it. [s]
    pub validation_segment_s: [f64; 2],
    /// The nominal model (the rig file) on the validation segment.
    pub baseline: Fit,
    /// Candidate effects, most likely first; `none` leads when the nominal model explains
    /// the log within its noise.
    pub causes: Vec<Cause>,
    /// The model extended by the kept effects (the nominal one when none is kept), on the
    /// validation segment.
    pub extended: Extended,
    /// Extended minus baseline.
    pub gain: Gain,
    /// The nominal model calibrated within its tolerance bands: per relation, each
    /// parameter's fitted value (SI) — beyond the contract, for the engineer.
    pub calibration: BTreeMap<String, BTreeMap<String, f64>>,
}

/// Goodness of fit of one model on the validation segment.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fit {
    /// Fit of the pressure `p_pa`, 100·(1 − ‖y − ŷ‖/‖y − ȳ‖). [%]
    pub fit_percent: f64,
    /// Root-mean-square pressure error. [Pa]
    pub rmse_pa: f64,
    /// The same fit measure for each logged signal the model predicts. [%]
    pub fit_percent_by_signal: BTreeMap<String, f64>,
    /// Per signal, the residual's RMS over the log's own noise RMS (1.0: explained down to
    /// the sensor noise). [1]
    pub noise_ratio_by_signal: BTreeMap<String, f64>,
}

/// One candidate cause.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Cause {
    /// Effect name from `shared/contracts/effects.md`.
    pub effect: String,
    /// Evidence score: higher is more likely. [1]
    pub score: f64,
    /// Fitted parameters, by the catalogue's parameter names (SI).
    pub parameters: BTreeMap<String, f64>,
    /// Standard error of each fitted parameter that has one (SI, infinite where the log
    /// does not bound it) — beyond the contract, for trends over many logs.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub standard_errors: BTreeMap<String, f64>,
    /// One line saying why.
    pub evidence: String,
    /// Effects the log cannot tell this one from (the evidence says which test would).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ambiguous_with: Vec<String>,
}

/// The extended model's fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Extended {
    /// Effects switched on (empty when none was kept).
    pub effects: Vec<String>,
    /// Fit of `p_pa`. [%]
    pub fit_percent: f64,
    /// Root-mean-square pressure error. [Pa]
    pub rmse_pa: f64,
    /// Fit per signal. [%]
    pub fit_percent_by_signal: BTreeMap<String, f64>,
    /// Residual RMS over noise RMS per signal. [1]
    pub noise_ratio_by_signal: BTreeMap<String, f64>,
}

/// What the extension gained on the validation segment.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Gain {
    /// Extended minus baseline pressure fit. [percentage points]
    pub fit_points: f64,
    /// 100·(1 − rmse_ext / rmse_base). [%]
    pub rmse_reduction_percent: f64,
}

impl Diagnosis {
    /// The causes of the effects the diagnosis names, in the order the extended model took
    /// them (largest share of the gain first); the leading cause (`none`) when it names none.
    pub fn named_causes(&self) -> Vec<&Cause> {
        let named: Vec<&Cause> = self
            .extended
            .effects
            .iter()
            .filter_map(|e| self.causes.iter().find(|c| &c.effect == e))
            .collect();
        if named.is_empty() {
            self.causes.iter().take(1).collect()
        } else {
            named
        }
    }

    /// What the diagnosis names, as the terminal and the report say it: the effects joined
    /// by ` + `, or `none`.
    pub fn named_label(&self) -> String {
        if self.extended.effects.is_empty() {
            "none".into()
        } else {
            self.extended.effects.join(" + ")
        }
    }
}

impl Cause {
    /// The evidence, with the effects the log cannot tell this one from.
    pub fn evidence_in_full(&self) -> String {
        if self.ambiguous_with.is_empty() {
            self.evidence.clone()
        } else {
            format!(
                "{} (the log cannot tell it from {})",
                self.evidence,
                self.ambiguous_with.join(", ")
            )
        }
    }
}
