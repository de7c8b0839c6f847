//! The plant's share of one closed-loop PWM period, without the controller: `sample`,
//! `observe` and a 50 µs `advance` per period, as the closed loop calls them, at the nominal
//! rig in low-speed pressure holding (blocked cylinder, 5 MPa, shaft near 60 rpm) with the
//! paper's low-speed effects on. The workload for instruction counts:
//!
//! ```text
//! valgrind --tool=callgrind target/release/examples/period_cost 20000 [INTEGRATOR]
//! ```
//!
//! Run it with two period counts and divide the difference of the totals by the difference
//! of the counts for the cost of one period, free of start-up. INTEGRATOR is one of
//! `exponential` (the default), `rk4`, `rk4-quarter`.

use plant_model::effects::paper_low_speed_effects;
use plant_model::{InitialConditions, Inputs, Integrator, Plant, Rig};
use std::hint::black_box;

fn main() {
    let periods: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20_000);
    let integrator = match std::env::args().nth(2) {
        Some(name) => Integrator::from_name(&name).unwrap_or_else(|| {
            eprintln!("period_cost: unknown integrator `{name}`");
            std::process::exit(2)
        }),
        None => Integrator::default(),
    };
    let mut rig = Rig::nominal();
    rig.cylinder.blocked = true;
    for e in paper_low_speed_effects() {
        e.apply(&mut rig);
    }
    let init = InitialConditions {
        omega_rad_s: 6.0,
        ..InitialConditions::holding(&rig, 5e6)
    };
    let mut plant = Plant::new(&rig, &init, 1).expect("valid rig");
    plant.set_integrator(integrator);
    let u_dc = rig.inverter.u_dc_v;
    let p_n = rig.motor.pole_pairs as f64;
    for _ in 0..periods {
        black_box(plant.sample());
        let o = black_box(plant.observe());
        // A voltage vector on the q axis, locked to the rotor: the shaft keeps turning.
        let theta_e = p_n * o.theta_m_rad;
        let (s, c) = (theta_e.sin(), theta_e.cos());
        let (alpha, beta) = (-2.0 * s, 2.0 * c);
        let va = alpha;
        let vb = -0.5 * alpha + 0.866_025_403_784_438_6 * beta;
        let vc = -0.5 * alpha - 0.866_025_403_784_438_6 * beta;
        let d = [0.5 + va / u_dc, 0.5 + vb / u_dc, 0.5 + vc / u_dc];
        plant.advance(50e-6, &Inputs::duties(d, true));
    }
    let o = plant.observe();
    println!(
        "{periods} periods ({}): ω {:.3} rad/s, p_A {:.1} Pa",
        integrator.name(),
        o.omega_m_rad_s,
        o.p_a_pa
    );
}
