//! The plant against independent numbers: analytic solutions of its sub-models, textbook
//! formulas, the paper's equations, and conservation of energy and oil.

mod common;
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

#[test]
fn locked_rotor_current_steps_rise_with_l_over_r() {
    let mut rig = quiet(Rig::nominal());
    // A rotor held by a brake: breakaway (the largest a rig may have) far above any torque
    // here.
    rig.shaft.static_nm = 1e3;
    rig.shaft.coulomb_nm = 1e3;
    let (r, u_dc) = (rig.motor.r_s_ohm, rig.inverter.u_dc_v);
    for (axis, l) in [("d", rig.motor.l_d_h), ("q", rig.motor.l_q_h)] {
        let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
        let u = 10.0;
        let duties = if axis == "d" {
            duties_for(u, 0.0, 0.0, u_dc)
        } else {
            duties_for(0.0, u, 0.0, u_dc)
        };
        let tau = l / r;
        let dt = 10e-6;
        let mut t = 0.0;
        let mut t63 = None;
        while t < 6.0 * tau {
            plant.advance(dt, &Inputs::duties(duties, true));
            t += dt;
            let o = plant.observe();
            let i = if axis == "d" { o.i_d_a } else { o.i_q_a };
            if t63.is_none() && i >= (1.0 - (-1.0f64).exp()) * u / r {
                t63 = Some(t);
            }
        }
        let o = plant.observe();
        let (i_axis, i_other) = if axis == "d" {
            (o.i_d_a, o.i_q_a)
        } else {
            (o.i_q_a, o.i_d_a)
        };
        let t63 = t63.expect("current never reached 63 %");
        assert!(
            (t63 - tau).abs() < 0.01 * tau,
            "{axis}: τ {t63} vs L/R {tau}"
        );
        assert!(
            (i_axis - u / r * (1.0 - (-6.0f64).exp())).abs() < 1e-3 * u / r,
            "{axis}: {i_axis}"
        );
        assert!(i_other.abs() < 1e-6, "{axis}: cross-axis current {i_other}");
        assert_eq!(o.omega_m_rad_s, 0.0, "the rotor must stay locked");
    }
}

#[test]
fn back_emf_at_constant_speed_is_psi_f_times_omega_e() {
    // A flywheel so heavy that the speed is constant: applying exactly u_q = ψ_f·ω_e, u_d = 0
    // keeps the currents at zero; 5 % less makes them flow.
    let mut rig = quiet(Rig::nominal());
    rig.shaft.motor_inertia_kg_m2 = 10.0; // the largest a rig may have
    rig.cylinder.blocked = true;
    let omega_m = 100.0;
    let omega_e = 4.0 * omega_m;
    let emf = rig.motor.psi_f_wb * omega_e;
    for (scale, expect_zero) in [(1.0, true), (0.95, false)] {
        let init = InitialConditions {
            omega_rad_s: omega_m,
            ..InitialConditions::at_rest(&rig)
        };
        let mut plant = Plant::new(&rig, &init, 1).unwrap();
        let dt = 10e-6;
        let mut worst: f64 = 0.0;
        for _ in 0..2000 {
            let theta_e = 4.0 * plant.observe().theta_m_rad;
            let d = duties_for(
                0.0,
                scale * emf,
                theta_e + omega_e * dt / 2.0,
                rig.inverter.u_dc_v,
            );
            plant.advance(dt, &Inputs::duties(d, true));
            let o = plant.observe();
            worst = worst.max(o.i_d_a.hypot(o.i_q_a));
        }
        if expect_zero {
            assert!(worst < 0.05, "current with u_q = ψ_f·ω_e: {worst} A");
        } else {
            // Steady state of eq. 2 with ΔU = 5 % of the EMF: |i| ≈ ΔU/|Z| with Z ≈ ω_e·L.
            assert!(worst > 0.5, "current with 95 % of the EMF: {worst} A");
        }
    }
}

#[test]
fn torque_is_eq_3_and_accelerates_the_shaft() {
    let rig = quiet(Rig::nominal());
    let m = &rig.motor;
    for (i_d, i_q) in [(0.0, 10.0), (-5.0, 8.0), (3.0, -4.0)] {
        let expected = 1.5 * 4.0 * (m.psi_f_wb * i_q + (m.l_d_h - m.l_q_h) * i_d * i_q);
        let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
        let inputs = Inputs {
            drive: Drive::Currents { i_d, i_q },
            piston: None,
            external_force_n: 0.0,
            external_torque_nm: 0.0,
        };
        plant.advance(1e-5, &inputs);
        let o = plant.observe();
        assert!((o.torque_em_nm - expected).abs() < 1e-9 * expected.abs().max(1.0));
        // Newton: after 2 ms from rest, ω ≈ T·t/J (viscous and pump torque negligible).
        plant.advance(2e-3 - 1e-5, &inputs);
        let w = plant.observe().omega_m_rad_s;
        let w_expected = expected * 2e-3 / 8.0e-4;
        assert!(
            (w - w_expected).abs() < 0.01 * w_expected.abs(),
            "ω {w} vs {w_expected}"
        );
    }
}

#[test]
fn cogging_appears_at_lcm_of_slots_and_poles() {
    let mut rig = quiet(Rig::nominal());
    Effect::parse("cogging_torque:amplitude_nm=0.05")
        .unwrap()
        .apply(&mut rig);
    // 9 slots, 8 poles: LCM(9, 8) = 72 cycles per revolution (nominal-rig.md).
    assert_eq!(rig.motor.cogging[0].order, 72);
    let motor = Motor::new(&rig.motor);
    let n = 4096;
    let torque: Vec<f64> = (0..n)
        .map(|k| motor.cogging_torque_nm(2.0 * PI * k as f64 / n as f64))
        .collect();
    let spec = amplitude_spectrum(&torque);
    assert_eq!(dominant_order(&spec), 72);
    assert!((spec[72] - 0.05).abs() < 1e-9);
    // In the running plant: the shaft torque seen at constant speed repeats 72 times per turn.
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
    let omega = 2.0 * PI; // one revolution per second
    let inputs = Inputs {
        drive: Drive::ShaftSpeed { omega_rad_s: omega },
        piston: None,
        external_force_n: 0.0,
        external_torque_nm: 0.0,
    };
    let samples: Vec<f64> = (0..n)
        .map(|_| {
            plant.advance(1.0 / n as f64, &inputs);
            plant.observe().torque_cogging_nm
        })
        .collect();
    assert_eq!(dominant_order(&amplitude_spectrum(&samples)), 72);
}

#[test]
fn flux_harmonics_give_the_predicted_6th_and_12th_torque() {
    let mut rig = quiet(Rig::nominal());
    let (psi5, psi7, psi11, psi13) = (0.002, 0.001, 0.0005, -0.0003);
    rig.motor.flux_harmonics = [
        FluxHarmonic {
            amplitude_wb: psi5,
            order: 5,
            phase_rad: 0.0,
        },
        FluxHarmonic {
            amplitude_wb: psi7,
            order: 7,
            phase_rad: 0.0,
        },
        FluxHarmonic {
            amplitude_wb: psi11,
            order: 11,
            phase_rad: 0.0,
        },
        FluxHarmonic {
            amplitude_wb: psi13,
            order: 13,
            phase_rad: 0.0,
        },
    ];
    let motor = Motor::new(&rig.motor);
    let i_q = 5.0;
    let n = 1024;
    let torque: Vec<f64> = (0..n)
        .map(|k| {
            let th = 2.0 * PI * k as f64 / n as f64;
            motor.torque_nm(0.0, i_q, &motor.magnet_flux(th))
        })
        .collect();
    let spec = amplitude_spectrum(&torque);
    // Classical result for i_d = 0: T_6 = 1.5·p_n·i_q·(7ψ_7 − 5ψ_5), T_12 = 1.5·p_n·i_q·(13ψ_13 − 11ψ_11).
    let k = 1.5 * 4.0 * i_q;
    assert!((spec[0] - k * rig.motor.psi_f_wb).abs() < 1e-9);
    assert!(
        (spec[6] - (k * (7.0 * psi7 - 5.0 * psi5)).abs()).abs() < 1e-9,
        "T6 {}",
        spec[6]
    );
    assert!(
        (spec[12] - (k * (13.0 * psi13 - 11.0 * psi11)).abs()).abs() < 1e-9,
        "T12 {}",
        spec[12]
    );
    for (h, a) in spec.iter().enumerate().skip(1) {
        if h != 6 && h != 12 {
            assert!(*a < 1e-9, "unexpected harmonic {h}: {a}");
        }
    }
    // The catalogue's t6_ratio is the 6th-harmonic torque over the mean torque.
    let mut rig = quiet(Rig::nominal());
    Effect::parse("flux_harmonics:t6_ratio=0.03")
        .unwrap()
        .apply(&mut rig);
    let motor = Motor::new(&rig.motor);
    let torque: Vec<f64> = (0..n)
        .map(|k| motor.torque_nm(0.0, i_q, &motor.magnet_flux(2.0 * PI * k as f64 / n as f64)))
        .collect();
    let spec = amplitude_spectrum(&torque);
    assert!((spec[6] / spec[0] - 0.03).abs() < 1e-9);
}

/// Eq. 20 summed the plain way: every piston whose velocity term is positive delivers.
fn brute_force_shape(theta: f64, z: u32) -> f64 {
    (0..z)
        .map(|i| (theta + 2.0 * PI * i as f64 / z as f64).sin().max(0.0))
        .sum::<f64>()
        * PI
        / z as f64
}

#[test]
fn pump_flow_ripple_matches_the_kinematic_formula() {
    for (z, ratio, order) in [(9u32, 0.0152, 18usize), (8, 0.078, 8)] {
        let mut rig = Rig::nominal();
        Effect::parse(&format!("piston_ripple:pistons={z}"))
            .unwrap()
            .apply(&mut rig);
        let pump = Pump::new(&rig.pump);
        let n = 8192;
        let shape: Vec<f64> = (0..n)
            .map(|k| pump.displacement_factor(2.0 * PI * k as f64 / n as f64))
            .collect();
        for (k, s) in shape.iter().enumerate().step_by(37) {
            let b = brute_force_shape(2.0 * PI * k as f64 / n as f64, z);
            assert!((s - b).abs() < 1e-12, "z={z}: closed form {s} vs sum {b}");
        }
        let mean = shape.iter().sum::<f64>() / n as f64;
        let pp = shape.iter().cloned().fold(f64::MIN, f64::max)
            - shape.iter().cloned().fold(f64::MAX, f64::min);
        assert!((mean - 1.0).abs() < 1e-6, "z={z}: mean {mean}");
        assert!(
            (pp - ratio).abs() < 0.0005 * (ratio / 0.0152),
            "z={z}: p-p {pp} vs {ratio}"
        );
        assert_eq!(dominant_order(&amplitude_spectrum(&shape)), order, "z={z}");
    }
    // A measured ripple ratio scales the kinematic shape.
    let mut rig = Rig::nominal();
    Effect::parse("piston_ripple:pistons=9,amplitude_ratio=0.05")
        .unwrap()
        .apply(&mut rig);
    let pump = Pump::new(&rig.pump);
    let s: Vec<f64> = (0..8192)
        .map(|k| pump.displacement_factor(2.0 * PI * k as f64 / 8192.0))
        .collect();
    let pp =
        s.iter().cloned().fold(f64::MIN, f64::max) - s.iter().cloned().fold(f64::MAX, f64::min);
    assert!((pp - 0.05).abs() < 1e-4);
}

#[test]
fn mean_pump_flow_is_displacement_times_speed_minus_leakage() {
    // Blocked cylinder, no absorber: dp/dt·V/β is the net flow into port A.
    let mut rig = quiet(Rig::nominal());
    rig.cylinder.blocked = true;
    rig.absorber.enabled = false;
    let p0 = 5e6;
    let omega = 6.0;
    // Port B starts where its check valve passes the pump's suction flow, so it stays put.
    let suction = 1.5e-6 / (2.0 * PI) * omega;
    let init = InitialConditions {
        p_b_pa: rig.fill.pressure_pa
            - rig.fill.check_cracking_pa
            - suction / rig.fill.check_conductance_m3_s_pa,
        ..InitialConditions::holding(&rig, p0)
    };
    let mut plant = Plant::new(&rig, &init, 1).unwrap();
    let t = 0.01;
    let before = plant.observe();
    plant.advance(t, &speed_drive(omega));
    let after = plant.observe();
    let dp_dt = (after.p_a_pa - before.p_a_pa) / t;
    let p = 0.5 * (after.p_a_pa + before.p_a_pa);
    let p_low = 0.5 * (before.p_b_pa + after.p_b_pa);
    let q = 1.5e-6 / (2.0 * PI) * omega
        - 1e-13 * (p - p_low) // pump internal (eq. 9)
        - 1e-13 * (p - before.p_fill_pa) // pump external, case at fill pressure
        - 1e-13 * (p - p_low); // cylinder cross-piston
    let expected = q * 6.5e8 / 450e-6;
    assert!(
        (dp_dt - expected).abs() < 1e-3 * expected.abs(),
        "dp/dt {dp_dt} vs {expected}"
    );
}

#[test]
fn blocked_cylinder_pressure_rises_at_q_over_total_capacitance() {
    let mut rig = quiet(Rig::nominal());
    rig.cylinder.blocked = true;
    rig.pump.internal_leakage_m3_s_pa = 0.0;
    rig.pump.external_leakage_m3_s_pa = 0.0;
    rig.cylinder.internal_leakage_m3_s_pa = 0.0;
    let (v0, p0, n) = (400e-6, 3e6, 1.3);
    let c_oil = 450e-6 / 6.5e8;
    // The gas law in absolute pressure; the contract's formula with p and p_0 absolute.
    let c_acc = |p: f64| {
        if p <= p0 {
            0.0
        } else {
            let (pa, p0a) = (p + ATMOSPHERE_PA, p0 + ATMOSPHERE_PA);
            v0 * (p0a / pa).powf(1.0 / n) / (n * pa)
        }
    };
    let omega = 50.0;
    let q = 1.5e-6 / (2.0 * PI) * omega;
    let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 1e6), 1).unwrap();
    // Below precharge: oil only.
    let dt = 1e-3;
    let a = plant.observe().p_a_pa;
    plant.advance(dt, &speed_drive(omega));
    let b = plant.observe().p_a_pa;
    let expected = q / (c_oil + c_acc(0.5 * (a + b)));
    assert!(
        ((b - a) / dt - expected).abs() < 1e-3 * expected,
        "below precharge"
    );
    assert_eq!(c_acc(b), 0.0);
    // Above precharge, once the inlet's oscillation has died out: a quasi-static ramp.
    while plant.observe().p_a_pa < p0 {
        plant.advance(dt, &speed_drive(omega));
    }
    plant.advance(1.0, &speed_drive(omega));
    for _ in 0..3 {
        let a = plant.observe().p_a_pa;
        let window = 0.2;
        plant.advance(window, &speed_drive(omega));
        let b = plant.observe().p_a_pa;
        let expected = q / (c_oil + c_acc(0.5 * (a + b)));
        let got = (b - a) / window;
        assert!(
            (got - expected).abs() < 0.01 * expected,
            "at {:.2} MPa: {got} vs {expected}",
            a / 1e6
        );
        plant.advance(1.0, &speed_drive(omega));
    }
}

#[test]
fn payload_oscillates_at_the_hydraulic_natural_frequency() {
    let mut rig = quiet(Rig::nominal());
    rig.absorber.enabled = false;
    rig.cylinder.static_friction_n = 0.0;
    rig.cylinder.coulomb_friction_n = 0.0;
    rig.cylinder.viscous_n_s_per_m = 0.0;
    rig.pump.internal_leakage_m3_s_pa = 0.0;
    rig.pump.external_leakage_m3_s_pa = 0.0;
    rig.cylinder.internal_leakage_m3_s_pa = 0.0;
    let init = InitialConditions {
        p_a_pa: 5.02e6,
        p_b_pa: 4.98e6,
        ..InitialConditions::at_rest(&rig)
    };
    let mut plant = Plant::new(&rig, &init, 1).unwrap();
    let (beta, a, v, m): (f64, f64, f64, f64) = (6.5e8, 71e-4, 450e-6, 2000.0);
    let omega_h = (beta * a * a * (2.0 / v) / m).sqrt();
    let dt = 1e-5;
    let mut crossings = Vec::new();
    let mut last_v = 0.0;
    let mut t = 0.0;
    while crossings.len() < 11 && t < 1.0 {
        plant.advance(dt, &speed_drive(0.0));
        t += dt;
        let vel = plant.observe().v_m_s;
        if last_v > 0.0 && vel <= 0.0 {
            crossings.push(t - dt * vel / (vel - last_v));
        }
        last_v = vel;
    }
    let periods = (crossings[10] - crossings[0]) / 10.0;
    let omega = 2.0 * PI / periods;
    assert!(
        (omega - omega_h).abs() < 0.005 * omega_h,
        "ω {omega} vs ω_h {omega_h}"
    );
}

/// Runs the rig with a voltage vector locked to the rotor (u_q fixed, u_d = 0) for `t_end`;
/// returns the plant and ∫ V̇·p²/(2β) dt over both chambers, sampled every PWM period.
fn run_open_loop(rig: &Rig, u_q: f64, t_end: f64) -> (Plant, f64) {
    run_open_loop_with(rig, u_q, t_end, Integrator::default())
}

/// [`run_open_loop`] with the plant's integration scheme `integrator`.
fn run_open_loop_with(rig: &Rig, u_q: f64, t_end: f64, integrator: Integrator) -> (Plant, f64) {
    let mut plant = Plant::new(rig, &InitialConditions::holding(rig, 2e6), 7).unwrap();
    plant.set_integrator(integrator);
    let pwm = 50e-6;
    let (area, beta) = (rig.cylinder.area_m2, rig.oil.bulk_modulus_pa);
    let boundary_term = |o: &plant_model::Observables| {
        area * o.v_m_s * (o.p_a_pa * o.p_a_pa - o.p_b_pa * o.p_b_pa) / (2.0 * beta)
    };
    let mut t = 0.0;
    let mut term = 0.0;
    while t < t_end {
        let o = plant.observe();
        let theta_e = 4.0 * o.theta_m_rad + 4.0 * o.omega_m_rad_s * pwm / 2.0;
        let d = duties_for(0.0, u_q, theta_e, rig.inverter.u_dc_v);
        plant.advance(pwm, &Inputs::duties(d, true));
        term += 0.5 * pwm * (boundary_term(&o) + boundary_term(&plant.observe()));
        t += pwm;
    }
    (plant, term)
}

#[test]
fn energy_in_equals_stored_plus_losses() {
    // Every effect that has an energy path on, the piston free to move with friction.
    let mut rig = quiet(Rig::nominal());
    for e in [
        "cogging_torque",
        "flux_harmonics",
        "piston_ripple",
        "dead_time",
        "shaft_friction",
        "extra_leakage",
    ] {
        Effect::parse(e).unwrap().apply(&mut rig);
    }
    // Lifting the 2000 kg payload vertically: the pump works against ≈ 2.8 MPa.
    rig.cylinder.gravity_angle_rad = PI / 2.0;
    let (plant, boundary) = run_open_loop(&rig, 30.0, 0.5);
    let e = plant.energy();
    let o = plant.observe();
    assert!(
        o.omega_m_rad_s > 5.0 && o.x_m.abs() > 1e-5,
        "the run must move shaft and piston"
    );
    assert!(e.input_j > 1.0, "input {}", e.input_j);
    // The constant-β continuity equation dp/dt = β/V·(Q − V̇) is not exactly conservative:
    // d/dt(V·p²/2β) = p·(Q − V̇) + V̇·p²/(2β). The last term (the elastic energy carried by
    // the displaced oil, O(p/2β) of the boundary work) is computed here from the trajectory.
    let rel = (e.residual_j() + boundary).abs() / e.input_j;
    eprintln!(
        "energy: in {:.4} J, residual {:.3e} J, constant-β term {:.3e} J, unexplained {:.2e} of input",
        e.input_j, e.residual_j(), -boundary, rel
    );
    assert!(
        rel < 1e-3,
        "energy residual {:.3e} J of {:.3} J in ({:?})",
        e.residual_j(),
        e.input_j,
        e
    );
    // Blocked piston: no boundary work, the balance closes to rounding.
    rig.cylinder.blocked = true;
    let (plant, _) = run_open_loop(&rig, 30.0, 0.5);
    let e = plant.energy();
    assert!(e.residual_j().abs() < 1e-6 * e.input_j, "blocked: {:?}", e);
}

#[test]
fn oil_is_conserved_in_the_closed_circuit() {
    let mut rig = quiet(Rig::nominal());
    Effect::parse("piston_ripple").unwrap().apply(&mut rig);
    let before = Plant::new(&rig, &InitialConditions::holding(&rig, 2e6), 7)
        .unwrap()
        .oil_inventory_m3();
    let (plant, _) = run_open_loop(&rig, 8.0, 0.5);
    let after = plant.oil_inventory_m3();
    // Exact up to O((p/β)²)·V ≈ 1e-4·1e-3 m³.
    assert!((after - before).abs() < 2e-8, "oil {before} → {after} m³");
}

#[test]
fn integration_error_against_fine_step_reference() {
    // The same run at the default step (50 µs) with each integrator, and with RK4 at 1 µs
    // (the reference); the duties change every 50 µs in all of them. RK4 is fourth-order, the
    // exponential scheme third-order in its slow part: its bound of 1e-6 is 2 Pa at this
    // 2 MPa, a five-hundredth of the transducer's 1 kPa rms noise.
    let rk4 = Integrator::Rk4 { substeps: 1 };
    for (label, effects, tol_rk4, tol_exp) in [
        ("nominal", &[][..], 1e-7, 1e-6),
        (
            "all low-speed effects",
            &[
                "cogging_torque",
                "flux_harmonics",
                "piston_ripple",
                "shaft_friction",
            ][..],
            1e-6,
            1e-6,
        ),
    ] {
        let mut rig = quiet(Rig::nominal());
        for e in effects {
            Effect::parse(e).unwrap().apply(&mut rig);
        }
        let mut fine_rig = rig.clone();
        fine_rig.integration.max_step_s = 1e-6;
        let fine = run_open_loop_with(&fine_rig, 6.0, 0.2, rk4).0.observe();
        for (integrator, tol) in [(rk4, tol_rk4), (Integrator::Exponential, tol_exp)] {
            let coarse = run_open_loop_with(&rig, 6.0, 0.2, integrator).0.observe();
            let ep = (coarse.p_a_pa - fine.p_a_pa).abs() / fine.p_a_pa.abs();
            let ew = (coarse.omega_m_rad_s - fine.omega_m_rad_s).abs() / fine.omega_m_rad_s.abs();
            let name = integrator.name();
            eprintln!("{label}, {name}: relative error p_A {ep:.2e}, ω {ew:.2e} after 0.2 s");
            assert!(
                ep < tol && ew < tol,
                "{label}, {name}: p {ep:.2e}, ω {ew:.2e}"
            );
        }
    }
}

#[test]
fn step_never_panics_on_bad_inputs() {
    let rig = Rig::nominal();
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 3).unwrap();
    for inputs in [
        Inputs::duties([f64::NAN, 2.0, -1.0], true),
        Inputs::duties([0.5; 3], false),
        Inputs {
            drive: Drive::Currents {
                i_d: f64::INFINITY,
                i_q: f64::NAN,
            },
            piston: None,
            external_force_n: f64::NAN,
            external_torque_nm: 0.0,
        },
        Inputs {
            drive: Drive::ShaftSpeed {
                omega_rad_s: f64::NEG_INFINITY,
            },
            piston: Some((f64::NAN, 1e9)),
            external_force_n: 0.0,
            external_torque_nm: 0.0,
        },
    ] {
        for dt in [-1.0, 0.0, f64::NAN, 1e-4] {
            plant.advance(dt, &inputs);
            let _ = plant.sample();
        }
    }
    let o = plant.observe();
    assert!(o.p_a_pa.is_finite() && o.i_q_a.is_finite());
}

#[test]
fn sensors_quantise_and_wrap_like_the_peripherals() {
    let mut rig = quiet(Rig::nominal());
    rig.cylinder.blocked = true;
    let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 5e6), 1).unwrap();
    let s = plant.sample();
    // 5 MPa at 476.84 Pa/LSB above 6554 counts; zero current at mid-scale; 280 V at 0.1 V/LSB.
    assert_eq!(
        s.adc_pressure,
        (6554.0f64 + 5e6 / (25e6 / 52428.8)).round() as u16
    );
    assert_eq!(s.adc_phase_current, [2048; 3]);
    assert_eq!(s.adc_dc_link, 2800);
    // Turning one and a half revolutions passes the index once and wraps the counter.
    let mut index_seen = 0;
    for _ in 0..150 {
        plant.advance(0.01, &speed_drive(2.0 * PI));
        if plant.sample().encoder_index {
            index_seen += 1;
        }
    }
    assert_eq!(index_seen, 1);
    let count = plant.sample().encoder_count;
    assert!((count as i64 - 5000).abs() <= 2, "count {count}");
}

#[test]
fn dead_time_costs_one_dead_interval_per_pwm_period() {
    // A switching-level leg over one centre-aligned PWM period, independent of the average
    // model: the upper switch's gate is on while the triangular carrier is below the duty,
    // each turn-on delayed by t_d; while both gates are off, a positive current flows
    // through the lower diode (pole at 0 V). The pole's mean voltage falls short of
    // d·U_dc by t_d·f·U_dc: the falling edge loses nothing.
    use plant_model::inverter::Inverter;
    let rig = Rig::nominal();
    let mut p = rig.inverter.clone();
    p.dead_time_s = 1.5e-6;
    let (t_pwm, t_d, u_dc, duty) = (1.0 / p.pwm_frequency_hz, p.dead_time_s, p.u_dc_v, 0.6);
    let n = 200_000;
    let mut sum = 0.0;
    for k in 0..n {
        let t = (k as f64 + 0.5) / n as f64 * t_pwm;
        // The upper gate's command: the carrier 0 → 1 → 0 over the period below the duty.
        let upper_cmd = |t: f64| {
            let c = 1.0 - (2.0 * t.rem_euclid(t_pwm) / t_pwm - 1.0).abs();
            c < duty
        };
        // The upper switch conducts only if commanded now and for the last t_d.
        let upper_on = upper_cmd(t) && upper_cmd(t - t_d);
        // The lower switch conducts when commanded off now and for the last t_d; otherwise
        // (dead time) the positive current takes the lower diode: pole at 0 either way.
        sum += if upper_on { u_dc } else { 0.0 };
    }
    let mean = sum / n as f64;
    let loss_switching = duty * u_dc - mean;
    let average = Inverter::new(&p).pole_voltages(&[duty; 3], &[10.0, -5.0, -5.0])[0];
    let loss_average = duty * u_dc - average;
    let textbook = t_d / t_pwm * u_dc;
    assert!(
        (loss_switching - textbook).abs() < 0.01 * textbook,
        "{loss_switching} vs {textbook}"
    );
    assert!(
        (loss_average - textbook).abs() < 1e-9 * textbook,
        "{loss_average} vs {textbook}"
    );
}

#[test]
fn pressure_sensor_lag_trails_a_ramp_by_one_time_constant() {
    // A first-order lag τ·ṗ_s = p − p_s driven by a ramp settles to p − p_s = τ·ṗ. The pump
    // turned at a fixed speed into the blocked cylinder ramps port A; time constants from
    // twenty steps down to a fiftieth of one (where an explicit integration of the lag would
    // diverge) all trail it by τ·ṗ.
    for tau in [1e-3, 50e-6, 1e-6] {
        let mut rig = quiet(Rig::nominal());
        rig.cylinder.blocked = true;
        rig.sensors.pressure.lag_time_constant_s = tau;
        let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 2e6), 1).unwrap();
        let h = 50e-6;
        let mut p = Vec::new();
        let mut lag = Vec::new();
        for _ in 0..400 {
            plant.advance(h, &speed_drive(20.0));
            let o = plant.observe();
            p.push(o.p_a_pa);
            lag.push(o.p_a_pa - o.p_sensor_pa);
        }
        // After 20 ms (twenty time constants of the slowest), against the central difference.
        let k = 398;
        let slope = (p[k + 1] - p[k - 1]) / (2.0 * h);
        assert!(slope > 1e6, "τ = {tau}: the port ramps ({slope} Pa/s)");
        let expected = tau * slope;
        let err = (lag[k] - expected).abs() / expected;
        eprintln!(
            "τ = {tau}: p − p_s = {:.4e} Pa, τ·ṗ = {expected:.4e} Pa",
            lag[k]
        );
        assert!(
            err < 0.02,
            "τ = {tau}: trails by {} Pa, τ·ṗ = {expected} Pa",
            lag[k]
        );
    }
}
