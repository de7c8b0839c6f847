//! The cylinder's parity relation, when the piston moves: the force balance on the piston
//! and payload (eq. 12) read from the logged position and pressures, with the friction of
//! Karnopp's model (`plant_model::friction`, as the plant has it),
//!
//! ```text
//!   A·(p − p_low) = m·ẍ + B·ẋ + F_f + k·x + m·g·sin α − F_stop(x, ẋ)
//!   sliding:  F_f = F_c·sgn(ẋ)
//!   resting:  F_f = whatever holds the piston, |F_f| ≤ F_s      (ẋ = ẍ = 0)
//! ```
//!
//! solved for the port pressure (the plant's [`Cylinder::drive_force`] gives everything but
//! the inertia and the friction). Velocity and acceleration of a sliding row are central
//! differences of the logged position over ±[`RATE_HALF_WIDTH`] rows; the rows where the
//! piston rests and its breakaways are read from the position by [`Stick`] (a
//! backward-looking band at the transducer's resolution, so the last resting row before a
//! breakaway keeps its full force).
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
use crate::diagnose::facts::LogFacts;
use crate::diagnose::least_squares::{huber, ParamSpec};
use crate::diagnose::mechanical::central_rate;
use crate::diagnose::stick::Stick;
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
    /// Breakaway (static) friction (the Coulomb friction where below it).
    pub const BREAKAWAY: usize = 3;
    /// Low-side pressure, when it is not logged.
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
        let v = central_rate(&log.t_s, x, RATE_HALF_WIDTH);
        let a = central_rate(&log.t_s, &v, RATE_HALF_WIDTH);
        Some(CylinderRelation {
            log,
            facts,
            rig,
            x,
            v,
            a,
            stick: Stick::of(x),
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

    /// The breakaway level the identification segment shows at the rig file's values: the
    /// mean of its breakaways' levels, else the largest force held at rest; `None` when the
    /// piston never rests there. [N]
    pub fn breakaway_seen(&self) -> Option<f64> {
        if !self.sees_rest() {
            return None;
        }
        let cyl = Cylinder::new(&self.rig.cylinder);
        let low_side = self.log.p_low_pa.is_none().then(|| self.nominal_low_side());
        let ident = self.facts.identification();
        let levels: Vec<f64> = self
            .stick
            .breakaways
            .iter()
            .filter(|b| ident.contains(&b.row) && ident.contains(&(b.row + 1)))
            .map(|b| {
                let held = |k| self.held_force(&cyl, low_side, k);
                b.dir * 0.5 * (held(b.row) + held(b.row + 1))
            })
            .collect();
        if !levels.is_empty() {
            return Some(levels.iter().sum::<f64>() / levels.len() as f64);
        }
        ident
            .filter(|k| self.stick.rests[*k])
            .map(|k| self.held_force(&cyl, low_side, k).abs())
            .max_by(f64::total_cmp)
    }

    /// The low side's pressure the search starts from when the log does not have it. [Pa]
    fn nominal_low_side(&self) -> f64 {
        let (lo, hi) = LOW_SIDE_BAND_PA;
        self.rig.fill.pressure_pa.clamp(lo, hi)
    }

    /// The cylinder at `values` and its low-side pressure (`None`: logged).
    fn cylinder_at(&self, values: &[f64]) -> (Cylinder, Option<f64>) {
        let mut c = self.rig.cylinder.clone();
        c.viscous_n_s_per_m = values[ix::VISCOUS];
        c.mass_kg = values[ix::MASS];
        (Cylinder::new(&c), values.get(ix::LOW_SIDE).copied())
    }

    /// The net force on the piston at rest but friction at row `k`: what the friction
    /// holds while it rests. [N]
    fn held_force(&self, cyl: &Cylinder, low_side: Option<f64>, k: usize) -> f64 {
        let p_low = low_side.unwrap_or(self.facts.p_low_pa[k]);
        cyl.drive_force(self.log.p_pa[k], p_low, self.x[k], 0.0, 0.0)
    }

    /// The port pressure the balance predicts over `rows` at `values`, into `out`: at a
    /// resting row the measured one within the breakaway level's reach. [Pa]
    pub fn predict(&self, values: &[f64], rows: Range<usize>, out: &mut [f64]) {
        let (cyl, low_side) = self.cylinder_at(values);
        let area = cyl.area_m2;
        let coulomb = values[ix::COULOMB];
        let breakaway = breakaway_level(values);
        for k in rows {
            let p_low = low_side.unwrap_or(self.facts.p_low_pa[k]);
            let p = self.log.p_pa[k];
            if self.stick.rests[k] {
                // held = A·(p − p_low) − rest: the friction takes it up to ±F_s.
                let held = self.held_force(&cyl, low_side, k);
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
        let (cyl, low_side) = self.cylinder_at(values);
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
                let before = b.dir * self.held_force(&cyl, low_side, b.row);
                let after = b.dir * self.held_force(&cyl, low_side, b.row + 1);
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
        if self.log.p_low_pa.is_none() {
            let (lo, hi) = LOW_SIDE_BAND_PA;
            let fill = self.nominal_low_side();
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
        out.extend(
            self.breakaway_residuals(values, rows, sigma)
                .into_iter()
                .map(huber),
        );
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::calibration::{calibrate, fit_relation, test_release};
    use crate::diagnose::test_noise::gaussian;

    /// Rig file's cylinder (nominal: A = 71 cm², m = 2000 kg, B = 150 N·s/m, no spring,
    /// level) with these friction levels in the plant that made the log. [N]
    const COULOMB_N: f64 = 400.0;
    const BREAKAWAY_N: f64 = 650.0;
    const P_LOW_PA: f64 = 0.5e6;
    /// White noise on the logged port pressure, a transducer's. [Pa]
    const NOISE_PA: f64 = 300.0;
    /// How close the fitted breakaway must come (see the test). [N]
    const BREAKAWAY_TOLERANCE_N: f64 = 0.5 + 3.0 * 1.5;

    /// Time constant of the piston's speed after the breakaway. [s]
    const TAU_S: f64 = 0.1;

    /// A hand-built log of Karnopp's model at 1 kHz: the piston rests at 2 mm while the
    /// force on it ramps at 1 N per row from −0.4 N, so it reaches F_s at 650.4 ms
    /// (between rows 650 and 651); from then on the friction drops to F_c and the piston
    /// speeds up as v = v_f·(1 − e^(−s/τ)), s = t − t_b, its acceleration at the breakaway
    /// (F_s − F_c)/m, the force following the balance m·a + B·v + F_c exactly. The pressure
    /// is logged with [`NOISE_PA`] of white noise.
    fn breakaway_log() -> BenchLog {
        let rig = Rig::nominal();
        let c = &rig.cylinder;
        let (area, m, b) = (c.area_m2, c.mass_kg, c.viscous_n_s_per_m);
        let t_b = (BREAKAWAY_N + 0.4) / 1000.0;
        let v_f = (BREAKAWAY_N - COULOMB_N) / m * TAU_S;
        let n = 1000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let (x, force): (Vec<f64>, Vec<f64>) = t
            .iter()
            .map(|&t| {
                if t < t_b {
                    (2e-3, -0.4 + 1000.0 * t)
                } else {
                    let e = (-(t - t_b) / TAU_S).exp();
                    let (v, a) = (v_f * (1.0 - e), v_f / TAU_S * e);
                    let x = 2e-3 + v_f * (t - t_b - TAU_S * (1.0 - e));
                    (x, m * a + b * v + COULOMB_N)
                }
            })
            .unzip();
        BenchLog {
            t_s: t,
            p_ref_pa: vec![P_LOW_PA; n],
            p_pa: force
                .iter()
                .zip(gaussian(n, 17))
                .map(|(f, e)| P_LOW_PA + f / area + NOISE_PA * e)
                .collect(),
            speed_rad_s: vec![0.0; n],
            iq_a: vec![0.0; n],
            id_a: vec![0.0; n],
            x_m: Some(x),
            p_low_pa: Some(vec![P_LOW_PA; n]),
            ..BenchLog::default()
        }
    }

    #[test]
    fn a_resting_piston_holds_up_to_the_breakaway_level_and_the_fit_finds_it() {
        let rig = Rig::nominal();
        let log = breakaway_log();
        let facts = LogFacts::of(&log, &rig);
        let rel = CylinderRelation::of(&log, &facts, &rig).expect("the piston moves");
        assert_eq!(rel.stick().breakaways.len(), 1);
        assert_eq!(rel.stick().breakaways[0].row, 650);
        let area = rig.cylinder.area_m2;

        // At rest the friction takes up the drive up to F_s: with F_s = 300 N a row whose
        // drive is 499.6 N is predicted at the breakaway level's pressure, 300 N/A over
        // p_low; one with 199.6 N at its measured pressure.
        let mut v = vec![2000.0, 150.0, 100.0, 300.0];
        let mut out = vec![0.0; log.len()];
        rel.predict(&v, 200..601, &mut out);
        assert!(
            (out[500] - (P_LOW_PA + 300.0 / area)).abs() < 1e-6,
            "{}",
            out[500]
        );
        assert!((out[200] - log.p_pa[200]).abs() < 1e-6, "{}", out[200]);

        // The calibrated baseline, then both friction levels released: the breakaway comes
        // out within the half row (0.5 N) its crossing is known to and three standard
        // deviations of the two rows' mean pressure noise (A·σ/√2 = 1.5 N), the Coulomb
        // force within the percent the central differences' smearing of the kink allows.
        // The whole log after the start skip, in the calibration's one-second windows.
        let rows = facts.windows(facts.identification().start..log.len(), 1.0);
        let t = test_release(
            &rel,
            &rows,
            Release::CylinderFriction,
            &calibrate(&rel, &rows),
        );
        let f = &t.fitted.values;
        let breakaway = breakaway_level(f);
        assert!(
            (breakaway - BREAKAWAY_N).abs() < BREAKAWAY_TOLERANCE_N,
            "{f:?}"
        );
        assert!(
            (f[ix::COULOMB] - COULOMB_N).abs() < 0.01 * COULOMB_N,
            "{f:?}"
        );

        // Started far above, the fit comes back down: the breakaway bounds F_s from above
        // where the resting rows leave it flat.
        v[ix::COULOMB] = COULOMB_N;
        v[ix::BREAKAWAY] = 3000.0;
        let high = fit_relation(&rel, &rows, Release::CylinderFriction, 1.0, Some(&v));
        let breakaway = breakaway_level(&high.values);
        assert!(
            (breakaway - BREAKAWAY_N).abs() < BREAKAWAY_TOLERANCE_N,
            "{:?}",
            high.values
        );
    }

    #[test]
    fn a_log_that_never_shows_the_piston_resting_keeps_the_breakaway_in_its_band() {
        // The same log from 10 ms after the breakaway: the piston slides throughout, the
        // breakaway level is not in it, and cylinder friction releases the Coulomb force
        // alone.
        let rig = Rig::nominal();
        let log = breakaway_log().tail(661);
        let facts = LogFacts::of(&log, &rig);
        let rel = CylinderRelation::of(&log, &facts, &rig).expect("the piston moves");
        assert!(!rel.sees_rest());
        let specs = rel.specs(Release::CylinderFriction);
        assert!(specs[ix::BREAKAWAY].band.is_some() && specs[ix::COULOMB].band.is_none());
    }
}
