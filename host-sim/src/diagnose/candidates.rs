//! Every effect of the catalogue (`shared/contracts/effects.md`) tested against the
//! calibrated nominal model, each on the relation or the lines where it acts:
//!
//! | effect | evidence | parameter's tolerance band |
//! |---|---|---|
//! | `extra_leakage` | hydraulic relation, leakage released upward | leakage ±20 % |
//! | `entrained_air` | hydraulic relation (on a moving piston read for its position), bulk modulus released | β ±5 % |
//! | `accumulator_precharge` | hydraulic relation, precharge released | p_0 ±5 % |
//! | `pressure_sensor_lag` | hydraulic relation, lag released | 0–2.5 ms |
//! | `shaft_friction` | mechanical relation, Coulomb torque released | 0–0.02 N·m |
//! | `cylinder_friction` | cylinder relation, Coulomb and breakaway force released together (the breakaway where the piston rests), read at the rig file's transducer zero unless a reversal tells the zero apart | each 0–3× the rig's, with the transducer zero ±30 kPa |
//! | `dead_time` | electrical relation and the 6·p_n voltage lines (voltages logged), else the d/q current lines at 6·p_n | 0–0.1 µs |
//! | `cogging_torque` | torque line at the slot order | 0.01 N·m |
//! | `flux_harmonics` | torque line at 6·p_n ∝ mean torque, and (angle logged) its back-EMF's current lines | 0.5 % |
//! | `piston_ripple` | torque line at 2z ∝ Δp | the kinematic ripple |
//! | `current_sensor_offset` | torque line at p_n (the current that did not flow) | 0.03 A |
//!
//! Each test yields the generalised likelihood ratio Λ on the identification segment (the
//! objectives' difference for a released parameter, the line's power for a line), its
//! degrees of freedom, the parameter's estimate with its standard error, and the gain on
//! the validation segment in the same units. A relation's releases are read into that
//! form by `release_verdict`; the lines' and the dead time's tests are read here.

use crate::diagnose::angle_locked::{
    fit_line, line_gain, offset_from_line, plant_phase, LineEffect, LineFit, LineReading,
    ShaftConstants, OFFSET_HYPOTHESES, UNSEEN_ARRANGEMENT,
};
use crate::diagnose::calibration::{Calibration, Release};
use crate::diagnose::cylinder;
use crate::diagnose::dead_time::{dead_time_gain, fit_dead_time, standard_error, DeadTimeFit};
use crate::diagnose::electrical::{ix as elec, DEAD_TIME_BAND_S};
use crate::diagnose::emf_law::{EmfLaw, EmfLine};
use crate::diagnose::hydraulic::nominal_leakage;
use crate::diagnose::hydraulic_relation::hyd;
use crate::diagnose::lines::WindowLines;
use crate::diagnose::mechanical_relation::mech;
use crate::diagnose::speed_angle::AngleSource;
use plant_model::pump::kinematic_ripple_ratio;
use plant_model::Rig;

/// Smallest line amplitudes a healthy rig is granted, per line effect.
pub const COGGING_BAND_NM: f64 = 0.01;
/// Flux harmonics' torque ratio a healthy motor is granted. [1]
pub const FLUX_BAND: f64 = 0.005;
/// Current-sensor offset a calibrated channel is granted. [A]
pub const OFFSET_BAND_A: f64 = 0.03;

/// The usual odd piston counts of axial piston pumps, the ones the diagnosis tries.
pub const RIPPLE_PISTONS: [u32; 3] = [7, 9, 11];

/// How an effect, once named, extends the model's predictions.
#[derive(Clone, Debug)]
pub enum Extension {
    /// The hydraulic relation at these values.
    Hydraulic(Vec<f64>),
    /// The mechanical relation at these values.
    Mechanical(Vec<f64>),
    /// The electrical relation at these values.
    Electrical(Vec<f64>),
    /// The cylinder relation at these values.
    Cylinder(Vec<f64>),
    /// A torque line on the shaft.
    TorqueLine(LineFit),
    /// The dead time's current lines.
    CurrentLines(DeadTimeFit),
}

/// One effect, tested.
#[derive(Clone, Debug)]
pub struct Tested {
    /// The catalogue's name.
    pub effect: &'static str,
    /// Its parameters by the catalogue's names (SI).
    pub parameters: Vec<(&'static str, f64)>,
    /// Generalised likelihood ratio on the identification segment. [1]
    pub lambda: f64,
    /// Its degrees of freedom under the nominal model.
    pub dof: usize,
    /// Whether the parameter lies beyond its tolerance band by two standard errors.
    pub outside_band: bool,
    /// Gain on the validation segment, same units as `lambda` (`None`: nothing to score).
    pub validation_gain: Option<f64>,
    /// Standard error of a validation loss from the two fits' parameter uncertainty, same
    /// units (`None`: not a loss, or not a relation's test).
    pub validation_spread: Option<f64>,
    /// A structural reason it cannot be the cause, when one holds.
    pub veto: Option<String>,
    /// What was measured, in words.
    pub evidence: String,
    /// How it extends the model.
    pub extension: Extension,
    /// Standard error of each parameter in `parameters` that has one (SI; infinite where
    /// the log leaves it unbounded).
    pub standard_errors: Vec<(&'static str, f64)>,
    /// The release a relation's test freed (`Nothing` for a line's), and the released fit
    /// with the residuals' variance it was weighed with: the baseline of the effects
    /// judged after it.
    pub release: Release,
    /// The released fit, for a relation's test.
    pub fit: Option<Calibration>,
    /// Effects the log cannot tell this one from.
    pub ambiguous_with: Vec<&'static str>,
}

#[cfg(test)]
impl Tested {
    /// A test of `effect` with Λ `lambda` on `dof` degrees of freedom, outside its band and
    /// otherwise blank: for the decision's unit tests.
    pub fn bare(effect: &'static str, lambda: f64, dof: usize, extension: Extension) -> Tested {
        Tested {
            effect,
            parameters: Vec::new(),
            lambda,
            dof,
            outside_band: true,
            validation_gain: None,
            validation_spread: None,
            veto: None,
            evidence: String::new(),
            extension,
            standard_errors: Vec::new(),
            release: Release::Nothing,
            fit: None,
            ambiguous_with: Vec::new(),
        }
    }
}

/// The catalogue's effect a release tests, the indices of the parameters it may release
/// (the first the main one) and the extension at the released values `v`.
pub(super) fn released_effect(
    release: Release,
    v: &[f64],
) -> (&'static [usize], &'static str, Extension) {
    let v = v.to_vec();
    match release {
        Release::Leakage => (&[hyd::LEAKAGE], "extra_leakage", Extension::Hydraulic(v)),
        Release::BulkModulus => (&[hyd::BETA], "entrained_air", Extension::Hydraulic(v)),
        Release::Precharge => (
            &[hyd::PRECHARGE],
            "accumulator_precharge",
            Extension::Hydraulic(v),
        ),
        Release::SensorLag => (&[hyd::LAG], "pressure_sensor_lag", Extension::Hydraulic(v)),
        Release::ShaftFriction => (&[mech::COULOMB], "shaft_friction", Extension::Mechanical(v)),
        Release::DeadTime => (
            &[crate::diagnose::electrical::ix::DEAD_TIME],
            "dead_time",
            Extension::Electrical(v),
        ),
        // The breakaway is released with the Coulomb force: two parameters.
        Release::CylinderFriction => (
            &[cylinder::ix::COULOMB, cylinder::ix::BREAKAWAY],
            "cylinder_friction",
            Extension::Cylinder(v),
        ),
        Release::Nothing => (&[0], "none", Extension::Hydraulic(v)),
    }
}

/// The catalogue's parameters of `release` at the relation's `values` (the main parameter's
/// value first).
pub fn parameters_at(release: Release, v: &[f64], rig: &Rig) -> Vec<(&'static str, f64)> {
    let (all, _, _) = released_effect(release, v);
    let value = v[all[0]];
    match release {
        Release::Leakage => vec![("coefficient_m3_s_pa", value - nominal_leakage(rig))],
        Release::BulkModulus => {
            // Only V/β is seen: the bulk modulus the rig file's volume would need.
            let volume = v[hyd::VOLUME] / rig.cylinder.chamber_a_volume_m3;
            vec![("effective_bulk_modulus_pa", value / volume)]
        }
        Release::Precharge => vec![("precharge_pa", value)],
        Release::SensorLag => vec![("time_constant_s", value)],
        Release::ShaftFriction => vec![("coulomb_nm", value), ("static_nm", value)],
        Release::DeadTime => vec![("dead_time_s", value)],
        Release::CylinderFriction => {
            // Both levels beyond the rig file's; the plant raises a breakaway below the
            // Coulomb level to it.
            let c = &rig.cylinder;
            let coulomb = (value - c.coulomb_friction_n).max(0.0);
            let static_n = (cylinder::breakaway_level(v) - c.static_friction_n).max(coulomb);
            vec![("coulomb_n", coulomb), ("static_n", static_n)]
        }
        Release::Nothing => Vec::new(),
    }
}

/// `t`, a relation's test, read again at `fit`: the same relation driven further than the
/// fit it was tested with (the extended model the report predicts with). The parameters,
/// the extension and the fit move; the test's verdict and evidence stay as they were.
pub fn reread(t: &mut Tested, fit: &Calibration, rig: &Rig) {
    let v = &fit.fitted.values;
    let (_, _, extension) = released_effect(t.release, v);
    t.parameters = parameters_at(t.release, v, rig);
    t.extension = extension;
    t.fit = Some(fit.clone());
}

/// `v` with four decimals, or in scientific notation where that would lose it (below 10⁻²
/// or from 10⁴ on: dead times in seconds, leakages in m³/(s·Pa), pressures in pascals); a
/// whole number below 10⁴ (a count of pistons, a slot order, a band's end) as it is.
pub(crate) fn short(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e4 {
        format!("{v:.0}")
    } else if v.abs() < 1e-2 || v.abs() >= 1e4 {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// The line effects' tests on the steady windows split at the validation segment. With the
/// voltages logged (`electrical`: the electrical relation's calibrated values) the dead
/// time is read from the flux harmonics' voltage lines ([`dead_time_tested`]), beside the
/// relation's own test, instead of from the current lines.
pub fn test_lines(
    identification: &[&WindowLines],
    validation: &[&WindowLines],
    rig: &Rig,
    shaft: ShaftConstants,
    orders: &[u32],
    reading: LineReading,
    electrical: Option<&[f64]>,
) -> Vec<Tested> {
    let mut effects = vec![LineEffect::CurrentOffset, LineEffect::FluxHarmonics];
    effects.push(LineEffect::Cogging(rig.motor.cogging_fundamental_order()));
    effects.extend(RIPPLE_PISTONS.iter().map(|z| LineEffect::PistonRipple(*z)));
    let mut out = Vec::new();
    for e in effects {
        let Some(f) = fit_line(e, identification, rig, shaft, orders, reading) else {
            continue;
        };
        let val = line_gain(&f, validation, rig, shaft, orders);
        if let (Some(law), Some(values)) = (f.emf_law, electrical) {
            out.extend(dead_time_tested(
                &law,
                f.windows,
                &val.voltage_lines,
                values,
            ));
        }
        out.push(line_verdict(f, val.gain, rig, shaft.kt));
    }
    if electrical.is_none() {
        if let Some(f) = fit_dead_time(identification, rig, orders) {
            let gain = dead_time_gain(&f, validation, rig, orders);
            out.push(dead_time_verdict(f, gain, identification.len()));
        }
    }
    out
}

fn line_verdict(f: LineFit, validation_gain: Option<f64>, rig: &Rig, kt: f64) -> Tested {
    // Standard error of the amplitude: one over the root of the information.
    let info = f.information;
    let se = if info > 0.0 {
        1.0 / info.sqrt()
    } else {
        f64::INFINITY
    };
    let a = f.amplitude.norm();
    let order = f.effect.order(rig);
    let (parameters, floor, what) = match f.effect {
        LineEffect::CurrentOffset => {
            let (off, label) = offset_from_line(f.amplitude, kt, f.angle.is_logged());
            let per_nm = off.abs() / a.max(f64::MIN_POSITIVE);
            // Without the angle the line's phase cannot tell the sensor arrangement: the
            // same line is a larger offset behind a three-sensor Clarke transform.
            let other = if f.angle.is_logged() {
                String::new()
            } else {
                let three = OFFSET_HYPOTHESES[0];
                format!(
                    "; the angle is not logged, so the arrangement is not seen: behind \
                     three sensors the same line is {:+.3} A",
                    off * OFFSET_HYPOTHESES[UNSEEN_ARRANGEMENT].2 / three.2
                )
            };
            (
                vec![("offset_a", off)],
                OFFSET_BAND_A / per_nm.max(f64::MIN_POSITIVE),
                format!("offset {off:+.3} A ({label}{other})"),
            )
        }
        LineEffect::FluxHarmonics => {
            let phase = plant_phase(f.effect, f.amplitude, rig);
            (
                vec![("t6_ratio", a), ("phase_rad", phase)],
                FLUX_BAND,
                format!("{:.2} % of the mean torque", 100.0 * a),
            )
        }
        LineEffect::Cogging(k) => {
            let phase = plant_phase(f.effect, f.amplitude, rig);
            (
                vec![
                    ("amplitude_nm", a),
                    ("order", k as f64),
                    ("phase_rad", phase),
                ],
                COGGING_BAND_NM,
                format!("{a:.3} N·m"),
            )
        }
        LineEffect::PistonRipple(z) => (
            vec![("pistons", z as f64), ("amplitude_ratio", a)],
            kinematic_ripple_ratio(z),
            format!(
                "{:.2} % peak-to-peak flow ripple ({:.1}× kinematic)",
                100.0 * a,
                a / kinematic_ripple_ratio(z)
            ),
        ),
    };
    let with_emf = f.emf.describe();
    let law = f.emf_law.map_or(String::new(), |l| {
        format!(
            "; its voltage lines as a back-EMF Λ = {:.1}, as a dead time's Λ = {:.1} \
             ({:.3e} s, fade band {:.2} A)",
            l.emf_lambda,
            l.dead_time_lambda,
            l.dead_time_s,
            l.band_a()
        )
    });
    let evidence = format!(
        "unexplained torque line at order {order}{with_emf} over {} steady window(s){}: {what}; \
         Λ = {:.1} ({} degrees of freedom){law}",
        f.windows,
        match f.angle {
            AngleSource::Logged => ", phase-locked to the logged angle",
            AngleSource::Counted => ", phase-locked to the angle counted back from the speed",
            AngleSource::Integrated => "",
        },
        f.lambda,
        f.dof
    );
    let standard_errors = parameters
        .iter()
        .filter(|(name, _)| !matches!(*name, "order" | "pistons" | "phase_rad"))
        .map(|(name, v)| (*name, se * v.abs() / a.max(f64::MIN_POSITIVE)))
        .collect();
    Tested {
        effect: f.effect.name(),
        parameters,
        lambda: f.lambda,
        dof: f.dof,
        outside_band: a - 2.0 * se > floor,
        validation_gain,
        validation_spread: None,
        veto: None,
        evidence,
        extension: Extension::TorqueLine(f),
        standard_errors,
        release: Release::Nothing,
        fit: None,
        ambiguous_with: Vec::new(),
    }
}

/// The dead time the flux harmonics' voltage lines read as, tested like any effect: its
/// Λ on the identification windows, its gain on the validation windows' lines
/// (`validation`), and the electrical relation's calibrated `values` with that dead time
/// as the extended model. `None` when the lines read as no dead time.
pub fn dead_time_tested(
    law: &EmfLaw,
    windows: usize,
    validation: &[EmfLine],
    values: &[f64],
) -> Option<Tested> {
    if law.dead_time_s <= 0.0 {
        return None;
    }
    let se = standard_error(law.dead_time_s, law.dead_time_lambda);
    let mut extended = values.to_vec();
    *extended.get_mut(elec::DEAD_TIME)? = law.dead_time_s;
    Some(Tested {
        effect: "dead_time",
        parameters: vec![("dead_time_s", law.dead_time_s)],
        lambda: law.dead_time_lambda,
        dof: 1,
        outside_band: law.dead_time_s - 2.0 * se > DEAD_TIME_BAND_S,
        validation_gain: law.gain(validation),
        validation_spread: None,
        veto: None,
        evidence: format!(
            "d and q voltage lines at order 6·p_n over {windows} steady window(s) as an \
             inverter's dead-time voltage read from the logged currents (fade band {:.2} A): \
             Λ = {:.1}, against Λ = {:.1} for a back-EMF's lines",
            law.band_a(),
            law.dead_time_lambda,
            law.emf_lambda
        ),
        extension: Extension::Electrical(extended),
        standard_errors: vec![("dead_time_s", se)],
        release: Release::Nothing,
        fit: None,
        ambiguous_with: Vec::new(),
    })
}

fn dead_time_verdict(f: DeadTimeFit, validation_gain: Option<f64>, windows: usize) -> Tested {
    let evidence = format!(
        "d- and q-current lines at order 6·p_n over {windows} steady window(s) as the current \
         loops pass an inverter's dead-time voltage (fade band {:.2} A): Λ = {:.1}",
        f.band_a, f.lambda
    );
    let se_scale = standard_error(f.dead_time_s, f.lambda);
    Tested {
        effect: "dead_time",
        parameters: vec![("dead_time_s", f.dead_time_s)],
        lambda: f.lambda,
        dof: 1,
        outside_band: f.dead_time_s - 2.0 * se_scale > DEAD_TIME_BAND_S,
        validation_gain,
        validation_spread: None,
        veto: None,
        evidence,
        extension: Extension::CurrentLines(f),
        standard_errors: vec![("dead_time_s", se_scale)],
        release: Release::Nothing,
        fit: None,
        ambiguous_with: Vec::new(),
    }
}
