//! A fleet to show `eha fleet` on, and its truth: drives of the nominal design built
//! within their tolerances ([`crate::blind::seeded_tolerance_rig`]), each logged once a
//! month on the same check procedure ([`health_check`]), through the closed loop with the
//! firmware's controller configured from the nominal rig file.
//!
//! Some absorbers lose gas through the bladder at rates of their own (linear in time),
//! some pumps wear to a growing leakage (an extra leakage coefficient rising linearly from
//! nothing at the first log), the rest stay healthy. The truth of each drive — what
//! drifts, how fast, where it starts and when it crosses the limit `eha fleet` trends it
//! against — is written beside the logs as `truth.json`; the logs carry only their
//! `# drive:` and `# recorded_at:` lines and the simulation's plain metadata (source,
//! procedure, seed), never the drift.
//!
//! The ranges, per month of 30.44 days:
//! - gas loss 45–80 kPa a month from the drive's ≈3 MPa: the precharge stays above
//!   0.6 MPa over 30 logs (the diagnosis reads it down to 0.3 MPa, a tenth of the rig
//!   file's) and crosses the design's lowest precharge (0.26 MPa at 5 MPa working pressure)
//!   5–32 months after the last log;
//! - leakage growth that reaches the rig file's own leakage (3e-13 m³/(s·Pa), the limit)
//!   34–60 months after the first log.

use crate::blind::seeded_tolerance_rig;
use closed_loop::{Scenario, ScenarioKind};
use firmware::{Command, Mode};
use host_sim::bench_log::{self, BenchLog, DRIVE_KEY, RECORDED_AT_KEY};
use host_sim::fleet::limits::{rig_leakage_m3_s_pa, LEAKAGE, PRECHARGE};
use host_sim::run::{run, RunOptions};
use host_sim::study::accumulator_design::design;
use host_sim::timestamp::{parse_days, rfc3339};
use plant_model::{Effect, Rig};
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::{Path, PathBuf};

/// Mean days per month (365.2425 / 12). [day]
pub const DAYS_PER_MONTH: f64 = 30.436_875;

/// The working pressure of the precharge limit (the paper's holding case). [Pa]
pub const WORKING_PRESSURE_PA: f64 = 5e6;

/// Name of the check procedure every log records.
pub const PROCEDURE: &str = "pressure-rise";

/// The fill (boost) pressure the check starts from, the rig's. [Pa]
pub const FILL_PRESSURE_PA: f64 = 0.5e6;

/// The monthly check every log records: the cylinder blocked, the pressure held at the
/// fill pressure, then stepped to the 5 MPa working pressure at 0.5 s and held to the end.
///
/// The rise passes the absorber's precharge wherever gas loss has taken it: below it only
/// the oil is compressed, above it the gas too, so where the pressure's rise slows shows
/// the precharge itself — which the scenarios starting at 3 MPa cannot show for a
/// precharge between 2.5 and 3 MPa, where the absorber's volume and the pump's
/// displacement within their tolerances mimic it. Holding 5 MPa, the pump turns only to
/// replace the leakage. A 0.4 L absorber at 0.6 MPa takes 0.3 L of oil on the way up,
/// 6.3 s at the pump's 200 rad/s speed limit: the default 8 s log sees the fill end.
pub fn health_check(duration_s: f64) -> Scenario {
    Scenario {
        name: PROCEDURE,
        description: "fill pressure, then a step to 5 MPa at 0.5 s, blocked cylinder",
        kind: ScenarioKind::PressureStep,
        blocked: true,
        initial_pressure_pa: FILL_PRESSURE_PA,
        duration_s,
        steady_from_s: 0.5,
        events: [
            Some((
                0.0,
                Command::SetPressure {
                    pa: FILL_PRESSURE_PA as f32,
                },
            )),
            Some((0.0, Command::SetMode(Mode::Pressure))),
            Some((
                0.5,
                Command::SetPressure {
                    pa: WORKING_PRESSURE_PA as f32,
                },
            )),
            None,
            None,
            None,
        ],
        profile: None,
    }
}

/// Log rate (the firmware's telemetry). [Hz]
pub const LOG_RATE_HZ: f64 = 1e3;

/// What the fleet is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FleetPlan {
    /// Drives.
    pub drives: usize,
    /// Logs per drive, one a month.
    pub logs: usize,
    /// Drives whose absorber loses gas.
    pub gas_loss: usize,
    /// Drives whose leakage grows.
    pub wear: usize,
    /// Length of each log. [s]
    pub duration_s: f64,
    /// Seed of every draw.
    pub seed: u64,
}

impl Default for FleetPlan {
    /// 20 drives × 30 monthly logs of 8 s: 6 losing gas, 4 wearing, 10 healthy.
    fn default() -> Self {
        FleetPlan {
            drives: 20,
            logs: 30,
            gas_loss: 6,
            wear: 4,
            duration_s: 8.0,
            seed: 1,
        }
    }
}

/// What drifts on one drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drift {
    /// Nothing.
    Healthy,
    /// The absorber's precharge falls. [Pa/day]
    GasLoss(f64),
    /// An extra leakage grows from nothing at the first log. [m³/(s·Pa)/day]
    Wear(f64),
}

/// One drive: its rig, its drift and its log times.
#[derive(Clone, Debug)]
pub struct Drive {
    /// Its name, `D01`….
    pub name: String,
    /// The plant as built (tolerances), before any drift.
    pub rig: Rig,
    /// What drifts.
    pub drift: Drift,
    /// Each log's start. [day since the Unix epoch]
    pub log_days: Vec<f64>,
    /// Each log's noise seed.
    pub seeds: Vec<u64>,
}

/// Uniform in [lo, hi) from the stream.
fn uniform(s: &mut Xoshiro256PlusPlus, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * ((s.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
}

/// The limits `eha fleet` trends against on the nominal rig file: the lowest precharge of
/// the eq. 26–32 design at [`WORKING_PRESSURE_PA`], and the rig file's own leakage.
pub fn limits() -> (f64, f64) {
    let nominal = Rig::nominal();
    let precharge = design(&nominal, WORKING_PRESSURE_PA)
        .map(|d| d.precharge_range_pa[0])
        .unwrap_or(f64::NAN);
    (precharge, rig_leakage_m3_s_pa(&nominal))
}

/// Draws every drive of `plan`. The roles are dealt to the drives in a drawn order, so a
/// drive's name says nothing of its drift.
pub fn draw(plan: &FleetPlan) -> Vec<Drive> {
    let mut s = Xoshiro256PlusPlus::seed_from_u64(plan.seed);
    let mut roles: Vec<usize> = (0..plan.drives).collect();
    for i in (1..roles.len()).rev() {
        let j = (s.next_u64() % (i as u64 + 1)) as usize;
        roles.swap(i, j);
    }
    let start = parse_days("2024-01-08T06:00:00Z").unwrap_or(0.0);
    (0..plan.drives)
        .map(|d| {
            let rig = seeded_tolerance_rig(s.next_u64());
            let role = roles[d];
            let drift = if role < plan.gas_loss {
                Drift::GasLoss(uniform(&mut s, 45e3, 80e3) / DAYS_PER_MONTH)
            } else if role < plan.gas_loss + plan.wear {
                let months = uniform(&mut s, 34.0, 60.0);
                Drift::Wear(limits().1 / (months * DAYS_PER_MONTH))
            } else {
                Drift::Healthy
            };
            let first = start + uniform(&mut s, 0.0, 20.0);
            let log_days = (0..plan.logs)
                .map(|k| first + k as f64 * DAYS_PER_MONTH + uniform(&mut s, 0.0, 3.0))
                .collect();
            let seeds = (0..plan.logs).map(|_| s.next_u64()).collect();
            Drive {
                name: format!("D{:02}", d + 1),
                rig,
                drift,
                log_days,
                seeds,
            }
        })
        .collect()
}

impl Drive {
    /// The plant at `t_days`: the built rig with the drift so far.
    pub fn plant_at(&self, t_days: f64) -> Rig {
        let mut rig = self.rig.clone();
        let age = t_days - self.log_days[0];
        match self.drift {
            Drift::Healthy => {}
            Drift::GasLoss(rate) => {
                Effect::AccumulatorPrecharge {
                    precharge_pa: self.rig.absorber.precharge_pa - rate * age,
                }
                .apply(&mut rig);
            }
            Drift::Wear(rate) => {
                Effect::ExtraLeakage {
                    coefficient_m3_s_pa: rate * age,
                }
                .apply(&mut rig);
            }
        }
        rig
    }

    /// The drive's `k`-th log.
    pub fn log(&self, k: usize, plan: &FleetPlan) -> Result<BenchLog, String> {
        let t = self.log_days[k];
        let scenario = health_check(plan.duration_s);
        let opt = RunOptions {
            duration_s: plan.duration_s,
            log_rate_hz: LOG_RATE_HZ,
            seed: self.seeds[k],
            progress: false,
            metadata: vec![
                ("source".into(), "simulation (fleet generator)".into()),
                ("procedure".into(), PROCEDURE.into()),
                ("seed".into(), self.seeds[k].to_string()),
                (DRIVE_KEY.into(), self.name.clone()),
                (
                    RECORDED_AT_KEY.into(),
                    rfc3339(t).ok_or("a log time out of range")?,
                ),
            ],
            compensation: None,
            integrator: Default::default(),
        };
        Ok(run(&self.plant_at(t), &Rig::nominal(), &scenario, &opt)?.log)
    }

    /// Where the drive's `k`-th log goes under `dir`: `<drive>/<date>.csv`.
    pub fn log_path(&self, dir: &Path, k: usize) -> PathBuf {
        let stamp = rfc3339(self.log_days[k]).unwrap_or_default();
        dir.join(&self.name)
            .join(format!("{}.csv", stamp.get(..10).unwrap_or("log")))
    }

    /// The truth `eha fleet` must find, as JSON: the parameter that drifts, its rate per
    /// day, its value at the first log and when it crosses its limit.
    pub fn truth(&self) -> serde_json::Value {
        let (precharge_limit, leakage_limit) = limits();
        let first = self.log_days[0];
        // Leakage beyond the rig file's that the tolerances already give: every path
        // (pump internal and external, cylinder) drains to the fill pressure, so their
        // coefficients add as one conductance, like the extra leakage's.
        let tolerance_leakage =
            rig_leakage_m3_s_pa(&self.rig) - rig_leakage_m3_s_pa(&Rig::nominal());
        let (parameter, rate, start, limit) = match self.drift {
            Drift::Healthy => return serde_json::json!({"drive": self.name, "drifts": null}),
            Drift::GasLoss(r) => (
                PRECHARGE,
                -r,
                self.rig.absorber.precharge_pa,
                precharge_limit,
            ),
            Drift::Wear(r) => (LEAKAGE, r, tolerance_leakage, leakage_limit),
        };
        let crossing = first + (limit - start) / rate;
        serde_json::json!({
            "drive": self.name,
            "drifts": parameter,
            "rate_per_day": rate,
            "value_at_first_log": start,
            "first_log": rfc3339(first),
            "limit": limit,
            "crossing_day": crossing,
            "crossing_date": host_sim::timestamp::date(crossing),
        })
    }
}

/// Writes the drive's `k`-th log under `dir`; returns its path.
pub fn write_log(drive: &Drive, k: usize, plan: &FleetPlan, dir: &Path) -> Result<PathBuf, String> {
    let log = drive.log(k, plan)?;
    let path = drive.log_path(dir, k);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    bench_log::write(&path, &log).map_err(|e| e.to_string())?;
    Ok(path)
}

/// The fleet's truth document.
pub fn truth(plan: &FleetPlan, drives: &[Drive]) -> serde_json::Value {
    let (precharge_limit, leakage_limit) = limits();
    serde_json::json!({
        "plan": {
            "drives": plan.drives, "logs": plan.logs, "gas_loss": plan.gas_loss,
            "wear": plan.wear, "duration_s": plan.duration_s, "seed": plan.seed,
            "procedure": PROCEDURE, "log_rate_hz": LOG_RATE_HZ,
        },
        "limits": {
            "precharge_pa": precharge_limit,
            "extra_leakage_m3_s_pa": leakage_limit,
            "working_pressure_pa": WORKING_PRESSURE_PA,
        },
        "drives": drives.iter().map(Drive::truth).collect::<Vec<_>>(),
    })
}
