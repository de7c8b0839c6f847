//! Real-time factor of the full closed loop at the nominal rig with the paper's low-speed
//! effects on (cogging, flux harmonics, piston ripple): the firmware's control core at
//! 20 kHz against the plant, in the low-speed pressure-holding scenario. One iteration is
//! 0.1 s of simulated time (2000 PWM periods); the real-time factor is 0.1 s / the time
//! per iteration.

use closed_loop::{by_name, controller_config, ClosedLoop};
use criterion::{criterion_group, criterion_main, Criterion};
use plant_model::effects::paper_low_speed_effects;
use plant_model::Rig;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let controller = Rig::nominal();
    let mut plant = controller.clone();
    for e in paper_low_speed_effects() {
        e.apply(&mut plant);
    }
    let scenario = by_name("pressure-hold").expect("scenario");
    let config = controller_config(&controller);
    let mut cl = ClosedLoop::new(&plant, &config, scenario, 1).expect("valid rig");
    // Settle into the holding state first.
    cl.run(0.5, 1000, |_| {});
    let mut group = c.benchmark_group("closed_loop");
    group.sample_size(20);
    group.bench_function("pressure_hold_0.1s_sim", |b| {
        b.iter(|| {
            let t_end = cl.time_s() + 0.1;
            cl.run(t_end, 2000, |s| {
                black_box(s);
            });
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
