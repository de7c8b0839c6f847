//! Speed step 0 → 50 rad/s (scenario `speed-step`, payload free) in closed loop, against the
//! response the speed loop's design implies.
//!
//! Design (Table 1 speed PI, `contracts/nominal-rig.md`; Ba read as active damping, see
//! `firmware::speed_loop`): i_q* = Kp·(ω* − ω) + Ki·∫(ω* − ω) − Ba·ω, and with an ideal
//! current loop J·ω' = K_t·i_q − B·ω. Hence
//!
//! ```text
//! ω/ω* = K_t·(Kp·s + Ki) / (J·s² + (B + K_t·(Kp + Ba))·s + K_t·Ki)
//! ```
//!
//! with K_t = 1.5·p_n·ψ_f = 1.0962 N·m/A, J = 8.0e-4 kg·m², B = 3.035e-4 N·m·s: poles at
//! −67.1 and −142.9 rad/s, zero at −Ki/Kp = −50 rad/s. The zero is slower than both poles, so
//! the step overshoots although the poles are real: the partial fractions give
//! `ω(t)/ω* = 1 + r₁·e^{p₁t} + r₂·e^{p₂t}` with r₁ = 0.645, r₂ = −1.645, a peak of 7.7 % at
//! 22 ms, 2 % settling at 52 ms and no steady-state error. The test computes these from
//! the rig and the Table 1 gains and compares the whole trajectory.
//!
//! What the ideal model leaves out: the current loop (first order, τ = 1/1100 s, eight times
//! faster than the fastest pole), the 2 kHz speed loop (its output held for 0.5 ms) and the
//! speed estimate as the mean over the last speed period (0.25 ms behind) — about 1.6 ms of
//! lag, ≈ 18° at the ≈ 200 rad/s crossover, which raises the overshoot by a few points. The
//! test therefore also integrates the *sampled* design model — the same linear shaft and
//! PI, with the current loop as its first-order design response and the speed loop sampled
//! and held as specified — and holds the closed loop to that trajectory. The pump's load
//! torque (the free 2000 kg payload accelerates to 1.7 mm/s through 24 kPa, 0.006 N·m) is
//! negligible in both.

use closed_loop::by_name;
use plant_model::Rig;
use tests::{closed_loop_at, mean_between, overshoot, settling_time, window};

const STEP_RAD_S: f64 = 50.0;

/// The ideal closed loop's poles, residues and zero from the rig and the Table 1 gains.
struct Ideal {
    p1: f64,
    p2: f64,
    r1: f64,
    r2: f64,
}

impl Ideal {
    fn from_design(rig: &Rig) -> Ideal {
        // Table 1 speed regulator.
        let (kp, ki, ba) = (0.14, 7.0, 0.013);
        let kt = rig.motor.torque_constant_nm_per_a();
        let j = rig.shaft.inertia_kg_m2();
        let b = rig.shaft.viscous_nm_s;
        let a1 = (b + kt * (kp + ba)) / j;
        let a0 = kt * ki / j;
        let disc = (a1 * a1 - 4.0 * a0).sqrt();
        let (p1, p2) = ((-a1 + disc) / 2.0, (-a1 - disc) / 2.0);
        // Y(s) = g·(s + z)/(s·(s − p1)·(s − p2)), g = K_t·Kp/J, z = Ki/Kp.
        let (g, z) = (kt * kp / j, ki / kp);
        let r1 = g * (p1 + z) / (p1 * (p1 - p2));
        let r2 = g * (p2 + z) / (p2 * (p2 - p1));
        Ideal { p1, p2, r1, r2 }
    }

    fn response(&self, t: f64) -> f64 {
        1.0 + self.r1 * (self.p1 * t).exp() + self.r2 * (self.p2 * t).exp()
    }
}

/// The sampled design model: J·ω' = K_t·i_q − B·ω, i_q' = ω_c·(i_q* − i_q); every speed
/// period T_s from `t_first_tick` the PI takes the mean speed over the last period
/// (Δθ/T_s) and sets i_q* = Kp·e + x − Ba·ω̂, x += Ki·T_s·e, held until the next tick.
/// Integrated by Euler at 1 µs (1/900 of the current loop's τ). Returns `(t, ω)` every
/// `dt_out` from t = 0 (the step).
fn sampled_design_model(rig: &Rig, t_first_tick: f64, t_end: f64, dt_out: f64) -> Vec<(f64, f64)> {
    let (kp, ki, ba, omega_c, t_s) = (0.14, 7.0, 0.013, 1100.0, 1.0 / 2000.0);
    let kt = rig.motor.torque_constant_nm_per_a();
    let j = rig.shaft.inertia_kg_m2();
    let b = rig.shaft.viscous_nm_s;
    let h = 1e-6;
    let (mut w, mut theta, mut iq, mut iq_ref, mut x) = (0.0f64, 0.0f64, 0.0, 0.0, 0.0);
    let mut theta_last_tick = 0.0;
    let mut next_tick = t_first_tick;
    let mut next_out = 0.0;
    let mut out = Vec::new();
    let n = (t_end / h).round() as usize;
    for k in 0..=n {
        let t = k as f64 * h;
        if t >= next_tick - 0.5 * h {
            let w_meas = (theta - theta_last_tick) / t_s;
            theta_last_tick = theta;
            let e = STEP_RAD_S - w_meas;
            iq_ref = kp * e + x - ba * w_meas;
            x += ki * t_s * e;
            next_tick += t_s;
        }
        if t >= next_out - 0.5 * h {
            out.push((t, w));
            next_out += dt_out;
        }
        let dw = (kt * iq - b * w) / j;
        let diq = omega_c * (iq_ref - iq);
        theta += w * h;
        w += dw * h;
        iq += diq * h;
    }
    out
}

#[test]
fn speed_step_follows_the_design_response() {
    let scenario = by_name("speed-step").expect("scenario speed-step");
    let rig = Rig::nominal();
    let ideal = Ideal::from_design(&rig);
    // The documented poles (firmware::speed_loop) come out of the rig and Table 1.
    assert!((ideal.p1 + 67.0).abs() < 1.0 && (ideal.p2 + 143.0).abs() < 1.0);
    // Ideal peak and settling by dense evaluation of the analytic response.
    let ts_ideal: Vec<(f64, f64)> = (0..20_000)
        .map(|k| {
            let t = k as f64 * 1e-5;
            (t, ideal.response(t))
        })
        .collect();
    let os_ideal = overshoot(&ts_ideal, 0.0, 1.0);
    let settle_ideal = settling_time(&ts_ideal, 1.0, 0.02, 0.0);
    assert!((os_ideal - 0.077).abs() < 0.003, "{os_ideal}");

    let mut l = closed_loop_at(&rig, scenario, 20e3, 7);
    let t_step = 0.1;
    let mut trace = Vec::new();
    let mut first_tick = None;
    l.run(0.6, 1, |s| {
        trace.push((s.truth.t_s, s.truth.omega_m_rad_s));
        // The speed loop's first tick on the new setpoint: its reference shows in telemetry.
        if first_tick.is_none() && s.telemetry.speed_ref_rad_s == STEP_RAD_S as f32 {
            first_tick = Some(s.truth.t_s);
        }
    });
    let first_tick = first_tick.expect("the speed reference reaches 50 rad/s") - t_step;
    assert!(
        (0.0..=0.5e-3 + 1e-9).contains(&first_tick),
        "the speed loop took the setpoint {first_tick} s after it was sent"
    );
    let after: Vec<(f64, f64)> = window(&trace, t_step - 1e-9, 0.6)
        .into_iter()
        .map(|(t, w)| (t - t_step, w))
        .collect();
    let model = sampled_design_model(&rig, first_tick, 0.5, l.period_s());
    let os = overshoot(&after, 0.0, STEP_RAD_S);
    let os_model = overshoot(&model, 0.0, STEP_RAD_S);
    let settle = settling_time(&after, STEP_RAD_S, 0.02 * STEP_RAD_S, 0.0);
    let settle_model = settling_time(&model, STEP_RAD_S, 0.02 * STEP_RAD_S, 0.0);
    let steady = mean_between(&after, 0.3, 0.5);
    let worst = after
        .iter()
        .zip(model.iter())
        .map(|((ta, a), (tm, m))| {
            assert!((ta - tm).abs() < 1e-6, "sample times {ta} vs {tm}");
            (a - m).abs()
        })
        .fold(0.0, f64::max);
    println!(
        "speed step 0 → 50 rad/s: overshoot {:.2} % (ideal {:.2} %, sampled model {:.2} %), \
         2 % settling {:.1} ms (ideal {:.1} ms, sampled model {:.1} ms), steady-state error \
         {:.4} rad/s, largest deviation from the sampled model {worst:.3} rad/s",
        os * 100.0,
        os_ideal * 100.0,
        os_model * 100.0,
        settle * 1e3,
        settle_ideal * 1e3,
        settle_model * 1e3,
        steady - STEP_RAD_S
    );
    // Before the step the drive holds zero speed.
    let before = mean_between(&trace, 0.05, t_step);
    assert!(before.abs() < 0.5, "speed before the step {before} rad/s");
    // Overshoot: the zero at −50 rad/s makes 7.7 % with ideal loops; the lags add a few
    // points. Within 1.5 points of the sampled model, and never the 15 % of a loop that has
    // lost a third of its phase margin.
    assert!(
        (os - os_model).abs() <= 0.015 && os <= 0.15,
        "overshoot {:.2} %, sampled design model {:.2} %",
        os * 100.0,
        os_model * 100.0
    );
    // 2 % settling: the slow mode (−67 rad/s) sets it; within 20 % of the sampled model.
    assert!(
        (settle - settle_model).abs() <= 0.2 * settle_model,
        "2 % settling {:.1} ms, sampled design model {:.1} ms",
        settle * 1e3,
        settle_model * 1e3
    );
    // No steady-state error (integral action): the true mean speed within 0.5 % of the
    // setpoint; the estimate's quantum (1.26 rad/s per speed period) dithers around it.
    assert!(
        (steady - STEP_RAD_S).abs() < 0.005 * STEP_RAD_S,
        "steady-state speed {steady} rad/s, setpoint {STEP_RAD_S}"
    );
    // The trajectory, not only its figures: within 3 % of the step of the sampled model
    // everywhere (the encoder's quantisation of the estimate, 1.26 rad/s × Kp = 0.18 A of
    // current reference, moves the speed by a fraction of a rad/s).
    assert!(
        worst < 0.03 * STEP_RAD_S,
        "deviates {worst} rad/s from the sampled design model"
    );
}
