//! Prints, for one log, a candidate's identification cost over a sweep of its first search
//! coordinate (the others at their start), per signal: a tool to see whether a replay can
//! tell an effect at all (`cargo run --release -p host-sim --example cost_probe -- LOG.csv
//! EFFECT [U1 …]`).

use host_sim::diagnose::candidates::candidates;
use host_sim::diagnose::fit::Target;
use host_sim::diagnose::predict::{piston_moves, predict};
use plant_model::Rig;
use std::path::PathBuf;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().expect("usage: cost_probe LOG.csv EFFECT [U…]"));
    let name = args.next().expect("an effect name");
    let rest: Vec<f64> = args.map(|a| a.parse().expect("a number")).collect();
    let log = host_sim::bench_log::read(&path).expect("a valid bench log");
    let rig = Rig::nominal();
    let cands = candidates(&rig, true, piston_moves(&log), true, &[72]);
    let c = cands
        .iter()
        .find(|c| c.name == name)
        .expect("a candidate of that name");
    let n = log.len();
    let split = (n / 2).min(2500);
    let base = predict(&log, &rig, c.predictor, usize::MAX, 0.0).expect("replay");
    let from: usize = std::env::var("FROM")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100);
    let target = Target::new(&log, &rig, split, from, &base);
    println!("baseline sse {:?}", target.baseline_sse);
    let mut u = c.start.clone();
    for (k, v) in rest.iter().enumerate() {
        if k < u.len() {
            u[k] = *v;
        }
    }
    if std::env::var("WINDOWS").is_ok() {
        windows(&log, &base);
        let p = predict(
            &log,
            &c.rig_at(&u, &rig),
            c.predictor,
            usize::MAX,
            c.phase_a_offset_a(&u),
        )
        .expect("replay");
        windows(&log, &p);
        return;
    }
    for g in [-3.0, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 3.0] {
        let mut v = u.clone();
        v[0] = g;
        let r = c.rig_at(&v, &rig);
        let p = predict(&log, &r, c.predictor, split, c.phase_a_offset_a(&v)).expect("replay");
        println!(
            "u0 {g:+.1} {:?} cost {:.4} sse {:?}",
            c.parameters(&v, &rig),
            target.cost(c, &v),
            target.sse(&p)
        );
    }
}

/// Windowed RMS residuals of `predicted` against the log (`WINDOWS=1`).
#[allow(dead_code)]
pub fn windows(log: &host_sim::bench_log::BenchLog, p: &[(&'static str, Vec<f64>)]) {
    for (name, y_hat) in p {
        let y = log
            .column(host_sim::bench_log::Signal::from_name(name).unwrap())
            .unwrap();
        let w = 200;
        let mut line = format!("{name:>12}");
        for k in (0..y_hat.len().min(y.len())).step_by(w) {
            let e = (k..(k + w).min(y_hat.len()))
                .map(|i| (y[i] - y_hat[i]).powi(2))
                .sum::<f64>()
                / w as f64;
            line.push_str(&format!(" {:.3}", e.sqrt()));
        }
        println!("{line}");
    }
}
