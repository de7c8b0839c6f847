//! The decision: which effect, if any, the log convicts.
//!
//! An effect is named only when all of these hold:
//!
//! 1. **Significance.** Its generalised likelihood ratio Λ on the identification segment
//!    exceeds the χ² quantile of its degrees of freedom at [`FALSE_ALARM`]: with the
//!    residuals weighed by their own variance per independent sample (the noise level and
//!    correlation time estimated from the log) or, for a line, by the floor of the
//!    neighbouring orders, this is the test's false-alarm rate if the nominal model within
//!    its tolerances were the truth.
//! 2. **Beyond tolerance.** Its parameter's estimate lies outside its tolerance band (a
//!    few percent of displacement is not entrained air). For a released rig parameter the
//!    baseline of Λ is the fit held within the band, so a significant Λ with the estimate
//!    outside says the band's edge is itself rejected; a line's amplitude must clear its
//!    band by two standard errors.
//! 3. **It holds on the validation segment.** The fitted extension does not make the
//!    validation segment significantly worse (its gain there, in the same χ² units, above
//!    −[`VALIDATION_TOLERANCE`]): an effect the validation segment excites must improve it
//!    or be refuted; one it does not excite (a bulk modulus seen only in a fill below the
//!    precharge) cannot be confirmed there and stands on its identification evidence. A
//!    loss is weighed against its spread ([`crate::diagnose::validation_spread`]): each fit
//!    extrapolates with its tolerances where the identification left them, and along a
//!    direction the identification leaves flat (a misfitting baseline bends its tolerances
//!    to absorb the misfit) that end point, and the loss with it, is arbitrary. A loss
//!    within [`SPREAD_QUANTILE`] standard errors of the tolerance does not refute an effect,
//!    nor does one under [`LOSS_SHARE_OF_EVIDENCE`] of Λ: the validation segment does not
//!    excite that effect ([`loss_inconclusive`]).
//! 4. **No structural veto.** A dead time and the flux harmonics share the lines at order
//!    6·p_n: only the one that explains them better is named ([`apply_vetoes`]).
//!
//! Among the effects that qualify the one with the largest Λ is named; `none` otherwise.

use crate::diagnose::candidates::Tested;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The per-test false-alarm rate of the significance test (a dozen tests: about 0.1 % for
/// the whole catalogue under the nominal model). [1]
pub const FALSE_ALARM: f64 = 1e-4;

pub use crate::diagnose::validation_spread::VALIDATION_TOLERANCE;

/// Standard errors of a validation loss within which the validation segment cannot tell
/// the extension from the baseline: the normal distribution's two-sided 95 % quantile. [1]
pub const SPREAD_QUANTILE: f64 = 1.96;

/// Whether the validation loss `g` of `t` lies within what the two fits' own parameter
/// uncertainty makes of it (within [`SPREAD_QUANTILE`] standard errors of the tolerance):
/// the validation segment then cannot refute what the identification shows. So too a loss
/// under [`LOSS_SHARE_OF_EVIDENCE`] of Λ, whatever its spread.
pub fn loss_inconclusive(t: &Tested, g: f64) -> bool {
    let slight = -g <= LOSS_SHARE_OF_EVIDENCE * t.lambda;
    slight
        || t.validation_spread.is_some_and(|s| {
            let reach = SPREAD_QUANTILE * s;
            g + reach >= -VALIDATION_TOLERANCE
        })
}

/// Largest share of the identification's evidence Λ a validation loss may be and still be
/// taken as the validation segment not exciting the effect: an effect the validation
/// excited would gain there about what it gained on the identification, so a loss twenty
/// times smaller than Λ comes from the other tolerances' extrapolation, not from the
/// effect. [1]
pub const LOSS_SHARE_OF_EVIDENCE: f64 = 0.05;

/// The χ² threshold at [`FALSE_ALARM`] for `dof` degrees of freedom.
pub fn threshold(dof: usize) -> f64 {
    ChiSquared::new(dof.max(1) as f64)
        .map(|c| c.inverse_cdf(1.0 - FALSE_ALARM))
        .unwrap_or(f64::INFINITY)
}

/// Why a tested effect is not named, or `None` when it qualifies.
pub fn why_not(t: &Tested) -> Option<String> {
    let limit = threshold(t.dof);
    if t.lambda.is_nan() || t.lambda <= limit {
        return Some(format!(
            "not significant (Λ = {:.1} below {:.1}, the χ²({}) quantile at {:.0e})",
            t.lambda, limit, t.dof, FALSE_ALARM
        ));
    }
    if !t.outside_band {
        return Some("within its tolerance band".into());
    }
    if let Some(g) = t.validation_gain {
        if g < -VALIDATION_TOLERANCE && !loss_inconclusive(t, g) {
            return Some(format!("the validation segment refutes it (gain {g:.1})"));
        }
    }
    t.veto.clone()
}

/// Applies the structural vetoes across `tested`: an inverter dead time and the flux
/// harmonics share the lines at order 6·p_n, and only one of them is named.
///
/// With the angle and the voltages logged both laws are fitted to the same voltage lines
/// ([`crate::diagnose::emf_law`]): a back-EMF growing with the speed (four degrees of
/// freedom) and the dead-time voltage the logged currents make (one); the one standing
/// further above its χ² quantile explains them and the other is vetoed (every dead-time
/// reading, the electrical relation's too). Without the voltages the dead time is fitted to
/// the current lines and the flux harmonics with their back-EMF's current lines: the one
/// whose Λ stands further above its own threshold is named. Without the angle the flux
/// harmonics have only the torque line's magnitudes, and a significant one vetoes the dead
/// time (a dead time moves current and shaft together and leaves no torque).
pub fn apply_vetoes(tested: &mut [Tested]) {
    use crate::diagnose::angle_locked::EmfLines;
    use crate::diagnose::candidates::Extension;
    let flux = tested.iter().position(|t| t.effect == "flux_harmonics");
    let dead: Vec<usize> = (0..tested.len())
        .filter(|&i| tested[i].effect == "dead_time")
        .collect();
    let (Some(f), Some(&d)) = (flux, dead.first()) else {
        return;
    };
    let line = match &tested[f].extension {
        Extension::TorqueLine(l) => Some(l),
        _ => None,
    };
    if let Some(law) = line.and_then(|l| l.emf_law) {
        let (me, md) = (
            law.emf_lambda - threshold(4),
            law.dead_time_lambda - threshold(1),
        );
        if md > 0.0 && md > me {
            tested[f].veto = Some(format!(
                "its voltage lines at 6·p_n are an inverter dead time's, read from the logged \
                 currents (Λ − threshold {md:.1} against {me:.1} as a back-EMF)"
            ));
        } else if me > 0.0 {
            for i in dead {
                tested[i].veto = Some(format!(
                    "the voltage lines at 6·p_n are a back-EMF's (Λ − threshold {me:.1} \
                     against {md:.1} as a dead time's)"
                ));
            }
        }
        return;
    }
    let margin = |t: &Tested| t.lambda - threshold(t.dof);
    let (mf, md) = (margin(&tested[f]), margin(&tested[d]));
    let joint = line.is_some_and(|l| l.emf != EmfLines::None);
    if joint && mf > 0.0 && mf >= md {
        tested[d].veto = Some(format!(
            "the flux harmonics explain the lines at 6·p_n better (Λ − threshold {mf:.1} \
             against {md:.1})"
        ));
    } else if joint && md > 0.0 && md > mf {
        tested[f].veto = Some(format!(
            "an inverter dead time explains the lines at 6·p_n better (Λ − threshold {md:.1} \
             against {mf:.1})"
        ));
    } else if !joint && mf > 0.0 {
        tested[d].veto = Some(
            "the torque balance leaves a line at the same order: a torque ripple, not a voltage error"
                .into(),
        );
    }
}

/// Index of the named effect in `tested`, if any qualifies.
pub fn decide(tested: &[Tested]) -> Option<usize> {
    tested
        .iter()
        .enumerate()
        .filter(|(_, t)| why_not(t).is_none())
        .max_by(|a, b| a.1.lambda.total_cmp(&b.1.lambda))
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::angle_locked::{EmfLines, LineEffect, LineFit};
    use crate::diagnose::back_emf::Stator;
    use crate::diagnose::candidates::{dead_time_tested, Extension};
    use crate::diagnose::emf_law::EmfLaw;
    use rustfft::num_complex::Complex64;

    /// The flux harmonics' test with the voltages logged, its voltage lines read by both
    /// laws as `law` says, and the dead time's two readings (the electrical relation's, Λ
    /// 32, and the voltage lines').
    fn tested(law: EmfLaw) -> Vec<Tested> {
        let fit = LineFit {
            effect: LineEffect::FluxHarmonics,
            amplitude: Complex64::new(0.04, 0.0),
            information: 1e6,
            back_emf_d: Complex64::default(),
            lambda: 2462.0,
            dof: 4,
            windows: 2,
            angle: crate::diagnose::speed_angle::AngleSource::Logged,
            emf: EmfLines::Voltages(Stator {
                r_s_ohm: 1.15,
                l_d_h: 5.5e-3,
                l_q_h: 13.2e-3,
                psi_f_wb: 0.188,
            }),
            emf_law: Some(law),
        };
        vec![
            Tested::bare("dead_time", 32.0, 1, Extension::Electrical(vec![0.0; 5])),
            Tested::bare("flux_harmonics", 2462.0, 4, Extension::TorqueLine(fit)),
            dead_time_tested(&law, 2, &[], &[1.15, 5.5e-3, 13.2e-3, 0.188, 0.0]).unwrap(),
        ]
    }

    /// The two laws' reading of a log's voltage lines: Λ as a back-EMF, as a dead time.
    fn law(emf_lambda: f64, dead_time_lambda: f64) -> EmfLaw {
        EmfLaw {
            emf_lambda,
            dead_time_lambda,
            dead_time_s: 1.06e-6,
            band: 3,
        }
    }

    #[test]
    fn the_law_that_explains_the_voltage_lines_better_names_them() {
        // A dead time's lines as a blind log read them: 4599 as its own law (1 dof) against 2543 as a
        // back-EMF's (4 dof). The flux harmonics are vetoed whatever their Λ on the torque
        // line, and both dead-time readings stand (the stronger is named).
        let mut t = tested(law(2542.7, 4598.6));
        apply_vetoes(&mut t);
        assert!(t[1].veto.is_some() && t[0].veto.is_none() && t[2].veto.is_none());
        assert_eq!(decide(&t), Some(2));
        // A flux harmonics' back-EMF lines: every dead-time reading is vetoed.
        let mut t = tested(law(632.0, 25.2));
        apply_vetoes(&mut t);
        assert!(t[1].veto.is_none() && t[0].veto.is_some() && t[2].veto.is_some());
        assert_eq!(decide(&t), Some(1));
        // Within the margin the extra three degrees of freedom cost: 4 dof need 8.4 more.
        let mut t = tested(law(100.0 + threshold(4) - threshold(1) - 1.0, 100.0));
        apply_vetoes(&mut t);
        assert!(t[1].veto.is_some(), "{:?}", t[1].veto);
    }

    #[test]
    fn a_validation_loss_within_the_fits_spread_does_not_refute_strong_evidence() {
        // Λ 150 000, a loss of 98 with a spread of 160: −98 + 1.96·160 = 215.6 lies above
        // −3.84: the validation cannot tell, the effect stands.
        let mut t = Tested::bare("entrained_air", 150_000.0, 1, Extension::Hydraulic(vec![]));
        t.validation_gain = Some(-98.0);
        t.validation_spread = Some(160.0);
        assert!(why_not(&t).is_none(), "{:?}", why_not(&t));
        // A spread of 40: −98 + 78.4 = −19.6 lies below −3.84, a conclusive loss, but one
        // under 5 % of Λ (98 against 150 000): the validation does not excite the effect.
        t.validation_spread = Some(40.0);
        assert!(why_not(&t).is_none(), "{:?}", why_not(&t));
        // Λ 1 500: the same loss is 6.5 % of it, and refutes.
        t.lambda = 1_500.0;
        assert!(why_not(&t).is_some_and(|w| w.contains("refutes")));
        // No spread known: the loss refutes as it reads.
        t.validation_spread = None;
        assert!(why_not(&t).is_some_and(|w| w.contains("refutes")));
        // Evidence weaker than the spread's reach stands on the identification as well: a
        // loss of 35 within 1.96·137 = 268.5 of the tolerance does not refute Λ 32.
        let mut w = Tested::bare("extra_leakage", 32.0, 1, Extension::Hydraulic(vec![]));
        w.validation_gain = Some(-35.0);
        w.validation_spread = Some(137.0);
        assert!(why_not(&w).is_none(), "{:?}", why_not(&w));
        // Beyond the reach it refutes: a loss of 300.
        w.validation_gain = Some(-300.0);
        assert!(why_not(&w).is_some_and(|w| w.contains("refutes")));
    }

    #[test]
    fn thresholds_are_the_chi_square_quantiles() {
        // χ²(1) at 1 − 1e-4 is 15.137; χ²(2) is −2·ln(1e-4) = 18.42 exactly.
        assert!((threshold(1) - 15.137).abs() < 0.01, "{}", threshold(1));
        assert!((threshold(2) + 2.0 * FALSE_ALARM.ln()).abs() < 1e-6);
    }
}
