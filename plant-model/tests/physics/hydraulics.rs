//! The pump and the hydraulics against eq. 20 and their analytic solutions: the kinematic
//! flow ripple, mean flow minus leakage, a blocked cylinder's dp/dt = Q/C and the payload's ω_h.

use super::*;

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
