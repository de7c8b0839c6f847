//! Space-vector PWM by min–max zero-sequence injection (the paper's SVPWM block, Figure 4;
//! equivalent to the sector/dwell-time method).
//!
//! The commanded α-β voltage is split into phase voltages, and the common-mode offset
//! −(max + min)/2 is added, which centres the active vectors in the period exactly as the
//! sector method's equal zero-vector halves do. The duty of phase x is then
//! `d_x = 1/2 + (v_x + v_0)/U_dc`; the average phase voltages `U_dc·(d_x − mean(d))`
//! reproduce the command.
//!
//! Linear range: the hexagon `max(v) − min(v) ≤ U_dc`, whose inscribed circle has radius
//! U_dc/√3 (161.6 V at 280 V, the Table 1 voltage limit). Beyond the hexagon the vector is
//! scaled down onto it, keeping its angle, so the current loop sees the best voltage in the
//! commanded direction. Duties are in [0, 1] by construction and clamped against rounding.

use crate::transforms::{inverse_clarke, AlphaBeta};

/// Duties and whether the command had to be limited.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modulation {
    /// Duties of phases a, b, c in [0, 1]. [1]
    pub duties: [f32; 3],
    /// The command was outside the hexagon and was scaled onto it.
    pub limited: bool,
    /// The α-β voltage the duties realise (the command, or its limited version). [V]
    pub applied: AlphaBeta,
}

/// Duties for the α-β voltage `v` [V] from the DC link `u_dc` [V]. A DC link below 1 V
/// gives 50 % on all phases (zero voltage).
#[inline]
pub fn modulate(v: AlphaBeta, u_dc: f32) -> Modulation {
    if u_dc.is_nan() || u_dc < 1.0 || !(v.alpha.is_finite() && v.beta.is_finite()) {
        return Modulation {
            duties: [0.5; 3],
            limited: true,
            applied: AlphaBeta::default(),
        };
    }
    let [a, b, c] = inverse_clarke(v);
    // Comparisons rather than f32::max/min: those become fmaxf/fminf calls on the M4F.
    let (hi_ab, lo_ab) = if a > b { (a, b) } else { (b, a) };
    let max = if c > hi_ab { c } else { hi_ab };
    let min = if c < lo_ab { c } else { lo_ab };
    let span = max - min;
    let (scale, limited) = if span > u_dc {
        (u_dc / span, true)
    } else {
        (1.0, false)
    };
    let k = scale / u_dc;
    let zero = -0.5 * (max + min);
    let duty = |x: f32| (0.5 + (x + zero) * k).clamp(0.0, 1.0);
    Modulation {
        duties: [duty(a), duty(b), duty(c)],
        limited,
        applied: AlphaBeta {
            alpha: v.alpha * scale,
            beta: v.beta * scale,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::PI;

    /// α-β of the average phase voltages the bridge produces with duties `d`, computed from
    /// the pole voltages U_dc·d_x independently of the modulator.
    fn realised(d: [f32; 3], u_dc: f32) -> (f32, f32) {
        let mean = (d[0] + d[1] + d[2]) / 3.0;
        let v: [f32; 3] = core::array::from_fn(|i| u_dc * (d[i] - mean));
        // Amplitude-invariant Clarke written out.
        let alpha = (2.0 * v[0] - v[1] - v[2]) / 3.0;
        let beta = (v[1] - v[2]) / libm::sqrtf(3.0);
        (alpha, beta)
    }

    /// Radius of the SVPWM hexagon at angle `phi`: U_dc·2/3 at the vertices (0°, 60°, ...),
    /// U_dc/√3 at the edge midpoints.
    fn hexagon_radius(phi: f32, u_dc: f32) -> f32 {
        let sector = PI / 3.0;
        let rel = phi.rem_euclid(sector) - sector / 2.0;
        (u_dc / libm::sqrtf(3.0)) / libm::cosf(rel)
    }

    #[test]
    fn reproduces_commands_over_a_grid_inside_the_hexagon() {
        let u_dc = 280.0;
        let mut checked = 0;
        for i in -20..=20 {
            for j in -20..=20 {
                let alpha = i as f32 * 9.5;
                let beta = j as f32 * 9.5;
                let r = libm::sqrtf(alpha * alpha + beta * beta);
                let phi = libm::atan2f(beta, alpha);
                if r > 0.999 * hexagon_radius(phi, u_dc) {
                    continue;
                }
                let m = modulate(AlphaBeta { alpha, beta }, u_dc);
                assert!(!m.limited, "({alpha}, {beta}) is inside");
                for d in m.duties {
                    assert!((0.0..=1.0).contains(&d));
                }
                let (a, b) = realised(m.duties, u_dc);
                assert!(
                    (a - alpha).abs() < 1e-3 && (b - beta).abs() < 1e-3,
                    "{alpha} {beta}"
                );
                checked += 1;
            }
        }
        assert!(checked > 900);
    }

    #[test]
    fn circle_of_radius_udc_over_sqrt3_is_linear() {
        let u_dc = 280.0;
        let r = u_dc / libm::sqrtf(3.0) * 0.9999;
        for k in 0..360 {
            let phi = k as f32 * PI / 180.0;
            let m = modulate(
                AlphaBeta {
                    alpha: r * libm::cosf(phi),
                    beta: r * libm::sinf(phi),
                },
                u_dc,
            );
            assert!(!m.limited);
            let (a, b) = realised(m.duties, u_dc);
            assert!((a - r * libm::cosf(phi)).abs() < 1e-2);
            assert!((b - r * libm::sinf(phi)).abs() < 1e-2);
        }
    }

    #[test]
    fn beyond_the_hexagon_the_angle_is_kept_and_the_magnitude_is_the_hexagon() {
        let u_dc = 280.0;
        for k in 0..72 {
            let phi = k as f32 * 5.0 * PI / 180.0 + 0.01;
            let r = 400.0;
            let m = modulate(
                AlphaBeta {
                    alpha: r * libm::cosf(phi),
                    beta: r * libm::sinf(phi),
                },
                u_dc,
            );
            assert!(m.limited);
            for d in m.duties {
                assert!((0.0..=1.0).contains(&d));
            }
            let (a, b) = realised(m.duties, u_dc);
            let got_phi = libm::atan2f(b, a);
            let dphi = (got_phi - phi + 3.0 * PI).rem_euclid(2.0 * PI) - PI;
            assert!(dphi.abs() < 1e-4, "angle moved by {dphi}");
            let got_r = libm::sqrtf(a * a + b * b);
            assert!((got_r - hexagon_radius(phi, u_dc)).abs() < 1e-2 * u_dc);
            // On the hexagon one phase is fully high and one fully low.
            let max = m.duties.iter().cloned().fold(0.0, f32::max);
            let min = m.duties.iter().cloned().fold(1.0, f32::min);
            assert!((max - 1.0).abs() < 1e-5 && min.abs() < 1e-5);
        }
    }

    #[test]
    fn bad_inputs_give_zero_voltage() {
        for (v, u) in [
            (
                AlphaBeta {
                    alpha: 10.0,
                    beta: 0.0,
                },
                0.0,
            ),
            (
                AlphaBeta {
                    alpha: f32::NAN,
                    beta: 0.0,
                },
                280.0,
            ),
            (
                AlphaBeta {
                    alpha: 1.0,
                    beta: 0.0,
                },
                f32::NAN,
            ),
        ] {
            assert_eq!(modulate(v, u).duties, [0.5; 3]);
        }
    }
}
