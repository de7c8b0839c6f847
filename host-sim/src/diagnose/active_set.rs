//! Hard bounds for the Levenberg–Marquardt iterations: the sine transform's unconstrained
//! search with an active set of parameters resting on their bounds.
//!
//! The `levenberg-marquardt` crate searches without bounds; each parameter's bounds are kept
//! by searching v with u = c + h·sin(v) ([`ParamSpec`]). Where the data press a parameter
//! against a bound the transform's slope du/dv vanishes, and the Gauss–Newton step, which
//! knows nothing of the transform's curvature, overshoots the crest and is cut back, again
//! and again: the optimiser creeps towards the bound by ever smaller steps, gaining
//! hundredths of a noise unit an iteration, until its budget ends. A tolerance band pressed
//! by a model error does that in most fits of a foreign log.
//!
//! So a parameter that comes within [`AT_BOUND`] of its range's end is put on the bound
//! and held there (the active set), and the search goes on over the others, restarted. When
//! the search ends with nothing new on a bound, each held parameter is tried a step
//! inside: where the objective falls there, the data pull it off its bound (the
//! Karush–Kuhn–Tucker condition fails) and it is searched again, free of the bound from
//! then on, so the set cannot cycle.
//!
//! The Jacobian is taken by forward differences in v, its columns in parallel.

use crate::diagnose::effort::Effort;
use crate::diagnose::param_spec::ParamSpec;
use crate::diagnose::secant::Secant;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Residuals of a model at parameter values: data rows already divided by their noise
/// scale, so each is about unit variance for a right model.
pub trait Model: Sync {
    /// The residuals at `values` (one per parameter spec, in order).
    fn residuals(&self, values: &[f64]) -> Vec<f64>;
}

impl<F: Fn(&[f64]) -> Vec<f64> + Sync> Model for F {
    fn residuals(&self, values: &[f64]) -> Vec<f64> {
        self(values)
    }
}

/// Share of a parameter's range from either end within which it is taken to rest on that
/// end: a millionth, where the transform's slope is 0.2 % of its greatest and the
/// search left alone would still be creeping. Only the creep from there to the bound is
/// saved: holding a parameter earlier (a thousandth of the range) changes where fits in
/// the hydraulic relation's flat valleys stop, and with their end points the validation
/// segment's verdict on some logs (`docs/diagnosis.md`, Speed). [1]
pub const AT_BOUND: f64 = 1e-6;

/// Step inside its range, as a share of the range, at which a held parameter's
/// optimality is tried. [1]
const INSIDE_STEP: f64 = 1e-3;

/// The search over the free parameters, the held ones fixed at their bounds.
struct Problem<'a, M: Model> {
    model: &'a M,
    specs: &'a [ParamSpec],
    /// Every parameter's coordinate u; the free ones' are read from `v`.
    u: Vec<f64>,
    /// The free parameters' indices, in the order of `v`.
    free: Vec<usize>,
    /// Whether a free parameter is put on its bound when it comes within [`AT_BOUND`].
    may_hold: Vec<bool>,
    v: DVector<f64>,
    evaluations: AtomicUsize,
    /// The residuals last computed by `residuals` and the point they were computed at:
    /// the optimiser asks for the Jacobian at the point whose residuals it just had.
    last: Mutex<Option<(Vec<f64>, Vec<f64>)>>,
    /// Free parameters found within [`AT_BOUND`] of a bound at an accepted point.
    reached: Mutex<Vec<usize>>,
    /// Whether a differenced Jacobian is kept for its update at the next accepted point
    /// ([`Effort::secant`]).
    updates: bool,
    /// The last Jacobian kept for that.
    secant: Mutex<Option<Secant>>,
}

/// Where `u` lies in `spec`'s hard bounds, 0 at the lower and 1 at the upper. [1]
fn position(spec: &ParamSpec, u: f64) -> f64 {
    let (lo, hi) = spec.u_bounds;
    if hi > lo {
        (u - lo) / (hi - lo)
    } else {
        0.5
    }
}

/// The residuals of `model` at coordinates `u`, the priors' rows appended; a row that is
/// not finite counts as a large residual.
fn full_residuals<M: Model>(model: &M, specs: &[ParamSpec], u: &[f64]) -> Vec<f64> {
    let values: Vec<f64> = specs.iter().zip(u).map(|(s, u)| s.value(*u)).collect();
    let mut r = model.residuals(&values);
    for r in r.iter_mut() {
        if !r.is_finite() {
            *r = 1e6;
        }
    }
    for (s, u) in specs.iter().zip(u) {
        if let Some((m, sd)) = s.prior {
            r.push((u - m) / sd);
        }
    }
    r
}

/// The objective at coordinates `u`: the sum of squares of [`full_residuals`].
fn objective<M: Model>(model: &M, specs: &[ParamSpec], u: &[f64]) -> f64 {
    full_residuals(model, specs, u).iter().map(|r| r * r).sum()
}

impl<M: Model> Problem<'_, M> {
    fn u_at(&self, v: &[f64]) -> Vec<f64> {
        let mut u = self.u.clone();
        for (&k, v) in self.free.iter().zip(v) {
            u[k] = self.specs[k].u_of_v(*v);
        }
        u
    }

    fn residuals_at(&self, v: &[f64]) -> Vec<f64> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        full_residuals(self.model, self.specs, &self.u_at(v))
    }

    /// The free parameters within [`AT_BOUND`] of a bound at `v` (residuals `r`) that may
    /// be held there and fit at least as well on the bound as where they are.
    fn pressed(&self, v: &[f64], r: &[f64]) -> Vec<usize> {
        let here: f64 = r.iter().map(|r| r * r).sum();
        let u = self.u_at(v);
        self.free
            .iter()
            .filter(|&&k| {
                let (lo, hi) = self.specs[k].u_bounds;
                let p = position(&self.specs[k], u[k]);
                if !self.may_hold[k] || (AT_BOUND..=1.0 - AT_BOUND).contains(&p) {
                    return false;
                }
                let mut on = u.clone();
                on[k] = if p < 0.5 { lo } else { hi };
                self.evaluations.fetch_add(1, Ordering::Relaxed);
                objective(self.model, self.specs, &on) <= here
            })
            .copied()
            .collect()
    }
}

impl<M: Model> LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, M> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.v.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.v.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let v: Vec<f64> = self.v.iter().copied().collect();
        let r = self.residuals_at(&v);
        if let Ok(mut last) = self.last.lock() {
            *last = Some((v, r.clone()));
        }
        Some(DVector::from_vec(r))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let v0: Vec<f64> = self.v.iter().copied().collect();
        // The residuals just computed at this point, taken (not copied): the optimiser asks
        // one Jacobian a point.
        let cached = self
            .last
            .lock()
            .ok()
            .and_then(|mut l| l.take().filter(|(v, _)| *v == v0).map(|(_, r)| r));
        let r0 = cached.unwrap_or_else(|| self.residuals_at(&v0));
        // The optimiser asks for a Jacobian at each point it accepts: a parameter that has
        // come near its bound, and fits at least as well on it, ends this search there.
        let reached = self.pressed(&v0, &r0);
        if !reached.is_empty() {
            if let Ok(mut r) = self.reached.lock() {
                *r = reached;
            }
            return None;
        }
        let (m, n) = (r0.len(), v0.len());
        let mut secant = self.secant.lock().ok()?;
        if let Some(updated) = secant.as_mut().and_then(|s| s.updated(&v0, &r0)) {
            return Some(DMatrix::from_vec(m, n, updated));
        }
        // Each column's difference quotient written straight into the matrix's storage
        // (column-major), the columns in parallel: no second copy of the Jacobian. Rows a
        // shorter residual vector lacks stay zero.
        let mut storage = vec![0.0; m * n];
        storage
            .par_chunks_mut(m.max(1))
            .enumerate()
            .for_each(|(k, column)| {
                let h = 1e-4 * (1.0 + v0[k].abs());
                let mut v = v0.clone();
                v[k] += h;
                let r = self.residuals_at(&v);
                for (c, (a, b)) in column.iter_mut().zip(r.iter().zip(&r0)) {
                    *c = (a - b) / h;
                }
            });
        if self.updates {
            *secant = Some(Secant::differenced(v0, r0, storage.clone()));
        }
        Some(DMatrix::from_vec(m, n, storage))
    }
}

/// The end of a bounded search: the coordinates u and the model evaluations spent.
pub struct Minimum {
    /// Coordinates at the minimum.
    pub u: Vec<f64>,
    /// Model evaluations spent.
    pub evaluations: usize,
}

/// Minimises the sum of squares of `model`'s residuals (and the priors') over `specs`' u
/// within their hard bounds, from `u0` (inside the bounds), the optimiser allowed
/// `effort`'s iterations per free parameter in each search and stopped at its tolerance.
pub fn minimise<M: Model>(model: &M, specs: &[ParamSpec], u0: Vec<f64>, effort: Effort) -> Minimum {
    let n = specs.len();
    let mut u = u0;
    // A parameter pinned to one value (bounds that meet) is held from the start, and for
    // good: there is no inside to try it at.
    let pinned: Vec<bool> = specs.iter().map(|s| s.u_bounds.1 <= s.u_bounds.0).collect();
    let mut held = pinned.clone();
    let mut may_hold = vec![true; n];
    let mut evaluations = 0;
    // Each round either holds a parameter more or frees one for good: at most 2n + 1.
    for _ in 0..=2 * n {
        let free: Vec<usize> = (0..n).filter(|&k| !held[k]).collect();
        let reached = if free.is_empty() {
            Vec::new()
        } else {
            let (found, spent) = search(model, specs, &mut u, free, &may_hold, effort);
            evaluations += spent;
            found
        };
        if !reached.is_empty() {
            for k in reached {
                let (lo, hi) = specs[k].u_bounds;
                u[k] = if position(&specs[k], u[k]) < 0.5 {
                    lo
                } else {
                    hi
                };
                held[k] = true;
            }
            continue;
        }
        // Nothing new on a bound: is each held parameter's bound still where the
        // objective falls?
        let holding: Vec<usize> = (0..n).filter(|&k| held[k] && !pinned[k]).collect();
        if holding.is_empty() {
            break;
        }
        let here = objective(model, specs, &u);
        evaluations += 1;
        let mut freed = false;
        for k in holding {
            let (lo, hi) = specs[k].u_bounds;
            let step = INSIDE_STEP * (hi - lo);
            let mut inside = u.clone();
            inside[k] = if u[k] <= lo { lo + step } else { hi - step };
            evaluations += 1;
            if objective(model, specs, &inside) < here {
                u[k] = inside[k];
                held[k] = false;
                may_hold[k] = false;
                freed = true;
            }
        }
        if !freed {
            break;
        }
    }
    Minimum { u, evaluations }
}

/// One Levenberg–Marquardt search over the `free` parameters from `u`, left in `u`; returns
/// the free parameters that came onto a bound (the search ended there) and the
/// evaluations spent.
fn search<M: Model>(
    model: &M,
    specs: &[ParamSpec],
    u: &mut [f64],
    free: Vec<usize>,
    may_hold: &[bool],
    effort: Effort,
) -> (Vec<usize>, usize) {
    let v0 = DVector::from_iterator(free.len(), free.iter().map(|&k| specs[k].v_of_u(u[k])));
    let problem = Problem {
        model,
        specs,
        u: u.to_vec(),
        free,
        may_hold: may_hold.to_vec(),
        v: v0,
        evaluations: AtomicUsize::new(0),
        last: Mutex::new(None),
        reached: Mutex::new(Vec::new()),
        updates: effort.secant,
        secant: Mutex::new(None),
    };
    let (problem, _report) = LevenbergMarquardt::<f64>::new()
        .with_patience(effort.patience)
        .with_ftol(effort.tolerance)
        .with_xtol(effort.tolerance)
        .minimize(problem);
    let v: Vec<f64> = problem.v.iter().copied().collect();
    u.copy_from_slice(&problem.u_at(&v));
    let reached = problem.reached.into_inner().unwrap_or_default();
    (reached, problem.evaluations.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The screening fits' effort.
    const EFFORT: Effort = Effort::SCREENING;

    #[test]
    fn a_parameter_pressed_against_its_bound_rests_on_it_and_the_others_fit_given_it() {
        // y = 2x + 0.5 without noise; the slope may not exceed 1. With the slope on that
        // bound the intercept's least-squares value is mean(y − x) = 0.5 + mean(x).
        let x: Vec<f64> = (0..20).map(|k| k as f64 * 0.1).collect();
        let model = |v: &[f64]| -> Vec<f64> {
            x.iter()
                .map(|x| v[0] * x + v[1] - (2.0 * x + 0.5))
                .collect()
        };
        let specs = [
            ParamSpec::linear("slope", 0.5, 1.0, 0.0, 1.0),
            ParamSpec::linear("intercept", 0.0, 1.0, -5.0, 5.0),
        ];
        let m = minimise(&model, &specs, vec![0.0, 0.0], EFFORT);
        let mean_x = x.iter().sum::<f64>() / x.len() as f64;
        assert_eq!(m.u[0], specs[0].u_bounds.1, "the slope rests on its bound");
        assert!(
            (specs[1].value(m.u[1]) - (0.5 + mean_x)).abs() < 1e-6,
            "intercept {} against {}",
            specs[1].value(m.u[1]),
            0.5 + mean_x
        );
    }

    #[test]
    fn a_parameter_held_on_its_bound_is_set_free_where_the_optimum_lies_inside() {
        // r = (a + b − 1, b − 0.8): zero at a = 0.2, b = 0.8. Started a hair below a's
        // upper bound with b = 0 the bound fits at least as well as the start, so a is held
        // there; b then fits to 0.4, where a step inside lowers the objective: a is set
        // free and the search ends at the unconstrained optimum.
        let model = |v: &[f64]| vec![v[0] + v[1] - 1.0, v[1] - 0.8];
        let specs = [
            ParamSpec::linear("a", 0.5, 1.0, 0.0, 1.0),
            ParamSpec::linear("b", 0.0, 1.0, -5.0, 5.0),
        ];
        let start = specs[0].u_bounds.1 - 0.1 * AT_BOUND;
        let m = minimise(&model, &specs, vec![start, 0.0], EFFORT);
        let (a, b) = (specs[0].value(m.u[0]), specs[1].value(m.u[1]));
        assert!(
            (a - 0.2).abs() < 1e-6 && (b - 0.8).abs() < 1e-6,
            "a {a}, b {b}"
        );
    }

    #[test]
    fn jacobians_carried_by_broyden_updates_reach_the_same_optimum_for_fewer_evaluations() {
        // y = a·e^(−k·t) + c over 0–3 s without noise, a = 2, k = 1.5 s⁻¹, c = 0.3, started
        // at a = 1, k = 0.5, c = 0: the optimum is the generating values, found with every
        // Jacobian differenced and with updates between differencings; the updates save
        // the differences' evaluations.
        let t: Vec<f64> = (0..60).map(|k| k as f64 * 0.05).collect();
        let model = |v: &[f64]| -> Vec<f64> {
            t.iter()
                .map(|t| v[0] * (-v[1] * t).exp() + v[2] - (2.0 * (-1.5 * t).exp() + 0.3))
                .collect()
        };
        let specs = [
            ParamSpec::linear("a", 1.0, 1.0, 0.0, 10.0),
            ParamSpec::linear("k", 0.5, 1.0, 0.01, 10.0),
            ParamSpec::linear("c", 0.0, 1.0, -5.0, 5.0),
        ];
        let spent = |secant: bool| {
            let effort = Effort {
                patience: 50,
                tolerance: 1e-12,
                secant,
            };
            let m = minimise(
                &model,
                &specs,
                specs.iter().map(|s| s.start).collect(),
                effort,
            );
            let values: Vec<f64> = specs.iter().zip(&m.u).map(|(s, u)| s.value(*u)).collect();
            for (v, truth) in values.iter().zip([2.0, 1.5, 0.3]) {
                assert!((v - truth).abs() < 1e-6, "{values:?} (secant {secant})");
            }
            m.evaluations
        };
        let (differenced, updated) = (spent(false), spent(true));
        assert!(
            updated < differenced,
            "{updated} against {differenced} evaluations"
        );
    }
}
