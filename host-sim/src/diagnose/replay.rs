//! Subsystem replays of a bench log (issue 5): the plant model driven by the logged signals
//! at a subsystem's boundary instead of by the controller, so that the diagnosis works on
//! logs from any controller, whatever its gains or structure.
//!
//! - Hydraulics ([`replay_hydraulics`]): the shaft is prescribed ([`Drive::ShaftSpeed`])
//!   from the logged angle, or from the logged speed when no angle is logged; the pump's
//!   flow (eq. 9, 20–21), the pressure nodes with the absorber (eq. 10–11, 22–26) and the
//!   transducer follow.
//! - Motor and shaft ([`replay_motor`]): the d-q currents are prescribed
//!   ([`Drive::Currents`]); the torque (eq. 3, 16–19) turns the shaft (eq. 4) against the
//!   pump, and the hydraulics follow the simulated shaft.
//!
//! In both the piston is prescribed from the logged `x_m` (velocity by differentiation),
//! or blocked when `x_m` is absent: its load force is not logged, so simulating its motion
//! would mix an unknown into every replay.
//!
//! # Between log samples
//! The plant steps at its own `integration.max_step_s`; each log interval is cut into equal
//! steps and the drive is set per step:
//! - Angle logged: the interval's mean speed (θ_{k+1} − θ_k)/(t_{k+1} − t_k) is held, i.e.
//!   the angle is interpolated linearly. The simulated shaft then passes through every logged
//!   angle, so the displaced volume is exact to the encoder's resolution (no drift of the
//!   pressure, which integrates the flow with the slow leakage time constant C/G ≈ 100 s),
//!   and the angle-periodic terms (piston ripple) see the logged shaft position.
//! - Speed only: interpolated linearly, evaluated at each step's midpoint (the trapezoid
//!   rule for the angle travelled, exact for a speed ramp; holding the sample would shift
//!   the angle by half a log interval's travel).
//! - Currents: interpolated linearly at each step's midpoint, for the same reason (the
//!   torque impulse of the interval is the trapezoid of the samples).
//! - Piston: its position interpolated linearly (start of each step), the interval's mean
//!   velocity held.
//!
//! # Initial state
//! The port pressure starts where the hydraulic replay of the first [`INITIAL_SAMPLES`] rows has zero
//! mean residual (one shooting correction from the first logged pressure): a single
//! sample's transducer noise would persist as an offset over the whole replay (the
//! hydraulics forget it only with the leakage time constant), and a start-up transient in
//! the first rows (the pressure falls by leakage at ≈ 1 MPa/s while the absorber is empty)
//! biases any fit of the samples alone, but not the replay's, which has the transient. The low
//! side starts at the logged `p_low_pa` or the rig's fill pressure; shaft angle and speed
//! at the logged angle and the first interval's mean speed (or the logged speed).

use crate::bench_log::{BenchLog, BenchLogError};
use plant_model::{Drive, InitialConditions, Inputs, Plant, Rig, RigError};
use std::f64::consts::PI;
use std::path::Path;

/// Logged rows the initial port pressure is fitted to (0.1 s at 1 kHz): the start's error
/// from the transducer's noise is σ/√100 ≈ 0.1 kPa at the nominal rig.
pub const INITIAL_SAMPLES: usize = 100;

/// What a replay cannot be run on.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The log breaks the bench-log contract (lengths, finiteness, time order, rows).
    #[error(transparent)]
    Log(#[from] BenchLogError),
    /// The rig or the initial state taken from the log is invalid.
    #[error("cannot replay on this rig: {0}")]
    Rig(#[from] RigError),
}

/// Which subsystem was replayed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayKind {
    /// Hydraulics from the shaft angle (or speed) and the piston.
    Hydraulics,
    /// Motor and shaft from the d-q currents, hydraulics following.
    Motor,
}

/// Where the shaft's motion came from in a hydraulic replay.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaftSource {
    /// The logged, unwrapped `theta_m_rad`.
    Angle,
    /// The logged `speed_rad_s`.
    Speed,
    /// Simulated from the logged currents (motor replay).
    Currents,
}

/// Simulated signals at the log's instants, row for row.
#[derive(Clone, Debug, PartialEq)]
pub struct Replay {
    /// The subsystem replayed.
    pub kind: ReplayKind,
    /// What drove the shaft.
    pub shaft_source: ShaftSource,
    /// The log's time. [s]
    pub t_s: Vec<f64>,
    /// Port-A pressure at the transducer (its lag included, noise-free): compare with the
    /// log's `p_pa`. [Pa]
    pub p_pa: Vec<f64>,
    /// Port-B pressure. [Pa]
    pub p_low_pa: Vec<f64>,
    /// Shaft speed. [rad/s]
    pub speed_rad_s: Vec<f64>,
    /// Shaft angle, unwrapped. [rad]
    pub theta_m_rad: Vec<f64>,
}

impl Replay {
    /// Fit (see [`super::fit_percent`]) of the simulated pressure to the logged `p_pa`.
    pub fn pressure_fit(&self, log: &BenchLog) -> Option<f64> {
        super::fit_percent(&log.p_pa, &self.p_pa)
    }

    /// Fit of the simulated speed to the logged `speed_rad_s`.
    pub fn speed_fit(&self, log: &BenchLog) -> Option<f64> {
        super::fit_percent(&log.speed_rad_s, &self.speed_rad_s)
    }
}

/// Replays the hydraulics of `log` on `rig`: the shaft prescribed from the logged angle
/// (or speed), the piston from `x_m` (or blocked). See the module documentation.
pub fn replay_hydraulics(log: &BenchLog, rig: &Rig) -> Result<Replay, ReplayError> {
    replay(log, rig, ReplayKind::Hydraulics)
}

/// Replays motor and shaft of `log` on `rig`: the d-q currents prescribed from `id_a` and
/// `iq_a`, the hydraulics following the simulated shaft, the piston from `x_m` (or
/// blocked). See the module documentation.
pub fn replay_motor(log: &BenchLog, rig: &Rig) -> Result<Replay, ReplayError> {
    replay(log, rig, ReplayKind::Motor)
}

/// The name errors give an in-memory log (the CLI has named the file when reading it).
const IN_MEMORY: &str = "bench log being replayed";

fn replay(log: &BenchLog, rig: &Rig, kind: ReplayKind) -> Result<Replay, ReplayError> {
    log.check(Path::new(IN_MEMORY))?;
    let theta = log.theta_m_rad.as_deref().map(unwrap_angle);
    // Shooting for the initial pressure: replay the first rows' hydraulics from the first
    // logged pressure and correct the start by their mean residual. With the shaft
    // prescribed the simulated pressure moves with its start one to one over those rows
    // (the leakage time constant is seconds), so one correction suffices; the motor replay
    // starts from the same estimate (its shaft would answer a wrong start within the head,
    // so shooting through it would fit the start to the current noise instead).
    let head = INITIAL_SAMPLES.min(log.len());
    let trial = simulate(
        log,
        rig,
        ReplayKind::Hydraulics,
        theta.as_deref(),
        log.p_pa[0],
        head,
    )?;
    let offset = log.p_pa[..head]
        .iter()
        .zip(&trial.p_pa)
        .map(|(y, s)| y - s)
        .sum::<f64>()
        / head as f64;
    simulate(
        log,
        rig,
        kind,
        theta.as_deref(),
        log.p_pa[0] + offset,
        log.len(),
    )
}

/// Replays the first `rows` rows of a checked `log` from port pressure `p0_pa`.
fn simulate(
    log: &BenchLog,
    rig: &Rig,
    kind: ReplayKind,
    theta: Option<&[f64]>,
    p0_pa: f64,
    rows: usize,
) -> Result<Replay, ReplayError> {
    let n = rows.min(log.len());
    let t = &log.t_s[..n];
    let x_piston = log.x_m.as_deref();
    let mut rig = rig.clone();
    if x_piston.is_none() {
        rig.cylinder.blocked = true;
    }
    // The log was checked (at least MIN_ROWS rows) and `rows` ≥ 2, so the first interval
    // exists.
    let dt0 = log.t_s[1] - log.t_s[0];
    let init = InitialConditions {
        p_a_pa: p0_pa,
        p_b_pa: log.p_low_pa.as_ref().map_or(rig.fill.pressure_pa, |p| p[0]),
        x_m: x_piston.map_or(0.0, |x| x[0]),
        omega_rad_s: theta.map_or(log.speed_rad_s[0], |th| (th[1] - th[0]) / dt0),
        theta_m_rad: theta.map_or(0.0, |th| th[0]),
    };
    let mut plant = Plant::new(&rig, &init, 0)?;
    let shaft_source = match (kind, theta) {
        (ReplayKind::Motor, _) => ShaftSource::Currents,
        (ReplayKind::Hydraulics, Some(_)) => ShaftSource::Angle,
        (ReplayKind::Hydraulics, None) => ShaftSource::Speed,
    };
    let mut out = Replay {
        kind,
        shaft_source,
        t_s: t.to_vec(),
        p_pa: Vec::with_capacity(n),
        p_low_pa: Vec::with_capacity(n),
        speed_rad_s: Vec::with_capacity(n),
        theta_m_rad: Vec::with_capacity(n),
    };
    let mut record = |plant: &Plant| {
        let o = plant.observe();
        out.p_pa.push(o.p_sensor_pa);
        out.p_low_pa.push(o.p_b_pa);
        out.speed_rad_s.push(o.omega_m_rad_s);
        out.theta_m_rad.push(o.theta_m_rad);
    };
    record(&plant);
    let lerp = |y: &[f64], k: usize, f: f64| y[k] + (y[k + 1] - y[k]) * f;
    for k in 0..n.saturating_sub(1) {
        let dt = t[k + 1] - t[k];
        let steps = (dt / rig.integration.max_step_s).ceil().max(1.0) as u32;
        let h = dt / steps as f64;
        let mean_speed = theta.map(|th| (th[k + 1] - th[k]) / dt);
        let piston_speed = x_piston.map(|x| (x[k + 1] - x[k]) / dt);
        for j in 0..steps {
            let start = j as f64 / steps as f64;
            let mid = (j as f64 + 0.5) / steps as f64;
            let drive = match kind {
                ReplayKind::Hydraulics => Drive::ShaftSpeed {
                    omega_rad_s: mean_speed.unwrap_or_else(|| lerp(&log.speed_rad_s, k, mid)),
                },
                ReplayKind::Motor => Drive::Currents {
                    i_d: lerp(&log.id_a, k, mid),
                    i_q: lerp(&log.iq_a, k, mid),
                },
            };
            let piston = x_piston
                .zip(piston_speed)
                .map(|(x, v)| (lerp(x, k, start), v));
            plant.advance(
                h,
                &Inputs {
                    drive,
                    piston,
                    external_force_n: 0.0,
                },
            );
        }
        record(&plant);
    }
    Ok(out)
}

/// Unwraps an angle logged wrapped (to [0, 2π) or any 2π range) or already unwrapped: each
/// step is taken as the one of its 2π-equivalents closest to zero, which is right while
/// the shaft turns less than half a revolution per log interval (3 000 rad/s at 1 kHz).
fn unwrap_angle(wrapped: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(wrapped.len());
    let mut acc = wrapped.first().copied().unwrap_or(0.0);
    let mut prev = acc;
    for &a in wrapped {
        let d = a - prev;
        acc += d - 2.0 * PI * (d / (2.0 * PI)).round();
        prev = a;
        out.push(acc);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwrapping_restores_a_steady_rotation() {
        // 0.3 rad per sample over several revolutions, logged wrapped to [0, 2π).
        let truth: Vec<f64> = (0..100).map(|k| 1.0 + 0.3 * k as f64).collect();
        let wrapped: Vec<f64> = truth.iter().map(|a| a.rem_euclid(2.0 * PI)).collect();
        for (u, a) in unwrap_angle(&wrapped).iter().zip(&truth) {
            assert!((u - a).abs() < 1e-9, "{u} vs {a}");
        }
        // Backwards too.
        let back: Vec<f64> = truth.iter().map(|a| (-a).rem_euclid(2.0 * PI)).collect();
        let u = unwrap_angle(&back);
        assert!((u[99] - u[0] + 0.3 * 99.0).abs() < 1e-9);
    }
}
