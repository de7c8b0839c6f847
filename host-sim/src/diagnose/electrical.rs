//! The electrical parity relation, when the log holds the commanded voltages: the d-q
//! voltages the controller must have commanded, from the logged currents and speed with the
//! stator equations (eq. 1–2) and the inverter's dead-time error (Section 4.1 (2)):
//!
//! ```text
//!   u_d = R_s·i_d + L_d·di_d/dt − ω_e·L_q·i_q + ΔU_d,   u_q = R_s·i_q + L_q·di_q/dt + ω_e·(L_d·i_d + ψ_f) + ΔU_q
//! ```
//!
//! with ΔU the plant's [`Inverter`] loss at the logged currents and angle (each leg loses
//! t_d·f_pwm·U_dc against its current's sign, faded within the rig's current band), which the
//! controller, regulating the currents, adds to its command. A dead time the model lacks
//! shows as a voltage along the current with a sixth-harmonic ripple. The relation is
//! algebraic: one pass over the log per evaluation; the derivatives are central
//! differences of the logged currents over ±[`CURRENT_RATE_HALF_WIDTH_S`].

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::back_emf::Stator;
use crate::diagnose::calibration::{Relation, Release};
use crate::diagnose::facts::{rows_spanning, LogFacts};
use crate::diagnose::least_squares::{huber, ParamSpec};
use plant_model::inverter::{dq_to_abc, pole_to_dq, Inverter};
use plant_model::rig::InverterParams;
use plant_model::Rig;
use std::ops::Range;
use std::sync::OnceLock;

/// Time on each side of the currents' central differences (one row of a 1 kHz log): a
/// faster log's current noise is not differentiated over a shorter interval. [s]
pub const CURRENT_RATE_HALF_WIDTH_S: f64 = 1e-3;

/// Upper end of the dead time's tolerance band: the rig file says 0, a residual error
/// below this is a compensated inverter's. [s]
pub const DEAD_TIME_BAND_S: f64 = 0.1e-6;

/// Index of each electrical parameter in the search vector.
pub mod ix {
    /// Stator resistance.
    pub const R: usize = 0;
    /// d inductance.
    pub const LD: usize = 1;
    /// q inductance.
    pub const LQ: usize = 2;
    /// Magnet flux linkage.
    pub const PSI: usize = 3;
    /// Dead time.
    pub const DEAD_TIME: usize = 4;
}

/// The stator constants of the electrical relation's search `values`.
pub fn stator(values: &[f64]) -> Stator {
    Stator {
        r_s_ohm: values[ix::R],
        l_d_h: values[ix::LD],
        l_q_h: values[ix::LQ],
        psi_f_wb: values[ix::PSI],
    }
}

/// The electrical relation of a log with `ud_v`, `uq_v` and the shaft angle.
pub struct ElectricalRelation<'a> {
    /// The log.
    pub log: &'a BenchLog,
    /// Its facts.
    pub facts: &'a LogFacts,
    /// The rig file.
    pub rig: &'a Rig,
    /// Mean DC link (logged, else the rig's). [V]
    pub u_dc_v: f64,
    /// (sin, cos) of the electrical angle p_n·θ at every row, made at the first prediction
    /// that needs it (the dead-time loss) and shared by every later one.
    angle: OnceLock<Vec<(f64, f64)>>,
}

impl<'a> ElectricalRelation<'a> {
    /// The relation, if the log has the voltages and the angle.
    pub fn of(
        log: &'a BenchLog,
        facts: &'a LogFacts,
        rig: &'a Rig,
    ) -> Option<ElectricalRelation<'a>> {
        if log.ud_v.is_none() || log.uq_v.is_none() || !facts.angle.is_logged() {
            return None;
        }
        let u_dc_v = log.udc_v.as_deref().map_or(rig.inverter.u_dc_v, |u| {
            u.iter().sum::<f64>() / u.len().max(1) as f64
        });
        Some(ElectricalRelation {
            log,
            facts,
            rig,
            u_dc_v,
            angle: OnceLock::new(),
        })
    }

    /// The predicted (u_d, u_q) over `rows` at parameter `values`, into `ud`, `uq`. [V]
    pub fn predict(&self, v: &[f64], rows: Range<usize>, ud: &mut [f64], uq: &mut [f64]) {
        let log = self.log;
        let t = &log.t_s;
        let n = log.len();
        let pp = self.rig.motor.pole_pairs as f64;
        let inverter = Inverter::new(&InverterParams {
            u_dc_v: self.u_dc_v,
            dead_time_s: v[ix::DEAD_TIME],
            ..self.rig.inverter.clone()
        });
        let h = rows_spanning(CURRENT_RATE_HALF_WIDTH_S, self.facts.period_s, 1);
        let deriv = |y: &[f64], k: usize| {
            let (a, b) = (k.saturating_sub(h), (k + h).min(n - 1));
            if b > a {
                (y[b] - y[a]) / (t[b] - t[a])
            } else {
                0.0
            }
        };
        let angle: &[(f64, f64)] = if inverter.has_dead_time() {
            self.angle.get_or_init(|| {
                let theta = &self.facts.theta_rad;
                theta.iter().map(|th| (pp * th).sin_cos()).collect()
            })
        } else {
            &[]
        };
        let base = rows.start;
        for k in rows {
            let (i_d, i_q) = (log.id_a[k], log.iq_a[k]);
            let w_e = pp * log.speed_rad_s[k];
            let mut u_d = v[ix::R] * i_d + v[ix::LD] * deriv(&log.id_a, k) - w_e * v[ix::LQ] * i_q;
            let mut u_q = v[ix::R] * i_q
                + v[ix::LQ] * deriv(&log.iq_a, k)
                + w_e * (v[ix::LD] * i_d + v[ix::PSI]);
            if inverter.has_dead_time() {
                let (s, c) = angle[k];
                let i_abc = dq_to_abc(i_d, i_q, s, c);
                let (loss_d, loss_q) = pole_to_dq(&inverter.pole_voltages(&[0.0; 3], &i_abc), s, c);
                u_d -= loss_d;
                u_q -= loss_q;
            }
            ud[k - base] = u_d;
            uq[k - base] = u_q;
        }
    }
}

impl Relation for ElectricalRelation<'_> {
    fn facts(&self) -> &LogFacts {
        self.facts
    }
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        let m = &self.rig.motor;
        let mut dead = ParamSpec::linear("dead_time_s", 0.0, 1e-7, 0.0, 10e-6);
        dead = if release == Release::DeadTime {
            dead.starting_at(1e-6)
        } else {
            dead.with_band(0.0, DEAD_TIME_BAND_S)
        };
        vec![
            // Copper's resistance moves 0.4 %/K: ±20 % covers a winding from cold to hot.
            ParamSpec::log("r_s_ohm", m.r_s_ohm, 0.3, 3.0)
                .with_band(0.8 * m.r_s_ohm, 1.2 * m.r_s_ohm),
            ParamSpec::log("l_d_h", m.l_d_h, 0.3, 3.0).with_band(0.9 * m.l_d_h, 1.1 * m.l_d_h),
            ParamSpec::log("l_q_h", m.l_q_h, 0.3, 3.0).with_band(0.9 * m.l_q_h, 1.1 * m.l_q_h),
            ParamSpec::log("psi_f_wb", m.psi_f_wb, 0.5, 2.0)
                .with_band(0.95 * m.psi_f_wb, 1.05 * m.psi_f_wb),
            dead,
        ]
    }

    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        (release == Release::DeadTime).then(|| (ix::DEAD_TIME, vec![0.05e-6, 0.3e-6, 1e-6, 3e-6]))
    }

    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        let (Some(ud_log), Some(uq_log)) = (self.log.ud_v.as_deref(), self.log.uq_v.as_deref())
        else {
            return Vec::new();
        };
        let sd = self.facts.noise(Signal::Ud).unwrap_or(1.0).max(1e-3);
        let sq = self.facts.noise(Signal::Uq).unwrap_or(1.0).max(1e-3);
        let mut out = Vec::new();
        for r in rows {
            let (mut ud, mut uq) = (vec![0.0; r.len()], vec![0.0; r.len()]);
            self.predict(values, r.clone(), &mut ud, &mut uq);
            for (i, k) in r.clone().enumerate() {
                out.push(huber((ud_log[k] - ud[i]) / sd));
                out.push(huber((uq_log[k] - uq[i]) / sq));
            }
        }
        out
    }
}
