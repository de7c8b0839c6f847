//! The whole closed loop replayed from the logged setpoints: the firmware's control core,
//! configured from the rig, against the plant model, sent the setpoint changes the log
//! shows at the times it shows them. It predicts every logged signal, the currents among
//! them, but only for logs taken with this project's controller (another controller's gains
//! or structure would be part of the mismatch); the subsystem replays
//! ([`super::predict`]) carry the diagnosis itself.
//!
//! The plant's sensors are noise-free here: the replay predicts the expected signals, and
//! the log's own noise is what the residual then shows.
//!
//! When the log has the shaft angle, a kinematic phase lock keeps the simulated shaft near
//! the logged angle: every period the simulated angle is moved by a fraction of its error,
//! a first-order pull with bandwidth [`ANGLE_LOCK_RAD_S`], its speed and every other state
//! left alone. Without it the simulated shaft drifts from the logged one by a few percent
//! of the distance turned (the rig's tolerances), and an angle-locked disturbance (cogging
//! at 72 per revolution) would be compared out of phase after a fraction of a revolution.
//! A tracking *torque* cannot do this: it fights the controller's integrators (the
//! pressure loop wants the simulated rig's own holding speed, not the logged one), and the
//! q current, which the replay predicts, then drifts with the fight; the kinematic pull
//! costs no torque, and the controller only sees its encoder advance by the pull's
//! fraction of a count per period. The pull must stay well below the speed loop's bandwidth
//! (190 rad/s): faster, it would hide the real shaft's motion from the simulated encoder
//! and open the loop.

use super::predict::piston_moves;
use crate::bench_log::BenchLog;
use closed_loop::scenario::MAX_EVENTS;
use closed_loop::{controller_config, ClosedLoop, Scenario, ScenarioKind};
use firmware::{Command, Mode};
use plant_model::Rig;

/// Bandwidth of the kinematic angle lock. [rad/s]
///
/// A rig within tolerance runs a few percent faster or slower than the nominal model (a
/// 3 % rate error at the holding speed of 6 rad/s is 0.17 rad/s): the lock's lag is that
/// over the bandwidth, 4 mrad at 40 rad/s, i.e. 0.3 rad at cogging order 72. The logged
/// angle's own ripple at that order (65 Hz in holding) passes into the simulated encoder by
/// only the bandwidth over its frequency, a tenth.
pub const ANGLE_LOCK_RAD_S: f64 = 40.0;

/// Signals the closed-loop replay predicts, row for row. [SI]
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedLoopReplay {
    /// Measured pressure. [Pa]
    pub p_pa: Vec<f64>,
    /// Measured speed. [rad/s]
    pub speed_rad_s: Vec<f64>,
    /// q current. [A]
    pub iq_a: Vec<f64>,
    /// d current. [A]
    pub id_a: Vec<f64>,
}

/// The scenario the log's setpoints describe: pressure control when a pressure setpoint is
/// logged (non-zero), else speed control from `speed_ref_rad_s`; `None` when neither is
/// usable.
pub fn scenario_of(log: &BenchLog) -> Option<Scenario> {
    let pressure = log.p_ref_pa.iter().any(|p| *p > 0.0);
    let (setpoints, kind): (&[f64], _) = if pressure {
        (&log.p_ref_pa, ScenarioKind::PressureStep)
    } else {
        (log.speed_ref_rad_s.as_deref()?, ScenarioKind::SpeedStep)
    };
    let command = |v: f64| {
        if pressure {
            Command::SetPressure { pa: v as f32 }
        } else {
            Command::SetSpeed { rad_s: v as f32 }
        }
    };
    let mode = if pressure {
        Mode::Pressure
    } else {
        Mode::Speed
    };
    let mut events: [Option<(f64, Command)>; MAX_EVENTS] = [None; MAX_EVENTS];
    events[0] = Some((0.0, command(setpoints[0])));
    events[1] = Some((0.0, Command::SetMode(mode)));
    let mut next = 2;
    let mut last = setpoints[0];
    for (k, &v) in setpoints.iter().enumerate().skip(1) {
        if (v - last).abs() > 1e-6 * last.abs().max(1.0) {
            if next == MAX_EVENTS {
                break;
            }
            events[next] = Some((log.t_s[k], command(v)));
            next += 1;
            last = v;
        }
    }
    Some(Scenario {
        name: "log replay",
        description: "the log's setpoints",
        kind,
        blocked: !piston_moves(log),
        initial_pressure_pa: log.p_pa[0],
        duration_s: log.t_s[log.len() - 1],
        steady_from_s: 0.0,
        events,
    })
}

/// Replays the closed loop of `log` on `rig`; `None` when the log has no usable setpoint or
/// the rig cannot be built.
pub fn replay_closed_loop(log: &BenchLog, rig: &Rig) -> Option<ClosedLoopReplay> {
    replay_closed_loop_rows(log, rig, usize::MAX)
}

/// [`replay_closed_loop`] over the first `rows` rows only (an identification segment).
pub fn replay_closed_loop_rows(log: &BenchLog, rig: &Rig, rows: usize) -> Option<ClosedLoopReplay> {
    let scenario = scenario_of(log)?;
    let mut quiet = rig.clone();
    quiet.sensors.current.noise_a_rms = 0.0;
    quiet.sensors.pressure.noise_pa_rms = 0.0;
    quiet.sensors.dc_link.noise_v_rms = 0.0;
    let mut cl = ClosedLoop::new(&quiet, &controller_config(rig), &scenario, 0).ok()?;
    let n = log.len();
    let mut out = ClosedLoopReplay {
        p_pa: Vec::with_capacity(n),
        speed_rad_s: Vec::with_capacity(n),
        iq_a: Vec::with_capacity(n),
        id_a: Vec::with_capacity(n),
    };
    let t0 = log.t_s[0];
    let theta = log.theta_m_rad.as_deref().map(super::replay::unwrap_angle);
    let pull = ANGLE_LOCK_RAD_S * cl.period_s();
    let mut row = 0;
    let mut last = cl.step();
    for &t in &log.t_s[..rows.min(log.len())] {
        // Each row takes the telemetry of the period whose sample instant is nearest.
        while cl.time_s() + 0.5 * cl.period_s() <= t - t0 {
            if let Some(th) = &theta {
                // The logged angle at this instant (linear between rows).
                let now = cl.time_s() + t0;
                while row + 2 < log.len() && log.t_s[row + 1] <= now {
                    row += 1;
                }
                let f = (now - log.t_s[row]) / (log.t_s[row + 1] - log.t_s[row]);
                let reference = th[row] + (th[row + 1] - th[row]) * f.clamp(0.0, 1.0);
                // The simulated shaft starts at angle 0, the logged one at th[0].
                let e = reference - th[0] - cl.plant().shaft_angle_rad();
                cl.shift_shaft_angle(pull * e);
            }
            last = cl.step();
        }
        let f = &last.telemetry;
        out.p_pa.push(f.p_pa as f64);
        out.speed_rad_s.push(f.speed_rad_s as f64);
        out.iq_a.push(f.iq_a as f64);
        out.id_a.push(f.id_a as f64);
    }
    Some(out)
}
