//! Conservation and accuracy: energy in equals energy stored plus losses, oil is conserved
//! in the closed circuit, and the 50 µs step against a fine-step reference.

use super::*;

/// Runs the rig with a voltage vector locked to the rotor (u_q fixed, u_d = 0) for `t_end`;
/// returns the plant and ∫ V̇·p²/(2β) dt over both chambers, sampled every PWM period.
fn run_open_loop(rig: &Rig, u_q: f64, t_end: f64) -> (Plant, f64) {
    run_open_loop_with(rig, u_q, t_end, Integrator::default())
}

/// [`run_open_loop`] with the plant's integration scheme `integrator`.
fn run_open_loop_with(rig: &Rig, u_q: f64, t_end: f64, integrator: Integrator) -> (Plant, f64) {
    run_open_loop_from(
        rig,
        &InitialConditions::holding(rig, 2e6),
        u_q,
        t_end,
        integrator,
    )
}

/// [`run_open_loop_with`] from the initial conditions `init`.
fn run_open_loop_from(
    rig: &Rig,
    init: &InitialConditions,
    u_q: f64,
    t_end: f64,
    integrator: Integrator,
) -> (Plant, f64) {
    let mut plant = Plant::new(rig, init, 7).unwrap();
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
fn an_end_stop_contact_keeps_the_energy_balance() {
    // The piston starts a tenth of a millimetre short of an end stop and is driven into it, one
    // way and the other, by both schemes: the stop's spring stores 0.5·k·(penetration)²
    // and its damper dissipates the rest of the contact force's work, so energy in equals
    // energy stored plus losses as it does away from the stops (the same tolerance as the
    // free run above).
    let rig = quiet(Rig::nominal());
    let h = rig.cylinder.half_stroke_m;
    for integrator in [Integrator::default(), Integrator::Rk4 { substeps: 1 }] {
        for (side, u_q) in [(1.0, 30.0), (-1.0, -30.0)] {
            let init = InitialConditions {
                x_m: side * (h - 1e-4),
                ..InitialConditions::holding(&rig, 2e6)
            };
            let (plant, boundary) = run_open_loop_from(&rig, &init, u_q, 0.5, integrator);
            let (o, e) = (plant.observe(), plant.energy());
            assert!(
                side * o.x_m > h,
                "{integrator:?}, side {side}: the piston must press into the stop: x {}",
                o.x_m
            );
            let rel = (e.residual_j() + boundary).abs() / e.input_j;
            assert!(
                rel < 1e-3,
                "{integrator:?}, side {side}: residual {:.3e} J of {:.3} J in ({e:?})",
                e.residual_j(),
                e.input_j
            );
        }
    }
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
