//! The model-based table: the q current that cancels the angle-locked torques of a rig's
//! own equations, as the plant applies them — cogging (eq. 16), the flux harmonics'
//! 6th-harmonic torque (eq. 17–19), the pump's torque ripple from its kinematic
//! displacement (eq. 20) and a phase-a current offset's image in the measured current.
//! Applied to the rig extended by the diagnosis's fitted effects it is the learned table
//! (the table is the model); applied to the plant's true rig, the ideal the study compares
//! learned tables against.
//!
//! | effect | channel | q current |
//! |---|---|---|
//! | cogging | constant [A] | −T_cog(θ)/K_t |
//! | current offset ε on phase a | constant [A] | −(2ε/3)·sin(p_n·θ) (its q image, amplitude-invariant Clarke) |
//! | flux harmonics | per q current [A/A] | 1 − T_e(θ, i_q = 1 A)/K_t |
//! | pump ripple | per pressure [A/Pa] | (s(θ) − 1)·D/2π/K_t |
//!
//! The low port's pressure is folded into the constant channel (the drive multiplies the
//! per-pressure channel by the port-A pressure alone). Each channel is carried as its
//! harmonics up to [`MAX_ORDER`].

use super::table::{Channels, Harmonic, MAX_ORDER};
use firmware::compensation::Channel;
use plant_model::motor::Motor;
use plant_model::pump::Pump;
use plant_model::Rig;
use rustfft::num_complex::Complex64;
use rustfft::FftPlannerScalar;
use std::f64::consts::PI;

/// Samples per revolution of the harmonic decompositions. [1]
const FINE: usize = 4096;

/// Harmonics 1‥=[`MAX_ORDER`] (and the mean as order 0) of `f` over a revolution, those
/// above `floor` of the largest. [the function's unit]
pub fn harmonics_of(f: impl Fn(f64) -> f64, floor: f64) -> Vec<Harmonic> {
    let mut buf: Vec<Complex64> = (0..FINE)
        .map(|i| Complex64::new(f(2.0 * PI * i as f64 / FINE as f64), 0.0))
        .collect();
    FftPlannerScalar::new()
        .plan_fft_forward(FINE)
        .process(&mut buf);
    let mut out: Vec<Harmonic> = (0..=MAX_ORDER as usize)
        .map(|k| Harmonic {
            order: k as u32,
            amplitude: buf[k] * if k == 0 { 1.0 } else { 2.0 } / FINE as f64,
        })
        .collect();
    let largest = out.iter().map(|h| h.amplitude.norm()).fold(0.0, f64::max);
    out.retain(|h| h.amplitude.norm() > floor * largest);
    out
}

/// The channels that cancel the angle-locked torques of `rig`'s own equations, with the
/// low port at `p_low_pa` [Pa], the effects named in `skip` (catalogue names) left out.
pub fn channels_from_rig(rig: &Rig, p_low_pa: f64, skip: &[String]) -> Channels {
    let on = |name: &str| !skip.iter().any(|s| s == name);
    let motor = Motor::new(&rig.motor);
    let pump = Pump::new(&rig.pump);
    let kt = rig.motor.torque_constant_nm_per_a();
    let pp = rig.motor.pole_pairs as f64;
    let d_per_rad = rig.pump.displacement_m3_per_rev / (2.0 * PI);
    let mut ch = Channels::default();
    let floor = 1e-4;
    let cogging = |th: f64| {
        if on("cogging_torque") {
            -motor.cogging_torque_nm(th) / kt
        } else {
            0.0
        }
    };
    // A phase-a offset ε reads, through the three-sensor Clarke transform, as an α of
    // 2ε/3 (amplitude-invariant): a q current of −(2ε/3)·sin θ_e that did not flow.
    let eps = if on("current_sensor_offset") {
        rig.sensors.current.offset_a[0]
    } else {
        0.0
    };
    let offset = |th: f64| -(2.0 / 3.0) * eps * (pp * th).sin();
    for h in harmonics_of(|th| cogging(th) + offset(th), floor) {
        ch.add(Channel::Constant, h);
    }
    let flux = |th: f64| 1.0 - motor.torque_nm(0.0, 1.0, &motor.magnet_flux(pp * th)) / kt;
    if on("flux_harmonics") {
        for h in harmonics_of(flux, floor)
            .into_iter()
            .filter(|h| h.order > 0)
        {
            ch.add(Channel::PerCurrent, h);
        }
    }
    if rig.pump.piston_ripple && on("piston_ripple") {
        let ripple = |th: f64| (pump.displacement_factor(th) - 1.0) * d_per_rad / kt;
        for h in harmonics_of(ripple, floor)
            .into_iter()
            .filter(|h| h.order > 0)
        {
            ch.add(Channel::PerPressure, h);
            ch.add(
                Channel::Constant,
                Harmonic {
                    order: h.order,
                    amplitude: -h.amplitude * p_low_pa,
                },
            );
        }
    }
    ch
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sine_decomposes_into_its_line() {
        let h = harmonics_of(|th| 0.3 * (18.0 * th - 0.5).cos() + 0.1, 1e-6);
        let line = h.iter().find(|h| h.order == 18).unwrap();
        assert!((line.amplitude - Complex64::from_polar(0.3, -0.5)).norm() < 1e-9);
        let mean = h.iter().find(|h| h.order == 0).unwrap();
        assert!((mean.amplitude.re - 0.1).abs() < 1e-12);
        assert_eq!(h.len(), 2);
    }
}
