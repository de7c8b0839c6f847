//! Bounded, regularised nonlinear least squares: the maximum a-posteriori fit of a model's
//! parameters to a log, with the `levenberg-marquardt` crate doing the iterations.
//!
//! Each parameter is searched in a dimensionless coordinate `u` ([`ParamSpec`]): the
//! logarithm of its ratio to the nominal value for positive quantities, a scaled difference
//! for signed ones. Hard bounds (the physically plausible range) are kept by searching
//! `v` with u = c + h·sin(v) (MINUIT's transform), so the optimiser is unconstrained. A
//! parameter with a tolerance band carries a Gaussian prior on `u` whose two standard
//! deviations span the band, as an extra residual: the fit stays in the band unless the
//! data insist, and how much they insist is the likelihood ratio the decision reads.
//!
//! A parameter the data press onto a hard bound is held there while the others are
//! searched ([`crate::diagnose::active_set`]), instead of creeping towards the transform's
//! flat end.

pub use crate::diagnose::active_set::Model;
use crate::diagnose::active_set::{minimise, Minimum};
pub use crate::diagnose::effort::Effort;
pub use crate::diagnose::param_spec::ParamSpec;
use nalgebra::DMatrix;
use rayon::prelude::*;

/// The result of a fit.
#[derive(Clone, Debug)]
pub struct Fitted {
    /// Best coordinates.
    pub u: Vec<f64>,
    /// Their values. [units of each]
    pub values: Vec<f64>,
    /// Sum of the squared data residuals at the optimum (the priors' share apart). [1]
    pub data_sse: f64,
    /// Sum of the squared prior residuals. [1]
    pub prior_sse: f64,
    /// Data residuals.
    pub residual_count: usize,
    /// Posterior covariance of `u` for unit-variance residuals, (JᵀJ)⁻¹ with the priors'
    /// rows; `None` when singular.
    pub covariance_u: Option<DMatrix<f64>>,
    /// Model evaluations spent.
    pub evaluations: usize,
}

impl Fitted {
    /// Standard error of coordinate `k` with the residuals' variance scaled by `inflation`
    /// (1 for white residuals of unit variance). [u]
    pub fn standard_error(&self, k: usize, inflation: f64) -> f64 {
        self.covariance_u
            .as_ref()
            .map_or(f64::INFINITY, |c| (c[(k, k)] * inflation).max(0.0).sqrt())
    }
}

/// Residual scale (in noise units) beyond which [`huber`] grows linearly, not
/// quadratically. [1]
pub const HUBER_SCALE: f64 = 3.0;

/// The Huber pseudo-residual of `r` (noise units): `r` within ±[`HUBER_SCALE`], beyond it
/// the value whose square is Huber's loss, 2c·|r| − c². A least-squares fit of these is the
/// robust M-estimate: a few transients (a current spike the smoothed acceleration cannot
/// follow) weigh as much as a few large residuals, not as their squares.
#[inline]
pub fn huber(r: f64) -> f64 {
    let c = HUBER_SCALE;
    if r.abs() <= c {
        r
    } else {
        r.signum() * (c * (2.0 * r.abs() - c)).sqrt()
    }
}

/// The variance a residual series carries per independent sample: its mean square times
/// its integrated autocorrelation time κ = 1 + 2·Σ ρ_l, summed with Sokal's automatic
/// window (stop at the first lag l ≥ 5·κ(l)). Divided by it, the squared residuals of a
/// series whose errors are correlated over κ rows count as N/κ independent ones, which is
/// what a likelihood ratio may rely on.
///
/// The series is first averaged over blocks of `bin` rows (blocking, Flyvbjerg & Petersen
/// 1989) and κ read on the block means, the result scaled back to one row: white noise
/// gives its variance whatever `bin`, while a model error correlated over a time T counts
/// T/bin blocks. With `bin` rows spanning a fixed time, the weighing does not depend on the
/// log's rate: Sokal's window, counted in rows, would otherwise stop ten times too early
/// on a 10 kHz log and take a slow model error for white noise. [unit²]
pub fn variance_per_independent_sample(r: &[f64], bin: usize) -> f64 {
    let bin = bin.max(1);
    let blocks: Vec<f64> = r
        .chunks_exact(bin)
        .map(|c| c.iter().sum::<f64>() / bin as f64)
        .collect();
    let n = blocks.len();
    if n < 4 {
        return 1.0;
    }
    let mean = blocks.iter().sum::<f64>() / n as f64;
    let var = blocks.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
    let ms = blocks.iter().map(|x| x * x).sum::<f64>() / n as f64;
    if var <= 0.0 {
        return (ms * bin as f64).max(f64::MIN_POSITIVE);
    }
    let mut tau = 1.0;
    let max_lag = (n / 4).min(2000);
    for l in 1..max_lag {
        let c = blocks[..n - l]
            .iter()
            .zip(&blocks[l..])
            .map(|(a, b)| (a - mean) * (b - mean))
            .sum::<f64>()
            / (n as f64 * var);
        tau += 2.0 * c;
        if l as f64 >= 5.0 * tau {
            break;
        }
    }
    (ms * bin as f64).max(f64::MIN_POSITIVE) * tau.max(1.0)
}

/// Fits `specs` to `model` from their starts.
pub fn fit<M: Model>(model: &M, specs: &[ParamSpec]) -> Fitted {
    fit_with(model, specs, Effort::REPORTED)
}

/// [`fit`] driven as far as `effort` says.
pub fn fit_with<M: Model>(model: &M, specs: &[ParamSpec], effort: Effort) -> Fitted {
    // A start on a bound would freeze the search there (the sine transform is flat at its
    // ends): every start at least 1 % of the range inside.
    let u0: Vec<f64> = specs
        .iter()
        .map(|s| {
            let (lo, hi) = s.u_bounds;
            let margin = 0.01 * (hi - lo);
            s.start.clamp(lo + margin, hi - margin)
        })
        .collect();
    let Minimum { u, evaluations } = minimise(model, specs, u0, effort);
    let values: Vec<f64> = specs.iter().zip(&u).map(|(s, u)| s.value(*u)).collect();
    let data = model.residuals(&values);
    let data_sse = data
        .iter()
        .map(|r| if r.is_finite() { r * r } else { 1e12 })
        .sum();
    let prior_sse = specs
        .iter()
        .zip(&u)
        .filter_map(|(s, u)| s.prior.map(|(m, sd)| ((u - m) / sd).powi(2)))
        .sum();
    let covariance_u = covariance(model, specs, &u, &data);
    Fitted {
        evaluations: evaluations + 1,
        u,
        values,
        data_sse,
        prior_sse,
        residual_count: data.len(),
        covariance_u,
    }
}

/// The Gauss–Newton information JᵀJ of the residuals' difference columns `columns` (each
/// `m` long, one for each parameter of `free`, an index into `specs`), with each such
/// parameter's Gaussian prior, 1/sd², on its diagonal.
pub fn information(
    columns: &[Vec<f64>],
    m: usize,
    specs: &[ParamSpec],
    free: &[usize],
) -> DMatrix<f64> {
    let f = free.len();
    let mut jtj = DMatrix::from_fn(f, f, |i, j| {
        (0..m).map(|r| columns[i][r] * columns[j][r]).sum::<f64>()
    });
    for (i, &k) in free.iter().enumerate() {
        if let Some((_, sd)) = specs[k].prior {
            jtj[(i, i)] += 1.0 / (sd * sd);
        }
    }
    jtj
}

/// (JᵀJ)⁻¹ in u at `u` (data and prior rows), by central differences kept inside the
/// bounds, over the parameters off their bounds: one held at a bound by the data is
/// fixed there (the reduced Hessian of a bound-constrained problem), its row and column
/// zero.
fn covariance<M: Model>(
    model: &M,
    specs: &[ParamSpec],
    u: &[f64],
    r0: &[f64],
) -> Option<DMatrix<f64>> {
    let n = specs.len();
    let free: Vec<usize> = (0..n)
        .filter(|&k| {
            let (lo, hi) = specs[k].u_bounds;
            let margin = 0.01 * (hi - lo);
            u[k] > lo + margin && u[k] < hi - margin
        })
        .collect();
    if free.is_empty() {
        return Some(DMatrix::zeros(n, n));
    }
    let columns: Vec<Vec<f64>> = free
        .par_iter()
        .map(|&k| {
            let (lo, hi) = specs[k].u_bounds;
            let h = 1e-3 * (1.0 + u[k].abs());
            let (a, b) = ((u[k] - h).max(lo), (u[k] + h).min(hi));
            let at = |x: f64| {
                let values: Vec<f64> = specs
                    .iter()
                    .zip(u)
                    .enumerate()
                    .map(|(j, (s, uj))| s.value(if j == k { x } else { *uj }))
                    .collect();
                model.residuals(&values)
            };
            let (ra, rb) = (at(a), at(b));
            let d = (b - a).max(f64::MIN_POSITIVE);
            ra.iter()
                .zip(&rb)
                .map(|(x, y)| {
                    if (y - x).is_finite() {
                        (y - x) / d
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    let inv = information(&columns, r0.len(), specs, &free).try_inverse()?;
    let mut full = DMatrix::zeros(n, n);
    for (i, &a) in free.iter().enumerate() {
        for (j, &b) in free.iter().enumerate() {
            full[(a, b)] = inv[(i, j)];
        }
    }
    Some(full)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::test_noise::gaussian;

    #[test]
    fn blocks_of_a_millisecond_read_a_slow_error_under_fast_white_noise() {
        // A 10 kHz residual: unit white noise plus 0.3 of an AR(1) error whose correlation
        // time is 5 ms (ρ = e^(−0.1/5) per row). Per independent row it carries
        // 1 + 0.09·(1 + ρ)/(1 − ρ) = 9.9 (the AR(1) sum Σ ρ^|l|); Sokal's window on the
        // raw rows stops within a few lags and reads about a third of it.
        let (n, rho) = (200_000, (-0.1f64 / 5.0).exp());
        let (w, e) = (gaussian(n, 11), gaussian(n, 12));
        let mut c = 0.0;
        let r: Vec<f64> = (0..n)
            .map(|k| {
                c = rho * c + (1.0 - rho * rho).sqrt() * e[k];
                w[k] + 0.3 * c
            })
            .collect();
        let expected = 1.0 + 0.09 * (1.0 + rho) / (1.0 - rho);
        let blocked = variance_per_independent_sample(&r, 10);
        assert!(
            (blocked / expected - 1.0).abs() < 0.15,
            "{blocked} against {expected}"
        );
        let raw = variance_per_independent_sample(&r, 1);
        assert!(raw < 0.5 * expected, "{raw}");
        // White noise alone reads its variance whatever the blocks.
        for bin in [1, 10] {
            let v = variance_per_independent_sample(&w, bin);
            assert!((v - 1.0).abs() < 0.05, "bin {bin}: {v}");
        }
    }

    #[test]
    fn an_exponential_decay_is_fitted_and_its_error_bars_are_the_textbook_ones() {
        // y = A·exp(−t/τ) + noise-free, A = 2, τ = 0.3; residuals divided by σ = 0.01.
        let t: Vec<f64> = (0..200).map(|k| k as f64 * 5e-3).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 * (-t / 0.3).exp()).collect();
        let model = |v: &[f64]| -> Vec<f64> {
            t.iter()
                .zip(&y)
                .map(|(t, y)| (y - v[0] * (-t / v[1]).exp()) / 0.01)
                .collect()
        };
        let specs = [
            ParamSpec::log("A", 1.0, 0.1, 10.0),
            ParamSpec::log("tau", 0.1, 0.1, 10.0),
        ];
        let f = fit(&model, &specs);
        assert!((f.values[0] - 2.0).abs() < 1e-4, "{:?}", f.values);
        assert!((f.values[1] - 0.3).abs() < 1e-4, "{:?}", f.values);
        assert!(f.data_sse < 1e-6, "{}", f.data_sse);
        // Linearised standard error of ln A: with unit-variance residuals the Fisher
        // information of ln A is Σ (A·e^{−t/τ}/σ)², its inverse bounds the variance.
        let info: f64 = t
            .iter()
            .map(|t| (2.0 * (-t / 0.3).exp() / 0.01).powi(2))
            .sum();
        let se = f.standard_error(0, 1.0);
        assert!(se >= (1.0 / info).sqrt() * 0.999, "{se}");
    }

    #[test]
    fn a_prior_holds_a_parameter_the_data_do_not_fix() {
        // The model does not depend on the second parameter: its prior keeps it at its mean,
        // and its error bar is the prior's.
        let model = |v: &[f64]| vec![(v[0] - 3.0) / 0.1];
        let specs = [
            ParamSpec::linear("x", 0.0, 1.0, -10.0, 10.0),
            ParamSpec::log("free", 1.0, 0.5, 2.0).with_prior(0.05, 0.02),
        ];
        let f = fit(&model, &specs);
        assert!((f.values[0] - 3.0).abs() < 1e-6);
        assert!(
            (f.values[1] - 0.05f64.exp()).abs() < 1e-3,
            "{}",
            f.values[1]
        );
        assert!((f.standard_error(1, 1.0) - 0.02).abs() < 1e-4);
    }

    #[test]
    fn a_band_holds_a_parameter_the_data_pull_out_of_it() {
        // The data want 3; the band is 0.9–1.1: the fit stops at its edge, whatever the start.
        let model = |v: &[f64]| vec![(v[0] - 3.0) / 0.1];
        let spec = ParamSpec::log("x", 1.0, 0.1, 10.0).with_band(0.9, 1.1);
        let f = fit(&model, &[spec]);
        assert!(
            f.values[0] <= 1.1 + 1e-9 && f.values[0] > 1.09,
            "{}",
            f.values[0]
        );
    }

    #[test]
    fn hard_bounds_hold() {
        // The data want x = 5; the bound is 2.
        let model = |v: &[f64]| vec![v[0] - 5.0];
        let f = fit(&model, &[ParamSpec::linear("x", 0.0, 1.0, -2.0, 2.0)]);
        assert!(
            f.values[0] <= 2.0 + 1e-9 && f.values[0] > 1.99,
            "{}",
            f.values[0]
        );
    }

    /// Rosenbrock's valley, y = x², under a floor of 10⁴ noise units (fixed rows of unit
    /// size, as a relation's residuals are): the objective falls along the valley by a few
    /// units in all, a fraction of a unit per iteration near its end. Minimum at (1, 1).
    fn valley(v: &[f64]) -> Vec<f64> {
        let mut r: Vec<f64> = (0..10_000)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        r.push(2.0 * (v[1] - v[0] * v[0]));
        r.push(1.0 - v[0]);
        r
    }

    #[test]
    fn a_screened_fit_driven_on_reaches_the_valley_floor_it_stopped_short_of() {
        let specs = [
            ParamSpec::linear("x", -1.2, 1.0, -3.0, 3.0),
            ParamSpec::linear("y", 1.0, 1.0, -3.0, 3.0),
        ];
        let floor = 10_000.0;
        let screened = fit_with(&valley, &specs, Effort::SCREENING);
        let from: Vec<ParamSpec> = specs
            .iter()
            .zip(&screened.values)
            .map(|(s, v)| s.clone().starting_at(*v))
            .collect();
        let reported = fit_with(&valley, &from, Effort::REPORTED);
        assert!(reported.data_sse <= screened.data_sse);
        // The screening stops where an iteration gains under 3·10⁻⁵ of the objective (0.3
        // of a unit): short of the floor along the valley.
        assert!(screened.data_sse - floor < 0.3, "{}", screened.data_sse);
        assert!(
            (screened.values[1] - 1.0).abs() > 0.01,
            "{:?}",
            screened.values
        );
        // Driven on, it reaches the analytic minimum.
        for v in &reported.values {
            assert!((v - 1.0).abs() < 1e-3, "{:?}", reported.values);
        }
    }
}
