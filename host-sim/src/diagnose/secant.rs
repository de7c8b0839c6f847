//! Broyden's rank-one update of a least-squares Jacobian between iterations (Broyden 1965,
//! the "good" update; Dennis & Schnabel, *Numerical Methods for Unconstrained Optimization*,
//! §8.1): from the Jacobian J at the last accepted point, the one at the next satisfies the
//! secant condition J₊·Δv = Δr with the least change in Frobenius norm,
//!
//! ```text
//!   J₊ = J + (Δr − J·Δv)·Δvᵀ / (Δvᵀ·Δv)
//! ```
//!
//! at the cost of no model evaluation, where forward differences cost one per parameter.
//!
//! The diagnosis's fits spend most of their evaluations creeping along flat curved valleys
//! (`effort`), each short step costing a whole differenced Jacobian. Over such a step the
//! last Jacobian's linear prediction of the residuals' change is rough — the step crosses
//! the valley's curvature, and the pressure windows' absorber events bend the residuals —
//! yet an update that meets the secant condition along the step keeps the search going the
//! way the differences would. So the update is taken where the last Jacobian predicted the
//! step's change to within the change itself ([`LINEAR_FIT`]): it refuses a Jacobian that
//! sent the search the wrong way (a step across a crest, a jump into another basin), and
//! the differences are taken afresh at least every [`MAX_AGE`] + 1 iterations, so the
//! directions the steps never probe cannot grow stale.

/// Most updates in a row before the Jacobian is differenced afresh.
pub const MAX_AGE: usize = 3;

/// Largest error of the last Jacobian's linear prediction of a step's change of the
/// residuals, relative to the change, for which the update is taken: at 1 a prediction
/// no better than predicting no change at all is refused. [1]
pub const LINEAR_FIT: f64 = 1.0;

/// A Jacobian and the point and residuals it was taken at.
pub struct Secant {
    /// The point. [search coordinates]
    v: Vec<f64>,
    /// The residuals there.
    r: Vec<f64>,
    /// The Jacobian, column-major, `r.len()` rows by `v.len()` columns.
    j: Vec<f64>,
    /// Updates since the Jacobian was last differenced.
    age: usize,
}

impl Secant {
    /// The Jacobian `j` (column-major) differenced at `v` with residuals `r`.
    pub fn differenced(v: Vec<f64>, r: Vec<f64>, j: Vec<f64>) -> Secant {
        Secant { v, r, j, age: 0 }
    }

    /// The Jacobian at `v` with residuals `r` by the rank-one update, when the last one
    /// predicted the change to `r` well and has not been updated [`MAX_AGE`] times;
    /// `None` when it must be differenced.
    pub fn updated(&mut self, v: &[f64], r: &[f64]) -> Option<Vec<f64>> {
        let (m, n) = (self.r.len(), self.v.len());
        if self.age >= MAX_AGE || v.len() != n || r.len() != m || self.j.len() != m * n {
            return None;
        }
        let dv: Vec<f64> = v.iter().zip(&self.v).map(|(a, b)| a - b).collect();
        let step2: f64 = dv.iter().map(|d| d * d).sum();
        if !step2.is_finite() || step2 <= 0.0 {
            return None;
        }
        // e = Δr − J·Δv, the linear prediction's error.
        let mut e: Vec<f64> = r.iter().zip(&self.r).map(|(a, b)| a - b).collect();
        let change2: f64 = e.iter().map(|d| d * d).sum();
        for (column, d) in self.j.chunks_exact(m).zip(&dv) {
            for (e, c) in e.iter_mut().zip(column) {
                *e -= c * d;
            }
        }
        let error2: f64 = e.iter().map(|d| d * d).sum();
        if !error2.is_finite() || error2 > LINEAR_FIT * LINEAR_FIT * change2 {
            return None;
        }
        for (column, d) in self.j.chunks_exact_mut(m).zip(&dv) {
            let f = d / step2;
            for (c, e) in column.iter_mut().zip(&e) {
                *c += e * f;
            }
        }
        self.v.copy_from_slice(v);
        self.r.copy_from_slice(r);
        self.age += 1;
        Some(self.j.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// Column-major m×n matrix times a vector (nalgebra's product, independent of the
    /// update's own loops).
    fn times(j: &[f64], m: usize, x: &[f64]) -> Vec<f64> {
        let a = DMatrix::from_column_slice(m, x.len(), j);
        (a * DVector::from_column_slice(x)).as_slice().to_vec()
    }

    #[test]
    fn a_linear_model_keeps_its_jacobian_and_the_update_meets_the_secant_condition() {
        // r(v) = A·v + b with A = [[1, 2], [3, 4], [5, 6]]: the differenced Jacobian is A,
        // and the update after any step changes nothing (Δr − A·Δv = 0).
        let a = vec![1.0, 3.0, 5.0, 2.0, 4.0, 6.0];
        let r = |v: &[f64]| {
            let mut y = times(&a, 3, v);
            y.iter_mut()
                .zip([0.5, -1.0, 2.0])
                .for_each(|(y, b)| *y += b);
            y
        };
        let v0 = vec![0.1, 0.2];
        let mut s = Secant::differenced(v0.clone(), r(&v0), a.clone());
        let v1 = vec![0.4, -0.3];
        assert_eq!(s.updated(&v1, &r(&v1)), Some(a.clone()));
        // A mildly nonlinear model, r = (v₀², v₀·v₁, v₁): after a short step the updated
        // Jacobian maps the step onto the residuals' change exactly (the secant condition).
        let f = |v: &[f64]| vec![v[0] * v[0], v[0] * v[1], v[1]];
        let v0 = vec![1.0, 2.0];
        let j0 = vec![2.0, 2.0, 0.0, 0.0, 1.0, 1.0];
        let mut s = Secant::differenced(v0.clone(), f(&v0), j0);
        let v1 = vec![1.01, 1.99];
        let j1 = s
            .updated(&v1, &f(&v1))
            .expect("a short step is nearly linear");
        let dr: Vec<f64> = f(&v1).iter().zip(f(&v0)).map(|(a, b)| a - b).collect();
        let predicted = times(&j1, 3, &[0.01, -0.01]);
        for (p, d) in predicted.iter().zip(&dr) {
            assert!((p - d).abs() < 1e-15, "{p} against {d}");
        }
    }

    #[test]
    fn a_step_the_jacobian_mispredicts_or_an_old_jacobian_is_differenced_afresh() {
        // r = v² − 3·v from J = −1 at v = 1: a step to 3 across the minimum changes r by
        // +2 where J predicts −2, an error of 4, twice the change.
        let mut s = Secant::differenced(vec![1.0], vec![-2.0], vec![-1.0]);
        assert_eq!(s.updated(&[3.0], &[0.0]), None);
        // Where J predicts within the change (r = v³ from J = 3 at 1 to 1.5: change 2.375,
        // predicted 1.5), the update is taken, and meets the secant condition.
        let mut s = Secant::differenced(vec![1.0], vec![1.0], vec![3.0]);
        let j = s
            .updated(&[1.5], &[3.375])
            .expect("predicted within the change");
        assert!((j[0] * 0.5 - 2.375).abs() < 1e-15);
        // Steps of 10⁻⁴ are linear to 10⁻⁴: updated MAX_AGE times, then refused however
        // well it predicts.
        let mut s = Secant::differenced(vec![1.0], vec![1.0], vec![3.0]);
        let mut v = 1.0;
        for _ in 0..MAX_AGE {
            v += 1e-4;
            assert!(s.updated(&[v], &[v * v * v]).is_some());
        }
        v += 1e-4;
        assert_eq!(s.updated(&[v], &[v * v * v]), None);
        // No step: nothing to update from.
        let mut s = Secant::differenced(vec![1.0], vec![1.0], vec![3.0]);
        assert_eq!(s.updated(&[1.0], &[1.0]), None);
    }
}
