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
use firmware::speed_observer::SpeedObserver;
use firmware::transforms::{clarke, park, sin_cos};
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
    /// Shaft speed: in a motor replay as the firmware's encoder observer estimates it (what
    /// the log's `speed_rad_s` is), else the true speed. [rad/s]
    pub speed_rad_s: Vec<f64>,
    /// Shaft angle, unwrapped. [rad]
    pub theta_m_rad: Vec<f64>,
    /// Motor replay: the q current the model needed to follow the logged shaft motion, the
    /// logged current plus the tracking correction (see [`TRACKING_BANDWIDTH_RAD_S`]); the
    /// logged current in a hydraulic replay. Compare with the log's `iq_a`. [A]
    pub iq_needed_a: Vec<f64>,
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

/// How a replay departs from the defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReplayOptions {
    /// Replay only the first `rows` rows (the identification segment). `usize::MAX`: all.
    pub rows: usize,
    /// Simulate the piston under the rig's load (friction, viscous damping, gravity, end
    /// stops) from the logged start instead of prescribing it from `x_m`: then cylinder
    /// friction shows in the port pressures. Ignored when `x_m` is not logged.
    pub piston_free: bool,
    /// A DC offset of phase a's current channel, assumed in the log's `id_a`/`iq_a` (motor
    /// replay): the motor is driven with the currents that flowed, the logged ones less the
    /// offset's d-q image at the logged angle. [A]
    pub phase_a_offset_a: f64,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            rows: usize::MAX,
            piston_free: false,
            phase_a_offset_a: 0.0,
        }
    }
}

/// Replays the hydraulics of `log` on `rig`: the shaft prescribed from the logged angle
/// (or speed), the piston from `x_m` (or blocked). See the module documentation.
pub fn replay_hydraulics(log: &BenchLog, rig: &Rig) -> Result<Replay, ReplayError> {
    replay_with(log, rig, ReplayKind::Hydraulics, &ReplayOptions::default())
}

/// Replays motor and shaft of `log` on `rig`: the d-q currents prescribed from `id_a` and
/// `iq_a`, the hydraulics following the simulated shaft, the piston from `x_m` (or
/// blocked). See the module documentation.
pub fn replay_motor(log: &BenchLog, rig: &Rig) -> Result<Replay, ReplayError> {
    replay_with(log, rig, ReplayKind::Motor, &ReplayOptions::default())
}

/// Bandwidth of the motor replay's tracking of the logged shaft angle. [rad/s]
///
/// Prescribed currents alone leave the shaft on a very soft spring: in pressure holding the
/// pump's stiffness D²/(4π²·C) against the inertia gives ≈ 1.3 rad/s, barely damped, so the
/// current sensor's noise and any small torque error make the simulated speed wander by
/// more than the effects sought. A critically damped PD torque pulls the simulated shaft
/// to the logged angle below this bandwidth; above it (cogging, flux harmonics, a current
/// offset's first electrical harmonic at any useful speed) the model's own dynamics show in
/// the speed, and below it a missing torque shows as the current the model needed.
pub const TRACKING_BANDWIDTH_RAD_S: f64 = 60.0;

/// Sub-counts per encoder count of the motor replay's speed observer.
const OBSERVER_SUBCOUNTS: u32 = 1024;

/// The name errors give an in-memory log (the CLI has named the file when reading it).
const IN_MEMORY: &str = "bench log being replayed";

/// Replays `log` on `rig` as `kind` with `options`.
pub fn replay_with(
    log: &BenchLog,
    rig: &Rig,
    kind: ReplayKind,
    options: &ReplayOptions,
) -> Result<Replay, ReplayError> {
    log.check(Path::new(IN_MEMORY))?;
    let theta = log.theta_m_rad.as_deref().map(unwrap_angle);
    // Shooting for the initial pressure: replay the first rows' hydraulics from the first
    // logged pressure and correct the start by their mean residual. With the shaft
    // prescribed the simulated pressure moves with its start one to one over those rows
    // (the leakage time constant is seconds), so one correction suffices; the motor replay
    // starts from the same estimate (its shaft would answer a wrong start within the head,
    // so shooting through it would fit the start to the current noise instead).
    let head = INITIAL_SAMPLES.min(log.len());
    let head_options = ReplayOptions {
        rows: head,
        ..*options
    };
    let trial = simulate(
        log,
        rig,
        ReplayKind::Hydraulics,
        theta.as_deref(),
        log.p_pa[0],
        &head_options,
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
        options,
    )
}

/// Replays the first `options.rows` rows of a checked `log` from port pressure `p0_pa`.
fn simulate(
    log: &BenchLog,
    rig: &Rig,
    kind: ReplayKind,
    theta: Option<&[f64]>,
    p0_pa: f64,
    options: &ReplayOptions,
) -> Result<Replay, ReplayError> {
    let n = options.rows.min(log.len()).max(2);
    let t = &log.t_s[..n];
    let x_logged = log.x_m.as_deref();
    let x_piston = x_logged.filter(|_| !options.piston_free);
    // The offset's d-q image rotates with the electrical angle: at the logged angle when
    // there is one, else at the simulated shaft's.
    let pole_pairs = rig.motor.pole_pairs as f64;
    let offset_a = options.phase_a_offset_a;
    let mut rig = rig.clone();
    if x_logged.is_none() {
        rig.cylinder.blocked = true;
    }
    // The log was checked (at least MIN_ROWS rows) and `rows` ≥ 2, so the first interval
    // exists.
    let dt0 = log.t_s[1] - log.t_s[0];
    let init = InitialConditions {
        p_a_pa: p0_pa,
        p_b_pa: log.p_low_pa.as_ref().map_or(rig.fill.pressure_pa, |p| p[0]),
        x_m: x_logged.map_or(0.0, |x| x[0]),
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
        iq_needed_a: Vec::with_capacity(n),
    };
    let record = |out: &mut Replay, plant: &Plant, iq_a: f64, speed: Option<f64>| {
        let o = plant.observe();
        out.p_pa.push(o.p_sensor_pa);
        out.p_low_pa.push(o.p_b_pa);
        out.speed_rad_s.push(speed.unwrap_or(o.omega_m_rad_s));
        out.theta_m_rad.push(o.theta_m_rad);
        out.iq_needed_a.push(iq_a);
    };
    // The motor replay's reference angle: the logged one, or the logged speed integrated.
    let theta_ref: Vec<f64> = match theta {
        Some(th) => th[..n].to_vec(),
        None => {
            let mut acc = 0.0;
            let mut v = vec![0.0];
            for k in 1..n {
                acc += 0.5 * (log.speed_rad_s[k] + log.speed_rad_s[k - 1]) * (t[k] - t[k - 1]);
                v.push(acc);
            }
            v
        }
    };
    let j_total = rig.shaft.inertia_kg_m2();
    let k_t = rig.motor.torque_constant_nm_per_a();
    let w_o = TRACKING_BANDWIDTH_RAD_S;
    let mut correction_a = 0.0;
    // The logged speed is the firmware's encoder observer's estimate (its PLL filters the
    // fast ripple the diagnosis looks at), so the motor replay's speed goes through the
    // same observer, fed with the simulated shaft angle on a 1024 times finer grid: its
    // dynamics without the encoder's quantisation noise, which the prediction should not
    // add a second, independent time to the log's own.
    let cpr = rig
        .sensors
        .encoder
        .counts_per_rev
        .saturating_mul(OBSERVER_SUBCOUNTS);
    let counts_per_rad = cpr as f64 / (2.0 * PI);
    let observer_bandwidth = closed_loop::controller_config(&rig)
        .speed
        .observer_bandwidth_rad_s;
    let mut observer: Option<SpeedObserver> = None;
    record(&mut out, &plant, log.iq_a[0], None);
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
                ReplayKind::Motor => {
                    let (mut i_d, mut i_q) = (lerp(&log.id_a, k, mid), lerp(&log.iq_a, k, mid));
                    let o = plant.observe();
                    let position = (o.theta_m_rad * counts_per_rad).floor() as i64;
                    let obs = observer.get_or_insert_with(|| {
                        let mut s = SpeedObserver::new(observer_bandwidth, (1.0 / h) as f32, cpr);
                        s.reset(position);
                        s
                    });
                    obs.update(position);
                    let w_ref = reference_rate(&theta_ref, t, k);
                    let torque = j_total
                        * (w_o * w_o * (lerp(&theta_ref, k, start) - o.theta_m_rad)
                            + 2.0 * w_o * (w_ref - o.omega_m_rad_s));
                    correction_a = torque / k_t;
                    i_q += correction_a;
                    if offset_a != 0.0 {
                        // The controller measured true + offset on phase a and transformed
                        // it with its own Clarke and Park: the truth is the log less that
                        // image.
                        let sc = sin_cos((pole_pairs * o.theta_m_rad) as f32);
                        let image = park(clarke(offset_a as f32, 0.0, 0.0), sc);
                        i_d -= image.d as f64;
                        i_q -= image.q as f64;
                    }
                    Drive::Currents { i_d, i_q }
                }
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
                    external_torque_nm: 0.0,
                },
            );
        }
        let observed = observer.as_ref().map(|o| o.speed_rad_s() as f64);
        record(&mut out, &plant, log.iq_a[k + 1] + correction_a, observed);
    }
    Ok(out)
}

/// Rows on each side of the central difference that gives a tracking reference's rate.
///
/// One encoder count (0.63 mrad at 10 000 counts/rev) over one 1 ms log interval is
/// 0.63 rad/s: the interval's own mean speed would feed the encoder's quantisation into a
/// tracking torque's damping term as a torque noise larger than the current sensor's. Over
/// ±5 rows the quantum is ten times smaller, and the fast ripple the diagnosis compares
/// (orders 24 and 72 at a few rad/s, i.e. 15–70 Hz) is averaged out of the reference, so
/// the tracking does not impose the logged ripple on the model: the model must make it.
pub const REFERENCE_RATE_HALF_WIDTH: usize = 5;

/// Rate of the reference angle `theta` (unwrapped, at instants `t`) around row `k`: the
/// central difference over ±[`REFERENCE_RATE_HALF_WIDTH`] rows, clipped at the log's ends.
/// [rad/s]
pub fn reference_rate(theta: &[f64], t: &[f64], k: usize) -> f64 {
    let n = theta.len().min(t.len());
    if n < 2 {
        return 0.0;
    }
    let lo = k.saturating_sub(REFERENCE_RATE_HALF_WIDTH).min(n - 2);
    let hi = (k + 1 + REFERENCE_RATE_HALF_WIDTH).min(n - 1).max(lo + 1);
    (theta[hi] - theta[lo]) / (t[hi] - t[lo])
}

/// Unwraps an angle logged wrapped (to [0, 2π) or any 2π range) or already unwrapped: each
/// step is taken as the one of its 2π-equivalents closest to zero, which is right while
/// the shaft turns less than half a revolution per log interval (3 000 rad/s at 1 kHz).
pub fn unwrap_angle(wrapped: &[f64]) -> Vec<f64> {
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
