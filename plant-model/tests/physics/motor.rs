//! The motor against its textbook numbers: the winding's L/R rise, the back-EMF ψ_f·ω_e,
//! the torque of eq. 3, cogging at LCM(slots, poles) and the flux harmonics' 6th and 12th torque.

use super::*;

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
