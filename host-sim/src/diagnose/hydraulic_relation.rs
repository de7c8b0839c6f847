//! The hydraulic parity relation as the calibration fits it: its search space (the
//! hydraulic model's parameters with their tolerance bands, eq. 9–11 and 22–26 through
//! [`super::hydraulic`]), the parameters a search vector means, and its residuals over the
//! windows in noise units.

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::calibration::{scaled, Relation, Release};
use crate::diagnose::facts::LogFacts;
use crate::diagnose::hydraulic::{HydraulicInputs, HydraulicParams, Hydraulics, LEAKAGE_BAND};
use crate::diagnose::least_squares::{huber, ParamSpec};
use plant_model::accumulator::GasCharge;
use plant_model::Rig;
use rayon::prelude::*;
use std::ops::Range;

/// Upper end of the transducer lag's tolerance band: a transducer with its snubber and
/// the logger's anti-aliasing filter. [s]
pub const LAG_BAND_S: f64 = 2.5e-3;

/// Half-width of the pressure transducer's zero (offset) tolerance band about the rig
/// file's: a calibrated transducer's zero after mounting and warm-up. Every relation that
/// reads the logged port pressure carries it (the hydraulic and the cylinder relations).
/// [Pa]
pub const SENSOR_OFFSET_BAND_PA: f64 = 30e3;

/// Length of a hydraulic shooting window. [s]
pub const HYDRAULIC_WINDOW_S: f64 = 0.25;

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
    /// The port-to-port share of the leakage.
    pub const PORT_SHARE: usize = 10;
}

/// The hydraulic relation's search space on `rig`, with `release` out of its band; the
/// leakage's port-to-port share free (anywhere from 0 to 1) when `split`, else the rig
/// file's.
pub fn hydraulic_specs(rig: &Rig, release: Release, split: bool) -> Vec<ParamSpec> {
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
            ParamSpec::log("leakage_m3_s_pa", n.leakage_m3_s_pa.max(1e-16), 0.05, 30.0).with_band(
                LEAKAGE_BAND.0 * n.leakage_m3_s_pa,
                LEAKAGE_BAND.1 * n.leakage_m3_s_pa,
            )
        },
        ParamSpec::linear("sensor_gain", 1.0, 0.01, 0.8, 1.2).with_band(0.99, 1.01),
        ParamSpec::linear("sensor_offset_pa", n.sensor_offset_pa, 1e4, -1e6, 1e6).with_band(
            n.sensor_offset_pa - SENSOR_OFFSET_BAND_PA,
            n.sensor_offset_pa + SENSOR_OFFSET_BAND_PA,
        ),
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
        {
            let share =
                ParamSpec::linear("port_to_port_share", n.port_to_port_share, 0.1, 0.0, 1.0);
            if split {
                share.with_band(0.0, 1.0)
            } else {
                share.with_band(n.port_to_port_share, n.port_to_port_share)
            }
        },
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
    p.port_to_port_share = v[hyd::PORT_SHARE];
    p
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
    // The windows start afresh (multiple shooting): each is run on its own, in parallel,
    // into its own stretch of the residuals, in the windows' order.
    let mut out = vec![0.0; windows.iter().map(|w| w.len().saturating_sub(1)).sum()];
    let mut stretches = Vec::with_capacity(windows.len());
    let mut rest = out.as_mut_slice();
    for w in windows {
        let (mine, others) = rest.split_at_mut(w.len().saturating_sub(1));
        stretches.push((w, mine));
        rest = others;
    }
    stretches.into_par_iter().for_each(|(w, stretch)| {
        let mut pred = vec![0.0; w.len()];
        model.predict_window(&inputs, w.clone(), &mut pred);
        for (k, r) in (w.start + 1..w.end).zip(stretch) {
            *r = huber((log.p_pa[k] - pred[k - w.start]) / sigma);
        }
    });
    out
}

/// The hydraulic relation's residuals on a moving piston (read − predicted position over
/// the logged position's noise, [`Hydraulics::predict_position_window`]; the position
/// smoothed ([`LogFacts::x_smooth_m`]), so the residuals' own noise lies below that unit and
/// the relation's likelihood ratios are the conservative side) over `windows`, each
/// window's first row left out; none without the position.
pub fn position_residuals(
    log: &BenchLog,
    facts: &LogFacts,
    rig: &Rig,
    params: HydraulicParams,
    windows: &[Range<usize>],
) -> Vec<f64> {
    let sigma = facts
        .noise(Signal::PistonPosition)
        .filter(|s| *s > 0.0)
        .unwrap_or(1e-6);
    let model = Hydraulics::new(params, rig);
    let inputs = HydraulicInputs::of(log, facts);
    let Some(x_logged) = inputs.x_m else {
        return Vec::new();
    };
    windows
        .par_iter()
        .map(|w| {
            let mut pred = vec![0.0; w.len()];
            model.predict_position_window(&inputs, w.clone(), &mut pred);
            (w.start + 1..w.end)
                .map(|k| huber((x_logged[k] - pred[k - w.start]) / sigma))
                .collect::<Vec<f64>>()
        })
        .flatten()
        .collect()
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

/// Closest ratio of two shooting-window start pressures between which the precharge grid
/// takes a point of its own.
const DISTINCT_START_RATIO: f64 = 1.03;

/// Points of the precharge's grid fitted besides its best one.
const PRECHARGE_BASINS: usize = 2;

impl HydraulicRelation<'_> {
    /// Whether the balance is read for the piston's position: the piston moves and its
    /// position is logged, read smoothed as the pressure is ([`LogFacts::p_smooth_pa`]).
    /// Against the raw position the smoothed pressure's rounded corners (a cylinder
    /// friction's stick-slip turns it every few tens of milliseconds) read as a softer oil.
    pub fn moving_piston(&self) -> bool {
        self.facts.piston_moves && self.facts.x_smooth_m.is_some()
    }

    /// The released precharge's starting grid around the rig file's `p0`: 0.3–3 times it,
    /// and a point between each two neighbouring start pressures of the identification's
    /// shooting windows. A window starting at p_w starts its absorber empty when the
    /// precharge lies above p_w and in equilibrium, filling at C(p_w)·ṗ, when it lies below:
    /// on a rise the objective jumps where the precharge meets a start pressure, so it has
    /// a basin between each two of them, and a local search from a point in another basin
    /// stops at the jump. The grid has a point in each.
    fn precharge_grid(&self, p0: f64) -> Vec<f64> {
        let starts = self
            .facts
            .windows(self.facts.identification(), HYDRAULIC_WINDOW_S)
            .iter()
            .filter_map(|w| self.log.p_pa.get(w.start).copied())
            .collect();
        precharge_grid(p0, starts)
    }
}

/// The precharge grid around `p0` with a point between each two neighbouring distinct
/// window `starts` (pressures) within it ([`HydraulicRelation::precharge_grid`]).
fn precharge_grid(p0: f64, mut starts: Vec<f64>) -> Vec<f64> {
    let (lo, hi) = (0.3 * p0, 3.0 * p0);
    let mut grid = scaled(p0, &[0.3, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0]);
    starts.retain(|p| *p > lo && *p < hi);
    starts.sort_by(f64::total_cmp);
    let mut distinct: Vec<f64> = Vec::new();
    for p in starts {
        if distinct.last().is_none_or(|q| p > q * DISTINCT_START_RATIO) {
            distinct.push(p);
        }
    }
    grid.extend(distinct.windows(2).map(|w| (w[0] * w[1]).sqrt()));
    grid.sort_by(f64::total_cmp);
    grid
}

impl Relation for HydraulicRelation<'_> {
    fn facts(&self) -> &LogFacts {
        self.facts
    }
    /// On a moving piston the transducer's gain, zero and lag held at the rig file's: the
    /// position's balance reads the pressure only through the oil's compliance and the
    /// leakage, so they would drift to their bands' edges there and bend the pressure the
    /// calibrated model predicts.
    fn specs(&self, release: Release) -> Vec<ParamSpec> {
        let mut specs = hydraulic_specs(self.rig, release, self.facts.low_side_apart);
        if self.moving_piston() {
            let n = HydraulicParams::nominal(self.rig);
            for (i, value) in [
                (hyd::GAIN, 1.0),
                (hyd::OFFSET, n.sensor_offset_pa),
                (hyd::LAG, n.sensor_lag_s),
            ] {
                let s = specs[i].clone().starting_at(value);
                specs[i] = s.with_band(value, value);
            }
        }
        specs
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
            Release::Precharge => (hyd::PRECHARGE, self.precharge_grid(p0)),
            Release::SensorLag => (hyd::LAG, vec![0.5e-3, 3e-3, 10e-3, 30e-3, 100e-3]),
            _ => return None,
        })
    }

    /// The precharge's objective has a basin between each two windows' start pressures
    /// ([`Self::precharge_grid`]), and the grid, scoring each point with the other
    /// parameters held, misjudges which one is deepest.
    fn grid_basins(&self, release: Release) -> usize {
        if release == Release::Precharge {
            PRECHARGE_BASINS
        } else {
            0
        }
    }

    /// On a moving piston with its position logged, the position's residuals
    /// ([`position_residuals`]); elsewhere the pressure's.
    fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
        if self.moving_piston() {
            return position_residuals(
                self.log,
                self.facts,
                self.rig,
                hydraulic_params(self.rig, values),
                rows,
            );
        }
        hydraulic_residuals(
            self.log,
            self.facts,
            self.rig,
            hydraulic_params(self.rig, values),
            rows,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_precharge_grid_has_a_point_between_each_two_window_starts() {
        // A rise through 1.1, 1.6, 2.0 and 2.5 MPa, two starts 1 % apart, a hold at 5 MPa
        // and a start below the grid's range.
        let starts = vec![5e6, 1.6e6, 0.5e6, 2.5e6, 2.0e6, 5e6, 1.1e6, 2.02e6, 5e6];
        let grid = precharge_grid(3e6, starts);
        for pair in [
            (1.1e6, 1.6e6),
            (1.6e6, 2.0e6),
            (2.02e6, 2.5e6),
            (2.5e6, 5e6),
        ] {
            assert!(
                grid.iter().any(|g| *g > pair.0 && *g < pair.1),
                "nothing between {pair:?} in {grid:?}"
            );
        }
        assert!(grid.windows(2).all(|w| w[0] <= w[1]), "{grid:?}");
        assert_eq!(grid.first(), Some(&(0.3 * 3e6)));
        assert_eq!(grid.last(), Some(&(3.0 * 3e6)));
        // The rig file's seven points and one between each two of the five distinct starts
        // in range (1.1, 1.6, 2.0, 2.5, 5 MPa; 2.02 within 3 % of 2.0).
        assert_eq!(grid.len(), 7 + 4, "{grid:?}");
    }
}
