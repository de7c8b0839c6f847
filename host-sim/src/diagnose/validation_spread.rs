//! How far the validation gain could move with the fits' own uncertainty.
//!
//! The validation gain compares the baseline and the extension on the validation segment,
//! each at the end point its identification fit reached. Where the identification leaves a
//! direction flat — a tolerance the segment does not excite, or one a misfitting model bends
//! to absorb its misfit — the end point along it is arbitrary, and so is the gain's share
//! that it makes. Linearised, the validation SSE S(u) of a fit at u moves by gᵀδu with
//! g = ∂S/∂u, and the fit's u is uncertain with covariance H⁻¹, where H = JᵀJ/s is the
//! Gauss–Newton information of the identification residuals r (their variance per
//! independent sample s, the model's own: a misfitting model's parameters are the less
//! certain) plus each parameter's uniform spread over its search bounds, 12/w² (a
//! tolerance's bounds are its band, so a direction the log leaves flat is bounded by the
//! band), and its prior's information where it has one. The gain's standard error from
//! both fits is then √(g_bᵀH_b⁻¹g_b + g_eᵀH_e⁻¹g_e).

use crate::diagnose::calibration::{weighed_sse, Relation};
use crate::diagnose::least_squares::{information, variance_per_independent_sample, ParamSpec};
use nalgebra::DVector;
use std::ops::Range;

/// How much worse the validation segment may get under an extension before it refutes it:
/// the χ²(1) quantile at 95 %. A loss beyond it is given its spread. [1]
pub const VALIDATION_TOLERANCE: f64 = 3.84;

/// Share of a parameter's search range its difference quotients step by. [1]
const STEP: f64 = 1e-3;

/// Standard error of one fit's validation SSE (in units of `scale`) from the uncertainty of
/// its coordinates `u`, identified on `id`. [1]
pub fn validation_spread<R: Relation>(
    relation: &R,
    specs: &[ParamSpec],
    u: &[f64],
    id: &[Range<usize>],
    val: &[Range<usize>],
    scale: f64,
) -> f64 {
    let values =
        |u: &[f64]| -> Vec<f64> { specs.iter().zip(u).map(|(s, &x)| s.value(x)).collect() };
    let v0 = values(u);
    let r0 = relation.residuals(&v0, id);
    let own = variance_per_independent_sample(&r0, relation.correlation_bin());
    let w = 1.0 / own.max(f64::MIN_POSITIVE).sqrt();
    let s0 = weighed_sse(relation, &v0, val, scale);
    let free: Vec<usize> = (0..specs.len())
        .filter(|&i| specs[i].u_bounds.1 > specs[i].u_bounds.0)
        .collect();
    let n = free.len();
    if n == 0 {
        return 0.0;
    }
    let mut columns = Vec::with_capacity(n);
    let mut g = DVector::<f64>::zeros(n);
    for (k, &i) in free.iter().enumerate() {
        let (lo, hi) = specs[i].u_bounds;
        let mut h = STEP * (hi - lo);
        if u[i] + h > hi {
            h = -h;
        }
        let mut up = u.to_vec();
        up[i] += h;
        let vi = values(&up);
        let ri = relation.residuals(&vi, id);
        columns.push(ri.iter().zip(&r0).map(|(a, b)| (a - b) / h * w).collect());
        g[k] = (weighed_sse(relation, &vi, val, scale) - s0) / h;
    }
    let mut info = information(&columns, r0.len(), specs, &free);
    for (k, &i) in free.iter().enumerate() {
        let (lo, hi) = specs[i].u_bounds;
        info[(k, k)] += 12.0 / ((hi - lo) * (hi - lo));
    }
    match info.cholesky() {
        Some(c) => g.dot(&c.solve(&g)).max(0.0).sqrt(),
        None => f64::INFINITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_log::BenchLog;
    use crate::diagnose::calibration::Release;
    use crate::diagnose::facts::LogFacts;
    use crate::diagnose::test_noise::gaussian;
    use plant_model::Rig;

    /// Rows of the toy log, the first half identification. [1]
    const N: usize = 2000;

    /// A relation of two parameters: `a` scales a regressor on every row, `b` offsets the
    /// second half only (or, if `b_seen`, every row), white unit noise on top.
    struct Toy {
        facts: LogFacts,
        noise: Vec<f64>,
        b_seen: bool,
    }

    impl Toy {
        fn new(b_seen: bool) -> Toy {
            let t: Vec<f64> = (0..N).map(|k| k as f64 * 1e-3).collect();
            let log = BenchLog {
                p_ref_pa: vec![3e6; N],
                p_pa: vec![3e6; N],
                speed_rad_s: vec![0.0; N],
                iq_a: vec![0.0; N],
                id_a: vec![0.0; N],
                t_s: t,
                ..BenchLog::default()
            };
            Toy {
                facts: LogFacts::of(&log, &Rig::nominal()),
                noise: gaussian(N, 5),
                b_seen,
            }
        }
    }

    impl Relation for Toy {
        fn specs(&self, _: Release) -> Vec<ParamSpec> {
            vec![
                ParamSpec::linear("a", 1.0, 1.0, -1.0, 3.0).with_band(0.5, 1.5),
                ParamSpec::linear("b", 0.0, 1.0, -2.0, 2.0).with_band(-0.5, 0.5),
            ]
        }
        fn residuals(&self, v: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
            rows.iter()
                .flat_map(|r| r.clone())
                .map(|k| {
                    let x = ((k % 7) as f64 - 3.0) * 0.5;
                    let offset = if self.b_seen || k >= N / 2 { v[1] } else { 0.0 };
                    (v[0] - 1.0) * x + offset + self.noise[k]
                })
                .collect()
        }
        fn released(&self, _: Release) -> Option<(usize, Vec<f64>)> {
            None
        }
        fn facts(&self) -> &LogFacts {
            &self.facts
        }
    }

    #[test]
    fn a_direction_the_identification_leaves_flat_spreads_over_its_band() {
        // b is not seen on the identification rows, so its end point (0.3 here) is
        // anywhere in its band of width 1: standard deviation 1/√12. The validation SSE
        // S = Σ(b + e_k)² moves with it at ∂S/∂b = 2·Σ(b + e_k); a, seen on both halves with
        // ⟨x²⟩ = 1, is pinned to ±1/√1000 and the validation's slope along it is Σ 2x(b + e),
        // small beside. The spread is |∂S/∂b|/√12 to within a percent.
        let toy = Toy::new(false);
        let specs = toy.specs(Release::Nothing);
        let halves = [0..N / 2, N / 2..N];
        let (id, val) = halves.split_at(1);
        let b = 0.3;
        let slope: f64 = (N / 2..N).map(|k| 2.0 * (b + toy.noise[k])).sum();
        let spread = validation_spread(&toy, &specs, &[0.0, b], id, val, 1.0);
        let expected = slope.abs() / 12f64.sqrt();
        assert!(
            (spread / expected - 1.0).abs() < 0.01,
            "spread {spread}, expected {expected}"
        );
        // Seen on the identification rows as well, b is pinned to about ±1/√1000 by the
        // thousand unit-noise rows: the spread falls by √(1000/12) ≈ 9, to within 10 %.
        let seen = Toy::new(true);
        let pinned = validation_spread(&seen, &specs, &[0.0, b], id, val, 1.0);
        let ratio = spread / pinned;
        assert!(
            (ratio / (1000.0f64 / 12.0).sqrt() - 1.0).abs() < 0.1,
            "ratio {ratio}"
        );
    }
}
