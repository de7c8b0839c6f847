//! The gain proposal's search: candidate designs, each a point of a loop's design space
//! (speed: natural frequency and damping; pressure: crossover and integral corner), are
//! replayed in closed loop on the identified plant in parallel, and the one meeting the
//! target nearest to the firmware's documented design is kept — the design is changed no
//! more than the plant requires.

use super::gains::Gains;
use super::predict::{self, StepSpec};
use super::step::{StepMetrics, Target};
use firmware::config::Config;
use plant_model::Rig;
use rayon::prelude::*;

/// A design to try.
#[derive(Clone, Copy, Debug)]
pub struct Design {
    /// Its point in the loop's two-parameter design space (both positive).
    pub point: (f64, f64),
    /// The controller configuration applying it.
    pub config: Config,
    /// The equivalent PI gains at the step's operating point.
    pub gains: Gains,
}

/// A design and its replay.
#[derive(Clone, Copy, Debug)]
pub struct Candidate {
    /// The design.
    pub design: Design,
    /// Overshoot and settling of its replay.
    pub metrics: StepMetrics,
}

/// Replays `spec` with every design on `plant` (seed 1; designs whose configuration is
/// refused or whose replay fails are dropped).
pub fn replay(plant: &Rig, spec: &StepSpec, designs: Vec<Design>) -> Vec<Candidate> {
    designs
        .into_par_iter()
        .filter_map(|design| {
            let r = predict::simulate(plant, &design.config, spec, 1).ok()?;
            Some(Candidate {
                design,
                metrics: r.metrics,
            })
        })
        .collect()
}

/// The candidate meeting `target` nearest (in log-distance, summed over both coordinates)
/// to `nominal`; when none does, the one violating the target least, or the nominal design
/// if it violates it at most 10 % more.
pub fn choose(tried: Vec<Candidate>, nominal: (f64, f64), target: &Target) -> Option<Candidate> {
    let distance = |c: &Candidate| {
        let (a, b) = c.design.point;
        (a / nominal.0).ln().abs() + (b / nominal.1).ln().abs()
    };
    let meeting = tried
        .iter()
        .filter(|c| c.metrics.meets(target))
        .min_by(|a, b| distance(a).total_cmp(&distance(b)));
    if let Some(c) = meeting {
        return Some(*c);
    }
    // None meets it (a flow- or current-limited step): change the design only where that
    // buys more than a tenth of the violation.
    let least = tried.iter().min_by(|a, b| {
        a.metrics
            .violation(target)
            .total_cmp(&b.metrics.violation(target))
    })?;
    let at_nominal = tried.iter().find(|c| distance(c) == 0.0);
    match at_nominal {
        Some(n) if n.metrics.violation(target) <= 1.1 * least.metrics.violation(target) => Some(*n),
        _ => Some(*least),
    }
}
