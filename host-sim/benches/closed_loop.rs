//! Real-time factor of the full closed loop at the nominal rig with the paper's low-speed
//! effects on (cogging, flux harmonics, piston ripple): the firmware's control core at
//! 20 kHz against the plant, in the low-speed pressure-holding scenario. One iteration is
//! 0.1 s of simulated time (2000 PWM periods); the real-time factor is 0.1 s / the time
//! per iteration.
//!
//! Beside it, the loop's parts alone over the same 0.1 s, replayed from a recording of
//! the loop itself, so that their sum bounds what any plant model can reach: the
//! controller's ISR on the recorded measurements (its step costs the same whatever the
//! plant), the plant's periods on the recorded duties with and without its sensors' reading
//! at each ADC trigger, and the bench log's text of the 200 rows `eha simulate` writes for
//! it (2 kHz, 14 columns). With a plant that cost nothing the controller and the log would
//! still take their share: 0.1 s over their sum is the ceiling of the real-time factor.

use closed_loop::{by_name, controller_config, ClosedLoop};
use criterion::{criterion_group, criterion_main, Criterion};
use firmware::Measurements;
use host_sim::bench_log;
use host_sim::run::{run, RunOptions, LOG_RATE_HZ};
use plant_model::effects::paper_low_speed_effects;
use plant_model::{Inputs, Integrator, Rig};
use std::hint::black_box;

/// PWM periods in 0.1 s at 20 kHz.
const PERIODS: usize = 2000;

/// The nominal rig with the paper's low-speed effects on: the plant the loop runs.
fn plant_rig() -> Rig {
    let mut plant = Rig::nominal();
    for e in paper_low_speed_effects() {
        e.apply(&mut plant);
    }
    plant
}

/// The settled loop of the pressure hold with the paper's low-speed effects.
fn settled() -> ClosedLoop {
    let scenario = by_name("pressure-hold").expect("scenario");
    let config = controller_config(&Rig::nominal());
    let mut cl = ClosedLoop::new(&plant_rig(), &config, scenario, 1).expect("valid rig");
    // Settle into the holding state first.
    cl.run(0.5, 1000, |_| {});
    cl
}

fn bench(c: &mut Criterion) {
    let mut cl = settled();
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

fn parts(c: &mut Criterion) {
    // One recording of 0.1 s of the loop: what the controller was given and what it set.
    let mut cl = settled();
    let controller = cl.controller_mut().clone();
    let plant = cl.plant().clone();
    let mut measured: Vec<Measurements> = Vec::with_capacity(PERIODS);
    let mut duties: Vec<([f64; 3], bool)> = Vec::with_capacity(PERIODS);
    for _ in 0..PERIODS {
        let s = cl.step_with(|m| {
            measured.push(m);
            m
        });
        let (d, on) = (s.outputs.duties, s.outputs.pwm_enabled);
        duties.push(([d[0] as f64, d[1] as f64, d[2] as f64], on));
    }
    let opt = RunOptions {
        duration_s: 0.1,
        log_rate_hz: LOG_RATE_HZ,
        seed: 1,
        progress: false,
        metadata: Vec::new(),
        compensation: None,
        integrator: Integrator::default(),
    };
    let scenario = by_name("pressure-hold").expect("scenario");
    let log = run(&plant_rig(), &Rig::nominal(), scenario, &opt)
        .expect("run")
        .log;
    let period = cl.period_s();

    let mut group = c.benchmark_group("closed_loop_parts");
    group.sample_size(20);
    group.bench_function("controller_0.1s", |b| {
        b.iter(|| {
            let mut k = controller.clone();
            for m in &measured {
                black_box(k.on_current_sample(m));
            }
        })
    });
    group.bench_function("plant_and_sensors_0.1s", |b| {
        b.iter(|| {
            let mut p = plant.clone();
            for (d, on) in &duties {
                black_box(p.sample());
                p.advance(period, &Inputs::duties(*d, *on));
            }
        })
    });
    group.bench_function("plant_0.1s", |b| {
        b.iter(|| {
            let mut p = plant.clone();
            for (d, on) in &duties {
                p.advance(period, &Inputs::duties(*d, *on));
            }
            black_box(p.time_s())
        })
    });
    group.bench_function("bench_log_text_0.1s", |b| {
        b.iter(|| black_box(bench_log::to_bytes(&log).expect("log")))
    });
    group.finish();
}

criterion_group!(benches, bench, parts);
criterion_main!(benches);
