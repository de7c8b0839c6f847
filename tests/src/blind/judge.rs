//! How a diagnosis is judged against what a log hides, read only through the contract's
//! JSON (`shared/contracts/eha-cli.md`): the suite depends on the contract, not on the
//! diagnosis's Rust types, and the truth comes from the generator (or a `truth.json`),
//! never from the diagnosis.
//!
//! A log is right when `extended.effects` names exactly the hidden effects (an empty list:
//! `none`) and each hidden effect's parameters, as its cause in `causes` gives them, are
//! within the standard: [`Standard::Every`] (the blind suite's) holds every parameter —
//! integers (`pistons`, `order`) exactly, phases within [`PHASE_TOLERANCE_RAD`] modulo 2π
//! (a negative fitted amplitude with the phase turned by π is the same harmonic), the rest
//! within [`PARAMETER_TOLERANCE`] — except those no test makes observable
//! ([`UNOBSERVABLE_PARAMETERS`]); [`Standard::Main`] (the foreign sets') holds only each
//! effect's main parameter within [`PARAMETER_TOLERANCE`].

use plant_model::pump::kinematic_ripple_ratio;
use plant_model::Rig;
use serde_json::Value;
use std::collections::BTreeMap;
use std::f64::consts::{PI, TAU};

/// Relative tolerance on a fitted continuous parameter. [1]
pub const PARAMETER_TOLERANCE: f64 = 0.25;
/// Tolerance on a fitted phase, modulo 2π. [rad]
pub const PHASE_TOLERANCE_RAD: f64 = 0.35;

/// Parameters no test makes observable, as (effect, parameter): the shaft's breakaway
/// torque. The speed loop's current step passes any breakaway level within one
/// current-loop period, and a pressure test's shaft never stops: the noise-free logs of
/// Coulomb 0.15 N·m with breakaway 0.24 N·m and with breakaway 0.15 N·m differ by less
/// than the quantisation floor. Shown, not held.
pub const UNOBSERVABLE_PARAMETERS: [(&str, &str); 1] = [("shaft_friction", "static_nm")];

/// Which parameters a judgement holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Standard {
    /// Every parameter (the blind suite).
    Every,
    /// The main parameter of each effect (the foreign sets, the held-out table).
    Main,
}

/// The parameter an effect is judged on under [`Standard::Main`]: its size (the pistons'
/// count and the phases are not sizes).
pub fn main_parameter(effect: &str) -> Option<&'static str> {
    Some(match effect {
        "piston_ripple" => "amplitude_ratio",
        "cogging_torque" => "amplitude_nm",
        "flux_harmonics" => "t6_ratio",
        "dead_time" => "dead_time_s",
        "shaft_friction" => "coulomb_nm",
        "cylinder_friction" => "coulomb_n",
        "extra_leakage" => "coefficient_m3_s_pa",
        "entrained_air" => "effective_bulk_modulus_pa",
        "accumulator_precharge" => "precharge_pa",
        "pressure_sensor_lag" => "time_constant_s",
        "current_sensor_offset" => "offset_a",
        _ => return None,
    })
}

/// One effect with its parameters (SI, by contract name).
#[derive(Clone, Debug, PartialEq)]
pub struct Named {
    /// Catalogue name.
    pub effect: String,
    /// Parameters.
    pub parameters: Vec<(String, f64)>,
}

/// One cause of the diagnosis's `causes`.
#[derive(Clone, Debug, PartialEq)]
pub struct SaidCause {
    /// The effect and its fitted parameters.
    pub named: Named,
    /// Its evidence line.
    pub evidence: String,
    /// `ambiguous_with`, when given.
    pub ambiguous_with: Vec<String>,
}

/// What a diagnosis said, from its contract JSON.
#[derive(Clone, Debug, PartialEq)]
pub struct Said {
    /// `extended.effects`.
    pub effects: Vec<String>,
    /// `causes`, in rank order.
    pub causes: Vec<SaidCause>,
    /// `baseline.fit_percent_by_signal`. [%]
    pub baseline_fit: BTreeMap<String, f64>,
    /// `extended.fit_percent_by_signal`. [%]
    pub extended_fit: BTreeMap<String, f64>,
}

impl Said {
    /// The first cause naming `effect`.
    pub fn cause(&self, effect: &str) -> Option<&SaidCause> {
        self.causes.iter().find(|c| c.named.effect == effect)
    }
}

fn numbers(v: Option<&Value>) -> Vec<(String, f64)> {
    v.and_then(Value::as_object)
        .map(|m| {
            m.iter()
                .filter_map(|(k, v)| v.as_f64().map(|v| (k.clone(), v)))
                .collect()
        })
        .unwrap_or_default()
}

fn strings(v: Option<&Value>) -> Result<Vec<String>, String> {
    v.and_then(Value::as_array)
        .ok_or("not an array")?
        .iter()
        .map(|e| e.as_str().map(str::to_string).ok_or("not a string".into()))
        .collect()
}

fn fits(json: &Value, model: &str) -> BTreeMap<String, f64> {
    numbers(json.pointer(&format!("/{model}/fit_percent_by_signal")))
        .into_iter()
        .collect()
}

/// Reads what a diagnosis said from its contract JSON.
pub fn read_said(json: &Value) -> Result<Said, String> {
    let effects = strings(json.pointer("/extended/effects"))
        .map_err(|e| format!("`extended.effects`: {e}"))?;
    let causes = json
        .get("causes")
        .and_then(Value::as_array)
        .ok_or("`causes` is not an array")?
        .iter()
        .map(|c| {
            let effect = c
                .get("effect")
                .and_then(Value::as_str)
                .ok_or("a cause's `effect` is not a string")?;
            Ok(SaidCause {
                named: Named {
                    effect: effect.to_string(),
                    parameters: numbers(c.get("parameters")),
                },
                evidence: c
                    .get("evidence")
                    .and_then(Value::as_str)
                    .unwrap_or_default()
                    .to_string(),
                ambiguous_with: strings(c.get("ambiguous_with")).unwrap_or_default(),
            })
        })
        .collect::<Result<_, String>>()?;
    Ok(Said {
        effects,
        causes,
        baseline_fit: fits(json, "baseline"),
        extended_fit: fits(json, "extended"),
    })
}

/// A parameter's value as the plant understands it: `amplitude_ratio = 0` is the kinematic
/// ripple of the pistons, `order = 0` the cogging fundamental LCM(slots, 2·pole pairs).
fn effective(name: &str, value: f64, params: &[(String, f64)]) -> f64 {
    match (name, value) {
        ("amplitude_ratio", 0.0) => {
            let z = params
                .iter()
                .find(|(k, _)| k == "pistons")
                .map_or(0.0, |(_, z)| *z);
            kinematic_ripple_ratio(z as u32)
        }
        ("order", 0.0) => Rig::nominal().motor.cogging_fundamental_order() as f64,
        (_, v) => v,
    }
}

/// The fitted parameters with a negative harmonic amplitude turned positive and its phase
/// by π (the same harmonic).
fn normalised(params: &[(String, f64)]) -> Vec<(String, f64)> {
    let flip = params
        .iter()
        .any(|(k, v)| (k == "amplitude_nm" || k == "t6_ratio") && *v < 0.0);
    params
        .iter()
        .map(|(k, v)| match k.as_str() {
            "amplitude_nm" | "t6_ratio" if flip => (k.clone(), -v),
            "phase_rad" if flip => (k.clone(), v + PI),
            _ => (k.clone(), *v),
        })
        .collect()
}

/// Distance of two angles modulo 2π. [rad]
pub fn angle_distance(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

/// Each truth parameter of `truth` held by `standard` against `fitted`; the failures,
/// described.
pub fn parameter_failures(
    truth: &Named,
    fitted: &[(String, f64)],
    standard: Standard,
) -> Vec<String> {
    let fitted = normalised(fitted);
    let main = main_parameter(&truth.effect);
    let mut out = Vec::new();
    for (name, t) in &truth.parameters {
        let held = match standard {
            Standard::Every => !UNOBSERVABLE_PARAMETERS.contains(&(truth.effect.as_str(), name)),
            Standard::Main => main == Some(name.as_str()),
        };
        if !held {
            continue;
        }
        let t = effective(name, *t, &truth.parameters);
        let Some((_, f)) = fitted.iter().find(|(k, _)| k == name) else {
            out.push(format!("{}: `{name}` not fitted", truth.effect));
            continue;
        };
        let f = effective(name, *f, &fitted);
        let ok = match name.as_str() {
            "pistons" | "order" => f == t,
            "phase_rad" => angle_distance(f, t) <= PHASE_TOLERANCE_RAD,
            _ => (f - t).abs() <= PARAMETER_TOLERANCE * t.abs(),
        };
        if !ok {
            out.push(format!(
                "{}: `{name}` fitted {f:.4e}, truth {t:.4e}",
                truth.effect
            ));
        }
    }
    out
}

/// Everything wrong with `said` against the hidden `truth` under `standard`: the named set
/// when it is not exactly the hidden one, else each hidden effect's parameters.
pub fn failures(truth: &[Named], said: &Said, standard: Standard) -> Vec<String> {
    let mut hidden: Vec<&str> = truth.iter().map(|n| n.effect.as_str()).collect();
    let mut named: Vec<&str> = said.effects.iter().map(String::as_str).collect();
    hidden.sort_unstable();
    named.sort_unstable();
    if hidden != named {
        let show = |v: &[&str]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join("+")
            }
        };
        return vec![format!("named {} (hidden {})", show(&named), show(&hidden))];
    }
    truth
        .iter()
        .flat_map(|t| match said.cause(&t.effect) {
            Some(c) => parameter_failures(t, &c.named.parameters, standard),
            None => vec![format!(
                "{}: named but no cause gives its parameters",
                t.effect
            )],
        })
        .collect()
}

/// The hidden effects of one entry of a `truth.json` in the foreign-logs layout: an
/// `effect` with its `parameters`, or for a pair an `effects` list of such; `none` is no
/// effect.
pub fn truth_of_entry(entry: &Value) -> Result<Vec<Named>, String> {
    let one = |v: &Value| -> Result<Named, String> {
        let effect = v
            .get("effect")
            .and_then(Value::as_str)
            .ok_or("no \"effect\" string")?;
        Ok(Named {
            effect: effect.to_string(),
            parameters: numbers(v.get("parameters")),
        })
    };
    if let Some(list) = entry.get("effects").and_then(Value::as_array) {
        return list.iter().map(one).collect();
    }
    let single = one(entry)?;
    Ok(if single.effect == "none" {
        Vec::new()
    } else {
        vec![single]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn named(effect: &str, p: &[(&str, f64)]) -> Named {
        Named {
            effect: effect.into(),
            parameters: p.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
        }
    }

    fn said(effects: &[Named]) -> Said {
        Said {
            effects: effects.iter().map(|n| n.effect.clone()).collect(),
            causes: effects
                .iter()
                .map(|n| SaidCause {
                    named: n.clone(),
                    evidence: String::new(),
                    ambiguous_with: Vec::new(),
                })
                .collect(),
            baseline_fit: BTreeMap::new(),
            extended_fit: BTreeMap::new(),
        }
    }

    #[test]
    fn the_judge_accepts_the_same_harmonic_and_refuses_a_wrong_parameter() {
        let truth = named(
            "cogging_torque",
            &[("amplitude_nm", 0.1), ("order", 72.0), ("phase_rad", 6.2)],
        );
        let fitted = |a: f64, o: f64, ph: f64| {
            named(
                "cogging_torque",
                &[("amplitude_nm", a), ("order", o), ("phase_rad", ph)],
            )
            .parameters
        };
        let every = Standard::Every;
        // 6.2 rad and 0.1 rad are 0.183 rad apart across 2π; order 0 is LCM(9, 8) = 72;
        // −0.11 N·m at phase 6.2 − π is +0.11 N·m at 6.2 (10 % off).
        assert!(parameter_failures(&truth, &fitted(0.085, 72.0, 0.1), every).is_empty());
        assert!(parameter_failures(&truth, &fitted(0.1, 0.0, 6.2), every).is_empty());
        assert!(parameter_failures(&truth, &fitted(-0.11, 72.0, 6.2 - PI), every).is_empty());
        // 30 % off, order 36, 0.5 rad off, a parameter missing: each refused.
        assert_eq!(
            parameter_failures(&truth, &fitted(0.13, 72.0, 6.2), every).len(),
            1
        );
        assert_eq!(
            parameter_failures(&truth, &fitted(0.1, 36.0, 6.2), every).len(),
            1
        );
        assert_eq!(
            parameter_failures(&truth, &fitted(0.1, 72.0, 5.7), every).len(),
            1
        );
        assert_eq!(
            parameter_failures(&truth, &fitted(0.1, 72.0, 6.2)[..2], every).len(),
            1
        );
        // The main-parameter standard holds the amplitude only.
        assert!(parameter_failures(&truth, &fitted(0.1, 36.0, 5.7), Standard::Main).is_empty());
        // Kinematic ripple of 9 pistons: (π/18)·tan(π/36) = 1.527 %; `amplitude_ratio = 0` is it.
        let ripple = named(
            "piston_ripple",
            &[("pistons", 9.0), ("amplitude_ratio", 0.01527)],
        );
        let zero = named(
            "piston_ripple",
            &[("pistons", 9.0), ("amplitude_ratio", 0.0)],
        );
        assert!(parameter_failures(&ripple, &zero.parameters, every).is_empty());
    }

    #[test]
    fn a_pair_is_right_only_when_exactly_both_are_named() {
        let leak = named("extra_leakage", &[("coefficient_m3_s_pa", 4e-13)]);
        let offset = named("current_sensor_offset", &[("offset_a", 0.5)]);
        let air = named("entrained_air", &[("effective_bulk_modulus_pa", 3e8)]);
        let pair = [leak.clone(), offset.clone()];
        let std = Standard::Every;
        assert!(failures(&pair, &said(&[offset.clone(), leak.clone()]), std).is_empty());
        assert_eq!(
            failures(&pair, &said(std::slice::from_ref(&leak)), std).len(),
            1
        );
        assert_eq!(
            failures(
                &pair,
                &said(&[leak.clone(), offset.clone(), air.clone()]),
                std
            )
            .len(),
            1
        );
        assert_eq!(failures(&[], &said(&[air]), std).len(), 1);
        assert!(failures(&[], &said(&[]), std).is_empty());
        // Both named, one 40 % off: that effect's parameter fails.
        let far = named("current_sensor_offset", &[("offset_a", 0.7)]);
        assert_eq!(failures(&pair, &said(&[leak, far]), std).len(), 1);
    }

    #[test]
    fn truth_json_entries_read_as_their_effects() {
        let single: Value =
            serde_json::from_str(r#"{"effect": "dead_time", "parameters": {"dead_time_s": 1e-6}}"#)
                .expect("json");
        let pair: Value = serde_json::from_str(
            r#"{"effect": "a+b", "effects": [{"effect": "dead_time", "parameters": {}},
                {"effect": "extra_leakage", "parameters": {"coefficient_m3_s_pa": 1e-13}}]}"#,
        )
        .expect("json");
        let none: Value =
            serde_json::from_str(r#"{"effect": "none", "parameters": {}}"#).expect("json");
        assert_eq!(truth_of_entry(&single).expect("single").len(), 1);
        assert_eq!(truth_of_entry(&pair).expect("pair").len(), 2);
        assert!(truth_of_entry(&none).expect("none").is_empty());
    }
}
