//! The mechanical parity relation as the calibration fits it: the shaft's torque balance
//! (eq. 12–19 through [`super::mechanical`]) with its search space and tolerance bands, the
//! angle-locked line basis it carries along, and its residuals over the windows.

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::calibration::{Relation, Release};
use crate::diagnose::facts::LogFacts;
use crate::diagnose::least_squares::{huber, ParamSpec};
use crate::diagnose::mechanical::{MechanicalParams, Mechanics, ShaftMotion};
use nalgebra::{DMatrix, DVector};
use plant_model::Rig;
use std::ops::Range;

/// Upper end of a healthy shaft's Coulomb friction (bearings and seals). [N·m]
pub const SHAFT_COULOMB_BAND_NM: f64 = 0.02;

/// Length of a speed shooting window. [s]
pub const SPEED_WINDOW_S: f64 = 0.05;

/// Points of the shaft friction's grid fitted besides its best one: the released fit has a
/// second, shallower basin near half the Coulomb torque that the grid, scoring each point
/// with the other parameters held, may judge the deeper one.
const SHAFT_FRICTION_BASINS: usize = 2;

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

    /// Lets go of the line bases the fits kept (a basis is some tens of bytes a row):
    /// once the effects are selected, nothing reads them again.
    pub fn forget_bases(&self) {
        if let Ok(mut m) = self.bases.lock() {
            *m = Default::default();
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
    fn facts(&self) -> &LogFacts {
        self.facts
    }
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        mechanical_specs(self.rig, release)
    }

    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        (release == Release::ShaftFriction).then(|| (mech::COULOMB, vec![0.02, 0.1, 0.3, 0.8]))
    }

    fn grid_basins(&self, release: Release) -> usize {
        if release == Release::ShaftFriction {
            SHAFT_FRICTION_BASINS
        } else {
            0
        }
    }

    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        let sigma = self.facts.noise(Signal::Iq).unwrap_or(1.0).max(1e-6)
            / ((2 * MECHANICAL_SMOOTHING_ROWS + 1) as f64).sqrt();
        let model = Mechanics::new(mechanical_params(self.rig, values));
        let mut out = Vec::new();
        for r in rows {
            let mut pred = vec![0.0; r.len()];
            model.needed_current(self.log, self.facts, self.motion, r.clone(), &mut pred);
            let mut e: Vec<f64> = r
                .clone()
                .zip(&pred)
                .map(|(k, p)| self.log.iq_a[k] - p)
                .collect();
            let basis = self.basis(r);
            mechanical_window_residuals(&mut e, basis.as_ref(), sigma, &mut out);
        }
        out
    }
}
