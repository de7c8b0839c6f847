//! The closed-loop fault campaign: randomized, seeded, repeatable injections of the faults
//! the plant, its sensors, the CAN bus and the application can produce, at random instants
//! of random scenarios, into the firmware's control core running against the plant model
//! ([`bench`]), each judged against the campaign's rules and the safety invariants
//! ([`spec`], [`run`]).
//!
//! A plan ([`plan`]) draws, from one seed, the bases (a scenario and its sensor-noise
//! seed) and the cases (a fault class, a base, an instant, the fault's own seed). A base is
//! run once up to each of its cases' instants in turn and copied there, so the cases of a
//! base share its history; each case draws its fault from its own stream, so it runs the
//! same alone ([`run_base`] with a plan of one) or in the whole campaign. The table
//! ([`table`]) counts outcomes per class.

pub mod bench;
pub mod bus;
pub mod catalogue;
pub mod rng;
pub mod run;
pub mod spec;
mod table;

pub use bench::{Bench, ScenarioId};
pub use catalogue::{Class, Fault};
pub use run::{Outcome, Verdict};
pub use table::{describe, table};

use rng::Rng;

/// One injection of the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case {
    /// Its index in the plan.
    pub index: usize,
    /// The fault class.
    pub class: Class,
    /// The base it runs on.
    pub base: usize,
    /// The injection instant. [s]
    pub t_inject_s: f64,
    /// The seed of its own draws.
    pub seed: u64,
}

/// A base run: a scenario with its sensor-noise seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Base {
    /// The scenario.
    pub scenario: ScenarioId,
    /// The plant's noise seed.
    pub noise_seed: u64,
}

/// The campaign's plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The seed everything was drawn from.
    pub seed: u64,
    /// The bases.
    pub bases: Vec<Base>,
    /// The cases, in index order.
    pub cases: Vec<Case>,
}

/// Draws a plan from `seed`: `per_class` cases of every class, on `bases_per_scenario`
/// bases of every scenario, each at an instant uniform in its scenario's window.
pub fn plan(seed: u64, per_class: usize, bases_per_scenario: usize) -> Plan {
    let mut rng = Rng::new(seed);
    let bases: Vec<Base> = ScenarioId::ALL
        .iter()
        .flat_map(|s| (0..bases_per_scenario.max(1)).map(move |_| *s))
        .map(|scenario| Base {
            scenario,
            noise_seed: rng.draw(),
        })
        .collect();
    let mut cases = Vec::new();
    for class in Class::ALL {
        for _ in 0..per_class {
            let base = rng.below(bases.len());
            let (a, b) = bases[base].scenario.window_s();
            cases.push(Case {
                index: cases.len(),
                class,
                base,
                t_inject_s: rng.uniform(a, b),
                seed: rng.draw(),
            });
        }
    }
    Plan { seed, bases, cases }
}

/// Runs the cases of base `base` of `plan` (in the order of their instants; `only` the
/// one of that index, if given), calling `done` with each outcome.
pub fn run_base(plan: &Plan, base: usize, only: Option<usize>, mut done: impl FnMut(Outcome)) {
    let Some(b) = plan.bases.get(base) else {
        return;
    };
    let mut cases: Vec<&Case> = plan.cases.iter().filter(|c| c.base == base).collect();
    cases.sort_by(|x, y| x.t_inject_s.total_cmp(&y.t_inject_s));
    let mut bench = Bench::new(b.scenario, b.noise_seed);
    for c in cases {
        if only.is_some_and(|k| k != c.index) {
            continue;
        }
        // Snap to the PWM grid; the base's own rules firing would be a broken scenario.
        let fired = bench.run_to(c.t_inject_s);
        assert!(
            fired.is_empty() && bench.cl.controller_mut().fault().is_none(),
            "base {base} ({}) faulted before any injection: {fired:?}",
            b.scenario.name()
        );
        let mut rng = Rng::new(c.seed);
        let fault = catalogue::draw(c.class, &mut rng);
        done(run::run_case(&bench, c.index, &fault, rng.draw()));
    }
}
