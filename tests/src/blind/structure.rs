//! What the blind suite draws beyond the listed tolerances, so that it measures how the
//! diagnosis generalises rather than how well it agrees with this project's own model:
//!
//! - the parts of the rig the rig contract leaves open: the oil volume of the line between
//!   pump port and chamber, the absorber inlet's inertance and resistance, the fill
//!   accumulator's pressure and precharge, which path the pump's leakage takes (to the low
//!   side, eq. 9, or to the case, eq. 10), the pressure transducer's offset;
//! - the controller: the current, speed and pressure loops tuned away from this project's
//!   defaults (a bench's drive is tuned by its engineer), the pressure feedback filter;
//! - the columns: a bench without voltage telemetry, without piston position or low-side
//!   pressure (the contract's optional columns).
//!
//! Each range is one a healthy rig has: a variant is not a fault, and the diagnosis must
//! call such a rig `none`.

use super::stream::Stream;
use firmware::config::Config;
use host_sim::bench_log::{BenchLog, Signal};
use plant_model::Rig;

/// One log's drawn structure.
#[derive(Clone, Debug, PartialEq)]
pub struct Structure {
    /// Oil volume of the line from port A to chamber A, added to the chamber. [m³]
    pub line_volume_m3: f64,
    /// Absorber inlet inertance over the rig file's. [1]
    pub inlet_inertance_factor: f64,
    /// Absorber inlet resistance over the rig file's. [1]
    pub inlet_resistance_factor: f64,
    /// Share of the pump's leakage that flows to the low port (eq. 9); the rest goes to
    /// the case (eq. 10). The total is the rig's. [1]
    pub leakage_to_low_side: f64,
    /// Fill accumulator pressure at the start. [Pa]
    pub fill_pressure_pa: f64,
    /// Pressure transducer offset. [Pa]
    pub transducer_offset_pa: f64,
    /// The controller's tuning.
    pub controller: ControllerVariant,
    /// Optional contract columns the bench did not log.
    pub dropped: Vec<&'static str>,
}

/// A controller tuned away from the defaults, as factors on the default configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerVariant {
    /// Current-loop gains (both axes, P and I: the loop's bandwidth). [1]
    pub current_gain: f64,
    /// Speed PI gains. [1]
    pub speed_gain: f64,
    /// Pressure loop crossover. [1]
    pub pressure_bandwidth: f64,
    /// Corner of the pressure feedback low-pass. [1]
    pub pressure_filter: f64,
}

impl ControllerVariant {
    /// This project's own tuning.
    pub const DEFAULT: ControllerVariant = ControllerVariant {
        current_gain: 1.0,
        speed_gain: 1.0,
        pressure_bandwidth: 1.0,
        pressure_filter: 1.0,
    };

    /// `config` with the variant's factors applied.
    pub fn apply(&self, config: &Config) -> Config {
        let mut c = *config;
        let f = |x: f32, k: f64| (f64::from(x) * k) as f32;
        c.current.kp_d = f(c.current.kp_d, self.current_gain);
        c.current.ki_d = f(c.current.ki_d, self.current_gain);
        c.current.kp_q = f(c.current.kp_q, self.current_gain);
        c.current.ki_q = f(c.current.ki_q, self.current_gain);
        c.speed.kp = f(c.speed.kp, self.speed_gain);
        c.speed.ki = f(c.speed.ki, self.speed_gain);
        c.pressure.bandwidth_rad_s = f(c.pressure.bandwidth_rad_s, self.pressure_bandwidth);
        c.pressure.feedback_filter_rad_s =
            f(c.pressure.feedback_filter_rad_s, self.pressure_filter);
        c
    }
}

/// The voltage columns a bench without voltage telemetry lacks.
const VOLTAGES: [&str; 3] = ["ud_v", "uq_v", "udc_v"];

impl Structure {
    /// Exactly the rig file's structure, this project's controller, every column.
    pub fn as_rig_file() -> Structure {
        let r = Rig::nominal();
        Structure {
            line_volume_m3: 0.0,
            inlet_inertance_factor: 1.0,
            inlet_resistance_factor: 1.0,
            leakage_to_low_side: r.pump.internal_leakage_m3_s_pa
                / (r.pump.internal_leakage_m3_s_pa + r.pump.external_leakage_m3_s_pa),
            fill_pressure_pa: r.fill.pressure_pa,
            transducer_offset_pa: r.sensors.pressure.offset_pa,
            controller: ControllerVariant::DEFAULT,
            dropped: Vec::new(),
        }
    }

    /// `rig` with the structure applied.
    pub fn apply(&self, rig: &mut Rig) {
        rig.cylinder.chamber_a_volume_m3 += self.line_volume_m3;
        rig.absorber.inlet_inertance_kg_m4 *= self.inlet_inertance_factor;
        rig.absorber.inlet_resistance_pa_s_m3 *= self.inlet_resistance_factor;
        let pump = &mut rig.pump;
        let total = pump.internal_leakage_m3_s_pa + pump.external_leakage_m3_s_pa;
        pump.internal_leakage_m3_s_pa = total * self.leakage_to_low_side;
        pump.external_leakage_m3_s_pa = total * (1.0 - self.leakage_to_low_side);
        rig.fill.pressure_pa = self.fill_pressure_pa;
        rig.sensors.pressure.offset_pa = self.transducer_offset_pa;
    }

    /// `log` without the dropped columns.
    pub fn drop_columns(&self, log: &mut BenchLog) {
        for name in &self.dropped {
            drop_column(log, name);
        }
    }
}

/// Takes the optional contract column `name` out of `log`; `false` when `name` is not an
/// optional column (the required ones cannot be dropped).
pub fn drop_column(log: &mut BenchLog, name: &str) -> bool {
    Signal::from_name(name).is_some_and(|s| log.remove(s))
}

/// Draws a structure: each open part within the range a healthy rig has, the controller's
/// gains within what a bench engineer's tuning gives, each optional column group dropped
/// half of the time (the reference a third of the time), except the columns `needed`.
pub(super) fn draw_structure(s: &mut Stream, needed: &[&str]) -> Structure {
    let r = Rig::nominal();
    // Hoses and manifold drillings: up to a quarter of the chamber's oil again.
    let line_volume_m3 = r.cylinder.chamber_a_volume_m3 * s.uniform(0.0, 0.25);
    // Port bore and hose of another absorber mount: half to twice the assumed inertance;
    // the bladder and inlet losses anywhere in a factor 3 either way.
    let inlet_inertance_factor = s.uniform(0.5, 2.0);
    let inlet_resistance_factor = (s.uniform(-1.0, 1.0) * 3f64.ln()).exp();
    // Either path or a mix: pumps drain their leakage to the case, the low port, or both.
    let leakage_to_low_side = s.uniform(0.0, 1.0);
    // A boost circuit set anywhere from 0.3 to 0.8 MPa.
    let fill_pressure_pa = s.uniform(0.3e6, 0.8e6);
    // A transducer zeroed to within ±20 kPa (0.1 % of its 25 MPa span, the data sheet's).
    let transducer_offset_pa = s.uniform(-20e3, 20e3);
    let controller = ControllerVariant {
        current_gain: s.uniform(0.6, 1.4),
        speed_gain: s.uniform(0.6, 1.5),
        pressure_bandwidth: s.uniform(0.6, 1.5),
        pressure_filter: s.uniform(0.5, 2.0),
    };
    let mut dropped = Vec::new();
    if s.unit() < 0.5 {
        dropped.extend(VOLTAGES);
    }
    if s.unit() < 0.5 {
        dropped.push("x_m");
    }
    if s.unit() < 0.5 {
        dropped.push("p_low_pa");
    }
    if s.unit() < 0.3 {
        dropped.push("iq_ref_a");
    }
    dropped.retain(|c| !needed.contains(c));
    Structure {
        line_volume_m3,
        inlet_inertance_factor,
        inlet_resistance_factor,
        leakage_to_low_side,
        fill_pressure_pa,
        transducer_offset_pa,
        controller,
        dropped,
    }
}
