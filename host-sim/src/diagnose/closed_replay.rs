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
//! When the log has the shaft angle, the inner-loop replay ([`Reference::SpeedReference`];
//! the whole loop runs free, its shaft speed being what it predicts) has a kinematic phase
//! lock keep the simulated shaft near
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
//! - The pump's torque ripple (eq. 20's instantaneous displacement times the port
//!   pressure difference), likewise a torque of the shaft angle, is taken out of the plant
//!   and applied at the logged angle with the plant model's own
//!   [`Pump::displacement_factor`], times the replayed pressure difference: at order 18 the
//!   10 mrad lag would be 0.2 rad of its fundamental and 0.7 rad of its fourth harmonic.
//!   Its flow ripple goes with it; at a few hundred pascals against the chambers' oil it is
//!   far below the transducer's resolution.
//!
use super::predict::piston_moves;
use crate::bench_log::BenchLog;
use closed_loop::scenario::MAX_EVENTS;
use closed_loop::{controller_config, ClosedLoop, Scenario, ScenarioKind};
use firmware::{Command, Mode};
use plant_model::motor::{Motor, Phasor};
use plant_model::pump::Pump;
use plant_model::Rig;

/// Bandwidth of the kinematic angle lock. [rad/s]
///
/// A rig within tolerance runs a few percent faster or slower than the nominal model (a
/// 3 % rate error at the holding speed of 6 rad/s is 0.17 rad/s): the lock's lag is that
/// over the bandwidth, 4 mrad at 40 rad/s, i.e. 0.3 rad at cogging order 72. The logged
/// angle's own ripple at that order (65 Hz in holding) passes into the simulated encoder by
/// only the bandwidth over its frequency, a tenth.
pub const ANGLE_LOCK_RAD_S: f64 = 40.0;

/// The torques of the shaft angle alone a replay applies at the logged angle instead of
/// the plant: the motor's cogging (eq. 16) and the pump's torque ripple (eq. 20), each by
/// the plant model's own equations.
struct AngleLockedTorques {
    /// The motor, when the rig has cogging.
    cogging: Option<Motor>,
    /// The pump, when the rig has piston ripple.
    ripple: Option<Pump>,
}

impl AngleLockedTorques {
    /// `rig`'s angle-locked torques; `None` when it has neither.
    fn of(rig: &Rig) -> Option<AngleLockedTorques> {
        let cogging = rig
            .motor
            .cogging
            .iter()
            .any(|c| c.amplitude_nm != 0.0)
            .then(|| Motor::new(&rig.motor));
        let ripple = rig.pump.piston_ripple.then(|| Pump::new(&rig.pump));
        (cogging.is_some() || ripple.is_some()).then_some(AngleLockedTorques { cogging, ripple })
    }

    /// `rig` without them.
    fn removed_from(&self, rig: &Rig) -> Rig {
        let mut r = rig.clone();
        for c in &mut r.motor.cogging {
            c.amplitude_nm = 0.0;
        }
        r.pump.piston_ripple = false;
        r
    }

    /// Their torque on the shaft at shaft angle `theta` [rad] with the port pressures
    /// (p_A, p_B) [Pa], in the motor's direction. [N·m]
    fn torque_nm(&self, theta: f64, (p_a, p_b): (f64, f64)) -> f64 {
        // One sine and cosine of the angle serve both.
        let rot = Phasor::of(theta);
        let cogging = self
            .cogging
            .as_ref()
            .map_or(0.0, |m| m.cogging_torque_at(rot));
        // The plant without the ripple loads the shaft with the mean displacement (factor
        // 1); the rest of the pump's own load torque opposes the motor.
        let ripple = self.ripple.as_ref().map_or(0.0, |p| {
            let factor = p.displacement_factor_at(theta, rot);
            p.load_torque(p_a, p_b, 1.0) - p.load_torque(p_a, p_b, factor)
        });
        cogging + ripple
    }
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
    Some(log_scenario(log, "the log's setpoints", kind, events))
}

/// A replay scenario of `log` with `events`: piston blocked unless the log shows it
/// moving, the logged initial pressure, the log's length.
fn log_scenario(
    log: &BenchLog,
    description: &'static str,
    kind: ScenarioKind,
    events: [Option<(f64, Command)>; MAX_EVENTS],
) -> Scenario {
    Scenario {
        name: "log replay",
        description,
        kind,
        blocked: !piston_moves(log),
        initial_pressure_pa: log.p_pa[0],
        duration_s: log.t_s[log.len() - 1],
        steady_from_s: 0.0,
        events,
    }
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
    log_scenario(
        log,
        "the log's speed reference",
        ScenarioKind::SpeedStep,
        events,
    )
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
    let n = log.len();
    // The rows replayed and the one after (the angle is interpolated towards it).
    let used = rows.saturating_add(1).min(n);
    let theta = log
        .theta_m_rad
        .as_deref()
        .map(|th| super::replay::unwrap_angle(&th[..used]));
    let injected = theta.as_ref().and(AngleLockedTorques::of(rig));
    let mut quiet = match &injected {
        Some(a) => a.removed_from(rig),
        None => rig.clone(),
    };
    quiet.sensors.current.noise_a_rms = 0.0;
    quiet.sensors.pressure.noise_pa_rms = 0.0;
    quiet.sensors.dc_link.noise_v_rms = 0.0;
    let config = controller_config(rig);
    let speed_limit = config.speed.speed_limit_rad_s;
    let mut cl = ClosedLoop::new(&quiet, &config, &scenario, 0).ok()?;
    let mut out = ClosedLoopReplay {
        p_pa: Vec::with_capacity(n),
        speed_rad_s: Vec::with_capacity(n),
        iq_a: Vec::with_capacity(n),
        id_a: Vec::with_capacity(n),
    };
    let t0 = log.t_s[0];
    // Only the inner loops are locked: the whole loop's shaft speed is what it predicts
    // (the pump speed that holds the pressure against the leakage), which a pull to the
    // logged angle would impose instead.
    let locked = reference == Reference::SpeedReference;
    let pull = ANGLE_LOCK_RAD_S * cl.period_s();
    // The logged interval [row, row + 1] holding the period about to run.
    let mut row = 0;
    let mut last = cl.step();
    for &t in &log.t_s[..rows.min(n)] {
        // Each row takes the telemetry of the period whose sample instant is nearest.
        while cl.time_s() + 0.5 * cl.period_s() <= t - t0 {
            let now = cl.time_s() + t0;
            while row + 2 < used && log.t_s[row + 1] <= now {
                row += 1;
            }
            let f = ((now - log.t_s[row]) / (log.t_s[row + 1] - log.t_s[row])).clamp(0.0, 1.0);
            if let Some(w) = speed_ref {
                // The pressure loop's output the first row at or after this instant logged:
                // the value the real speed loop was following by then.
                let next = if f > 0.0 { row + 1 } else { row };
                let rad_s = (w[next] as f32).clamp(-speed_limit, speed_limit);
                // In range by the clamp, so the controller accepts it.
                let _ = cl.command(Command::SetSpeed { rad_s });
            }
            if let Some(th) = &theta {
                // The logged angle at this instant (linear between rows).
                let reference = th[row] + (th[row + 1] - th[row]) * f;
                // The simulated shaft starts at angle 0, the logged one at th[0].
                if locked {
                    let e = reference - th[0] - cl.plant().shaft_angle_rad();
                    cl.shift_shaft_angle(pull * e);
                }
                if let Some(a) = &injected {
                    let ports = cl.plant().port_pressures_pa();
                    cl.set_external_torque_nm(a.torque_nm(reference, ports));
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

/// Pressure error, relative to the setpoint, within which the log holds its setpoint: the
/// fill's overshoot has died out to a few times the transducer's noise (10 kPa at 5 MPa,
/// against the mean's noise of 0.3 kPa over [`HOLD_MEAN_ROWS`]). [1]
pub const HOLD_BAND: f64 = 0.002;

/// Rows of the centred mean the hold test applies to the logged pressure (the transducer's
/// noise would otherwise break the band). [1]
pub const HOLD_MEAN_ROWS: usize = 21;

/// Time after which a hold no longer shows how it began: the whole loop settles from a
/// cold start at the held pressure in 0.1–0.2 s (the speed loop's integral builds the
/// holding torque, the pressure loop's the leakage speed; the suite's holding logs), and
/// the real loop's recovery from the fill's overshoot takes as long. [s]
pub const HOLD_SETTLING_S: f64 = 0.3;

/// First row of the pressure hold the log ends in: after it the logged pressure (its mean
/// over [`HOLD_MEAN_ROWS`]) stays within [`HOLD_BAND`] of a positive setpoint; `None`
/// without pressure control or when the log does not end holding.
pub fn final_hold_start(log: &BenchLog) -> Option<usize> {
    let n = log.len();
    let half = HOLD_MEAN_ROWS / 2;
    if n <= 2 * half {
        return None;
    }
    let width = 2 * half + 1;
    // holding[j]: row j + half, the centre of window j, holds.
    let holding: Vec<bool> = log
        .p_pa
        .windows(width)
        .zip(&log.p_ref_pa[half..])
        .map(|(w, &r)| {
            let mean = w.iter().sum::<f64>() / width as f64;
            r > 0.0 && (mean - r).abs() <= HOLD_BAND * r
        })
        .collect();
    if !holding.last().copied().unwrap_or(false) {
        return None;
    }
    let first = holding.iter().rposition(|h| !h).map_or(0, |j| j + 1);
    Some(first + half)
}

/// The pump speed of the whole loop holding the log's final pressure hold, replayed from
/// that hold's first row (its logged pressure, the controller cold): the rows before are
/// the logged speed, unscored (see [`hold_scored_from`]). In a hold the pump turns just fast
/// enough to replace the leakage, whatever happened before; a replay through the fill
/// before it would carry the fill's timing error (a few percent of its length, from the
/// absorber's tolerances) into a hold that, in the replay, has not begun yet. `None`
/// without a final pressure hold.
pub fn replay_pressure_hold(log: &BenchLog, rig: &Rig, rows: usize) -> Option<Vec<f64>> {
    let k0 = final_hold_start(log)?;
    let rows = rows.min(log.len());
    let mut speed = log.speed_rad_s[..k0.min(rows)].to_vec();
    if rows > k0 {
        let tail = log.tail(k0);
        let r = replay_closed_loop_rows(&tail, rig, rows - k0, Reference::Setpoints)?;
        speed.extend(r.speed_rad_s);
    }
    Some(speed)
}

/// First row a hold replay ([`replay_pressure_hold`]) predicts: [`HOLD_SETTLING_S`] into
/// the final hold.
pub fn hold_scored_from(log: &BenchLog) -> Option<usize> {
    let k0 = final_hold_start(log)?;
    let t = log.t_s[k0] + HOLD_SETTLING_S;
    Some(log.t_s.partition_point(|x| *x < t))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1 kHz pressure-control log at setpoint 5 MPa whose pressure is `low` before row
    /// `step` and exactly the setpoint from it on.
    fn stepped(n: usize, step: usize, low: f64) -> BenchLog {
        BenchLog {
            t_s: (0..n).map(|k| k as f64 * 1e-3).collect(),
            p_ref_pa: vec![5e6; n],
            p_pa: (0..n).map(|k| if k < step { low } else { 5e6 }).collect(),
            speed_rad_s: vec![0.0; n],
            iq_a: vec![0.0; n],
            id_a: vec![0.0; n],
            ..BenchLog::default()
        }
    }

    #[test]
    fn the_final_hold_starts_where_the_mean_pressure_enters_the_band() {
        // 100 kPa below the setpoint until row 400: a 21-row mean is within 0.2 % (10 kPa)
        // once at most 2 of its rows are low (2·100/21 = 9.5 kPa, 3 rows 14.3 kPa), i.e.
        // from the window starting at row 398, centred on row 408.
        let log = stepped(1000, 400, 4.9e6);
        assert_eq!(final_hold_start(&log), Some(408));
        // Scored 0.3 s later.
        assert_eq!(hold_scored_from(&log), Some(708));
        // A log that ends 100 kPa off its setpoint is not holding.
        let log = stepped(1000, 2000, 4.9e6);
        assert_eq!(final_hold_start(&log), None);
        // Without a pressure setpoint there is no hold.
        let mut log = stepped(1000, 400, 4.9e6);
        log.p_ref_pa = vec![0.0; 1000];
        assert_eq!(final_hold_start(&log), None);
    }

    #[test]
    fn a_tail_restarts_its_time_and_keeps_its_rows() {
        let log = stepped(1000, 400, 4.9e6);
        let tail = log.tail(400);
        assert_eq!(tail.len(), 600);
        assert_eq!(tail.t_s[0], 0.0);
        assert!((tail.t_s[599] - 0.599).abs() < 1e-12);
        assert!(tail.p_pa.iter().all(|p| *p == 5e6));
        assert!(tail.theta_m_rad.is_none());
    }
}
