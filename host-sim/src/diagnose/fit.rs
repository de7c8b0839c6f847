//! Fitting a candidate's parameters on the identification segment: a coarse grid over its
//! leading coordinate (the responses of pressure and friction to their parameters are far
//! from linear, and phases wrap), then the Nelder–Mead simplex of the `argmin` crate from the
//! best grid point.
//!
//! The cost is the candidate's replay error on its own signals over the identification
//! rows: each signal's squared error over the nominal model's, their geometric mean over
//! the signals: 1 is "explains nothing", 0 "explains everything".

use super::candidates::{grid_is_phase, tolerance_dims, Candidate};
use super::predict::{predict, Predicted};
use crate::bench_log::BenchLog;
use argmin::core::{CostFunction, Error, Executor, State};
use argmin::solver::neldermead::NelderMead;
use plant_model::Rig;

/// Simplex iterations per candidate: enough to settle two coordinates to a few percent
/// from a grid point (each iteration costs one or two replays).
pub const SIMPLEX_ITERATIONS: u64 = 18;

/// A candidate's fit.
#[derive(Clone, Debug, PartialEq)]
pub struct CandidateFit {
    /// The candidate.
    pub candidate: Candidate,
    /// Best search point.
    pub u: Vec<f64>,
    /// Normalised cost at `u` (1: no better than the nominal model). [1]
    pub cost: f64,
    /// Replays spent.
    pub evaluations: usize,
}

/// What a candidate's cost is measured against.
pub struct Target<'a> {
    /// The log.
    pub log: &'a BenchLog,
    /// The nominal rig.
    pub rig: &'a Rig,
    /// Identification rows (from the start).
    pub rows: usize,
    /// First row scored (the replays' start-up rows are skipped).
    pub from: usize,
    /// Each scored signal's noise variance over the scored rows (see [`noise_variance`]),
    /// measured once: it is a property of the log, not of the candidate. [unit²]
    noise: Vec<(&'static str, f64)>,
    /// The nominal model's squared error per signal over the scored rows, in units of the
    /// signal's noise variance.
    pub baseline_sse: Vec<(&'static str, f64)>,
}

/// A signal's white-noise variance estimated from its sample-to-sample differences,
/// mean((y_k − y_{k−1})²)/2: exact for white noise on a signal that changes little between
/// samples, and a floor for filtered ones. [unit²]
pub fn noise_variance(y: &[f64]) -> f64 {
    let n = y.len();
    if n < 2 {
        return 1.0;
    }
    let v = y.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / (2.0 * (n - 1) as f64);
    v.max(f64::MIN_POSITIVE)
}

impl<'a> Target<'a> {
    /// The target of rows `from..rows` of `log`, against the nominal model's prediction
    /// `baseline` of the signals a predictor scores (the log's signals it lacks are left
    /// out).
    pub fn new(
        log: &'a BenchLog,
        rig: &'a Rig,
        rows: usize,
        from: usize,
        baseline: &Predicted,
    ) -> Target<'a> {
        let rows = rows.min(log.len());
        let noise = baseline
            .iter()
            .filter_map(|(name, _)| {
                let y = log.column(crate::bench_log::Signal::from_name(name)?)?;
                Some((*name, noise_variance(&y[from.min(rows)..rows])))
            })
            .collect();
        let mut target = Target {
            log,
            rig,
            rows,
            from,
            noise,
            baseline_sse: Vec::new(),
        };
        target.baseline_sse = target.sse(baseline);
        target
    }

    /// Sum of squared errors per signal of `predicted` over the scored rows, in units of
    /// the signal's noise variance there. [1]
    pub fn sse(&self, predicted: &Predicted) -> Vec<(&'static str, f64)> {
        predicted
            .iter()
            .filter_map(|(name, y_hat)| {
                let noise = self.noise.iter().find(|(s, _)| s == name)?.1;
                let y = self
                    .log
                    .column(crate::bench_log::Signal::from_name(name)?)?;
                let end = self.rows.min(y_hat.len()).min(y.len());
                let e: f64 = (self.from..end).map(|k| (y[k] - y_hat[k]).powi(2)).sum();
                Some((*name, if e.is_finite() { e / noise } else { f64::MAX }))
            })
            .collect()
    }

    /// Normalised cost of `c` at `u`.
    pub fn cost(&self, c: &Candidate, u: &[f64]) -> f64 {
        if !c.is_plausible(u, self.rig) {
            return f64::MAX;
        }
        let rig = c.rig_at(u, self.rig);
        let Ok(p) = predict(
            self.log,
            &rig,
            c.predictor,
            self.rows,
            c.phase_a_offset_a(u),
        ) else {
            return f64::MAX;
        };
        // Each signal's squared error relative to the nominal model's, combined as a
        // geometric mean: the likelihood of white residuals whose variance per signal is
        // unknown (maximised over it, it is Π sse_s^(−N/2)). A fixed noise variance per
        // signal would not do: the speed the motor replay predicts carries, besides the
        // log's own noise, the current sensor's noise integrated through the shaft, so its
        // floor is far above the log's sample-to-sample noise and it would drown the
        // current's evidence.
        let mut log_ratio = 0.0;
        let mut signals = 0usize;
        for (name, e) in self.sse(&p) {
            if let Some((_, b)) = self.baseline_sse.iter().find(|(s, _)| *s == name) {
                if *b > 0.0 {
                    if !e.is_finite() || e >= f64::MAX {
                        return f64::MAX;
                    }
                    log_ratio += (e.max(f64::MIN_POSITIVE) / b).ln();
                    signals += 1;
                }
            }
        }
        if signals == 0 {
            return f64::MAX;
        }
        (log_ratio / signals as f64).exp()
    }
}

struct Problem<'a, 'b> {
    target: &'a Target<'b>,
    candidate: &'a Candidate,
    evaluations: &'a std::cell::Cell<usize>,
}

impl CostFunction for Problem<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, u: &Self::Param) -> Result<f64, Error> {
        self.evaluations.set(self.evaluations.get() + 1);
        Ok(self.target.cost(self.candidate, u))
    }
}

/// Fits `c` on `target`: grid, then simplex.
pub fn fit(target: &Target<'_>, c: &Candidate) -> CandidateFit {
    let evaluations = std::cell::Cell::new(0);
    let problem = Problem {
        target,
        candidate: c,
        evaluations: &evaluations,
    };
    let mut best = (c.start.clone(), f64::MAX);
    // The grid runs over the phase of a ripple, else over the first coordinate.
    let axis = usize::from(grid_is_phase(c));
    let dims = c.start.len();
    let tolerance_at = dims.saturating_sub(tolerance_dims(c.predictor));
    let tolerance_starts: Vec<Vec<f64>> = c
        .tolerance_grid
        .iter()
        .filter(|_| tolerance_at < dims)
        .map(|v| {
            let mut u = c.start.clone();
            u[tolerance_at] = *v;
            u
        })
        .collect();
    let starts = std::iter::once(&c.start)
        .chain(Some(&c.alternative_start).filter(|s| s.len() == dims))
        .chain(&tolerance_starts);
    for start in starts {
        for g in &c.grid {
            let mut u = start.clone();
            u[axis] = *g;
            let cost = problem.cost(&u).unwrap_or(f64::MAX);
            if cost < best.1 {
                best = (u, cost);
            }
        }
    }
    let simplex: Vec<Vec<f64>> = std::iter::once(best.0.clone())
        .chain((0..best.0.len()).map(|k| {
            let mut v = best.0.clone();
            v[k] += c.step[k];
            v
        }))
        .collect();
    let solved = NelderMead::new(simplex)
        .with_sd_tolerance(1e-4)
        .ok()
        .and_then(|solver| {
            Executor::new(problem, solver)
                .configure(|state| state.max_iters(SIMPLEX_ITERATIONS))
                .run()
                .ok()
        });
    if let Some(result) = solved {
        let state = result.state();
        if let Some(u) = state.get_best_param() {
            if state.get_best_cost() < best.1 {
                best = (u.clone(), state.get_best_cost());
            }
        }
    }
    CandidateFit {
        candidate: c.clone(),
        u: best.0,
        cost: best.1,
        evaluations: evaluations.get(),
    }
}
