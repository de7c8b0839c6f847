//! The catalogue's angle-locked effects fitted to the torque lines of the steady windows
//! ([`super::lines`]), each a line whose complex amplitude follows a known regressor from
//! window to window:
//!
//! | effect | order | the unexplained torque line is |
//! |---|---|---|
//! | cogging | slot order (72) | −T_cog: a constant amplitude (eq. 16) |
//! | flux harmonics | 6·p_n (24) | −T_6 = −r·T_e: proportional to the mean torque (eq. 19) |
//! | piston ripple | 2z (18) | −D/2π·(s(θ) − 1)·Δp: proportional to the pressure difference (eq. 20) |
//! | current-sensor offset | p_n (4) | K_t times the offset's d-q image (the measured current is not the one that flowed) |
//!
//! With the angle logged the line's phase is locked to the shaft, and the windows are
//! combined coherently (weighted least squares of the complex amplitude on the regressor);
//! without it (the angle integrated from the speed) only their magnitudes are. The
//! statistic is the generalised likelihood ratio of the line against the noise, whose
//! variance per window is the neighbouring orders' mean power plus what the tolerances of
//! K_t and J could leave of the measured current and angle lines ([`TORQUE_TOLERANCE`]):
//! a voltage disturbance moving current and angle together cannot pass for a torque.

use crate::diagnose::back_emf::{
    back_emf_lines, explained_power, voltage_lines, weighted_amplitude, LineObservation, Stator,
};
use crate::diagnose::emf_law::{emf_law, EmfLaw, EmfLine};
use crate::diagnose::lines::{OrderLines, WindowLines, DEAD_TIME_BANDS_A};
use crate::diagnose::speed_angle::AngleSource;
use plant_model::motor::Motor;
use plant_model::Rig;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// The shaft's constants the lines are read with: K_t, J, D/2π.
#[derive(Clone, Copy, Debug)]
pub struct ShaftConstants {
    /// Torque constant. [N·m/A]
    pub kt: f64,
    /// Inertia. [kg·m²]
    pub j: f64,
    /// Displacement per radian. [m³/rad]
    pub d_per_rad: f64,
}

/// Relative tolerance of the torque constant and the inertia in the torque line. [1]
pub const TORQUE_TOLERANCE: f64 = 0.1;

/// One of the angle-locked effects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineEffect {
    /// A DC offset on a phase-current channel: order p_n.
    CurrentOffset,
    /// 5th/7th flux harmonics: order 6·p_n, scaled by the mean torque.
    FluxHarmonics,
    /// Cogging at the given order.
    Cogging(u32),
    /// The pump's torque ripple of z pistons, scaled by the pressure difference.
    PistonRipple(u32),
}

impl LineEffect {
    /// The catalogue's name.
    pub fn name(self) -> &'static str {
        match self {
            LineEffect::CurrentOffset => "current_sensor_offset",
            LineEffect::FluxHarmonics => "flux_harmonics",
            LineEffect::Cogging(_) => "cogging_torque",
            LineEffect::PistonRipple(_) => "piston_ripple",
        }
    }

    /// The order it shows at on `rig`.
    pub fn order(self, rig: &Rig) -> u32 {
        let pp = rig.motor.pole_pairs;
        match self {
            LineEffect::CurrentOffset => pp,
            LineEffect::FluxHarmonics => 6 * pp,
            LineEffect::Cogging(k) => k,
            LineEffect::PistonRipple(z) => plant_model::pump::ripple_order(z),
        }
    }
}

/// The torque line's regressor in window `w`: what the effect's amplitude multiplies.
fn regressor(
    effect: LineEffect,
    w: &WindowLines,
    kt: f64,
    ripple_per_ratio: f64,
    d_per_rad: f64,
) -> f64 {
    match effect {
        LineEffect::CurrentOffset | LineEffect::Cogging(_) => 1.0,
        LineEffect::FluxHarmonics => kt * w.iq_mean_a,
        LineEffect::PistonRipple(_) => ripple_per_ratio * d_per_rad * w.dp_mean_pa,
    }
}

/// Noise variance per real component of the torque line `o` in window `w`: the floor of
/// its neighbouring orders (the candidate orders `candidates` left out), the model's
/// tolerance on the line's current and angle parts, and the torque J·(k·ω̄)² makes of the
/// line the encoder's rounding alone leaves in the angle ([`super::count_lines`]).
pub fn torque_variance(
    w: &WindowLines,
    o: &OrderLines,
    candidates: &[u32],
    kt: f64,
    j: f64,
) -> f64 {
    let floor = w.floor(o.order, candidates, |x| x.torque);
    let wk = o.order as f64 * w.window.speed_rad_s.abs();
    let current = TORQUE_TOLERANCE * kt * o.iq.norm();
    let angle = TORQUE_TOLERANCE * j * wk * wk * o.theta.norm();
    // The torque the encoder's rounding alone puts on this order's angle line.
    let counts = j * wk * wk * o.theta_counts;
    floor + 0.5 * (current * current + angle * angle + counts * counts)
}

/// A line effect fitted on some windows.
#[derive(Clone, Debug)]
pub struct LineFit {
    /// The effect.
    pub effect: LineEffect,
    /// Complex amplitude per unit regressor of the unexplained torque line (coherent), or
    /// its magnitude on the real axis (incoherent). [N·m or 1]
    pub amplitude: Complex64,
    /// Information about `amplitude` (Σ |x|²/σ² over its lines). [1/amplitude²]
    pub information: f64,
    /// Flux harmonics, phase-locked: the d-axis back-EMF's amplitude per ψ_f·ω_e, which the
    /// 5th/7th split leaves free ([`super::back_emf`]); zero otherwise. [1]
    pub back_emf_d: Complex64,
    /// Generalised likelihood ratio (twice the log-likelihood gain) on the fitted windows.
    pub lambda: f64,
    /// Degrees of freedom of `lambda` under no line (2 per complex amplitude coherent, 2
    /// per window otherwise).
    pub dof: usize,
    /// Windows used.
    pub windows: usize,
    /// Where the angle the lines were read against comes from: their phases were combined
    /// when it is logged or counted.
    pub angle: AngleSource,
    /// The flux harmonics' back-EMF lines fitted with the torque line.
    pub emf: EmfLines,
    /// Flux harmonics with the voltages: their voltage lines read as a back-EMF and as a
    /// dead time's ([`super::emf_law`]); `None` otherwise.
    pub emf_law: Option<EmfLaw>,
}

/// One line an effect explains in one window, and whether it follows the flux harmonics'
/// free d-axis amplitude instead of the effect's own.
#[derive(Clone, Copy, Debug)]
struct Observation {
    of: LineObservation,
    free_d: bool,
    /// A back-EMF voltage line: the dead time's lines on its axis per fade band. [V]
    dead_time: Option<[Complex64; DEAD_TIME_BANDS_A.len()]>,
}

/// The lines `effect` explains in window `w`: its torque line, and, for flux harmonics,
/// the back-EMF's lines `emf` says.
fn observations(
    effect: LineEffect,
    w: &WindowLines,
    rig: &Rig,
    shaft: ShaftConstants,
    candidates: &[u32],
    emf: EmfLines,
) -> Vec<Observation> {
    let ShaftConstants { kt, j, d_per_rad } = shaft;
    let Some(o) = w.at(effect.order(rig)) else {
        return Vec::new();
    };
    let ripple_per_ratio = match effect {
        LineEffect::PistonRipple(z) => super::mechanical::ripple_fundamental_per_ratio(rig, z),
        _ => 0.0,
    };
    let mut out = Vec::new();
    let var = torque_variance(w, o, candidates, kt, j);
    let x = regressor(effect, w, kt, ripple_per_ratio, d_per_rad);
    if var.is_finite() && x.abs() > 0.0 {
        out.push(Observation {
            of: LineObservation {
                line: o.torque,
                regressor: Complex64::new(x, 0.0),
                var,
            },
            free_d: false,
            dead_time: None,
        });
    }
    if effect == LineEffect::FluxHarmonics {
        let lines = match emf {
            EmfLines::None => None,
            EmfLines::Currents => back_emf_lines(w, o, rig, candidates),
            EmfLines::Voltages(s) => voltage_lines(w, o, rig, &s, candidates),
        };
        if let Some([q, d]) = lines {
            // The dead time's voltage lines on each axis (d first), with the voltages.
            let per_band = |axis: usize| {
                let v = &o.dead_time_voltages;
                (matches!(emf, EmfLines::Voltages(_)) && v.len() == DEAD_TIME_BANDS_A.len())
                    .then(|| std::array::from_fn(|b| v[b][axis]))
            };
            out.push(Observation {
                of: q,
                free_d: false,
                dead_time: per_band(1),
            });
            out.push(Observation {
                of: d,
                free_d: true,
                dead_time: per_band(0),
            });
        }
    }
    out
}

/// The weighted least-squares amplitude of `obs` (those with `free_d` as given) and its
/// information; `None` without information.
fn amplitude_of(obs: &[Observation], free_d: bool) -> Option<(Complex64, f64)> {
    weighted_amplitude(obs.iter().filter(|o| o.free_d == free_d).map(|o| &o.of))
}

/// Which lines carry the flux harmonics' back-EMF beside their torque line
/// ([`super::back_emf`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmfLines {
    /// None: the torque line alone (the lines' phases are not combined).
    None,
    /// The d- and q-current lines, as the current loops pass it (no voltages logged).
    Currents,
    /// The logged voltages' lines less the stator equations at these constants.
    Voltages(Stator),
}

impl EmfLines {
    /// The lines' description in the evidence.
    pub fn describe(self) -> &'static str {
        match self {
            EmfLines::None => "",
            EmfLines::Currents => " with its back-EMF's d- and q-current lines",
            EmfLines::Voltages(_) => " with its back-EMF in the d and q voltages",
        }
    }
}

/// How the lines of a log are read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineReading {
    /// Where the log's angle comes from: logged or counted, the windows' phases are combined.
    pub angle: AngleSource,
    /// The back-EMF lines the flux harmonics are fitted with (only with the angle).
    pub emf: EmfLines,
}

/// Fits `effect` to the windows `lines` (already restricted to the segment wanted), read
/// as `reading` says.
pub fn fit_line(
    effect: LineEffect,
    lines: &[&WindowLines],
    rig: &Rig,
    shaft: ShaftConstants,
    candidates: &[u32],
    reading: LineReading,
) -> Option<LineFit> {
    let coherent = reading.angle.combines_phases();
    let emf = match effect {
        LineEffect::FluxHarmonics if coherent => reading.emf,
        _ => EmfLines::None,
    };
    let per_window: Vec<Vec<Observation>> = lines
        .iter()
        .map(|w| observations(effect, w, rig, shaft, candidates, emf))
        .filter(|o| !o.is_empty())
        .collect();
    let obs: Vec<Observation> = per_window.iter().flatten().copied().collect();
    let lines_of = || obs.iter().map(|o| &o.of);
    let (amplitude, information) = amplitude_of(&obs, false)?;
    let (amplitude, back_emf_d, lambda, dof) = if coherent {
        let (d, d_info) = amplitude_of(&obs, true).unwrap_or_default();
        let lambda = amplitude.norm_sqr() * information + d.norm_sqr() * d_info;
        (amplitude, d, lambda, if d_info > 0.0 { 4 } else { 2 })
    } else {
        // Only magnitudes: the torque lines' (the only observations without the angle).
        let a = lines_of()
            .map(|o| o.line.norm() * o.regressor.norm() / o.var)
            .sum::<f64>()
            / information;
        let l = lines_of().map(|o| o.line.norm_sqr() / o.var).sum::<f64>();
        (
            Complex64::new(a, 0.0),
            Complex64::default(),
            l,
            2 * obs.len(),
        )
    };
    let emf_lines = emf_lines_of(&obs);
    Some(LineFit {
        effect,
        amplitude,
        information,
        back_emf_d,
        lambda,
        dof,
        windows: per_window.len(),
        angle: reading.angle,
        emf,
        emf_law: emf_law(&emf_lines, crate::diagnose::dead_time::max_scale(rig)),
    })
}

/// The back-EMF voltage lines among `obs`, with the dead time's regressors.
fn emf_lines_of(obs: &[Observation]) -> Vec<EmfLine> {
    obs.iter()
        .filter_map(|o| {
            o.dead_time.map(|dead_time| EmfLine {
                of: o.of,
                d_axis: o.free_d,
                dead_time,
            })
        })
        .collect()
}

/// What `fit` predicts in the windows `lines` (the validation segment's).
pub struct LineValidation {
    /// The line power it predicts: Σ (|y|² − |y − ŷ|²)/σ² over its lines, positive when the
    /// fitted line is there; `None` without a line. [1]
    pub gain: Option<f64>,
    /// The flux harmonics' back-EMF voltage lines there, as [`super::emf_law`] reads them
    /// (empty unless `fit` is the flux harmonics' with the voltages).
    pub voltage_lines: Vec<EmfLine>,
}

/// `fit` on the windows `lines` (the validation segment's), read as it was fitted.
pub fn line_gain(
    fit: &LineFit,
    lines: &[&WindowLines],
    rig: &Rig,
    shaft: ShaftConstants,
    candidates: &[u32],
) -> LineValidation {
    let obs: Vec<Observation> = lines
        .iter()
        .flat_map(|w| observations(fit.effect, w, rig, shaft, candidates, fit.emf))
        .collect();
    let gain = obs
        .iter()
        .map(|&Observation { of: o, free_d, .. }| {
            let predicted = if !fit.angle.combines_phases() {
                // Only the magnitude is known: the best phase, i.e. the magnitudes compared.
                o.line
                    * (fit.amplitude.re * o.regressor.norm() / o.line.norm().max(f64::MIN_POSITIVE))
            } else if free_d {
                fit.back_emf_d * o.regressor
            } else {
                fit.amplitude * o.regressor
            };
            explained_power(o.line, predicted, o.var)
        })
        .sum();
    LineValidation {
        gain: (!obs.is_empty()).then_some(gain),
        voltage_lines: emf_lines_of(&obs),
    }
}

/// The current-sensor offset hypotheses: the controller's Clarke transform and the channel
/// carrying the offset, as (label, direction of the offset's α-β image in degrees, its
/// magnitude per ampere of offset).
pub const OFFSET_HYPOTHESES: [(&str, f64, f64); 5] = [
    ("phase a, three-sensor Clarke", 0.0, 2.0 / 3.0),
    ("phase b, three-sensor Clarke", 120.0, 2.0 / 3.0),
    ("phase c, three-sensor Clarke", 240.0, 2.0 / 3.0),
    // Two sensors (a, b; c = −a − b): α = a, β = (a + 2b)/√3.
    ("phase a, two-sensor Clarke", 30.0, 1.154_700_538_379_251_5),
    ("phase b, two-sensor Clarke", 90.0, 1.154_700_538_379_251_5),
];

/// The hypothesis read when the log has no angle, so that the line's phase (which tells
/// the arrangement) is unknown: two sensors, the offset on phase a. A log without the angle
/// does not come from this project's drive, whose telemetry always carries it; two isolated
/// current sensors (the third phase computed) is the usual arrangement of servo drives at the
/// rig's DC-link voltage, and the one the independent bench's logs show wherever they hold
/// the angle. The same line is √3 times the offset behind a three-sensor transform, which the
/// cause's text gives beside it.
pub const UNSEEN_ARRANGEMENT: usize = 3;

/// The offset (signed, A) and its hypothesis from the torque line's complex amplitude `a`
/// (`absolute`: its phase against the true electrical angle p_n·θ_m). Without that phase
/// the arrangement cannot be seen and [`UNSEEN_ARRANGEMENT`] is read, with a positive sign.
///
/// The image (α, β) = m·off·(cos φ, sin φ) appears in the measured q current as
/// m·off·sin(φ − θ_e), i.e. the line K_t·m·off·j·e^{−jφ} against e^{jθ_e}.
pub fn offset_from_line(a: Complex64, kt: f64, absolute: bool) -> (f64, &'static str) {
    if !absolute {
        let (label, _, m) = OFFSET_HYPOTHESES[UNSEEN_ARRANGEMENT];
        return (a.norm() / (kt * m), label);
    }
    let angle = a.arg().to_degrees();
    let mut best = (f64::INFINITY, 0.0, OFFSET_HYPOTHESES[0].0);
    for (label, phi, m) in OFFSET_HYPOTHESES {
        for sign in [1.0, -1.0] {
            let expected = 90.0 - phi + if sign < 0.0 { 180.0 } else { 0.0 };
            let d = (angle - expected + 540.0).rem_euclid(360.0) - 180.0;
            if d.abs() < best.0 {
                best = (d.abs(), sign * a.norm() / (kt * m), label);
            }
        }
    }
    (best.1, best.2)
}

/// The phase of the plant's effect whose unexplained torque line (per unit regressor) is
/// `a`, found from the plant's own equations: the line the plant makes at phase 0 and at
/// π/2 fixes the map (it is φ ↦ ±φ + c). [rad]
pub fn plant_phase(effect: LineEffect, a: Complex64, rig: &Rig) -> f64 {
    let line_at = |phase: f64| -> Complex64 {
        let mut r = rig.clone();
        let e = match effect {
            LineEffect::Cogging(k) => plant_model::Effect::CoggingTorque {
                amplitude_nm: 1.0,
                order: k,
                phase_rad: phase,
            },
            LineEffect::FluxHarmonics => plant_model::Effect::FluxHarmonics {
                t6_ratio: 0.1,
                phase_rad: phase,
            },
            _ => return Complex64::new(1.0, 0.0),
        };
        e.apply(&mut r);
        let motor = Motor::new(&r.motor);
        let order = effect.order(rig) as f64;
        let pp = rig.motor.pole_pairs as f64;
        let n = 4096;
        let mut z = Complex64::new(0.0, 0.0);
        for i in 0..n {
            let th = 2.0 * PI * i as f64 / n as f64;
            let torque = match effect {
                LineEffect::Cogging(_) => motor.cogging_torque_nm(th),
                _ => motor.torque_nm(0.0, 1.0, &motor.magnet_flux(pp * th)),
            };
            // The unexplained torque line is minus the effect's torque.
            z -= Complex64::from_polar(torque, -order * th);
        }
        z * (2.0 / n as f64)
    };
    let (z0, z1) = (line_at(0.0), line_at(PI / 2.0));
    if z0.norm() == 0.0 {
        return 0.0;
    }
    // Rotation per radian of phase: +1 or −1.
    let turn = (z1 / z0).arg();
    let s = if turn >= 0.0 { 1.0 } else { -1.0 };
    wrap_pi(s * (a / z0).arg())
}

/// Wraps an angle to (−π, π]. [rad]
pub fn wrap_pi(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_offset_on_phase_a_of_a_three_sensor_controller_reads_back() {
        // Offset 0.3 A on phase a, three-sensor Clarke: image (0.2, 0) A; the measured q
        // current carries 0.2·sin(−θ_e), the line j·0.2·K_t against e^{jθ_e}.
        let kt = 1.0962;
        let a = Complex64::new(0.0, 0.2 * kt);
        let (off, label) = offset_from_line(a, kt, true);
        assert!((off - 0.3).abs() < 1e-9, "{off}");
        assert!(label.contains("phase a, three"), "{label}");
        let (off, _) = offset_from_line(-a, kt, true);
        assert!((off + 0.3).abs() < 1e-9, "{off}");
    }

    #[test]
    fn without_the_angle_the_line_reads_as_a_two_sensor_offset() {
        // Two sensors (c = −a − b), offset 0.15 A on phase a: α = 0.15, β = 0.15/√3, an image
        // of 0.15·2/√3 A whatever its phase; a three-sensor transform's image would be
        // 0.15·2/3 A, √3 times smaller.
        let kt = 1.0962;
        let image = 0.15 * 2.0 / 3f64.sqrt();
        for phase in [0.0f64, 1.0, 2.5] {
            let a = Complex64::from_polar(image * kt, phase);
            let (off, label) = offset_from_line(a, kt, false);
            assert!((off - 0.15).abs() < 1e-9, "{off}");
            assert!(label.contains("two-sensor"), "{label}");
        }
    }

    #[test]
    fn a_two_sensor_offset_is_told_by_its_phase() {
        // Two sensors, offset 0.2 A on phase a: α = 0.2, β = 0.2/√3, image 0.2309 A at 30°.
        let kt = 1.0;
        let m = 0.2 * 2.0 / 3f64.sqrt();
        let a = Complex64::from_polar(m, (60f64).to_radians());
        let (off, label) = offset_from_line(a, kt, true);
        assert!((off - 0.2).abs() < 1e-9, "{off}");
        assert!(label.contains("two-sensor"), "{label}");
    }
}
