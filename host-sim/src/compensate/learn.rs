//! What the diagnosis says about the angle-locked torques, as the feed-forward needs it.
//!
//! Only the diagnosis's public result is read ([`crate::diagnose::analysis::diagnose`]:
//! the contract's ranked causes, each an effect name from the catalogue with its fitted
//! parameters and its score Λ). A table needs every line effect that is there, not only
//! the one a diagnosis names, so every angle-locked effect of the catalogue ([`LINE_EFFECTS`])
//! whose Λ passes the χ² threshold of a phase-locked line goes in, whether or not it is
//! beyond its healthy tolerance band (a healthy motor's small cogging is still a ripple to
//! cancel).
//!
//! A phase-locked line's Λ (the generalised likelihood ratio of the complex amplitude
//! against noise) has two degrees of freedom under no line, whose χ² quantile at a false
//! alarm rate α is exactly −2·ln α ([`threshold`]).
//!
//! The diagnosis fits its parameters on the first half of the log it is given and scores
//! them on the second. To learn from more of each log without counting a sample twice,
//! each log is diagnosed whole (fitting on its first half) and then its second half alone
//! (fitting on the log's third quarter) — [`causes_of`].
//!
//! A load-scaled effect fitted where its regressor is nearly zero (the flux harmonics or
//! the pump's ripple on the bench sweep's free shaft) takes whatever line the catalogue
//! puts at its order — the inverter's dead time at 6·p_n, say — divided by almost nothing.
//! Such a fit is left out when it describes no machine ([`physical`]): a 6th-harmonic
//! torque larger than the mean torque, a flow ripple whose peak-to-peak exceeds twice the
//! mean flow (the pump would run backwards each stroke).
//!
//! Several logs (and these parts) combine by information (a sweep at low pressure carries the cogging and a
//! current offset; a hold at working pressure also the load-scaled pump ripple and flux
//! harmonics): per effect the information-weighted mean of its complex amplitude, the
//! information being Λ/|A|² (one over the amplitude's variance). Of the pump's piston
//! counts only the one with the largest total Λ is kept; of cogging orders likewise.

use crate::bench_log::BenchLog;
use crate::diagnose::analysis::{diagnose_to, Precision};
use crate::diagnose::diagnosis::Cause;
use crate::output::CliError;
use plant_model::{Effect, Rig};
use rustfft::num_complex::Complex64;

/// The catalogue's angle-locked effects, the ones a table indexed by the shaft angle acts on.
pub const LINE_EFFECTS: [&str; 4] = [
    "cogging_torque",
    "flux_harmonics",
    "piston_ripple",
    "current_sensor_offset",
];

/// False-alarm rate of a line taken into the table (the diagnosis's own). [1]
pub const FALSE_ALARM: f64 = 1e-4;

/// The Λ a phase-locked line must exceed: the χ²(2) quantile at [`FALSE_ALARM`], −2·ln α.
pub fn threshold() -> f64 {
    -2.0 * FALSE_ALARM.ln()
}

/// One effect as learned.
#[derive(Clone, Debug, PartialEq)]
pub struct Learned {
    /// The catalogue's effect with the combined parameters.
    pub effect: Effect,
    /// Λ summed over the logs it was significant in. [1]
    pub score: f64,
    /// Diagnoses it was significant in (a log and its second half count one each). [1]
    pub diagnoses: usize,
}

/// Largest 6th-harmonic torque ratio a motor can have: the mean torque. [1]
pub const MAX_T6_RATIO: f64 = 1.0;
/// Largest peak-to-peak flow ripple over mean flow of a pump that does not reverse. [1]
pub const MAX_RIPPLE_RATIO: f64 = 2.0;

/// Whether the cause's fitted parameters describe a machine (see the module's doc).
pub fn physical(c: &Cause) -> bool {
    let p = |k: &str| c.parameters.get(k).copied().unwrap_or(0.0);
    match c.effect.as_str() {
        "flux_harmonics" => p("t6_ratio").abs() <= MAX_T6_RATIO,
        "piston_ripple" => p("amplitude_ratio").abs() <= MAX_RIPPLE_RATIO,
        _ => true,
    }
}

/// The significant, physical angle-locked causes of one diagnosis.
fn significant(causes: Vec<Cause>) -> Vec<Cause> {
    causes
        .into_iter()
        .filter(|c| {
            LINE_EFFECTS.contains(&c.effect.as_str()) && c.score > threshold() && physical(c)
        })
        .collect()
}

/// The significant angle-locked causes the diagnosis finds in `log` and in its second
/// half, one list per diagnosis. The whole log's diagnosis must succeed; the second half's
/// may not (too short a log for it), and then adds nothing.
pub fn causes_of(log: &BenchLog, rig: &Rig) -> Result<Vec<Vec<Cause>>, CliError> {
    // The table is built from the fitted parameters themselves: the fits run to the end.
    // One diagnosis after the other (each runs its relations in parallel): side by side
    // they would hold the log, its half and both diagnoses' rows at once.
    let learn = |l: &BenchLog| diagnose_to(l, rig, Precision::Learning);
    let whole = learn(log)
        .map_err(|e| CliError::Failed(format!("the diagnosis of the log failed: {e}")))?;
    let mut out = vec![significant(whole.causes)];
    if let Ok(d) = learn(&log.tail(log.len() / 2)) {
        out.push(significant(d.causes));
    }
    Ok(out)
}

/// What one cause's parameters say, as a complex amplitude (magnitude, phase in the
/// plant's convention) and the discrete part that must agree to be combined (cogging
/// order, piston count).
fn amplitude_of(c: &Cause) -> Option<(Complex64, u32)> {
    let p = |k: &str| c.parameters.get(k).copied();
    let polar = |a: f64, ph: f64| Complex64::from_polar(a, ph);
    match c.effect.as_str() {
        "cogging_torque" => Some((
            polar(p("amplitude_nm")?, p("phase_rad")?),
            p("order")? as u32,
        )),
        "flux_harmonics" => Some((polar(p("t6_ratio")?, p("phase_rad")?), 0)),
        "piston_ripple" => Some((
            Complex64::new(p("amplitude_ratio")?, 0.0),
            p("pistons")? as u32,
        )),
        "current_sensor_offset" => Some((Complex64::new(p("offset_a")?, 0.0), 0)),
        _ => None,
    }
}

/// The catalogue's effect `name` with the combined amplitude `a` and discrete part `k`.
fn effect_of(name: &str, a: Complex64, k: u32) -> Option<Effect> {
    Some(match name {
        "cogging_torque" => Effect::CoggingTorque {
            amplitude_nm: a.norm(),
            order: k,
            phase_rad: a.arg(),
        },
        "flux_harmonics" => Effect::FluxHarmonics {
            t6_ratio: a.norm(),
            phase_rad: a.arg(),
        },
        "piston_ripple" => Effect::PistonRipple {
            pistons: k,
            amplitude_ratio: a.re.max(0.0),
        },
        "current_sensor_offset" => Effect::CurrentSensorOffset { offset_a: a.re },
        _ => return None,
    })
}

/// The causes of several logs combined, strongest first.
pub fn combine(per_log: &[Vec<Cause>]) -> Vec<Learned> {
    // (name, discrete part) → (Σ A·info, Σ info, Σ Λ, logs)
    let mut acc: Vec<(&str, u32, Complex64, f64, f64, usize)> = Vec::new();
    for causes in per_log {
        for c in causes {
            let Some((a, k)) = amplitude_of(c) else {
                continue;
            };
            let Some(name) = LINE_EFFECTS.iter().find(|n| **n == c.effect) else {
                continue;
            };
            let info = if a.norm_sqr() > 0.0 {
                c.score / a.norm_sqr()
            } else {
                0.0
            };
            match acc.iter_mut().find(|e| e.0 == *name && e.1 == k) {
                Some(e) => {
                    e.2 += a * info;
                    e.3 += info;
                    e.4 += c.score;
                    e.5 += 1;
                }
                None => acc.push((name, k, a * info, info, c.score, 1)),
            }
        }
    }
    // One pump and one slot order: the discrete part that explains most.
    let strongest = |name: &str| {
        acc.iter()
            .filter(|e| e.0 == name)
            .max_by(|a, b| a.4.total_cmp(&b.4))
            .map(|e| e.1)
    };
    let keep: Vec<(&str, Option<u32>)> = LINE_EFFECTS.iter().map(|n| (*n, strongest(n))).collect();
    let mut out: Vec<Learned> = acc
        .iter()
        .filter(|e| e.3 > 0.0 && keep.iter().any(|(n, k)| *n == e.0 && *k == Some(e.1)))
        .filter_map(|e| {
            Some(Learned {
                effect: effect_of(e.0, e.2 / e.3, e.1)?,
                score: e.4,
                diagnoses: e.5,
            })
        })
        .collect();
    out.sort_by(|a, b| b.score.total_cmp(&a.score));
    out
}

/// The low port's mean pressure over `logs`: its column where logged, the rig's fill
/// pressure where not. [Pa]
pub fn mean_low_pressure(logs: &[BenchLog], rig: &Rig) -> f64 {
    let (sum, n) = logs
        .iter()
        .fold((0.0, 0usize), |(s, n), log| match &log.p_low_pa {
            Some(p) => (s + p.iter().sum::<f64>(), n + p.len()),
            None => (s + rig.fill.pressure_pa * log.len() as f64, n + log.len()),
        });
    if n > 0 {
        sum / n as f64
    } else {
        rig.fill.pressure_pa
    }
}

/// What the diagnosis found in a set of logs.
pub struct Found {
    /// The significant angle-locked effects, combined over the logs, strongest first.
    pub effects: Vec<Learned>,
    /// The low port's mean pressure over the logs. [Pa]
    pub p_low_pa: f64,
}

/// Runs the diagnosis on each log (in parallel) and combines what it found.
pub fn find(logs: &[BenchLog], rig: &Rig) -> Result<Found, CliError> {
    use rayon::prelude::*;
    let per_log = logs
        .par_iter()
        .map(|log| causes_of(log, rig))
        .collect::<Result<Vec<_>, _>>()?;
    let diagnoses: Vec<_> = per_log.into_iter().flatten().collect();
    Ok(Found {
        effects: combine(&diagnoses),
        p_low_pa: mean_low_pressure(logs, rig),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn cause(effect: &str, score: f64, params: &[(&str, f64)]) -> Cause {
        Cause {
            effect: effect.into(),
            score,
            parameters: params
                .iter()
                .map(|(k, v)| (k.to_string(), *v))
                .collect::<BTreeMap<_, _>>(),
            standard_errors: BTreeMap::new(),
            evidence: String::new(),
            ambiguous_with: Vec::new(),
        }
    }

    #[test]
    fn the_threshold_is_the_chi_square_2_quantile() {
        // χ²(2) survival e^{−x/2}: at 18.42, 1e-4.
        assert!((threshold() - 18.420_680_7).abs() < 1e-6);
    }

    #[test]
    fn two_logs_combine_by_information_and_one_pump_is_kept() {
        // Cogging 0.05 N·m at 0 rad with Λ 400 (info 400/0.0025 = 1.6e5), and 0.06 N·m at
        // 0 rad with Λ 100 (info 100/0.0036 = 2.78e4): the weighted mean is
        // (0.05·1.6e5 + 0.06·2.78e4)/(1.6e5 + 2.78e4) = 0.05148 N·m.
        let a = vec![
            cause(
                "cogging_torque",
                400.0,
                &[("amplitude_nm", 0.05), ("order", 72.0), ("phase_rad", 0.0)],
            ),
            cause(
                "piston_ripple",
                50.0,
                &[("pistons", 9.0), ("amplitude_ratio", 0.03)],
            ),
        ];
        let b = vec![
            cause(
                "cogging_torque",
                100.0,
                &[("amplitude_nm", 0.06), ("order", 72.0), ("phase_rad", 0.0)],
            ),
            cause(
                "piston_ripple",
                30.0,
                &[("pistons", 7.0), ("amplitude_ratio", 0.05)],
            ),
        ];
        let l = combine(&[a, b]);
        assert_eq!(l.len(), 2, "{l:?}");
        let info = |lam: f64, amp: f64| lam / (amp * amp);
        let want = (0.05 * info(400.0, 0.05) + 0.06 * info(100.0, 0.06))
            / (info(400.0, 0.05) + info(100.0, 0.06));
        match l[0].effect {
            Effect::CoggingTorque {
                amplitude_nm,
                order,
                ..
            } => {
                assert!((amplitude_nm - want).abs() < 1e-12);
                assert!((amplitude_nm - 0.05148).abs() < 1e-4);
                assert_eq!(order, 72);
            }
            e => panic!("{e:?}"),
        }
        assert_eq!(l[0].diagnoses, 2);
        assert_eq!(
            l[1].effect,
            Effect::PistonRipple {
                pistons: 9,
                amplitude_ratio: 0.03
            }
        );
    }

    #[test]
    fn a_load_scaled_fit_that_describes_no_machine_is_left_out() {
        // A 6th-harmonic torque 2.3 times the mean torque, a flow ripple 5.5 times the
        // mean flow: not motors or pumps. 10 % and 36 % are.
        let flux = |r: f64| {
            cause(
                "flux_harmonics",
                50.0,
                &[("t6_ratio", r), ("phase_rad", 0.0)],
            )
        };
        let pump = |r: f64| {
            cause(
                "piston_ripple",
                50.0,
                &[("pistons", 9.0), ("amplitude_ratio", r)],
            )
        };
        assert!(!physical(&flux(2.3)) && physical(&flux(0.1)));
        assert!(!physical(&pump(5.5)) && physical(&pump(0.36)));
        let kept = significant(vec![flux(2.3), pump(0.36), flux(0.1)]);
        assert_eq!(kept.len(), 2);
    }

    #[test]
    fn opposite_phases_cancel_in_the_combination() {
        // The same line at 0 and π with equal information: nothing is locked to the angle.
        let at = |ph: f64| {
            vec![cause(
                "flux_harmonics",
                100.0,
                &[("t6_ratio", 0.02), ("phase_rad", ph)],
            )]
        };
        let l = combine(&[at(0.0), at(std::f64::consts::PI)]);
        match l[0].effect {
            Effect::FluxHarmonics { t6_ratio, .. } => assert!(t6_ratio < 1e-12, "{t6_ratio}"),
            e => panic!("{e:?}"),
        }
    }
}
