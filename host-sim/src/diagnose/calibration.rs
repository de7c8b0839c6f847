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
//! | transducer gain, offset, lag | ±1 %, ±30 kPa, 0–2.5 ms | a calibrated transducer behind a snubber and an anti-aliasing filter |
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
//! an absolute volume and fixes D.

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::facts::LogFacts;
use crate::diagnose::hydraulic::{HydraulicInputs, HydraulicParams, Hydraulics};
use crate::diagnose::least_squares::{
    fit_with_patience, huber, variance_per_independent_sample, Fitted, ParamSpec, PATIENCE,
};
use crate::diagnose::mechanical::{MechanicalParams, Mechanics, ShaftMotion};
use nalgebra::{DMatrix, DVector};
use plant_model::accumulator::GasCharge;
use plant_model::Rig;
use std::ops::Range;

/// Upper end of the transducer lag's tolerance band: a transducer with its snubber and
/// the logger's anti-aliasing filter. [s]
pub const LAG_BAND_S: f64 = 2.5e-3;

/// Upper end of a healthy shaft's Coulomb friction (bearings and seals). [N·m]
pub const SHAFT_COULOMB_BAND_NM: f64 = 0.02;

/// Length of a hydraulic shooting window. [s]
pub const HYDRAULIC_WINDOW_S: f64 = 0.25;

/// Length of a speed shooting window. [s]
pub const SPEED_WINDOW_S: f64 = 0.05;

/// Most rows a fit evaluates per model run: longer segments are thinned
/// ([`thinned`]). Twelve seconds at 1 kHz fix every rig parameter the relations carry;
/// more only narrows error bars already far inside the bands. [1]
pub const MAX_FIT_ROWS: usize = 12_000;

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
    /// Cylinder Coulomb friction.
    CylinderFriction,
}

/// Index of each hydraulic parameter in the search vector.
pub mod hyd {
    /// High-side volume.
    pub const VOLUME: usize = 0;
    /// Bulk modulus.
    pub const BETA: usize = 1;
    /// Absorber shell volume.
    pub const SHELL: usize = 2;
    /// Absorber precharge.
    pub const PRECHARGE: usize = 3;
    /// Absorber inlet resistance.
    pub const RESISTANCE: usize = 4;
    /// Leakage.
    pub const LEAKAGE: usize = 5;
    /// Transducer gain.
    pub const GAIN: usize = 6;
    /// Transducer offset.
    pub const OFFSET: usize = 7;
    /// Transducer lag.
    pub const LAG: usize = 8;
    /// Pump displacement (only the piston's volume is absolute: a blocked cylinder leaves
    /// it to its prior).
    pub const DISPLACEMENT: usize = 9;
}

/// Index of each mechanical parameter in the search vector.
pub mod mech {
    /// Magnet flux linkage (the torque constant's scale).
    pub const PSI: usize = 0;
    /// Inertia.
    pub const INERTIA: usize = 1;
    /// Viscous friction.
    pub const VISCOUS: usize = 2;
    /// Coulomb friction.
    pub const COULOMB: usize = 3;
    /// Pump displacement.
    pub const DISPLACEMENT: usize = 4;
    /// Fraction of the rig's saliency.
    pub const SALIENCY: usize = 5;
}

/// The hydraulic relation's search space on `rig`, with `release` out of its band.
pub fn hydraulic_specs(rig: &Rig, release: Release) -> Vec<ParamSpec> {
    let n = HydraulicParams::nominal(rig);
    let gas = n.absorber.unwrap_or(GasCharge {
        shell_volume_m3: 1e-4,
        precharge_pa: 1e6,
        exponent: 1.3,
    });
    let banded = |s: ParamSpec, lo: f64, hi: f64, released: bool| {
        if released {
            s
        } else {
            let nom = s.nominal;
            s.with_band(lo * nom, hi * nom)
        }
    };
    let mut lag = ParamSpec::linear("sensor_lag_s", 0.0, 1e-3, 0.0, 0.2);
    if release != Release::SensorLag {
        lag = lag.with_band(0.0, LAG_BAND_S);
    } else {
        lag = lag.starting_at(5e-3);
    }
    vec![
        banded(
            ParamSpec::log("high_side_volume_m3", n.high_side_volume_m3, 0.3, 3.0),
            0.97,
            1.3,
            false,
        ),
        banded(
            ParamSpec::log("bulk_modulus_pa", n.bulk_modulus_pa, 0.05, 1.5),
            0.95,
            1.05,
            release == Release::BulkModulus,
        ),
        banded(
            ParamSpec::log("shell_volume_m3", gas.shell_volume_m3, 0.3, 3.0),
            0.95,
            1.05,
            false,
        ),
        banded(
            ParamSpec::log("precharge_pa", gas.precharge_pa, 0.1, 5.0),
            0.95,
            1.05,
            release == Release::Precharge,
        ),
        banded(
            ParamSpec::log(
                "inlet_resistance_pa_s_m3",
                n.inlet_resistance_pa_s_m3.max(1.0),
                0.01,
                100.0,
            ),
            0.1,
            30.0,
            false,
        ),
        if release == Release::Leakage {
            // Extra leakage: only more than the band allows.
            ParamSpec::log("leakage_m3_s_pa", n.leakage_m3_s_pa.max(1e-16), 0.8, 30.0)
                .starting_at(1.5 * n.leakage_m3_s_pa)
        } else {
            ParamSpec::log("leakage_m3_s_pa", n.leakage_m3_s_pa.max(1e-16), 0.05, 30.0)
                .with_band(0.8 * n.leakage_m3_s_pa, 1.2 * n.leakage_m3_s_pa)
        },
        ParamSpec::linear("sensor_gain", 1.0, 0.01, 0.8, 1.2).with_band(0.99, 1.01),
        ParamSpec::linear("sensor_offset_pa", n.sensor_offset_pa, 1e4, -1e6, 1e6)
            .with_band(n.sensor_offset_pa - 3e4, n.sensor_offset_pa + 3e4),
        lag,
        ParamSpec::log(
            "displacement_m3_per_rev",
            n.displacement_m3_per_rev,
            0.5,
            2.0,
        )
        .with_band(
            0.95 * n.displacement_m3_per_rev,
            1.05 * n.displacement_m3_per_rev,
        ),
    ]
}

/// The hydraulic parameters at search `values` ([`hydraulic_specs`] order).
pub fn hydraulic_params(rig: &Rig, v: &[f64]) -> HydraulicParams {
    let mut p = HydraulicParams::nominal(rig);
    p.high_side_volume_m3 = v[hyd::VOLUME];
    p.bulk_modulus_pa = v[hyd::BETA];
    if let Some(g) = p.absorber.as_mut() {
        g.shell_volume_m3 = v[hyd::SHELL];
        g.precharge_pa = v[hyd::PRECHARGE];
    }
    p.inlet_resistance_pa_s_m3 = v[hyd::RESISTANCE];
    p.leakage_m3_s_pa = v[hyd::LEAKAGE];
    p.sensor_gain = v[hyd::GAIN];
    p.sensor_offset_pa = v[hyd::OFFSET];
    p.sensor_lag_s = v[hyd::LAG];
    p.displacement_m3_per_rev = v[hyd::DISPLACEMENT];
    p
}

/// `windows` thinned to at most [`MAX_FIT_ROWS`] rows together: half of the budget to the
/// windows where `signal` moves most (its range within the window: the steps, fills and
/// starts where the effects show), the rest spread evenly over the others, in time order.
pub fn thinned(windows: Vec<Range<usize>>, signal: &[f64]) -> Vec<Range<usize>> {
    let rows: usize = windows.iter().map(|w| w.len()).sum();
    if rows <= MAX_FIT_ROWS {
        return windows;
    }
    let per_window = (rows / windows.len().max(1)).max(1);
    let keep = (MAX_FIT_ROWS / per_window).clamp(1, windows.len());
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

/// The hydraulic relation's residuals (measured − predicted pressure over its noise) over
/// `windows`, each window's first row left out (it is the start).
pub fn hydraulic_residuals(
    log: &BenchLog,
    facts: &LogFacts,
    rig: &Rig,
    params: HydraulicParams,
    windows: &[Range<usize>],
) -> Vec<f64> {
    let sigma = facts.noise(Signal::Pressure).unwrap_or(1.0).max(1.0);
    let model = Hydraulics::new(params, rig);
    let inputs = HydraulicInputs::of(log, facts);
    let mut pred = vec![0.0; facts.rows];
    model.predict(&inputs, windows, &mut pred);
    windows
        .iter()
        .flat_map(|w| {
            (w.start + 1..w.end)
                .map(|k| huber((log.p_pa[k] - pred[k]) / sigma))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The mechanical relation's search space on `rig`.
pub fn mechanical_specs(rig: &Rig, release: Release) -> Vec<ParamSpec> {
    let n = MechanicalParams::nominal(rig);
    let mut coulomb = ParamSpec::linear("coulomb_nm", n.coulomb_nm, 0.01, 0.0, 2.0);
    if release != Release::ShaftFriction {
        coulomb = coulomb.with_band(n.coulomb_nm, n.coulomb_nm + SHAFT_COULOMB_BAND_NM);
    } else {
        coulomb = coulomb.starting_at(0.1);
    }
    let psi = n.motor.psi_f_wb;
    let d = n.pump.displacement_m3_per_rev;
    vec![
        ParamSpec::log("psi_f_wb", psi, 0.5, 2.0).with_band(0.95 * psi, 1.05 * psi),
        ParamSpec::log("inertia_kg_m2", n.inertia_kg_m2, 0.2, 5.0)
            .with_band(0.9 * n.inertia_kg_m2, 1.1 * n.inertia_kg_m2),
        ParamSpec::log("viscous_nm_s", n.viscous_nm_s.max(1e-6), 0.01, 100.0)
            .with_band(0.5 * n.viscous_nm_s, 2.0 * n.viscous_nm_s),
        coulomb,
        ParamSpec::log("displacement_m3_per_rev", d, 0.5, 2.0).with_band(0.95 * d, 1.05 * d),
        // The fraction of the rig's saliency L_d − L_q present (eq. 3's reluctance torque):
        // the saliency the Table 1 gains imply, which a motor may have less of.
        ParamSpec::linear("saliency_fraction", 1.0, 0.1, -0.5, 1.5).with_band(0.0, 1.2),
    ]
}

/// The mechanical parameters at search `values` ([`mechanical_specs`] order).
pub fn mechanical_params(rig: &Rig, v: &[f64]) -> MechanicalParams {
    let mut p = MechanicalParams::nominal(rig);
    p.motor.psi_f_wb = v[mech::PSI];
    p.inertia_kg_m2 = v[mech::INERTIA];
    p.viscous_nm_s = v[mech::VISCOUS];
    p.coulomb_nm = v[mech::COULOMB];
    p.pump.displacement_m3_per_rev = v[mech::DISPLACEMENT];
    p.motor.l_d_h = p.motor.l_q_h + v[mech::SALIENCY] * (p.motor.l_d_h - p.motor.l_q_h);
    p
}

/// Rows on each side of the moving average the mechanical residual is scored through.
pub const MECHANICAL_SMOOTHING_ROWS: usize = 5;

/// The mechanical relation's residuals over `window`: logged − needed q current with the
/// angle-locked lines projected out (`basis`, orthonormal columns over the window's rows),
/// through a moving average of ±[`MECHANICAL_SMOOTHING_ROWS`] rows, over the averaged
/// noise; appended to `out`.
///
/// The projection keeps the slow parameters blind to the lines the angle-locked effects
/// make (a cogging torque would otherwise be half-absorbed into the inertia through the
/// shaft's oscillation it causes). The relation is linear in its signals, so averaging the
/// residual averages every term alike; it removes the encoder's quantisation from the
/// acceleration (whose noise grows with frequency), which a regression would otherwise read
/// as a smaller inertia (errors in variables).
fn mechanical_window_residuals(
    e: &mut [f64],
    basis: Option<&DMatrix<f64>>,
    sigma: f64,
    out: &mut Vec<f64>,
) {
    if let Some(q) = basis {
        if q.nrows() == e.len() {
            let coef = q.tr_mul(&DVector::from_column_slice(e));
            let fit = q * coef;
            for (x, f) in e.iter_mut().zip(fit.iter()) {
                *x -= f;
            }
        }
    }
    let h = MECHANICAL_SMOOTHING_ROWS;
    if e.len() <= 2 * h {
        return;
    }
    let width = (2 * h + 1) as f64;
    let mut sum: f64 = e[..2 * h + 1].iter().sum();
    for k in h..e.len() - h {
        if k > h {
            sum += e[k + h] - e[k - h - 1];
        }
        out.push(huber(sum / width / sigma));
    }
}

/// An orthonormal basis of sin/cos of k·θ over `rows` for each of `orders` below a third
/// of the sampling rate at the window's mean speed; `None` when there is none.
fn line_basis(
    facts: &LogFacts,
    t: &[f64],
    rows: Range<usize>,
    orders: &[u32],
) -> Option<DMatrix<f64>> {
    let th = &facts.theta_rad;
    let n = rows.len();
    let span = t[rows.end - 1] - t[rows.start];
    if n < 4 || span <= 0.0 {
        return None;
    }
    let w = ((th[rows.end - 1] - th[rows.start]) / span).abs();
    let nyquist = 2.0 * std::f64::consts::PI / facts.period_s / 3.0;
    let ks: Vec<f64> = orders
        .iter()
        .map(|k| *k as f64)
        .filter(|k| k * w < nyquist && k * w > 0.0)
        .collect();
    if ks.is_empty() || 2 * ks.len() * 4 > n {
        return None;
    }
    let a = DMatrix::from_fn(n, 2 * ks.len(), |i, j| {
        let x = ks[j / 2] * th[rows.start + i];
        if j % 2 == 0 {
            x.cos()
        } else {
            x.sin()
        }
    });
    Some(a.qr().q())
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
    /// The optimiser's patience on this relation (iterations per parameter).
    fn patience(&self) -> usize {
        PATIENCE
    }
}

/// `nominal` times each of `factors`.
pub fn scaled(nominal: f64, factors: &[f64]) -> Vec<f64> {
    factors.iter().map(|f| nominal * f).collect()
}

/// The hydraulic relation of a log.
pub struct HydraulicRelation<'a> {
    /// The log.
    pub log: &'a BenchLog,
    /// Its facts.
    pub facts: &'a LogFacts,
    /// The rig file.
    pub rig: &'a Rig,
}

/// A relation fitted with another optimiser patience than [`PATIENCE`].
pub struct Patient<'r, R> {
    /// The relation.
    pub relation: &'r R,
    /// Iterations per parameter.
    pub patience: usize,
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
    fn patience(&self) -> usize {
        self.patience
    }
}

impl Relation for HydraulicRelation<'_> {
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        hydraulic_specs(self.rig, release)
    }

    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        let n = HydraulicParams::nominal(self.rig);
        let p0 = n.absorber.map_or(1e6, |g| g.precharge_pa);
        Some(match release {
            Release::Leakage => (
                hyd::LEAKAGE,
                scaled(n.leakage_m3_s_pa, &[1.0, 2.0, 4.0, 8.0, 16.0]),
            ),
            Release::BulkModulus => (
                hyd::BETA,
                scaled(n.bulk_modulus_pa, &[1.0, 0.6, 0.35, 0.2, 0.1]),
            ),
            Release::Precharge => (
                hyd::PRECHARGE,
                scaled(p0, &[0.3, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0]),
            ),
            Release::SensorLag => (hyd::LAG, vec![0.5e-3, 3e-3, 10e-3, 30e-3, 100e-3]),
            _ => return None,
        })
    }

    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        hydraulic_residuals(
            self.log,
            self.facts,
            self.rig,
            hydraulic_params(self.rig, values),
            rows,
        )
    }
}

/// A window's basis of the angle lines, or `None` when it has too few rows.
type LineBasis = Option<DMatrix<f64>>;

/// The mechanical relation of a log.
pub struct MechanicalRelation<'a> {
    log: &'a BenchLog,
    facts: &'a LogFacts,
    motion: &'a ShaftMotion,
    rig: &'a Rig,
    orders: Vec<u32>,
    /// The line bases of the windows seen so far, by their first and end rows.
    bases: std::sync::Mutex<std::collections::HashMap<(usize, usize), LineBasis>>,
}

impl<'a> MechanicalRelation<'a> {
    /// The relation, the lines at `orders` projected out of its residual.
    pub fn new(
        log: &'a BenchLog,
        facts: &'a LogFacts,
        motion: &'a ShaftMotion,
        rig: &'a Rig,
        orders: &[u32],
    ) -> MechanicalRelation<'a> {
        MechanicalRelation {
            log,
            facts,
            motion,
            rig,
            orders: orders.to_vec(),
            bases: Default::default(),
        }
    }

    fn basis(&self, rows: &Range<usize>) -> Option<DMatrix<f64>> {
        let key = (rows.start, rows.end);
        if let Some(b) = self.bases.lock().ok()?.get(&key) {
            return b.clone();
        }
        let b = line_basis(self.facts, &self.log.t_s, rows.clone(), &self.orders);
        if let Ok(mut m) = self.bases.lock() {
            m.insert(key, b.clone());
        }
        b
    }
}

impl Relation for MechanicalRelation<'_> {
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        mechanical_specs(self.rig, release)
    }

    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        (release == Release::ShaftFriction).then(|| (mech::COULOMB, vec![0.02, 0.1, 0.3, 0.8]))
    }

    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        let sigma = self.facts.noise(Signal::Iq).unwrap_or(1.0).max(1e-6)
            / ((2 * MECHANICAL_SMOOTHING_ROWS + 1) as f64).sqrt();
        let model = Mechanics::new(mechanical_params(self.rig, values));
        let mut pred = vec![0.0; self.facts.rows];
        let mut out = Vec::new();
        for r in rows {
            model.needed_current(self.log, self.facts, self.motion, r.clone(), &mut pred);
            let mut e: Vec<f64> = r.clone().map(|k| self.log.iq_a[k] - pred[k]).collect();
            let basis = self.basis(r);
            mechanical_window_residuals(&mut e, basis.as_ref(), sigma, &mut out);
        }
        out
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
    fit_with_patience(&model, &specs, relation.patience())
}

/// Calibrates `relation` within its bands over `rows`: weighed first by the nominal
/// model's residuals, then again by the calibrated model's.
pub fn calibrate<R: Relation>(relation: &R, rows: &[Range<usize>]) -> Calibration {
    let specs = relation.specs(Release::Nothing);
    let nominal: Vec<f64> = specs.iter().map(|s| s.value(s.start)).collect();
    let scale0 = variance_per_independent_sample(&relation.residuals(&nominal, rows));
    let first = fit_relation(relation, rows, Release::Nothing, scale0, None);
    let scale = variance_per_independent_sample(&relation.residuals(&first.values, rows));
    let fitted = reweighed(relation, rows, Release::Nothing, &first, scale0, scale);
    Calibration { fitted, scale }
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
    let mut start = base.fitted.values.clone();
    if let Some((k, grid)) = relation.released(release) {
        let best = grid
            .iter()
            .map(|g| {
                let mut v = start.clone();
                v[k] = *g;
                (objective_at(&v, base.scale), v)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((j, v)) = best {
            if j < objective_at(&start, base.scale) {
                start = v;
            }
        }
    }
    let first = fit_relation(relation, rows, release, base.scale, Some(&start));
    let scale =
        variance_per_independent_sample(&relation.residuals(&first.values, rows)).min(base.scale);
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
    ReleaseTest {
        release,
        lambda: (objective(&baseline) - objective(&fitted)).max(0.0),
        fitted,
        baseline,
        scale,
    }
}

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
