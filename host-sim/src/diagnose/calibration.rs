//! Calibration before accusation: each parity relation's parameters fitted to the log
//! within the rig's tolerance bands (hard bounds, every combination within them equally
//! likely, [`super::least_squares`]), and the same fit with one effect's parameter released
//! to its physically plausible range.
//!
//! The bands, as fractions of the rig file's value (or absolute where the nominal is 0):
//!
//! | parameter | band | why |
//! |---|---|---|
//! | high-side volume V_h | −3 % … +30 % | chamber listed ±2 %; the line volume is not listed |
//! | bulk modulus β | ±5 % | listed ±2 %; temperature moves it a few percent |
//! | absorber shell V_0, precharge p_0 | ±5 % | listed ±2 % |
//! | absorber inlet resistance R | ÷10 … ×30 | not listed (inlet, hose and bladder) |
//! | leakage G (pump and cylinder) | ±20 % | coefficients listed; the path (eq. 9 or 10) not |
//! | transducer gain, offset (zero), lag | ±1 %, ±30 kPa ([`SENSOR_OFFSET_BAND_PA`](super::hydraulic_relation::SENSOR_OFFSET_BAND_PA)), 0–2.5 ms | a calibrated transducer behind a snubber and an anti-aliasing filter; the zero in the cylinder relation too |
//! | cylinder Coulomb and breakaway force | 0 … 3× the rig file's | seals wear in and out ([`super::cylinder`]) |
//! | magnet flux ψ_f (K_t) | ±5 % | listed ±2 %; magnet temperature |
//! | inertia J | ±10 % | assumed in the rig contract |
//! | viscous friction B | ÷2 … ×2 | assumed in the rig contract |
//! | shaft Coulomb friction T_c | 0 … 0.02 N·m | seals and bearings of a healthy shaft |
//! | pump displacement D | ±5 % | listed ±2 % |
//! | saliency (reluctance torque) | 0 … 1.2 of the rig's | L_d, L_q derived from gains |
//!
//! With the cylinder blocked every volume of the hydraulic relation is relative to the pump
//! displacement (scaling D and all volumes together leaves p(θ) unchanged): there the
//! fit may settle anywhere along that direction within the bands; a moving piston's A·x is
//! an absolute volume and fixes D. On a blocked cylinder the torque balance and the stator
//! voltages fix D instead, and the volume balance's readings are taken at it
//! ([`super::displacement`]).
//!
//! The relations themselves live beside: [`super::hydraulic_relation`] and
//! [`super::mechanical_relation`] (the electrical and cylinder ones in their own modules).

use crate::diagnose::facts::{rows_spanning, LogFacts};
use crate::diagnose::least_squares::{
    fit_with, variance_per_independent_sample, Effort, Fitted, ParamSpec,
};
use rayon::prelude::*;
use std::ops::Range;

/// Most log time a fit evaluates per model run: longer segments are thinned
/// ([`thinned`]). Ten seconds fix every rig parameter the relations carry; more only
/// narrows error bars already far inside the bands, at a cost that grows with the rows.
/// A span in time, not rows: a fast log thinned to a row budget would keep a few windows
/// and fit the tolerances to them. [s]
pub const MAX_FIT_S: f64 = 10.0;

/// Which parameter of a relation an effect releases from its band.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Release {
    /// None: the calibrated nominal model.
    Nothing,
    /// Leakage G upward (extra leakage).
    Leakage,
    /// Bulk modulus β downward (entrained air).
    BulkModulus,
    /// Absorber precharge p_0 (gas loss or overcharge).
    Precharge,
    /// Transducer lag τ.
    SensorLag,
    /// Shaft Coulomb friction.
    ShaftFriction,
    /// Inverter dead time (electrical relation).
    DeadTime,
    /// Cylinder Coulomb friction and, with it, the breakaway's excess over it.
    CylinderFriction,
}

/// `windows` thinned to at most `max_rows` rows together ([`MAX_FIT_S`] of the log): half
/// of the budget to the windows where `signal` moves most (its range within the window:
/// the steps, fills and starts where the effects show), the rest spread evenly over the
/// others, in time order.
pub fn thinned(windows: Vec<Range<usize>>, signal: &[f64], max_rows: usize) -> Vec<Range<usize>> {
    let rows: usize = windows.iter().map(|w| w.len()).sum();
    if rows <= max_rows {
        return windows;
    }
    let per_window = (rows / windows.len().max(1)).max(1);
    let keep = (max_rows / per_window).clamp(1, windows.len());
    let range = |w: &Range<usize>| {
        let s = &signal[w.clone()];
        let (lo, hi) = s
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(*v), h.max(*v))
            });
        hi - lo
    };
    let mut by_motion: Vec<usize> = (0..windows.len()).collect();
    by_motion.sort_by(|a, b| range(&windows[*b]).total_cmp(&range(&windows[*a])));
    let mut chosen = vec![false; windows.len()];
    for &i in by_motion.iter().take(keep / 2) {
        chosen[i] = true;
    }
    let rest: Vec<usize> = (0..windows.len()).filter(|i| !chosen[*i]).collect();
    let even = keep - keep / 2;
    let step = rest.len() as f64 / even.max(1) as f64;
    for k in 0..even {
        if let Some(&i) = rest.get((k as f64 * step) as usize) {
            chosen[i] = true;
        }
    }
    windows
        .into_iter()
        .zip(chosen)
        .filter_map(|(w, c)| c.then_some(w))
        .collect()
}

/// A parity relation the calibration fits: its search space and its residuals.
pub trait Relation: Sync {
    /// The search space with `release` out of its band.
    fn specs(&self, release: Release) -> Vec<ParamSpec>;
    /// Robust residuals (noise units, [`huber`]) at search `values` over `rows`.
    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64>;
    /// The released parameter's index and the values a coarse grid tries before the
    /// local search (the calibrated tolerances may have bent towards a wrong basin: a
    /// precharge far off is half-mimicked by displacement and shell volume); `None` when
    /// the relation does not offer `release`.
    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)>;
    /// How many more points of `release`'s grid besides its best one are fitted as well
    /// ([`release_starts`]): none unless the relation's objective is known to have basins
    /// the grid, scoring with the other parameters held, misjudges.
    fn grid_basins(&self, _release: Release) -> usize {
        0
    }
    /// How far the optimiser is driven on this relation: the screening's looser stop only
    /// where a caller asks for it ([`Patient`]).
    fn effort(&self) -> Effort {
        Effort::REPORTED
    }
    /// The facts of the log the relation reads.
    fn facts(&self) -> &LogFacts;
    /// Rows whose residuals are averaged before their correlation time is read
    /// ([`variance_per_independent_sample`]): [`CORRELATION_BIN_S`] of the log.
    fn correlation_bin(&self) -> usize {
        rows_spanning(CORRELATION_BIN_S, self.facts().period_s, 1)
    }
}

/// Span of the blocks a relation's residuals are averaged over before their correlation
/// time is read: one row of a 1 kHz log, so faster logs weigh their residuals as a 1 kHz
/// log of the same bench does. [s]
pub const CORRELATION_BIN_S: f64 = 1e-3;

/// `nominal` times each of `factors`.
pub fn scaled(nominal: f64, factors: &[f64]) -> Vec<f64> {
    factors.iter().map(|f| nominal * f).collect()
}

/// A relation fitted with another effort than [`Effort::REPORTED`].
pub struct Patient<'r, R> {
    /// The relation.
    pub relation: &'r R,
    /// How far its fits are driven.
    pub effort: Effort,
}

impl<R: Relation> Relation for Patient<'_, R> {
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        self.relation.specs(release)
    }
    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        self.relation.residuals(values, rows)
    }
    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        self.relation.released(release)
    }
    fn effort(&self) -> Effort {
        self.effort
    }
    fn facts(&self) -> &LogFacts {
        self.relation.facts()
    }
    fn correlation_bin(&self) -> usize {
        self.relation.correlation_bin()
    }
    fn grid_basins(&self, release: Release) -> usize {
        self.relation.grid_basins(release)
    }
}

/// A relation with parameter `index` held at `value`: the best fit of the others there
/// (a profile of the relation's objective).
pub struct Pinned<'r, R> {
    /// The relation.
    pub relation: &'r R,
    /// Index of the held parameter in the search vector.
    pub index: usize,
    /// Its value. [unit of the parameter]
    pub value: f64,
}

impl<R: Relation> Relation for Pinned<'_, R> {
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        let mut specs = self.relation.specs(release);
        if let Some(s) = specs.get_mut(self.index) {
            let u = s.coordinate(self.value);
            s.u_bounds = (u, u);
            s.start = u;
        }
        specs
    }
    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        self.relation.residuals(values, rows)
    }
    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        self.relation.released(release)
    }
    fn effort(&self) -> Effort {
        self.relation.effort()
    }
    fn facts(&self) -> &LogFacts {
        self.relation.facts()
    }
    fn correlation_bin(&self) -> usize {
        self.relation.correlation_bin()
    }
    fn grid_basins(&self, release: Release) -> usize {
        self.relation.grid_basins(release)
    }
}

/// A relation with the parameters of `freed` out of their bands in every search space it
/// offers: the model already extended by named effects, against which a further effect is
/// judged (forward selection) and which is itself the baseline of that test.
pub struct Freed<'r, R> {
    /// The relation.
    pub relation: &'r R,
    /// The releases already granted.
    pub freed: Vec<Release>,
}

impl<R: Relation> Relation for Freed<'_, R> {
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        let mut specs = self.relation.specs(release);
        for r in &self.freed {
            for (s, f) in specs.iter_mut().zip(self.relation.specs(*r)) {
                if f.band.is_none() && s.band.is_some() {
                    *s = f;
                }
            }
        }
        specs
    }
    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        self.relation.residuals(values, rows)
    }
    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        self.relation.released(release)
    }
    fn effort(&self) -> Effort {
        self.relation.effort()
    }
    fn facts(&self) -> &LogFacts {
        self.relation.facts()
    }
    fn correlation_bin(&self) -> usize {
        self.relation.correlation_bin()
    }
    fn grid_basins(&self, release: Release) -> usize {
        self.relation.grid_basins(release)
    }
}

/// A relation calibrated on some rows: the fit and the residuals' variance per independent
/// sample it was weighed with ([`variance_per_independent_sample`]).
#[derive(Clone, Debug)]
pub struct Calibration {
    /// The fit (its `data_sse` in units of `scale`).
    pub fitted: Fitted,
    /// Variance per independent sample of the calibrated residuals. [noise units²]
    pub scale: f64,
}

/// Fits `relation` over `rows` with `release`, its residuals divided by √`scale`, from
/// `start` (values) when given.
pub fn fit_relation<R: Relation>(
    relation: &R,
    rows: &[Range<usize>],
    release: Release,
    scale: f64,
    start: Option<&[f64]>,
) -> Fitted {
    let mut specs = relation.specs(release);
    if let Some(v) = start {
        for (s, v) in specs.iter_mut().zip(v) {
            let (lo, hi) = s.u_bounds;
            s.start = s.coordinate(*v).clamp(lo, hi);
        }
    }
    let w = 1.0 / scale.max(f64::MIN_POSITIVE).sqrt();
    let model = |v: &[f64]| -> Vec<f64> {
        let mut r = relation.residuals(v, rows);
        r.iter_mut().for_each(|x| *x *= w);
        r
    };
    fit_with(&model, &specs, relation.effort())
}

/// Calibrates `relation` within its bands over `rows`: weighed first by the nominal
/// model's residuals, then again by the calibrated model's.
pub fn calibrate<R: Relation>(relation: &R, rows: &[Range<usize>]) -> Calibration {
    let specs = relation.specs(Release::Nothing);
    let nominal: Vec<f64> = specs.iter().map(|s| s.value(s.start)).collect();
    let bin = relation.correlation_bin();
    let scale0 = variance_per_independent_sample(&relation.residuals(&nominal, rows), bin);
    let first = fit_relation(relation, rows, Release::Nothing, scale0, None);
    let scale = variance_per_independent_sample(&relation.residuals(&first.values, rows), bin);
    let fitted = reweighed(relation, rows, Release::Nothing, &first, scale0, scale);
    Calibration { fitted, scale }
}

/// `f`, a fit of `relation` with `release` over `rows` weighed by 1/`scale`, driven on
/// with `effort` from where it stopped: the better of the two.
fn driven_on<R: Relation>(
    relation: &R,
    rows: &[Range<usize>],
    release: Release,
    scale: f64,
    f: Fitted,
    effort: Effort,
) -> Fitted {
    let further = Patient { relation, effort };
    let g = fit_relation(&further, rows, release, scale, Some(&f.values));
    let objective = |f: &Fitted| f.data_sse + f.prior_sse;
    if objective(&g) < objective(&f) {
        g
    } else {
        f
    }
}

/// `c`, a fit of `relation` within its bands over `rows`, driven on with `effort` from
/// where it stopped, at its weighing: the better of the two.
pub fn polished<R: Relation>(
    relation: &R,
    rows: &[Range<usize>],
    c: &Calibration,
    effort: Effort,
) -> Calibration {
    Calibration {
        fitted: driven_on(
            relation,
            rows,
            Release::Nothing,
            c.scale,
            c.fitted.clone(),
            effort,
        ),
        scale: c.scale,
    }
}

/// `f`, fitted with the residuals weighed by 1/`from`, as weighed by 1/`to`. Without
/// priors the weight is a constant factor of the objective: the optimum stays, the sums
/// of squares and the covariance scale. With priors the fit is redone.
fn reweighed<R: Relation>(
    relation: &R,
    rows: &[Range<usize>],
    release: Release,
    f: &Fitted,
    from: f64,
    to: f64,
) -> Fitted {
    if relation.specs(release).iter().any(|s| s.prior.is_some()) {
        return fit_relation(relation, rows, release, to, Some(&f.values));
    }
    let k = from / to.max(f64::MIN_POSITIVE);
    Fitted {
        data_sse: f.data_sse * k,
        covariance_u: f.covariance_u.as_ref().map(|c| c / k),
        ..f.clone()
    }
}

/// One effect's test on a relation: its parameter released from its band against the
/// calibrated nominal model, both weighed by the released model's residuals (the variance
/// of the larger model, as an F test takes it).
#[derive(Clone, Debug)]
pub struct ReleaseTest {
    /// What was released.
    pub release: Release,
    /// The released fit.
    pub fitted: Fitted,
    /// The calibrated nominal model refitted at the same weighing.
    pub baseline: Fitted,
    /// Variance per independent sample of the released model's residuals. [noise units²]
    pub scale: f64,
    /// Twice the log-likelihood ratio, J_baseline − J_released (objective incl. priors). [1]
    pub lambda: f64,
}

/// Tests `release` on `relation` over `rows`, from the calibration `base`.
pub fn test_release<R: Relation>(
    relation: &R,
    rows: &[Range<usize>],
    release: Release,
    base: &Calibration,
) -> ReleaseTest {
    // The grid's best point along the released parameter, the others as calibrated.
    let specs = relation.specs(release);
    let objective_at = |v: &[f64], scale: f64| -> f64 {
        let prior: f64 = specs
            .iter()
            .zip(v)
            .filter_map(|(s, x)| s.prior.map(|(m, sd)| ((s.coordinate(*x) - m) / sd).powi(2)))
            .sum();
        weighed_sse(relation, v, rows, scale) + prior
    };
    let (best, others) = release_starts(relation, release, base, |v| objective_at(v, base.scale));
    let fit_from = |start: &[f64]| fit_relation(relation, rows, release, base.scale, Some(start));
    let objective = |f: &Fitted| f.data_sse + f.prior_sse;
    // The starts fitted side by side; of equal objectives the first start's fit is kept.
    let (head, rest) = rayon::join(
        || fit_from(&best),
        || {
            others
                .par_iter()
                .map(|start| fit_from(start))
                .collect::<Vec<_>>()
        },
    );
    let first = rest.into_iter().fold(head, |kept, f| {
        if objective(&f) < objective(&kept) {
            f
        } else {
            kept
        }
    });
    let scale = variance_per_independent_sample(
        &relation.residuals(&first.values, rows),
        relation.correlation_bin(),
    )
    .min(base.scale);
    let fitted = reweighed(relation, rows, release, &first, base.scale, scale);
    // The baseline: the calibration, or a fit within the bands from the released optimum
    // brought into them, whichever is better. A baseline stopped short of its optimum
    // would credit the released parameter with what any in-band change gains.
    let in_band: Vec<f64> = relation
        .specs(Release::Nothing)
        .iter()
        .zip(&first.values)
        .map(|(s, v)| {
            let (lo, hi) = s.u_bounds;
            s.value(s.coordinate(*v).clamp(lo, hi))
        })
        .collect();
    // A released fit that stayed within every band is itself such a fit.
    let again = if in_band == first.values {
        first.clone()
    } else {
        fit_relation(relation, rows, Release::Nothing, base.scale, Some(&in_band))
    };
    let best = if again.data_sse < base.fitted.data_sse {
        &again
    } else {
        &base.fitted
    };
    let baseline = reweighed(relation, rows, Release::Nothing, best, base.scale, scale);
    let objective = |f: &Fitted| f.data_sse + f.prior_sse;
    let lambda =
        |fitted: &Fitted, baseline: &Fitted| (objective(baseline) - objective(fitted)).max(0.0);
    // A screened test that comes near the decision's thresholds is decided at the
    // effort the screening leaves out: a baseline stopped short of its optimum would credit
    // the released parameter with the rest of the valley. One far above them stands as
    // screened.
    let near = (REFINE_ABOVE..REFINE_BELOW).contains(&lambda(&fitted, &baseline));
    let (fitted, baseline) = match relation.effort().refined() {
        Some(effort) if near => {
            let on = |f, release| driven_on(relation, rows, release, scale, f, effort);
            rayon::join(|| on(fitted, release), || on(baseline, Release::Nothing))
        }
        _ => (fitted, baseline),
    };
    ReleaseTest {
        release,
        lambda: lambda(&fitted, &baseline),
        fitted,
        baseline,
        scale,
    }
}

/// Λ of a screened test from which both its fits are driven on to the refined effort: half
/// the least χ² threshold the decision applies (χ²(1) at 10⁻⁴, 15.1). The screening's
/// tolerance bounds what its last iteration gained, not how far a fit stopped short of the
/// valley's floor. Below this a test stands as screened: what the refinement could add
/// there is the released fit's shortfall, a missed effect, never a false alarm. [1]
const REFINE_ABOVE: f64 = 7.5;

/// Λ of a screened test up to which its fits are driven on: twenty times the least χ²
/// threshold. Above it what the refinement moved was measured to be a small share of Λ
/// (`docs/diagnosis.md`, Speed), far from carrying a test across any threshold, so such a
/// test is decided as screened, as every test was before the refinement. [1]
const REFINE_BELOW: f64 = 300.0;

/// Where the released fit of `release` starts: the grid's best point along the released
/// parameter, the other parameters either as `base` calibrated them or at their own starts
/// (the rig file's values), whichever fits better by `objective`. The calibration may
/// have pushed other tolerances to their band edges to mimic the effect (a smaller
/// absorber shell and a larger displacement for a lower precharge); with them there, the
/// effect's true value fits worse than the nominal one and a local search stays put.
///
/// Returned with it, up to [`Relation::grid_basins`] other grid points, the best-scoring first,
/// each a few per cent apart along the released parameter from the starts already taken:
/// the grid scores each point with the other parameters held, so of two basins the one
/// they were calibrated near looks better than it is (a precharge below a shooting
/// window's start pressure against one above it). Each start is fitted and the best fit
/// kept.
fn release_starts<R: Relation>(
    relation: &R,
    release: Release,
    base: &Calibration,
    objective: impl Fn(&[f64]) -> f64,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let specs = relation.specs(release);
    let base_specs = relation.specs(Release::Nothing);
    let grid = relation.released(release);
    // A parameter the release frees besides the grid's starts where the released search
    // space puts it (read off the log), not at the band's edge the baseline left it at.
    let freed = |mut v: Vec<f64>| {
        for (k, (s, b)) in specs.iter().zip(&base_specs).enumerate() {
            if s.band.is_none() && b.band.is_some() && grid.as_ref().is_none_or(|(g, _)| *g != k) {
                v[k] = s.value(s.start);
            }
        }
        v
    };
    let calibrated = freed(base.fitted.values.clone());
    let Some((k, points)) = &grid else {
        return (calibrated, Vec::new());
    };
    let nominal = freed(base_specs.iter().map(|s| s.value(s.start)).collect());
    let mut best = (objective(&calibrated), calibrated.clone());
    let mut scored: Vec<(f64, Vec<f64>)> = Vec::new();
    for from in [&calibrated, &nominal] {
        for g in points {
            let mut v = from.clone();
            v[*k] = *g;
            let o = objective(&v);
            if o < best.0 {
                best = (o, v.clone());
            }
            if o.is_finite() {
                scored.push((o, v));
            }
        }
    }
    let mut others: Vec<Vec<f64>> = Vec::new();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, v) in scored {
        if others.len() >= relation.grid_basins(release) {
            break;
        }
        let apart = |s: &Vec<f64>| (v[*k] / s[*k]).abs().ln().abs() > DISTINCT_START_LN;
        if apart(&best.1) && others.iter().all(apart) {
            others.push(v);
        }
    }
    (best.1, others)
}

/// Least log-ratio between two starts of one release's fits. [1]
const DISTINCT_START_LN: f64 = 0.03;

/// The weighed squared residuals of `relation` at `values` over `rows`. [1]
pub fn weighed_sse<R: Relation>(
    relation: &R,
    values: &[f64],
    rows: &[Range<usize>],
    scale: f64,
) -> f64 {
    relation
        .residuals(values, rows)
        .iter()
        .map(|r| r * r)
        .sum::<f64>()
        / scale.max(f64::MIN_POSITIVE)
}

/// How much worse a released fit may get with a tolerance held at the rig file's value
/// before the log is said to reject that value: the χ²(1) quantile at 95 %. [1]
pub const NOMINAL_REJECTION: f64 = 3.84;

/// `release` tested on `relation` over `rows` from the calibration `base` ([`test_release`]),
/// its effect read at parameter `index`'s rig-file value (a tolerance, within its band in
/// every fit) unless the log tells that value apart and rejects it.
///
/// Where the log leaves a direction flat — a tolerance that shows as the released effect
/// does, such as the transducer's zero and the cylinder's Coulomb force along a one-way
/// stroke — the free released fit may stop anywhere along it (or where the model's own
/// approximations push it): the effect is reported as it is with the tolerance at the rig
/// file's value, the same test run with the tolerance held there. `separable` says whether
/// the log can tell the tolerance from the effect at all; if it can, the free fit is
/// reported when the held one is worse by more than [`NOMINAL_REJECTION`] (a profile
/// likelihood ratio). Λ, which decides whether the effect is named, is measured against
/// the free baseline (the tolerance anywhere in its band): the effect must explain more
/// than any value within the band can. Also returns whether the effect is read at the rig
/// file's value.
pub fn test_release_at_nominal<R: Relation>(
    relation: &R,
    rows: &[Range<usize>],
    release: Release,
    base: &Calibration,
    index: usize,
    separable: bool,
) -> (ReleaseTest, bool) {
    let free = test_release(relation, rows, release, base);
    let Some(nominal) = relation
        .specs(Release::Nothing)
        .get(index)
        .map(|s| s.nominal)
    else {
        return (free, false);
    };
    let pinned = Pinned {
        relation,
        index,
        value: nominal,
    };
    let held = test_release(&pinned, rows, release, base);
    let j = |v: &[f64]| weighed_sse(relation, v, rows, free.scale);
    let (j_free, j_held) = (j(&free.fitted.values), j(&held.fitted.values));
    if separable && j_held - j_free > NOMINAL_REJECTION {
        return (free, false);
    }
    // The held fit is a point of the released search space too.
    let lambda = free.lambda + (j_free - j_held).max(0.0);
    let test = ReleaseTest {
        fitted: held.fitted,
        lambda,
        ..free
    };
    (test, true)
}
