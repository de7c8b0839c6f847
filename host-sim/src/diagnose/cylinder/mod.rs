//! The cylinder's parity relation, when the piston moves: the force balance on the piston
//! and payload (eq. 12) read from the logged position and pressures, with the friction of
//! Karnopp's model (`plant_model::friction`, as the plant has it),
//!
//! ```text
//!   A·(p − o − p_low) = m·ẍ + B·ẋ + F_f + k·x + m·g·sin α − F_stop(x, ẋ)
//!   sliding:  F_f = F_c·sgn(ẋ)
//!   resting:  F_f = whatever holds the piston, |F_f| ≤ F_s      (ẋ = ẍ = 0)
//! ```
//!
//! solved for the logged port pressure p (the plant's [`Cylinder::drive_force`] gives
//! everything but the inertia and the friction), o the port transducer's zero. Velocity
//! and acceleration of a sliding row are central differences of the logged position over
//! ±[`RATE_HALF_WIDTH_S`]; the rows where the piston rests and its breakaways are read
//! from the position by [`Stick`] (a backward-looking band at the transducer's resolution,
//! so the last resting row before a breakaway keeps its full force).
//!
//! - A sliding row predicts p from the Coulomb force: cylinder friction beyond the rig
//!   file shows as a pressure step with the direction of motion.
//! - A resting row predicts nothing but a range: the friction takes up the drive up to the
//!   breakaway level, so the prediction is the measured pressure clamped to
//!   `p_0 ± F_s/A` (`p_0` the friction-free balance at rest) and the residual is only the
//!   excess beyond the breakaway level: a piston held at rest by more than the model's
//!   F_s. Piecewise linear in F_s, continuous, and flat once F_s exceeds every held force.
//! - A breakaway bounds F_s from above: the piston rests at row k and is seen moving at
//!   k+1, so the drive crossed F_s in between. With the drive ramping over the interval
//!   and the crossing anywhere in it, the breakaway level is the mean of the two rows'
//!   drives with the uniform distribution's spread (width/√12, and the two rows' pressure
//!   noise): one more residual per breakaway. Without it the resting rows would leave
//!   every F_s above the largest held force equally good.
//!
//! The transducer's zero o is a tolerance like the calibration's (the rig file's ±
//! [`SENSOR_OFFSET_BAND_PA`], the band the hydraulic relation has): it shifts every row's
//! balance, sliding rows and the resting rows' friction-free level p_0 alike, so a
//! breakaway is read against it too. Without the low side logged it is one constant
//! pressure shift with the unknown low side, and the one parameter [`ix::LOW_SIDE`] holds
//! both. Along a one-way stroke the Coulomb force is the same constant pressure step as
//! the zero (A·30 kPa ≈ 210 N on a 71 cm² piston): cylinder friction is then named only
//! when it explains more than any zero within the band can, and its levels are read at the
//! rig file's zero ([`crate::diagnose::calibration::test_release_at_nominal`]; the
//! report says so and by how much the zero's band could move them). Only a reversal, where
//! the Coulomb step changes sign and the zero does not, separates the two
//! ([`CylinderRelation::strokes_both_ways`]); there the free fit is reported unless the
//! rig file's zero fits as well. The hydraulic relation's fitted zero is no help: the
//! pressure's volume balance depends on the zero only through the leakage and the
//! absorber's gas law, which leave it to its band's edges on a free payload's logs.
//!
//! The breakaway F_s is a parameter of its own beside the Coulomb force F_c, and the
//! model uses max(F_s, F_c) as the plant does (it raises a breakaway below the Coulomb level
//! to it): the resting rows and the breakaways fix F_s, the sliding rows F_c, each without
//! dragging the other (searched as an excess over F_c, the breakaway was pushed to its
//! floor whenever the search passed through too high a Coulomb force, and the bounds'
//! sine transform held it there). It is searched in logarithm, its tolerance band in the calibrated
//! baseline up to [`BREAKAWAY_BAND`] times the rig file's static level.
//! `cylinder_friction` releases it with the Coulomb force ([`super::candidates`]) when the
//! piston rests somewhere in the identification segment
//! ([`CylinderRelation::sees_rest`]), starting from the level the log shows
//! ([`CylinderRelation::breakaway_seen`]): a log that never shows the piston resting says
//! nothing of the breakaway, which then stays in its band. Rests without a breakaway bound
//! it from below only: the breakaway found is the largest force the piston was seen to
//! hold.

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::calibration::{Relation, Release};
use crate::diagnose::facts::{rows_spanning, LogFacts, MOVING_PISTON_TRAVEL_M};
use crate::diagnose::hydraulic_relation::SENSOR_OFFSET_BAND_PA;
use crate::diagnose::least_squares::{huber, ParamSpec};
use crate::diagnose::mechanical::central_rate;
use crate::diagnose::stick::Stick;
use plant_model::cylinder::Cylinder;
use plant_model::Rig;
use std::ops::Range;

/// Time on each side of the central differences of the position (five rows of a 1 kHz
/// log). [s]
pub const RATE_HALF_WIDTH_S: f64 = 5e-3;

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
    /// Breakaway (static) friction (the Coulomb friction where below it).
    pub const BREAKAWAY: usize = 3;
    /// The port pressure transducer's zero (offset), when the low side is logged.
    pub const ZERO: usize = 4;
    /// The low side's pressure as the port transducer reads it (its zero included), when
    /// the low side is not logged: the zero and the low side are then one constant
    /// pressure shift, and one parameter.
    pub const LOW_SIDE: usize = 4;
}

/// Tolerance band of the low side's (fill) pressure when the log does not have it: the
/// rig contract's 0.5 MPa is assumed, boost circuits are set anywhere in this range.
/// Along a one-way stroke it and the Coulomb force are the same constant pressure step:
/// there the friction is named only beyond what this band explains. [Pa]
pub const LOW_SIDE_BAND_PA: (f64, f64) = (0.2e6, 1.0e6);

/// Upper end of the cylinder Coulomb friction's tolerance band, as a multiple of the rig
/// file's (seals wear in and out). [1]
pub const COULOMB_BAND: f64 = 3.0;

/// Upper end of the breakaway force's tolerance band, as a multiple of the rig file's
/// static level (seals wear in and out). [1]
pub const BREAKAWAY_BAND: f64 = 3.0;

/// The breakaway force the band and the search scale from when the rig file's is smaller
/// (a rig file may switch the cylinder's friction off). [N]
pub const BREAKAWAY_REFERENCE_FLOOR_N: f64 = 10.0;

/// The cylinder relation of a log whose piston moves.
pub struct CylinderRelation<'a> {
    log: &'a BenchLog,
    facts: &'a LogFacts,
    rig: &'a Rig,
    x: &'a [f64],
    v: Vec<f64>,
    a: Vec<f64>,
    stick: Stick,
}

impl<'a> CylinderRelation<'a> {
    /// The relation, if the log shows the piston moving.
    pub fn of(
        log: &'a BenchLog,
        facts: &'a LogFacts,
        rig: &'a Rig,
    ) -> Option<CylinderRelation<'a>> {
        let x = log.x_m.as_deref().filter(|_| facts.piston_moves)?;
        let h = rows_spanning(RATE_HALF_WIDTH_S, facts.period_s, 1);
        let v = central_rate(&log.t_s, x, h);
        let a = central_rate(&log.t_s, &v, h);
        Some(CylinderRelation {
            log,
            facts,
            rig,
            x,
            v,
            a,
            stick: Stick::of(x, 2 * h, facts.period_s),
        })
    }

    /// Where the piston rests and breaks away.
    pub fn stick(&self) -> &Stick {
        &self.stick
    }

    /// Whether the piston rests somewhere in the identification segment: only then does
    /// the log say anything of the breakaway level (from below by the forces held, from
    /// above by a breakaway), and only then is it released with the Coulomb force.
    pub fn sees_rest(&self) -> bool {
        self.stick.rests[self.facts.identification()]
            .iter()
            .any(|r| *r)
    }

    /// Whether the piston travels both ways in the identification segment, by more than
    /// [`MOVING_PISTON_TRAVEL_M`] each: only a reversal, where the Coulomb force's
    /// pressure step changes sign and the transducer's zero does not, tells them apart.
    /// Along a one-way stroke they differ only where the piston starts and stops, in the
    /// Coulomb force's fade and the stick phase, which the model approximates.
    pub fn strokes_both_ways(&self) -> bool {
        let x = &self.x[self.facts.identification()];
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut rise, mut fall) = (0.0f64, 0.0f64);
        for &v in x {
            lo = lo.min(v);
            hi = hi.max(v);
            rise = rise.max(v - lo);
            fall = fall.max(hi - v);
        }
        rise > MOVING_PISTON_TRAVEL_M && fall > MOVING_PISTON_TRAVEL_M
    }

    /// What reading the friction at the rig file's transducer zero means, in words: the
    /// log did not tell the zero from the friction, so each level carries the zero's
    /// tolerance on the piston.
    pub fn zero_caveat(&self) -> String {
        let (what, half_band) = match self.log.p_low_pa {
            Some(_) => ("transducer zero", SENSOR_OFFSET_BAND_PA),
            None => {
                let (lo, hi) = LOW_SIDE_BAND_PA;
                (
                    "low-side pressure (not logged) with the transducer zero",
                    0.5 * (hi - lo) + SENSOR_OFFSET_BAND_PA,
                )
            }
        };
        format!(
            "; read at the rig file's {what}, which this log does not tell from the friction \
             (the piston does not stroke both ways, or the fit is no worse there): its \
             tolerance, ±{:.0} kPa, is ±{:.0} N on the piston",
            half_band / 1e3,
            half_band * self.rig.cylinder.area_m2
        )
    }

    /// The breakaway level the identification segment shows at the rig file's values: the
    /// mean of its breakaways' levels, else the largest force held at rest; `None` when the
    /// piston never rests there. [N]
    pub fn breakaway_seen(&self) -> Option<f64> {
        if !self.sees_rest() {
            return None;
        }
        let cyl = Cylinder::new(&self.rig.cylinder);
        let shift = self.nominal_shift();
        let ident = self.facts.identification();
        let levels: Vec<f64> = self
            .stick
            .breakaways
            .iter()
            .filter(|b| ident.contains(&b.row) && ident.contains(&(b.row + 1)))
            .map(|b| {
                let held = |k| self.held_force(&cyl, shift, k);
                b.dir * 0.5 * (held(b.row) + held(b.row + 1))
            })
            .collect();
        if !levels.is_empty() {
            return Some(levels.iter().sum::<f64>() / levels.len() as f64);
        }
        ident
            .filter(|k| self.stick.rests[*k])
            .map(|k| self.held_force(&cyl, shift, k).abs())
            .max_by(f64::total_cmp)
    }

    /// The rig file's transducer zero. [Pa]
    fn nominal_zero(&self) -> f64 {
        self.rig.sensors.pressure.offset_pa
    }

    /// The constant pressure shift the search starts from: the rig file's transducer zero
    /// ([`ix::ZERO`]), or, the low side not logged, the rig file's fill pressure as the
    /// port transducer reads it ([`ix::LOW_SIDE`]). [Pa]
    fn nominal_shift(&self) -> f64 {
        if self.log.p_low_pa.is_some() {
            return self.nominal_zero();
        }
        let (lo, hi) = LOW_SIDE_BAND_PA;
        self.rig.fill.pressure_pa.clamp(lo, hi) + self.nominal_zero()
    }

    /// The low side's pressure at row `k` as the port transducer reads it, with the
    /// relation's pressure shift `shift` (the value of [`ix::ZERO`] or [`ix::LOW_SIDE`]):
    /// the logged low side plus the port transducer's zero, or the shift itself. [Pa]
    fn low_side(&self, shift: f64, k: usize) -> f64 {
        match &self.log.p_low_pa {
            Some(p) => p[k] + shift,
            None => shift,
        }
    }

    /// The cylinder at `values` and its pressure shift ([`CylinderRelation::low_side`]).
    fn cylinder_at(&self, values: &[f64]) -> (Cylinder, f64) {
        let mut c = self.rig.cylinder.clone();
        c.viscous_n_s_per_m = values[ix::VISCOUS];
        c.mass_kg = values[ix::MASS];
        (Cylinder::new(&c), values[ix::ZERO])
    }

    /// The net force on the piston at rest but friction at row `k` with the pressure shift
    /// `shift`: what the friction holds while it rests. [N]
    fn held_force(&self, cyl: &Cylinder, shift: f64, k: usize) -> f64 {
        let p_low = self.low_side(shift, k);
        cyl.drive_force(self.log.p_pa[k], p_low, self.x[k], 0.0, 0.0)
    }

    /// The port pressure the balance predicts over `rows` at `values`, into `out`: at a
    /// resting row the measured one within the breakaway level's reach. [Pa]
    pub fn predict(&self, values: &[f64], rows: Range<usize>, out: &mut [f64]) {
        let (cyl, shift) = self.cylinder_at(values);
        let area = cyl.area_m2;
        let coulomb = values[ix::COULOMB];
        let breakaway = breakaway_level(values);
        for k in rows {
            let p_low = self.low_side(shift, k);
            let p = self.log.p_pa[k];
            if self.stick.rests[k] {
                // held = A·(p − p_low) − rest: the friction takes it up to ±F_s.
                let held = self.held_force(&cyl, shift, k);
                out[k] = p - (held - held.clamp(-breakaway, breakaway)) / area;
                continue;
            }
            // drive_force(p, p_low) = A·(p − p_low) − rest; solve m·a + F_c·sgn(v) = it.
            let rest = -cyl.drive_force(0.0, 0.0, self.x[k], self.v[k], 0.0);
            let friction = coulomb * (self.v[k] / COULOMB_FADE_M_S).tanh();
            out[k] = p_low + (cyl.mass_kg * self.a[k] + friction + rest) / area;
        }
    }

    /// Each breakaway within `rows` (its last resting row and the next in one range): the
    /// breakaway level it shows minus the model's, over its spread (`sigma`: the pressure
    /// noise). [1]
    pub fn breakaway_residuals(
        &self,
        values: &[f64],
        rows: &[Range<usize>],
        sigma: f64,
    ) -> Vec<f64> {
        let (cyl, shift) = self.cylinder_at(values);
        let breakaway = breakaway_level(values);
        let noise_n = cyl.area_m2 * sigma;
        self.stick
            .breakaways
            .iter()
            .filter(|b| {
                rows.iter()
                    .any(|r| r.contains(&b.row) && r.contains(&(b.row + 1)))
            })
            .map(|b| {
                let before = b.dir * self.held_force(&cyl, shift, b.row);
                let after = b.dir * self.held_force(&cyl, shift, b.row + 1);
                let spread = ((after - before).powi(2) / 12.0 + 0.5 * noise_n * noise_n).sqrt();
                (0.5 * (before + after) - breakaway) / spread.max(f64::MIN_POSITIVE)
            })
            .collect()
    }
}

/// The breakaway force at search `values`: F_s, or F_c where F_s is below it (never
/// negative, so the clamp's range is never empty). [N]
pub fn breakaway_level(values: &[f64]) -> f64 {
    values[ix::BREAKAWAY].max(values[ix::COULOMB]).max(0.0)
}

impl Relation for CylinderRelation<'_> {
    fn facts(&self) -> &LogFacts {
        self.facts
    }
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        let c = &self.rig.cylinder;
        let nominal = c.coulomb_friction_n;
        let mut coulomb = ParamSpec::linear("coulomb_n", nominal, 10.0, 0.0, 20e3);
        coulomb = if release == Release::CylinderFriction {
            coulomb.starting_at(nominal + 300.0)
        } else {
            coulomb.with_band(0.0, COULOMB_BAND * nominal.max(10.0))
        };
        let reference = c
            .static_friction_n
            .max(c.coulomb_friction_n)
            .max(BREAKAWAY_REFERENCE_FLOOR_N);
        let mut breakaway = ParamSpec::log("breakaway_n", reference, 1e-2, 2e3);
        breakaway = match self.breakaway_seen() {
            Some(seen) if release == Release::CylinderFriction => breakaway.starting_at(seen),
            _ => breakaway.with_band(1e-2 * reference, BREAKAWAY_BAND * reference),
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
            breakaway,
        ];
        // The transducer's zero shifts the whole balance, sliding and resting rows alike;
        // without the low side logged it is part of the low side's band.
        let (zero, z) = (self.nominal_zero(), SENSOR_OFFSET_BAND_PA);
        let shift = self.nominal_shift();
        specs.push(match self.log.p_low_pa {
            Some(_) => ParamSpec::linear("sensor_offset_pa", shift, 1e4, -1e6, 1e6)
                .with_band(zero - z, zero + z),
            None => {
                let (lo, hi) = LOW_SIDE_BAND_PA;
                ParamSpec::linear("low_side_pa", shift, 1e4, -1e6, 6e6)
                    .with_band(lo + zero - z, hi + zero + z)
            }
        });
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
        out.extend(
            self.breakaway_residuals(values, rows, sigma)
                .into_iter()
                .map(huber),
        );
        out
    }
}

#[cfg(test)]
mod tests;
