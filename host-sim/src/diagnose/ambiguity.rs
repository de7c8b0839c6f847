//! What the log cannot tell apart: a named cause with an alternative that fits it as well.
//!
//! Three kinds of alternative, each found from numbers the selection already has:
//!
//! - **Two catalogue effects on the same signature.** A dead time and the flux harmonics
//!   both explain the lines at order 6·p_n; two hydraulic releases may each explain the
//!   pressure alone. They are ambiguous when their margins over their own χ² thresholds
//!   (Λ less the quantile of its degrees of freedom, the first-round Λ for a hydraulic
//!   release, each against the same calibrated baseline) differ by less than
//!   [`AMBIGUITY_MARGIN`] or [`AMBIGUITY_FRACTION`] of the larger: a difference the log's
//!   own likelihood does not resolve. Both are listed, each `ambiguous_with` the other;
//!   the one ahead stays named.
//! - **Entrained air against the line volume.** With the cylinder blocked the pressure
//!   reads only the oil's compliance V_h/β (eq. 11): a bulk modulus β̂ below the rig's is
//!   the same log as a high-side volume V_h·β/β̂ at the listed β. The rig's line volume is
//!   not a catalogue effect, so the evidence says it. On a stroke the piston's position
//!   reads the compliance (`hydraulic/stroke.rs`), and its travel A·x, a small part of the
//!   chamber, separates the two only in part: the evidence says the bulk modulus reads low
//!   by what a longer line adds.
//! - **Coulomb against viscous friction at one speed.** T_c·sign(ω) and B·ω are the same
//!   column when |ω| takes one value: a shaft friction read from steady windows at one
//!   speed (their speeds within [`ONE_SPEED_SPREAD`] of their mean) is as well a viscous
//!   friction T_c/|ω|; a second speed separates them.

use super::candidates::Tested;
use super::decision::{threshold, why_not};
use super::facts::LogFacts;

/// Difference of margins over threshold below which two explanations are not told apart:
/// the χ²(1) quantile at 95 %. [1]
pub const AMBIGUITY_MARGIN: f64 = 3.84;

/// Relative difference of margins below which two explanations are not told apart on a
/// log the model leaves residual structure in (Λ in the thousands, where a few percent is
/// the model's mismatch, not evidence). [1]
pub const AMBIGUITY_FRACTION: f64 = 0.1;

/// Spread of the steady windows' speeds about their mean (as a fraction of it) within
/// which the log turns the shaft at one speed. [1]
pub const ONE_SPEED_SPREAD: f64 = 0.15;

/// Pairs of catalogue effects that can explain the same signature, and the test that
/// separates them.
const PAIRS: &[(&str, &str, &str)] = &[
    (
        "dead_time",
        "flux_harmonics",
        "a second speed separates them (the back-EMF's harmonic grows with speed, the dead \
         time's voltage does not), as do the stator voltage columns",
    ),
    (
        "entrained_air",
        "accumulator_precharge",
        "a pressure level below the precharge separates them (the absorber closed, only the \
         oil's compliance left)",
    ),
    (
        "entrained_air",
        "extra_leakage",
        "a hold at a second pressure level separates them (leakage drains at a rate, air \
         only delays)",
    ),
    (
        "extra_leakage",
        "accumulator_precharge",
        "a hold at a second pressure level separates them",
    ),
    (
        "pressure_sensor_lag",
        "entrained_air",
        "a faster pressure step separates them (the transducer's lag does not move the \
         pump, the oil's compliance does)",
    ),
];

/// Margin of a test over its own threshold.
fn margin(lambda: f64, dof: usize) -> f64 {
    lambda - threshold(dof)
}

/// Whether two margins are within each other's resolution.
fn alike(a: f64, b: f64) -> bool {
    a > 0.0 && b > 0.0 && (a - b).abs() < AMBIGUITY_MARGIN.max(AMBIGUITY_FRACTION * a.max(b))
}

/// Marks the ambiguities among `tested` (the selection's `named` indices ahead; `first`
/// each test's Λ against the calibrated baseline, before the forward rounds re-tested the
/// hydraulic releases against the model extended by the named ones; `bulk_modulus_pa` the
/// rig file's β). [Pa]
pub(super) fn mark(
    tested: &mut [Tested],
    named: &[usize],
    first: &[f64],
    facts: &LogFacts,
    bulk_modulus_pa: f64,
) {
    for &(a, b, separates) in PAIRS {
        let (Some(i), Some(j)) = (position(tested, first, a), position(tested, first, b)) else {
            continue;
        };
        if !(named.contains(&i) || named.contains(&j)) || named.contains(&i) && named.contains(&j) {
            continue;
        }
        if !alike(
            margin(first[i], tested[i].dof),
            margin(first[j], tested[j].dof),
        ) {
            continue;
        }
        // The other one must fail only through the named one: on its own it qualified.
        let (n, o) = if named.contains(&i) { (i, j) } else { (j, i) };
        if !only_through_named(&tested[o]) {
            continue;
        }
        let margins: Vec<f64> = [n, o]
            .iter()
            .map(|&k| margin(first[k], tested[k].dof))
            .collect();
        for (k, other, mk, mo) in [
            (n, o, margins[0], margins[1]),
            (o, n, margins[1], margins[0]),
        ] {
            let name = tested[other].effect;
            if !tested[k].ambiguous_with.contains(&name) {
                tested[k].ambiguous_with.push(name);
            }
            tested[k].evidence.push_str(&format!(
                "; the log does not tell it from {name} (margins over threshold {mk:.1} and \
                 {mo:.1}): {separates}"
            ));
        }
    }
    for &i in named {
        match tested[i].effect {
            "entrained_air" if !facts.piston_moves => {
                let beta = tested[i]
                    .parameters
                    .iter()
                    .find(|(k, _)| *k == "effective_bulk_modulus_pa")
                    .map(|(_, b)| *b)
                    .filter(|b| *b > 0.0);
                if let Some(b) = beta {
                    tested[i].evidence.push_str(&format!(
                        "; with the cylinder blocked the log reads only the oil's compliance \
                         V/β: a high-side (line) volume {:.2}× the rig file's at its listed \
                         bulk modulus fits as well; a stroke with the piston moving separates \
                         them",
                        bulk_modulus_pa / b
                    ));
                }
            }
            "entrained_air" => tested[i].evidence.push_str(
                "; read from the piston's position, which lags the pump by the oil's \
                 compressed volume (V/β)·Δp/A where the port pressure moves: a longer line \
                 to chamber A (a larger V) takes part of that compliance, so the bulk \
                 modulus reads low by as much as the line adds to the chamber",
            ),
            "shaft_friction" => {
                if let Some(speed) = one_speed(facts) {
                    tested[i].evidence.push_str(&format!(
                        "; the steady windows turn the shaft at one speed ({speed:.1} rad/s): \
                         a viscous friction of the Coulomb torque over that speed fits as \
                         well; a second speed separates them"
                    ));
                }
            }
            _ => {}
        }
    }
}

/// Whether a test that is not named fails only because another effect explains it: it is
/// significant and beyond its band, the remaining reason a veto or the named ones.
fn only_through_named(t: &Tested) -> bool {
    t.outside_band && (why_not(t).is_none() || t.veto.is_some())
}

/// The test of `effect` with the largest first-round Λ (`first`): an effect read two ways
/// (a dead time by the electrical relation and from the voltage lines) is judged by the
/// stronger reading.
fn position(tested: &[Tested], first: &[f64], effect: &str) -> Option<usize> {
    (0..tested.len())
        .filter(|&k| tested[k].effect == effect)
        .max_by(|&x, &y| first[x].total_cmp(&first[y]))
}

/// The one speed the steady windows turn at (their row-weighted mean magnitude), when
/// they all lie within [`ONE_SPEED_SPREAD`] of it. [rad/s]
pub fn one_speed(facts: &LogFacts) -> Option<f64> {
    let rows: f64 = facts.steady.iter().map(|w| w.rows.len() as f64).sum();
    if facts.steady.is_empty() || rows <= 0.0 {
        return None;
    }
    let mean = facts
        .steady
        .iter()
        .map(|w| w.speed_rad_s.abs() * w.rows.len() as f64)
        .sum::<f64>()
        / rows;
    let within = facts
        .steady
        .iter()
        .all(|w| (w.speed_rad_s.abs() - mean).abs() <= ONE_SPEED_SPREAD * mean);
    (mean > 0.0 && within).then_some(mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn margins_within_resolution_are_alike() {
        // Absolute: 3.84 apart at small margins; relative: 10 % at large ones.
        assert!(alike(20.0, 17.0));
        assert!(!alike(20.0, 15.0));
        assert!(alike(1000.0, 920.0));
        assert!(!alike(1000.0, 850.0));
        // A test below its threshold is not an alternative.
        assert!(!alike(20.0, -1.0));
    }

    #[test]
    fn an_effect_read_two_ways_is_judged_by_its_stronger_reading() {
        use crate::diagnose::candidates::Extension;
        let dead = || Tested::bare("dead_time", 0.0, 1, Extension::Electrical(Vec::new()));
        let flux = Tested::bare("flux_harmonics", 0.0, 4, Extension::Electrical(Vec::new()));
        let tested = [dead(), flux, dead()];
        assert_eq!(
            position(&tested, &[32.0, 2462.0, 4599.0], "dead_time"),
            Some(2)
        );
        assert_eq!(
            position(&tested, &[32.0, 2462.0, 3.0], "dead_time"),
            Some(0)
        );
        assert_eq!(
            position(&tested, &[32.0, 2462.0, 3.0], "cogging_torque"),
            None
        );
    }
}
