//! The high-pressure node's volume balance read for the piston, when it moves: the position
//! the pump's swept volume and the logged port pressure give, eq. 9–11 of the paper solved
//! for A·dx/dt instead of dp/dt,
//!
//! ```text
//!   A·dx = D/2π·s(θ)·dθ − [G_pp·(p − p_low) + (G − G_pp)·(p − p_c)]·dt − dv_abs − (V_h + A·x)/β·dp
//! ```
//!
//! with p the true port pressure the transducer's reading gives ((p_meas − o)/g) and v_abs
//! the absorber's oil at it (the gas law quasi-static: the inlet's time constant is tens of
//! microseconds). On a moving piston the pressure's own balance multiplies the position
//! transducer's noise by the oil's stiffness (β/V·A·σ_x, tens of kPa for a micrometre);
//! read this way round, the pressure's noise enters only through the oil's compliance
//! (V/β/A·σ_p, below a nanometre) and the position carries its own noise alone. The oil's
//! compliance then shows in the position wherever the port pressure moves: the piston
//! lags the pump by (V/β)·Δp/A when the port is loaded at a reversal or an acceleration.
//!
//! Position and pressure are both read smoothed by the same filter
//! ([`crate::diagnose::facts::LogFacts::p_smooth_pa`]): the relation is linear in them, so
//! it holds between the filtered signals as between the raw ones, while the pressure's
//! noise, multiplied by the compliance, no longer favours a stiffer oil, and the filter's
//! rounding of a sharp pressure turn (a friction's stick-slip) is the position's too.
//!
//! Each window is summed from its first row, and the start position is the least-squares
//! one (the mean difference between the logged position and the window's sum), so a noisy
//! first row does not shift the window. A port sucked down to the fill level takes oil from
//! the check valve as well, which the balance leaves out: the leakage's make-up flow, a
//! fraction of a micrometre over a window.

use super::{HydraulicInputs, Hydraulics};
use std::f64::consts::PI;
use std::ops::Range;

impl Hydraulics {
    /// Predicts the piston position of `x` (`x_m`, as the relation reads it: smoothed as
    /// the pressure is) over the window `rows` into `out`, row `rows.start + i` at index i,
    /// from the pump's swept volume and the port pressure; nothing without a position.
    pub fn predict_position_window(
        &self,
        x: &HydraulicInputs<'_>,
        rows: Range<usize>,
        out: &mut [f64],
    ) {
        let Some(x_logged) = x.x_m else {
            return;
        };
        let hp = &self.params;
        let gain = hp.sensor_gain.max(1e-6);
        let p_logged = x.p_smooth_pa.unwrap_or(x.p_pa);
        let p_true = |k: usize| (p_logged[k] - hp.sensor_offset_pa) / gain;
        let per_rad = hp.displacement_m3_per_rev / (2.0 * PI);
        let area = hp.area_m2.max(1e-9);
        let g = hp.leakage_m3_s_pa;
        let gpp = self.port_to_port;
        let leak =
            |k: usize, p: f64| gpp * (p - x.p_low_pa.at(k)) + (g - gpp) * (p - x.case_pa.at(k));
        let absorbed = |p: f64| hp.absorber.as_ref().map_or(0.0, |a| a.oil_volume_m3(p));
        let ripple = hp.ripple.1 > 0.0;
        let Some(first) = out.first_mut() else {
            return;
        };
        *first = 0.0;
        let mut sum = 0.0;
        let (mut p, mut v_abs) = (p_true(rows.start), 0.0);
        v_abs += absorbed(p);
        let steps = rows.start..rows.end.saturating_sub(1).max(rows.start);
        for (k, x_here) in steps.clone().zip(&x_logged[steps]) {
            let next = k + 1;
            let dt = x.t_s[next] - x.t_s[k];
            let dtheta = x.theta_rad[next] - x.theta_rad[k];
            let factor = if ripple {
                self.pump.displacement_factor(x.theta_rad[k] + 0.5 * dtheta)
            } else {
                1.0
            };
            let p_next = p_true(next);
            let v_next = absorbed(p_next);
            let compliance =
                (hp.high_side_volume_m3 + area * x_here).max(1e-9) / hp.bulk_modulus_pa;
            let volume = per_rad * factor * dtheta
                - 0.5 * (leak(k, p) + leak(next, p_next)) * dt
                - (v_next - v_abs)
                - compliance * (p_next - p);
            sum += volume / area;
            out[next - rows.start] = sum;
            (p, v_abs) = (p_next, v_next);
        }
        // The start position that fits the window best in least squares.
        let n = rows.len().max(1) as f64;
        let start = rows
            .clone()
            .map(|k| x_logged[k] - out[k - rows.start])
            .sum::<f64>()
            / n;
        for o in out.iter_mut().take(rows.len()) {
            *o += start;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{HydraulicParams, Hydraulics, LowSide};
    use super::*;
    use plant_model::Rig;

    /// The position predicted over one window from a logged angle, port pressure and
    /// position, the model's leakage and absorber taken out unless `leak` is given.
    fn predicted(hp: HydraulicParams, th: &[f64], p: &[f64], x: &[f64], low: f64) -> Vec<f64> {
        let n = th.len();
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let inputs = HydraulicInputs {
            t_s: &t,
            theta_rad: th,
            p_low_pa: LowSide::Level(low),
            case_pa: LowSide::Level(low),
            x_m: Some(x),
            p_pa: p,
            p_smooth_pa: None,
            start_rows: 10,
            fill_pa: low,
            fill_track_pa: None,
        };
        let mut out = vec![0.0; n];
        Hydraulics::new(hp, &Rig::nominal()).predict_position_window(&inputs, 0..n, &mut out);
        out
    }

    fn plain(rig: &Rig) -> HydraulicParams {
        let mut hp = HydraulicParams::nominal(rig);
        hp.absorber = None;
        hp.leakage_m3_s_pa = 0.0;
        hp.ripple = (9, 0.0);
        hp
    }

    #[test]
    fn a_stroke_at_a_steady_pressure_moves_by_the_swept_volume_over_the_area() {
        // p constant, no leakage: x = x_0 + D/2π·θ/A, the window's start fitted.
        let rig = Rig::nominal();
        let hp = plain(&rig);
        let n = 250;
        let th: Vec<f64> = (0..n).map(|k| 0.02 * k as f64).collect();
        let per_m = 1.5e-6 / (2.0 * PI) / 71e-4;
        let x: Vec<f64> = th.iter().map(|t| -3e-3 + per_m * t).collect();
        let out = predicted(hp, &th, &vec![0.6e6; n], &x, 0.5e6);
        for (a, b) in out.iter().zip(&x) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn a_stuck_piston_takes_the_swept_volume_into_the_oil() {
        // The piston held at x = 2 mm while the pump turns: the port rises by
        // Δp = D/2π·θ·β/(V_h + A·x), and the position the balance gives stays at 2 mm. Read
        // with half the bulk modulus, the predicted position lags the pump by the extra
        // compliance's volume, (V/β' − V/β)·Δp/A, a straight line in the rise (its mean is
        // the fitted start).
        let rig = Rig::nominal();
        let hp = plain(&rig);
        let (v, beta, area) = (450e-6 + 71e-4 * 2e-3, 6.5e8, 71e-4);
        let n = 200;
        let th: Vec<f64> = (0..n).map(|k| 0.015 * k as f64).collect();
        let swept: Vec<f64> = th.iter().map(|t| 1.5e-6 / (2.0 * PI) * t).collect();
        let p: Vec<f64> = swept.iter().map(|s| 0.6e6 + s * beta / v).collect();
        let x = vec![2e-3; n];
        let held = predicted(hp.clone(), &th, &p, &x, 0.5e6);
        for y in &held {
            assert!((y - 2e-3).abs() < 1e-12, "{y}");
        }
        let mut soft = hp;
        soft.bulk_modulus_pa = beta / 2.0;
        let lagging = predicted(soft, &th, &p, &x, 0.5e6);
        let lag: Vec<f64> = p.iter().map(|q| v / beta * (q - p[0]) / area).collect();
        let mean = lag.iter().sum::<f64>() / n as f64;
        for (y, l) in lagging.iter().zip(&lag) {
            let expected = 2e-3 - (l - mean);
            assert!((y - expected).abs() < 1e-12, "{y} vs {expected}");
        }
        assert!(lag[n - 1] > 10e-6, "the test's lag is {} m", lag[n - 1]);
    }

    #[test]
    fn a_leaking_port_lets_the_piston_fall_behind_the_pump() {
        // Leakage G·(p − p_case) over t at a steady port: A·Δx = D/2π·θ − G·(p − p_c)·t.
        let rig = Rig::nominal();
        let mut hp = plain(&rig);
        hp.leakage_m3_s_pa = 1e-12;
        hp.port_to_port_share = 0.0;
        let n = 250;
        let th: Vec<f64> = (0..n).map(|k| 0.02 * k as f64).collect();
        let (p, pc, area) = (1.5e6, 0.5e6, 71e-4);
        let x: Vec<f64> = (0..n)
            .map(|k| (1.5e-6 / (2.0 * PI) * th[k] - 1e-12 * (p - pc) * k as f64 * 1e-3) / area)
            .collect();
        let out = predicted(hp, &th, &vec![p; n], &x, pc);
        for (a, b) in out.iter().zip(&x) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }
}
