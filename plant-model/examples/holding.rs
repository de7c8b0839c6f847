//! The paper's low-speed pressure holding on the plant alone: blocked cylinder at 5 MPa, the
//! shaft turned at the speed that replaces leakage, piston ripple on; prints the pressure
//! pulsation with and without the absorber for a few precharges. (The closed loop with the
//! firmware's controller is `eha demo`.) Also the workload profiled with callgrind.

use plant_model::{Drive, Effect, InitialConditions, Inputs, Plant, Rig};

fn main() {
    let p_hold = 5e6;
    println!("precharge   absorber   mean p_A    pulsation p-p   shaft speed");
    for (precharge, absorber) in [
        (3e6, false),
        (2e6, true),
        (4e6, true),
        (5e6, true),
        (13e6, true),
    ] {
        let mut rig = Rig::nominal();
        rig.cylinder.blocked = true;
        rig.absorber.enabled = absorber;
        rig.absorber.precharge_pa = precharge;
        Effect::parse("piston_ripple")
            .expect("catalogue name")
            .apply(&mut rig);
        // Leakage at the holding pressure (eq. 9 and the cylinder's C_ic), replaced by the pump.
        let leak =
            1e-13 * (p_hold - rig.fill.pressure_pa) * 2.0 + 1e-13 * (p_hold - rig.fill.pressure_pa);
        let omega = leak / rig.pump.displacement_m3_per_rad();
        let mut plant =
            Plant::new(&rig, &InitialConditions::holding(&rig, p_hold), 1).expect("valid rig");
        let inputs = Inputs {
            drive: Drive::ShaftSpeed { omega_rad_s: omega },
            piston: None,
            external_force_n: 0.0,
            external_torque_nm: 0.0,
        };
        plant.advance(1.0, &inputs);
        let (mut lo, mut hi, mut sum, n) = (f64::MAX, f64::MIN, 0.0, 20_000);
        for _ in 0..n {
            plant.advance(50e-6, &inputs);
            let p = plant.observe().p_a_pa;
            lo = lo.min(p);
            hi = hi.max(p);
            sum += p;
        }
        println!(
            "{:>6.1} MPa   {:>8}   {:>7.4} MPa   {:>9.1} Pa    {:>5.1} rpm",
            precharge / 1e6,
            if absorber { "fitted" } else { "none" },
            sum / n as f64 / 1e6,
            hi - lo,
            omega * 60.0 / (2.0 * std::f64::consts::PI)
        );
    }
}
