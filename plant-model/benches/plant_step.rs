//! One plant step (one 50 µs PWM period: one step at the default h_max) at the nominal rig in
//! the paper's low-speed pressure-holding state (blocked cylinder, 5 MPa, shaft at ≈ 60 rpm),
//! with the catalogue's effects off and with every low-speed effect on, by the exponential
//! integrator (the default) and by RK4 (the scheme before it).

use criterion::{criterion_group, criterion_main, Criterion};
use plant_model::{Effect, InitialConditions, Inputs, Integrator, Plant, Rig};
use std::hint::black_box;

fn holding_plant(effects: &[&str], integrator: Integrator) -> Plant {
    let mut rig = Rig::nominal();
    rig.cylinder.blocked = true;
    for e in effects {
        Effect::parse(e).expect("catalogue name").apply(&mut rig);
    }
    let init = InitialConditions {
        omega_rad_s: 6.0,
        ..InitialConditions::holding(&rig, 5e6)
    };
    let mut plant = Plant::new(&rig, &init, 1).expect("valid rig");
    plant.set_integrator(integrator);
    plant
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("plant_step_50us");
    for (label, effects) in [
        ("effects_off", &[][..]),
        (
            "all_low_speed_effects",
            &[
                "cogging_torque",
                "flux_harmonics",
                "piston_ripple",
                "dead_time",
                "shaft_friction",
            ][..],
        ),
    ] {
        for integrator in [Integrator::Exponential, Integrator::Rk4 { substeps: 1 }] {
            let mut plant = holding_plant(effects, integrator);
            // A slowly rotating voltage vector keeps every term of the step busy.
            let mut k = 0u32;
            group.bench_function(format!("{label}/{}", integrator.name()), |b| {
                b.iter(|| {
                    k = k.wrapping_add(1);
                    let a = (k as f64) * 1e-3;
                    let d = [
                        0.5 + 0.01 * a.sin(),
                        0.5 + 0.01 * (a - 2.1).sin(),
                        0.5 + 0.01 * (a + 2.1).sin(),
                    ];
                    plant.advance(50e-6, &Inputs::duties(d, true));
                    black_box(plant.sample())
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
