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
//!
//! # Three-shunt sampling window ([`modulate_sampled`])
//!
//! Low-side shunts read a phase's current only while its low-side switch conducts around
//! the sampling instant (the counter peak): a duty d leaves (1 − d)/(2·f_PWM) of low-side
//! conduction before the sample, which must cover the dead time, the switching ringing,
//! the amplifier's settling and the ADC's sampling ([`crate::shunt`]). With a largest
//! readable duty w, at most one phase may be above w: its current is rebuilt from the other
//! two. So the middle duty is kept at or below w — first by moving the zero sequence down
//! (all duties by the same amount, which changes no phase-to-phase voltage; possible while
//! the lowest duty stays ≥ 0, i.e. while `(v_mid − v_min)/U_dc ≤ w`), and only beyond that
//! by scaling the vector down, keeping its angle. Inside the linear circle
//! `v_mid − v_min ≤ (√3/2)·U_dc`, so for w ≥ √3/2 ≈ 0.866 no command up to the Table 1 limit
//! loses any voltage; the shift happens only where the middle duty would pass w, so the
//! centred pattern is kept everywhere else.

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
    /// The phase (0‥2) whose duty is above the sampling window, if any
    /// ([`modulate_sampled`]; never with [`modulate`]).
    pub above_window: Option<u8>,
}

/// The hexagon's span `max(v) − min(v)` a command may use, as a fraction of U_dc: a hair
/// inside the hexagon, so that the unclamped duties of the common path stay inside [0, 1]
/// whatever the f32 rounding (see [`modulate_finite`]); 15 ppm of the voltage. [1]
pub const SPAN_LIMIT: f32 = 1.0 - 1.0 / 65536.0;

/// Duties for the α-β voltage `v` [V] from the DC link `u_dc` [V]. A DC link below 1 V
/// gives 50 % on all phases (zero voltage).
#[inline]
pub fn modulate(v: AlphaBeta, u_dc: f32) -> Modulation {
    modulate_sampled(v, u_dc, 1.0)
}

/// As [`modulate`], with at most one duty above `max_sampled_duty` (the largest duty whose
/// low-side shunt can still be read, see the module documentation); `1.0` is [`modulate`].
/// A non-finite command or a DC link below 1 V (or NaN) gives 50 % on all phases.
#[inline(always)]
pub fn modulate_sampled(v: AlphaBeta, u_dc: f32, max_sampled_duty: f32) -> Modulation {
    if !(v.alpha.is_finite() && v.beta.is_finite()) {
        return Modulation::ZERO;
    }
    modulate_finite(v, u_dc, DutyWindow::new(max_sampled_duty))
}

/// The sampling window as the modulator's common path uses it: the largest readable duty
/// w and the largest span (as a fraction of U_dc) that keeps every duty within it and
/// inside [`SPAN_LIMIT`], `min(2w − 1, SPAN_LIMIT)`, computed once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DutyWindow {
    /// Largest readable duty w. [1]
    pub max_duty: f32,
    /// Largest span of the common path. [1]
    pub common_span: f32,
}

impl DutyWindow {
    /// For the largest readable duty `max_duty` [1].
    pub fn new(max_duty: f32) -> DutyWindow {
        let top = 2.0 * max_duty - 1.0;
        DutyWindow {
            max_duty,
            common_span: if top < SPAN_LIMIT { top } else { SPAN_LIMIT },
        }
    }
}

/// [`modulate_sampled`] for a command known to be finite (the current loop's: its PIs'
/// outputs are saturated finite values, its sine table finite for any angle). A DC link
/// below 1 V (or NaN) gives 50 % on all phases. Always inlined (the current loop's hot
/// path); a command beyond the hexagon or the window takes a cold branch.
///
/// No clamp on the common path: with the span at most [`SPAN_LIMIT`]·U_dc each phase's
/// distance from the centring offset is at most half the span (the three phase voltages
/// sum to zero, so the highest is ≥ 0 ≥ the lowest and every rounding error is relative
/// to the span), so `(x + offset)/U_dc` is below ½ by far more than the few ulps the f32
/// arithmetic can add, and `½ + (x + offset)/U_dc` rounds into [0, 1].
#[inline(always)]
pub fn modulate_finite(v: AlphaBeta, u_dc: f32, window: DutyWindow) -> Modulation {
    // One comparison that also refuses NaN.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(u_dc >= 1.0) {
        return Modulation::ZERO;
    }
    let [a, b, c] = inverse_clarke(v);
    // Comparisons rather than f32::max/min: those become fmaxf/fminf calls on the M4F.
    let (hi_ab, lo_ab) = if a > b { (a, b) } else { (b, a) };
    let max = if c > hi_ab { c } else { hi_ab };
    let min = if c < lo_ab { c } else { lo_ab };
    let span = max - min;
    let k = 1.0 / u_dc;
    let zero = -0.5 * (max + min);
    // The highest duty is 1/2 + span·k/2: at or below the window (the usual case) the
    // middle one is too, and nothing moves.
    if span * k > window.common_span {
        let p = Phases {
            v: [a, b, c],
            max,
            min,
            zero,
        };
        return beyond_common(v, p, u_dc, window.max_duty);
    }
    let duty = |x: f32| 0.5 + (x + zero) * k;
    Modulation {
        duties: [duty(a), duty(b), duty(c)],
        limited: false,
        applied: v,
        above_window: None,
    }
}

impl Modulation {
    /// 50 % on every phase: zero voltage.
    pub const ZERO: Modulation = Modulation {
        duties: [0.5; 3],
        limited: true,
        applied: AlphaBeta {
            alpha: 0.0,
            beta: 0.0,
        },
        above_window: None,
    };
}

/// The phase voltages of a command and where they sit. [V]
#[derive(Clone, Copy)]
struct Phases {
    /// Phase voltages a, b, c (summing to zero).
    v: [f32; 3],
    /// The highest and lowest of them.
    max: f32,
    min: f32,
    /// The centring offset −(max + min)/2.
    zero: f32,
}

/// The command is beyond the hexagon (its span above [`SPAN_LIMIT`]·U_dc) or its highest
/// duty above the window `w`: the command limited to the hexagon keeping its angle, then
/// the modulation of `cmd` (phases `p`, from the DC link `u_dc`) with the middle duty at
/// most `w` (see the module documentation). The duties are clamped to [0, 1] against
/// rounding here, off the common path.
#[cold]
#[inline(never)]
fn beyond_common(cmd: AlphaBeta, p: Phases, u_dc: f32, w: f32) -> Modulation {
    let span = p.max - p.min;
    let linear = 1.0 / u_dc;
    let (k, limited) = if span * linear > SPAN_LIMIT {
        (SPAN_LIMIT / span, true)
    } else {
        (linear, false)
    };
    let Phases { v, max, min, zero } = p;
    // The phase voltages sum to zero.
    let mid = -(max + min);
    let (k, limited) = if (mid - min) * k > w {
        (w / (mid - min), true)
    } else {
        (k, limited)
    };
    let d_mid = 0.5 + (mid + zero) * k;
    let shift = if d_mid > w { d_mid - w } else { 0.0 };
    let base = 0.5 - shift;
    let [a, b, c] = v;
    let top = if max == a {
        0
    } else if max == b {
        1
    } else {
        2
    };
    let above_window = (base + (max + zero) * k > w).then_some(top);
    let duty = |x: f32| (base + (x + zero) * k).clamp(0.0, 1.0);
    let scale = k * u_dc;
    Modulation {
        duties: [duty(a), duty(b), duty(c)],
        limited,
        applied: AlphaBeta {
            alpha: cmd.alpha * scale,
            beta: cmd.beta * scale,
        },
        above_window,
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

    /// Sorted duties, lowest first.
    fn sorted(d: [f32; 3]) -> [f32; 3] {
        let mut d = d;
        d.sort_by(|x, y| x.total_cmp(y));
        d
    }

    #[test]
    fn the_sampling_window_keeps_the_middle_duty_readable_without_losing_voltage() {
        // w = 0.92: 2 µs of low-side conduction before the sample at 20 kHz. Up to the
        // linear circle (Table 1's 161.6 V) every command is realised exactly, and at most
        // one duty is above w.
        let u_dc = 280.0;
        let w = 0.92;
        let mut shifted = 0;
        for k in 0..720 {
            for r in [0.3, 0.6, 0.9, 0.9999] {
                let r = r * u_dc / libm::sqrtf(3.0);
                let phi = k as f32 * PI / 360.0;
                let v = AlphaBeta {
                    alpha: r * libm::cosf(phi),
                    beta: r * libm::sinf(phi),
                };
                let m = modulate_sampled(v, u_dc, w);
                assert!(!m.limited, "{r} V at {phi} rad");
                let [lo, mid, hi] = sorted(m.duties);
                assert!(mid <= w + 1e-6 && lo >= 0.0, "{:?}", m.duties);
                // The phase named above the window is the one with the highest duty.
                match m.above_window {
                    Some(p) => assert!(m.duties[p as usize] == hi && hi > w),
                    None => assert!(hi <= w + 1e-6, "{:?}", m.duties),
                }
                let (a, b) = realised(m.duties, u_dc);
                assert!((a - v.alpha).abs() < 1e-2 && (b - v.beta).abs() < 1e-2);
                if m.duties != modulate(v, u_dc).duties {
                    shifted += 1;
                }
            }
        }
        // Only near the top of the circle's vertex directions does anything move.
        assert!(shifted > 0 && shifted < 720, "{shifted}");
        // Inside, where the middle duty is below w anyway, the centred pattern is kept.
        let v = AlphaBeta {
            alpha: 40.0,
            beta: -25.0,
        };
        assert_eq!(modulate_sampled(v, u_dc, w), modulate(v, u_dc));
    }

    #[test]
    fn a_narrow_window_scales_the_vector_keeping_its_angle() {
        // w = 0.6 (100 kHz PWM with 2 µs settling): at a vertex direction the two highest
        // phases are |v|/2 and the lowest −|v| (amplitude-invariant Clarke), 1.5·|v| apart,
        // so |v| is held to 0.6·U_dc/1.5 = 112 V: a 100 V command passes, 150 V is scaled
        // to 112 V.
        let u_dc = 280.0;
        for (r, want_r, limited) in [(100.0, 100.0, false), (150.0, 112.0, true)] {
            // 60°: phases a and b equal and highest.
            let phi = PI / 3.0;
            let v = AlphaBeta {
                alpha: r * libm::cosf(phi),
                beta: r * libm::sinf(phi),
            };
            let m = modulate_sampled(v, u_dc, 0.6);
            assert_eq!(m.limited, limited);
            let [lo, mid, _] = sorted(m.duties);
            assert!(mid <= 0.6 + 1e-6 && lo >= -1e-6, "{:?}", m.duties);
            let (a, b) = realised(m.duties, u_dc);
            assert!((libm::atan2f(b, a) - phi).abs() < 1e-4);
            assert!((libm::sqrtf(a * a + b * b) - want_r).abs() < 0.05, "{r}");
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
