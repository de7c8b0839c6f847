//! The closed-loop fault campaign ([`tests::campaign`]): faults of the power stage, the
//! supply, the encoder, the pressure transducer, the current sensors, the hydraulics, the
//! CAN bus and the application's timing, injected at random instants of random scenarios
//! into the firmware's control core running against the plant model. Every injection must
//! be detected in time where the drive can see it, and keep the safety invariants
//! everywhere (see [`tests::campaign::run`]).
//!
//! CI runs a fast subset; the full campaign of the record (docs/fault-campaign.md) is
//!
//! ```text
//! cargo test -p tests --release --test fault_campaign -- --ignored --nocapture
//! ```
//!
//! or, with its seed and size as arguments, the `fault_campaign` example.

use rayon::prelude::*;
use tests::campaign::{describe, plan, run_base, table, Class, Outcome, Plan};

/// The record's campaign: seed, cases per class, bases per scenario (1036 injections).
const FULL: (u64, usize, usize) = (18, 37, 12);

fn run(p: &Plan) -> Vec<Outcome> {
    let mut out: Vec<Outcome> = (0..p.bases.len())
        .into_par_iter()
        .flat_map_iter(|b| {
            let mut v = Vec::new();
            run_base(p, b, None, |o| v.push(o));
            v
        })
        .collect();
    out.sort_by_key(|o| o.index);
    out
}

fn check(seed: u64, outcomes: &[Outcome]) {
    println!("{}", table(seed, outcomes));
    for c in Class::ALL {
        assert!(
            outcomes.iter().any(|o| o.class == c),
            "no injection of {}",
            c.name()
        );
    }
    let failed: Vec<String> = outcomes
        .iter()
        .filter(|o| !o.passed())
        .map(describe)
        .collect();
    assert!(
        failed.is_empty(),
        "{} of {} injections failed:\n{}",
        failed.len(),
        outcomes.len(),
        failed.join("\n")
    );
}

#[test]
fn fast_subset_detects_in_time_and_keeps_the_invariants() {
    // Five of every class on two bases of every scenario.
    let seed = 7;
    let p = plan(seed, 5, 2);
    let outcomes = run(&p);
    assert_eq!(outcomes.len(), 5 * Class::ALL.len());
    check(seed, &outcomes);
}

#[test]
fn a_case_runs_the_same_alone_as_in_its_campaign() {
    let p = plan(7, 3, 1);
    let all = run(&p);
    let k = all.len() / 2;
    let mut alone = None;
    run_base(&p, p.cases[k].base, Some(k), |o| alone = Some(o));
    let alone = alone.expect("the case ran");
    assert_eq!(describe(&alone), describe(&all[k]));
}

#[test]
#[ignore = "the full campaign: cargo test -p tests --release --test fault_campaign -- --ignored --nocapture"]
fn full_campaign() {
    let (seed, per_class, bases) = FULL;
    check(seed, &run(&plan(seed, per_class, bases)));
}
