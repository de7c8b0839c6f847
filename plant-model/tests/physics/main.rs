//! The plant against independent numbers: analytic solutions of its sub-models, textbook
//! formulas, the paper's equations, and conservation of energy and oil.

#[path = "../common/mod.rs"]
mod common;

mod conservation;
mod hydraulics;
mod motor;
mod sensing;

use common::{quiet, speed_drive};
use plant_model::accumulator::ATMOSPHERE_PA;
use plant_model::motor::Motor;
use plant_model::pump::Pump;
use plant_model::rig::FluxHarmonic;
use plant_model::{Drive, Effect, InitialConditions, Inputs, Integrator, Plant, Rig};
use rustfft::{num_complex::Complex, FftPlannerScalar};
use std::f64::consts::PI;

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// Amplitude spectrum of one period sampled uniformly (bin k = k cycles per period).
fn amplitude_spectrum(samples: &[f64]) -> Vec<f64> {
    let n = samples.len();
    let mut buf: Vec<Complex<f64>> = samples.iter().map(|&x| Complex::new(x, 0.0)).collect();
    FftPlannerScalar::new()
        .plan_fft_forward(n)
        .process(&mut buf);
    buf.iter()
        .take(n / 2)
        .enumerate()
        .map(|(k, c)| {
            if k == 0 {
                c.norm() / n as f64
            } else {
                2.0 * c.norm() / n as f64
            }
        })
        .collect()
}

fn dominant_order(spectrum: &[f64]) -> usize {
    (1..spectrum.len())
        .max_by(|&a, &b| spectrum[a].total_cmp(&spectrum[b]))
        .unwrap()
}

/// Duties that apply phase voltages with d-q components (u_d, u_q) at electrical angle
/// `theta_e` (sinusoidal modulation about half the DC link).
fn duties_for(u_d: f64, u_q: f64, theta_e: f64, u_dc: f64) -> [f64; 3] {
    let (s, c) = theta_e.sin_cos();
    let alpha = u_d * c - u_q * s;
    let beta = u_d * s + u_q * c;
    let va = alpha;
    let vb = -0.5 * alpha + 0.5 * SQRT3 * beta;
    let vc = -0.5 * alpha - 0.5 * SQRT3 * beta;
    [0.5 + va / u_dc, 0.5 + vb / u_dc, 0.5 + vc / u_dc]
}
