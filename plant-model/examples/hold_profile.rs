//! Runs the plant alone in the low-speed holding state for 2 s of simulated time (for
//! profiling the plant step with callgrind or perf).
use plant_model::{Effect, InitialConditions, Inputs, Plant, Rig};
fn main() {
    let mut rig = Rig::nominal();
    rig.cylinder.blocked = true;
    for e in [
        "cogging_torque",
        "flux_harmonics",
        "piston_ripple",
        "dead_time",
        "shaft_friction",
    ] {
        Effect::parse(e).expect("catalogue name").apply(&mut rig);
    }
    let init = InitialConditions {
        omega_rad_s: 6.0,
        ..InitialConditions::holding(&rig, 5e6)
    };
    let mut plant = Plant::new(&rig, &init, 1).expect("valid rig");
    let mut acc = 0u64;
    for k in 0..40_000u32 {
        let a = k as f64 * 1e-3;
        let d = [
            0.5 + 0.01 * a.sin(),
            0.5 + 0.01 * (a - 2.1).sin(),
            0.5 + 0.01 * (a + 2.1).sin(),
        ];
        plant.advance(50e-6, &Inputs::duties(d, true));
        acc += plant.sample().adc_pressure as u64;
    }
    println!("{acc} {}", plant.observe().p_a_pa);
}
