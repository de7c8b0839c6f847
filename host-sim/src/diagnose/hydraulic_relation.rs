//! The hydraulic parity relation as the calibration fits it: its search space (the
//! hydraulic model's parameters with their tolerance bands, eq. 9–11 and 22–26 through
//! [`super::hydraulic`]), the parameters a search vector means, and its residuals over the
//! windows in noise units.

use crate::bench_log::{BenchLog, Signal};
use crate::diagnose::calibration::{scaled, Relation, Release};
use crate::diagnose::facts::LogFacts;
use crate::diagnose::hydraulic::{HydraulicInputs, HydraulicParams, Hydraulics};
use crate::diagnose::least_squares::{huber, ParamSpec};
use plant_model::accumulator::GasCharge;
use plant_model::Rig;
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
    let mut out = Vec::new();
    let mut pred = Vec::new();
    for w in windows {
        pred.clear();
        pred.resize(w.len(), 0.0);
        model.predict_window(&inputs, w.clone(), &mut pred);
        out.extend((w.start + 1..w.end).map(|k| huber((log.p_pa[k] - pred[k - w.start]) / sigma)));
    }
    out
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

impl Relation for HydraulicRelation<'_> {
    fn facts(&self) -> &LogFacts {
        self.facts
    }
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
