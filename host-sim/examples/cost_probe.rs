//! Prints, for one log, a candidate's identification cost over a sweep of one search
//! coordinate (the first, or the K-th with `--coord K`; a phase coordinate of a ripple is
//! swept over a revolution), the others as given, else at their start, with each signal's
//! squared error: a tool to see whether a replay can tell an effect at all and where its
//! minimum lies
//! (`cargo run --release -p host-sim --example cost_probe -- LOG.csv EFFECT[/PREDICTOR][@N] [--coord K] [--values A,B,…] [U1 …]`).

use host_sim::diagnose::analysis::{predictors, scored_rows, segments};
use host_sim::diagnose::candidates::{candidates, grid_is_phase, Structure, RIPPLE_PISTONS};
use host_sim::diagnose::fit::Target;
use host_sim::diagnose::predict::predict;
use plant_model::Rig;
use std::path::PathBuf;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().expect("usage: cost_probe LOG.csv EFFECT [U…]"));
    let name = args.next().expect("an effect name");
    // EFFECT or EFFECT/PREDICTOR (e.g. extra_leakage/PressureLoop) when several replays fit
    // it, then @N for a structure (pistons, cogging order) when several are tried.
    let (name, structure) = match name.split_once('@') {
        Some((n, k)) => (
            n.to_string(),
            Some(k.parse::<u32>().expect("@N: a whole number")),
        ),
        None => (name, None),
    };
    let (effect, predictor) = match name.split_once('/') {
        Some((e, p)) => (e.to_string(), Some(p.to_string())),
        None => (name.clone(), None),
    };
    let mut rest: Vec<String> = args.collect();
    let coord = match rest.first().map(String::as_str) {
        Some("--coord") => {
            let k = rest.get(1).and_then(|k| k.parse().ok()).expect("--coord K");
            rest.drain(..2);
            k
        }
        _ => 0,
    };
    // --values A,B,… sweeps those values instead of the default ones.
    let values: Option<Vec<f64>> = match rest.first().map(String::as_str) {
        Some("--values") => {
            let v = rest
                .get(1)
                .expect("--values A,B,…")
                .split(',')
                .map(|a| a.parse().expect("a number"))
                .collect();
            rest.drain(..2);
            Some(v)
        }
        _ => None,
    };
    let given: Vec<f64> = rest.iter().map(|a| a.parse().expect("a number")).collect();
    let log = host_sim::bench_log::read(&path).expect("a valid bench log");
    let rig = Rig::nominal();
    let cands = candidates(
        &rig,
        &predictors(&log),
        log.theta_m_rad.is_some(),
        &[rig.motor.cogging_fundamental_order()],
        &RIPPLE_PISTONS,
    );
    let c = cands
        .iter()
        .find(|c| {
            c.name == effect
                && predictor
                    .as_ref()
                    .is_none_or(|p| format!("{:?}", c.predictor) == *p)
                && structure.is_none_or(|k| match c.structure {
                    Structure::Pistons(n) | Structure::Order(n) => n == k,
                    Structure::None => false,
                })
        })
        .expect("a candidate of that name");
    let (split, from) = segments(&log);
    let (from, rows) = scored_rows(&log, c.predictor, split, from);
    let base = predict(&log, &rig, c.predictor, rows, 0.0).expect("replay");
    let target = Target::new(&log, &rig, rows, from, &base);
    println!("baseline sse {:?}", target.baseline_sse);
    let mut u = c.start.clone();
    for (k, v) in given.iter().enumerate().take(u.len()) {
        u[k] = *v;
    }
    let sweep: Vec<f64> = if let Some(v) = values {
        v
    } else if coord == 1 && grid_is_phase(c) {
        (0..12)
            .map(|k| -std::f64::consts::PI + k as f64 * std::f64::consts::PI / 6.0)
            .collect()
    } else {
        vec![-3.0, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 3.0]
    };
    for g in sweep {
        u[coord] = g;
        let r = c.rig_at(&u, &rig);
        let p = predict(&log, &r, c.predictor, rows, c.phase_a_offset_a(&u)).expect("replay");
        println!(
            "u{coord} {g:+.2} {:?} cost {:.4} sse {:?}",
            c.parameters(&u, &rig),
            target.cost(c, &u),
            target.sse(&p)
        );
    }
}
