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
//!
//! The lock alone still lags the logged angle when the real shaft wanders (in holding, the
//! pressure loop answers its transducer's noise with tenths of a rad/s that a noise-free
//! replay cannot reproduce): 10 mrad of lag is 0.7 rad of phase at cogging order 72. Two
//! things close that gap:
//! - The speed and current loops can be replayed on the logged speed reference
//!   ([`Reference::SpeedReference`]): in pressure control that is the pressure loop's
//!   output, noise answer included, so the simulated shaft wanders as the real one did.
//! - Cogging (eq. 16), a torque of the shaft angle alone, is taken out of the plant and
//!   applied as an external torque evaluated at the *logged* angle with the plant model's
//!   own [`Motor::cogging_torque_nm`]: the simulated loop answers the disturbance the real
//!   shaft met, when it met it. The flux harmonics (eq. 17–19) stay in the plant: at speed
//!   they act mostly through their back-EMF on the simulated current loop, which needs
//!   the simulated currents and angle.
//!
use super::predict::piston_moves;
use crate::bench_log::BenchLog;
use closed_loop::scenario::MAX_EVENTS;
use closed_loop::{controller_config, ClosedLoop, Scenario, ScenarioKind};
use firmware::{Command, Mode};
use plant_model::motor::Motor;
use plant_model::Rig;

/// Bandwidth of the kinematic angle lock. [rad/s]
///
/// A rig within tolerance runs a few percent faster or slower than the nominal model (a
/// 3 % rate error at the holding speed of 6 rad/s is 0.17 rad/s): the lock's lag is that
/// over the bandwidth, 4 mrad at 40 rad/s, i.e. 0.3 rad at cogging order 72. The logged
/// angle's own ripple at that order (65 Hz in holding) passes into the simulated encoder by
/// only the bandwidth over its frequency, a tenth.
pub const ANGLE_LOCK_RAD_S: f64 = 40.0;

/// `rig` without its cogging harmonics.
fn without_cogging(rig: &Rig) -> Rig {
    let mut r = rig.clone();
    for c in &mut r.motor.cogging {
        c.amplitude_nm = 0.0;
    }
    r
}

/// `rig`'s cogging torque (eq. 16) by the plant model's own motor equations; `None` when
/// `rig` has none.
fn cogging_of(rig: &Rig) -> Option<Motor> {
    rig.motor
        .cogging
        .iter()
        .any(|c| c.amplitude_nm != 0.0)
        .then(|| Motor::new(&rig.motor))
}

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
    replay_closed_loop_rows(log, rig, usize::MAX, Reference::Setpoints)
}

/// What the replayed controller is sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    /// The logged setpoints ([`scenario_of`]): the whole loop, pressure loop included.
    Setpoints,
    /// The logged speed reference, period by period, to the speed loop (the inner loops
    /// replayed from the signal at their boundary; the setpoints when no speed reference
    /// is logged).
    SpeedReference,
}

/// The speed-loop replay's scenario: speed control from the first logged speed reference.
fn speed_reference_scenario(log: &BenchLog, speed_ref: &[f64]) -> Scenario {
    let mut events: [Option<(f64, Command)>; MAX_EVENTS] = [None; MAX_EVENTS];
    events[0] = Some((
        0.0,
        Command::SetSpeed {
            rad_s: speed_ref[0] as f32,
        },
    ));
    events[1] = Some((0.0, Command::SetMode(Mode::Speed)));
    Scenario {
        name: "log replay",
        description: "the log's speed reference",
        kind: ScenarioKind::SpeedStep,
        blocked: !piston_moves(log),
        initial_pressure_pa: log.p_pa[0],
        duration_s: log.t_s[log.len() - 1],
        steady_from_s: 0.0,
        events,
    }
}

/// [`replay_closed_loop`] over the first `rows` rows only (an identification segment),
/// the controller sent `reference`.
pub fn replay_closed_loop_rows(
    log: &BenchLog,
    rig: &Rig,
    rows: usize,
    reference: Reference,
) -> Option<ClosedLoopReplay> {
    let speed_ref = match reference {
        Reference::SpeedReference => log.speed_ref_rad_s.as_deref(),
        Reference::Setpoints => None,
    };
    let scenario = match speed_ref {
        Some(w) => speed_reference_scenario(log, w),
        None => scenario_of(log)?,
    };
    let theta = log.theta_m_rad.as_deref().map(super::replay::unwrap_angle);
    let injected = theta.as_ref().and(cogging_of(rig));
    let mut quiet = match injected {
        Some(_) => without_cogging(rig),
        None => rig.clone(),
    };
    quiet.sensors.current.noise_a_rms = 0.0;
    quiet.sensors.pressure.noise_pa_rms = 0.0;
    quiet.sensors.dc_link.noise_v_rms = 0.0;
    let config = controller_config(rig);
    let speed_limit = config.speed.speed_limit_rad_s;
    let mut cl = ClosedLoop::new(&quiet, &config, &scenario, 0).ok()?;
    let n = log.len();
    let mut out = ClosedLoopReplay {
        p_pa: Vec::with_capacity(n),
        speed_rad_s: Vec::with_capacity(n),
        iq_a: Vec::with_capacity(n),
        id_a: Vec::with_capacity(n),
    };
    let t0 = log.t_s[0];
    let pull = ANGLE_LOCK_RAD_S * cl.period_s();
    let mut row = 0;
    let mut last = cl.step();
    let mut next_row = 0;
    for &t in &log.t_s[..rows.min(log.len())] {
        // Each row takes the telemetry of the period whose sample instant is nearest.
        while cl.time_s() + 0.5 * cl.period_s() <= t - t0 {
            if let Some(w) = speed_ref {
                // The pressure loop's output the row after this instant logged: the value
                // the real speed loop was following by then.
                let now = cl.time_s() + t0;
                while next_row + 1 < log.len() && log.t_s[next_row] < now {
                    next_row += 1;
                }
                let rad_s = (w[next_row] as f32).clamp(-speed_limit, speed_limit);
                // In range by the clamp, so the controller accepts it.
                let _ = cl.command(Command::SetSpeed { rad_s });
            }
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
                if let Some(m) = &injected {
                    cl.set_external_torque_nm(m.cogging_torque_nm(reference));
                }
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
