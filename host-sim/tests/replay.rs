//! Subsystem replays (issue 5 groundwork): a closed-loop run of the nominal rig becomes a
//! bench log; replaying that log's hydraulics (from the logged shaft angle and piston) and
//! its motor (from the logged currents) on the same rig reproduces it up to the sensors'
//! noise, and on a rig with another absorber precharge or more leakage clearly does not.

use closed_loop::scenario::by_name;
use host_sim::diagnose::replay::ShaftSource;
use host_sim::diagnose::{fit_percent, replay_hydraulics, replay_motor, ReplayError};
use host_sim::run::{run, Run, RunOptions};
use plant_model::Rig;

/// The pressure-step run (3 → 5 MPa at 0.5 s, blocked cylinder): the step gives the
/// pressure a spread far above the transducer's noise, and filling the absorber turns the
/// shaft through many revolutions.
fn pressure_step_log() -> Run {
    let rig = Rig::nominal();
    let scenario = by_name("pressure-step").expect("scenario exists");
    run(
        &rig,
        &rig,
        scenario,
        &RunOptions {
            duration_s: 2.0,
            log_rate_hz: 1e3,
            seed: 11,
            progress: false,
            metadata: Vec::new(),
        },
    )
    .expect("nominal run")
}

/// The best fit any model can reach on the logged pressure: the transducer's white noise
/// and its ADC's rounding (uniform over one LSB, variance LSB²/12) are in the log and in no
/// simulation, so ‖y − ŷ‖ ≥ σ·√N for the true ŷ.
fn pressure_fit_bound(rig: &Rig, measured: &[f64]) -> f64 {
    let s = &rig.sensors.pressure;
    let sigma = (s.noise_pa_rms.powi(2) + s.pa_per_lsb.powi(2) / 12.0).sqrt();
    let mean = measured.iter().sum::<f64>() / measured.len() as f64;
    let spread = measured
        .iter()
        .map(|y| (y - mean).powi(2))
        .sum::<f64>()
        .sqrt();
    100.0 * (1.0 - sigma * (measured.len() as f64).sqrt() / spread)
}

/// The nominal rig with its absorber's precharge down to 2 MPa (gas loss) and with extra
/// leakage of 5e-13 (m³/s)/Pa (2.5 times the pump's own): rigs a replay must tell apart.
fn other_rigs() -> (Rig, Rig) {
    let mut gas_loss = Rig::nominal();
    gas_loss.absorber.precharge_pa = 2e6;
    let mut leaky = Rig::nominal();
    leaky.pump.extra_leakage_m3_s_pa = 5e-13;
    (gas_loss, leaky)
}

#[test]
fn hydraulic_replay_reproduces_the_pressure_to_the_noise_and_tells_rigs_apart() {
    let r = pressure_step_log();
    let log = &r.log;
    let nominal = Rig::nominal();
    let bound = pressure_fit_bound(&nominal, &log.p_pa);
    let same = replay_hydraulics(log, &nominal).expect("replay");
    let fit = same.pressure_fit(log).expect("fit");
    let truth_fit = fit_percent(&log.p_pa, &r.p_true_pa).expect("fit");
    let (gas_loss, leaky) = other_rigs();
    let [fit_gas, fit_leak] = [gas_loss, leaky].map(|rig| {
        replay_hydraulics(log, &rig)
            .expect("replay")
            .pressure_fit(log)
            .expect("fit")
    });
    eprintln!(
        "hydraulic replay: fit {fit:.3} % (noise bound {bound:.3} %, true pressure {truth_fit:.3} %), \
         precharge 2 MPa {fit_gas:.2} %, extra leakage 5e-13 {fit_leak:.2} %"
    );
    assert!(
        fit > bound - 0.1 && fit < bound + 0.05,
        "{fit} vs bound {bound}"
    );
    assert!(fit_gas < fit - 10.0, "{fit_gas}");
    assert!(fit_leak < fit - 10.0, "{fit_leak}");
}

#[test]
fn hydraulic_replay_from_the_angle_is_closer_to_the_truth_than_from_the_speed() {
    let r = pressure_step_log();
    let mut log = r.log.clone();
    let nominal = Rig::nominal();
    let from_angle = replay_hydraulics(&log, &nominal).expect("replay");
    log.theta_m_rad = None;
    let from_speed = replay_hydraulics(&log, &nominal).expect("replay");
    assert_eq!(from_angle.shaft_source, ShaftSource::Angle);
    assert_eq!(from_speed.shaft_source, ShaftSource::Speed);
    let fit_angle = from_angle.pressure_fit(&log).expect("fit");
    let fit_speed = from_speed.pressure_fit(&log).expect("fit");
    // Against the true pressure of the generating run, without the transducer's noise.
    let rms = |sim: &[f64]| {
        let e: f64 = sim
            .iter()
            .zip(&r.p_true_pa)
            .map(|(s, p)| (s - p).powi(2))
            .sum();
        (e / sim.len() as f64).sqrt()
    };
    let (e_angle, e_speed) = (rms(&from_angle.p_pa), rms(&from_speed.p_pa));
    eprintln!(
        "hydraulic replay from the speed: fit {fit_speed:.3} %, rms error {e_speed:.0} Pa \
         (from the angle {fit_angle:.3} %, {e_angle:.0} Pa)"
    );
    // The angle carries the displaced volume exactly; the observer's speed carries its lag
    // and noise into the integral.
    assert!(e_speed > 1.1 * e_angle, "{e_speed} vs {e_angle}");
    assert!(fit_speed > 90.0, "{fit_speed}");
}

#[test]
fn a_log_breaking_the_contract_is_refused_with_its_place() {
    let mut log = pressure_step_log().log;
    log.t_s[40] = log.t_s[39];
    let err = replay_hydraulics(&log, &Rig::nominal()).expect_err("time does not increase");
    assert!(matches!(err, ReplayError::Log(_)), "{err}");
    assert!(err.to_string().contains("t_s"), "{err}");
}

#[test]
fn motor_replay_reproduces_the_speed_and_tells_rigs_apart() {
    // The motor replay keeps the simulated shaft on the logged angle below
    // TRACKING_BANDWIDTH_RAD_S, so a motor-side difference shows in the q current the model
    // needs to follow the logged motion (against the logged `iq_a`), not in a drifting
    // speed. Hydraulic differences are the hydraulic replay's to tell: at this bandwidth the
    // tracking's own correction noise is as large as their torque.
    let r = pressure_step_log();
    let log = &r.log;
    let nominal = Rig::nominal();
    let same = replay_motor(log, &nominal).expect("replay");
    let fit = same.speed_fit(log).expect("fit");
    let iq_fit =
        |rep: &host_sim::diagnose::Replay| fit_percent(&log.iq_a, &rep.iq_needed_a).expect("fit");
    let fit_iq = iq_fit(&same);
    // Shaft drag of 0.3 N·m the log's rig does not have: 0.27 A of q current at K_t = 1.1.
    let mut dragging = nominal.clone();
    dragging.shaft.coulomb_nm = 0.3;
    dragging.shaft.static_nm = 0.4;
    let fit_drag = iq_fit(&replay_motor(log, &dragging).expect("replay"));
    eprintln!(
        "motor replay: speed fit {fit:.3} %, needed-current fit {fit_iq:.2} %, \
         with 0.3 N·m shaft drag {fit_drag:.2} %"
    );
    assert!(fit > 90.0, "{fit}");
    // The error (100 − fit) on the needed current: the wrong rig leaves at least twice the
    // nominal rig's, which is the current sensor's noise and the tracking's.
    assert!(
        100.0 - fit_drag > 2.0 * (100.0 - fit_iq),
        "{fit_drag} vs {fit_iq}"
    );
}

/// Eq. 20's normalised displacement of a `z`-piston pump at shaft angle `theta`, summed
/// piston by piston (each delivers while its velocity, ∝ sin(θ + 2πi/z), is positive):
/// written here from the equation, not taken from the plant model.
fn kinematic_shape(z: u32, theta: f64) -> f64 {
    let zf = f64::from(z);
    (0..z)
        .map(|i| {
            (theta + std::f64::consts::TAU * f64::from(i) / zf)
                .sin()
                .max(0.0)
        })
        .sum::<f64>()
        * std::f64::consts::PI
        / zf
}

#[test]
fn inner_loop_replay_applies_the_pump_torque_ripple_at_the_logged_angle() {
    use host_sim::diagnose::predict::{predict, Predictor};
    // A 9-piston pump with ten times its kinematic ripple, holding 5 MPa: a torque line at
    // order 18 well above the current sensor's noise.
    let scale = 10.0;
    let with_ripple = |z: u32| {
        let mut r = Rig::nominal();
        r.pump.pistons = z;
        r.pump.piston_ripple = true;
        r.pump.ripple_amplitude_ratio = scale * plant_model::pump::kinematic_ripple_ratio(z);
        r
    };
    let truth = with_ripple(9);
    let scenario = by_name("pressure-hold").expect("scenario exists");
    let r = run(
        &truth,
        &Rig::nominal(),
        scenario,
        &RunOptions {
            duration_s: 2.0,
            log_rate_hz: 1e3,
            seed: 5,
            progress: false,
            metadata: Vec::new(),
        },
    )
    .expect("run");
    let log = &r.log;
    let from = log
        .t_s
        .iter()
        .position(|t| *t >= 1.0)
        .expect("rows after 1 s");
    let iq_error_power = |rig: &Rig| {
        let p = predict(log, rig, Predictor::InnerLoops, usize::MAX, 0.0).expect("replay");
        let iq = &p
            .iter()
            .find(|(n, _)| *n == "iq_a")
            .expect("iq predicted")
            .1;
        let n = log.len() - from;
        (from..log.len())
            .map(|i| (log.iq_a[i] - iq[i]).powi(2))
            .sum::<f64>()
            / n as f64
    };
    let (right, none, wrong) = (
        iq_error_power(&truth),
        iq_error_power(&Rig::nominal()),
        iq_error_power(&with_ripple(7)),
    );
    // The ripple's own q current: D/2π·Δp·scale·(s(θ) − 1)/K_t at the logged angles.
    let nominal = Rig::nominal();
    let d_per_rad = nominal.pump.displacement_m3_per_rev / std::f64::consts::TAU;
    let k_t = 1.5 * f64::from(nominal.motor.pole_pairs) * nominal.motor.psi_f_wb;
    let theta = log.theta_m_rad.as_ref().expect("angle logged");
    let k = plant_model::pump::kinematic_ripple_ratio(9);
    let ripple_power = (from..log.len())
        .map(|i| {
            let dp = log.p_pa[i] - nominal.fill.pressure_pa;
            (d_per_rad * dp * scale * (kinematic_shape(9, theta[i]) - 1.0) / k_t).powi(2)
        })
        .sum::<f64>()
        / (log.len() - from) as f64;
    eprintln!(
        "q-current error power: right ripple {right:.3e}, none {none:.3e}, 7 pistons \
         {wrong:.3e}; the ripple's own {ripple_power:.3e} A² (kinematic p-p {k:.4})"
    );
    // Most of the ripple's current is explained by the right ripple; a 7-piston ripple
    // of the same size, at order 14, explains none of it.
    assert!(none - right > 0.8 * ripple_power, "{none} − {right}");
    assert!(wrong > none, "{wrong} vs {none}");
}

#[test]
fn lock_in_recovers_a_ripple_amplitude_the_simplex_left_off() {
    use host_sim::diagnose::analysis::{predictors, scored_rows, segments};
    use host_sim::diagnose::candidates::{candidates, Structure};
    use host_sim::diagnose::fit::{CandidateFit, Target};
    use host_sim::diagnose::lock_in::refine_ripple_amplitude;
    use host_sim::diagnose::predict::{predict, Predictor};
    use plant_model::pump::kinematic_ripple_ratio;
    // A 9-piston pump at twice its kinematic ripple, holding 5 MPa on the nominal rig: a
    // q-current line below the current's noise per sample.
    let truth_ratio = 2.0 * kinematic_ripple_ratio(9);
    let mut truth = Rig::nominal();
    truth.pump.piston_ripple = true;
    truth.pump.ripple_amplitude_ratio = truth_ratio;
    let scenario = by_name("pressure-hold").expect("scenario exists");
    let options = RunOptions {
        duration_s: 3.0,
        log_rate_hz: 1e3,
        seed: 17,
        progress: false,
        metadata: Vec::new(),
    };
    let log = run(&truth, &Rig::nominal(), scenario, &options)
        .expect("run")
        .log;
    let nominal = Rig::nominal();
    let c = candidates(&nominal, &predictors(&log), true, &[72], &[9])
        .into_iter()
        .find(|c| {
            c.name == "piston_ripple"
                && c.predictor == Predictor::InnerLoops
                && c.structure == Structure::Pistons(9)
        })
        .expect("the inner loops' 9-piston ripple");
    let (split, from) = segments(&log);
    let (from, rows) = scored_rows(&log, c.predictor, split, from);
    let base = predict(&log, &nominal, c.predictor, rows, 0.0).expect("replay");
    let target = Target::new(&log, &nominal, rows, from, &base);
    // Start 60 % high and 40 % low (ln 1.6, ln 0.6 from the truth), tolerances nominal.
    for off in [1.6f64, 0.6] {
        let mut u = c.start.clone();
        u[0] = (truth_ratio * off / kinematic_ripple_ratio(9)).ln();
        let cost = target.cost(&c, &u);
        let start = CandidateFit {
            candidate: c.clone(),
            u,
            cost,
            evaluations: 0,
        };
        let refined = refine_ripple_amplitude(&target, start);
        let fitted = kinematic_ripple_ratio(9) * refined.u[0].exp();
        eprintln!("from {off}× the truth: {fitted:.4} against {truth_ratio:.4}");
        assert!(
            (fitted / truth_ratio - 1.0).abs() < 0.1,
            "{fitted} vs {truth_ratio}"
        );
    }
}
