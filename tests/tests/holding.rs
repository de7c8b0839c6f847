//! Low-speed pressure holding (scenario `pressure-hold`, the paper's working point): with the
//! cylinder blocked, the pump turns only to replace what leaks from the high side, so by
//! conservation of oil on port A (eq. 9–11) its mean speed is
//!
//! ```text
//! ω̄ = (Q_leak + dV_stored/dt) / K_q,   K_q = D_p/2π
//! Q_leak = C_ip·(p_A − p_B) + C_ep·(p_A − p_fill) + C_ic·(p_A − p_B)
//! ```
//!
//! (pump internal and external leakage, cylinder cross-piston leakage), with p_B and the
//! fill (case) pressure taken from the plant's observables, and the storage term (oil into
//! the absorber and compression of chamber A's oil over the window) close to zero once the
//! pressure is held.

use closed_loop::by_name;
use plant_model::Rig;
use tests::closed_loop_at;

#[test]
fn holding_speed_replaces_the_leakage() {
    let scenario = by_name("pressure-hold").expect("scenario pressure-hold");
    let rig = Rig::nominal();
    let mut l = closed_loop_at(&rig, scenario, 20e3, 3);
    let (t0, t1) = (scenario.steady_from_s, scenario.duration_s);
    l.run(t0, 1000, |_| {});
    let start = l.plant().observe();
    let (c_ip, c_ep, c_ic) = (
        rig.pump.internal_leakage_m3_s_pa,
        rig.pump.external_leakage_m3_s_pa,
        rig.cylinder.internal_leakage_m3_s_pa,
    );
    let (mut leak_sum, mut p_sum, mut n) = (0.0, 0.0, 0usize);
    l.run(t1, 1, |s| {
        let o = &s.truth;
        leak_sum += c_ip * (o.p_a_pa - o.p_b_pa)
            + c_ep * (o.p_a_pa - o.p_fill_pa)
            + c_ic * (o.p_a_pa - o.p_b_pa);
        p_sum += o.p_a_pa;
        n += 1;
    });
    let end = l.plant().observe();
    let span = end.t_s - start.t_s;
    let leak = leak_sum / n as f64;
    let stored = (end.absorber_oil_m3 - start.absorber_oil_m3
        + rig.cylinder.chamber_a_volume_m3 * (end.p_a_pa - start.p_a_pa) / rig.oil.bulk_modulus_pa)
        / span;
    let k_q = rig.pump.displacement_m3_per_rev / std::f64::consts::TAU;
    let expected = (leak + stored) / k_q;
    let mean_speed = (end.theta_m_rad - start.theta_m_rad) / span;
    println!(
        "holding at {:.3} MPa: mean shaft speed {mean_speed:.4} rad/s ({:.1} rpm), leakage \
         {:.4e} m³/s + storage {stored:.2e} m³/s → {expected:.4} rad/s, difference {:.2} %",
        p_sum / n as f64 / 1e6,
        mean_speed * 60.0 / std::f64::consts::TAU,
        leak,
        (mean_speed / expected - 1.0) * 100.0
    );
    assert!(
        (p_sum / n as f64 - 5e6).abs() < 0.01 * 5e6,
        "not holding 5 MPa"
    );
    // Conservation leaves nothing else on port A (the relief valve is shut at 5 MPa), so
    // 1 % (tighter than the 5 % asked of the holding figure) covers the rectangle-rule mean
    // of the leakage over the 20 kHz samples.
    assert!(
        (mean_speed - expected).abs() <= 0.01 * expected,
        "mean speed {mean_speed} rad/s, leakage replacement needs {expected} rad/s"
    );
}
