//! The cylinder's parity relation, when the piston moves: the force balance on the piston
//! and payload (eq. 12) read from the logged position and pressures,
//!
//! ```text
//!   A·(p − p_low) = m·ẍ + B·ẋ + F_c·sgn(ẋ) + k·x + m·g·sin α − F_stop(x, ẋ)
//! ```
//!
//! solved for the port pressure (the plant's [`Cylinder::drive_force`] gives everything but
//! the inertia and the friction). Cylinder friction beyond the rig file shows as a pressure
//! step with the direction of motion. Velocity and acceleration are central differences
//! of the logged position over ±[`RATE_HALF_WIDTH`] rows.

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::calibration::{Relation, Release};
use crate::diagnose::facts::LogFacts;
use crate::diagnose::least_squares::{huber, ParamSpec};
use crate::diagnose::mechanical::central_rate;
use plant_model::cylinder::Cylinder;
use plant_model::Rig;
use std::ops::Range;

/// Rows on each side of the central differences of the position.
pub const RATE_HALF_WIDTH: usize = 5;

/// Piston speed over which the Coulomb force's sign fades in. [m/s]
pub const COULOMB_FADE_M_S: f64 = 1e-4;

/// Index of each parameter in the search vector.
pub mod ix {
    /// Payload mass.
    pub const MASS: usize = 0;
    /// Viscous damping.
    pub const VISCOUS: usize = 1;
    /// Coulomb friction.
    pub const COULOMB: usize = 2;
    /// Low-side pressure, when it is not logged.
    pub const LOW_SIDE: usize = 3;
}

/// Tolerance band of the low side's (fill) pressure when the log does not have it: the
/// rig contract's 0.5 MPa is assumed, boost circuits are set anywhere in this range.
/// Along a one-way stroke it and the Coulomb force are the same constant pressure step:
/// there the friction is named only beyond what this band explains. [Pa]
pub const LOW_SIDE_BAND_PA: (f64, f64) = (0.2e6, 1.0e6);

/// Upper end of the cylinder Coulomb friction's tolerance band, as a multiple of the rig
/// file's (seals wear in and out). [1]
pub const COULOMB_BAND: f64 = 3.0;

/// The cylinder relation of a log whose piston moves.
pub struct CylinderRelation<'a> {
    log: &'a BenchLog,
    facts: &'a LogFacts,
    rig: &'a Rig,
    x: &'a [f64],
    v: Vec<f64>,
    a: Vec<f64>,
}

impl<'a> CylinderRelation<'a> {
    /// The relation, if the log shows the piston moving.
    pub fn of(
        log: &'a BenchLog,
        facts: &'a LogFacts,
        rig: &'a Rig,
    ) -> Option<CylinderRelation<'a>> {
        let x = log.x_m.as_deref().filter(|_| facts.piston_moves)?;
        let v = central_rate(&log.t_s, x, RATE_HALF_WIDTH);
        let a = central_rate(&log.t_s, &v, RATE_HALF_WIDTH);
        Some(CylinderRelation {
            log,
            facts,
            rig,
            x,
            v,
            a,
        })
    }

    /// The port pressure the balance predicts over `rows` at `values`, into `out`. [Pa]
    pub fn predict(&self, values: &[f64], rows: Range<usize>, out: &mut [f64]) {
        let mut c = self.rig.cylinder.clone();
        c.viscous_n_s_per_m = values[ix::VISCOUS];
        c.mass_kg = values[ix::MASS];
        let cyl = Cylinder::new(&c);
        let area = c.area_m2;
        let low_side = values.get(ix::LOW_SIDE).copied();
        for k in rows {
            let p_low = low_side.unwrap_or(self.facts.p_low_pa[k]);
            // drive_force(p, p_low) = A·(p − p_low) − rest; solve m·a + F_c·sgn(v) = it.
            let rest = -cyl.drive_force(0.0, 0.0, self.x[k], self.v[k], 0.0);
            let friction = values[ix::COULOMB] * (self.v[k] / COULOMB_FADE_M_S).tanh();
            out[k] = p_low + (c.mass_kg * self.a[k] + friction + rest) / area;
        }
    }
}

impl Relation for CylinderRelation<'_> {
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        let c = &self.rig.cylinder;
        let nominal = c.coulomb_friction_n;
        let mut coulomb = ParamSpec::linear("coulomb_n", nominal, 10.0, 0.0, 20e3);
        coulomb = if release == Release::CylinderFriction {
            coulomb.starting_at(nominal + 300.0)
        } else {
            coulomb.with_band(0.0, COULOMB_BAND * nominal.max(10.0))
        };
        let mut specs = vec![
            ParamSpec::log("mass_kg", c.mass_kg, 0.3, 3.0)
                .with_band(0.9 * c.mass_kg, 1.1 * c.mass_kg),
            ParamSpec::log(
                "viscous_n_s_per_m",
                c.viscous_n_s_per_m.max(1.0),
                0.01,
                100.0,
            )
            .with_band(0.5 * c.viscous_n_s_per_m, 2.0 * c.viscous_n_s_per_m),
            coulomb,
        ];
        if self.log.p_low_pa.is_none() {
            let (lo, hi) = LOW_SIDE_BAND_PA;
            let fill = self.rig.fill.pressure_pa.clamp(lo, hi);
            specs.push(ParamSpec::linear("low_side_pa", fill, 1e4, 0.0, 5e6).with_band(lo, hi));
        }
        specs
    }

    fn released(&self, release: Release) -> Option<(usize, Vec<f64>)> {
        let nominal = self.rig.cylinder.coulomb_friction_n;
        (release == Release::CylinderFriction).then(|| {
            (
                ix::COULOMB,
                [0.0, 100.0, 400.0, 1500.0, 5000.0]
                    .iter()
                    .map(|f| nominal + f)
                    .collect(),
            )
        })
    }

    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        let sigma = self.facts.noise(Signal::Pressure).unwrap_or(1.0).max(1.0);
        let mut pred = vec![0.0; self.log.len()];
        let mut out = Vec::new();
        for r in rows {
            self.predict(values, r.clone(), &mut pred);
            out.extend(
                r.clone()
                    .map(|k| huber((self.log.p_pa[k] - pred[k]) / sigma)),
            );
        }
        out
    }
}
