//! One closed-loop run turned into a bench log: the firmware's control core against the
//! plant through `closed_loop`, logged like the firmware's telemetry (the controller's
//! measured and commanded quantities) plus the plant-side columns a rig's extra sensors
//! would give (piston position, low-side pressure), and the true port pressure kept aside
//! for the pulsation study.
//!
//! A run is bounded before it starts: it may log at most the rows a bench log of its
//! [`LOGGED_COLUMNS`] may hold ([`most_rows`], [`log_plan`]); [`first_unphysical`]
//! finds where a run's state left the physical range (a rig the integration cannot follow),
//! for the commands to report instead of writing it.

use crate::bench_log::limits::{max_rows, physical_range};
use crate::bench_log::BenchLog;
use crate::feedforward::Feedforward;
use crate::output::progress::percent;
use closed_loop::{controller_config, ClosedLoop, Scenario};
use firmware::config::Config;
use firmware::parameters::ParamId;
use firmware::Command;
use plant_model::accumulator::Absorber;
use plant_model::{Integrator, Rig};
use std::time::Instant;

/// What a run produced.
pub struct Run {
    /// The bench log (every column the simulation knows).
    pub log: BenchLog,
    /// True port-A pressure at the log's instants. [Pa]
    pub p_true_pa: Vec<f64>,
    /// True shaft speed at the log's instants. [rad/s]
    pub speed_true_rad_s: Vec<f64>,
    /// The absorber's natural frequency and damping ratio at the run's mean pressure
    /// (0 when the absorber holds no oil). [Hz], [1]
    pub absorber_fn_hz: f64,
    /// The absorber's damping ratio at the run's mean pressure (0 when it holds no oil). [1]
    pub absorber_zeta: f64,
    /// Simulated seconds per wall-clock second. [1]
    pub real_time_factor: f64,
    /// Simulated seconds per second of the running thread's own CPU time (what the run
    /// costs, whatever else the machine is doing; the wall-clock factor where the platform
    /// has no thread clock). [1]
    pub cpu_real_time_factor: f64,
}

/// Options of a run.
pub struct RunOptions {
    /// Simulated length. [s]
    pub duration_s: f64,
    /// Log rate (the firmware's telemetry decimation gives 1 kHz at 20 kHz PWM). [Hz]
    pub log_rate_hz: f64,
    /// Sensor-noise seed.
    pub seed: u64,
    /// Show a progress bar when the run is expected to take over a second.
    pub progress: bool,
    /// Metadata lines for the log.
    pub metadata: Vec<(String, String)>,
    /// A torque feed-forward table (and the speed modulation's parameters) loaded into the
    /// controller before the run, and enabled, as the drive loads it from flash (`None`:
    /// uncompensated).
    pub compensation: Option<Feedforward>,
    /// The plant's integration scheme (the exponential one by default).
    pub integrator: Integrator,
}

/// Log rate of the bench logs `eha` simulates (`eha simulate`, `eha demo`, the holding
/// runs `eha compensate` and the precharge sweep predict with). [Hz]
pub const LOG_RATE_HZ: f64 = 2000.0;

/// The bench-log columns a run logs: the six required, the shaft angle, piston position,
/// low-side pressure, speed and current references and the three voltages.
pub const LOGGED_COLUMNS: usize = 14;

/// The most rows a run logs: those of a bench log of [`LOGGED_COLUMNS`] columns (the run
/// keeps two columns of truth beside them, 16 values a row, under 1 GiB at this bound).
pub const fn most_rows() -> usize {
    max_rows(LOGGED_COLUMNS)
}

/// How a run of `duration_s` [s] is logged at `log_rate_hz` [Hz] with the PWM period
/// `period_s` [s]: every how many periods a row is taken, and how many rows that gives.
pub fn log_plan(duration_s: f64, log_rate_hz: f64, period_s: f64) -> (u32, f64) {
    let every = ((1.0 / log_rate_hz) / period_s)
        .round()
        .clamp(1.0, u32::MAX as f64) as u32;
    let rows = (duration_s / (period_s * every as f64)).ceil();
    (every, rows)
}

/// The first logged value outside its column's physical range (NaN included): its time,
/// column and value.
pub fn first_unphysical(log: &BenchLog) -> Option<(f64, &'static str, f64)> {
    let mut first: Option<(usize, &'static str, f64)> = None;
    for (signal, column) in log.columns() {
        let (low, high, _) = physical_range(signal);
        if let Some(i) = column.iter().position(|v| !(low..=high).contains(v)) {
            if first.is_none_or(|(j, _, _)| i < j) {
                first = Some((i, signal.name(), column[i]));
            }
        }
    }
    first.map(|(i, name, v)| (log.t_s.get(i).copied().unwrap_or(f64::NAN), name, v))
}

/// Installs `ff`'s table in the loop's controller, sets the speed modulation's parameters
/// and enables the feed-forward, as the drive does at boot from its stored table and
/// parameters (the amplitude and depth limits checked the same way).
pub fn load_compensation(cl: &mut ClosedLoop, ff: &Feedforward) -> Result<(), String> {
    let c = cl.controller_mut();
    c.install_compensation(&ff.table)
        .map_err(|e| format!("the drive refuses the table: {e}"))?;
    for (id, value) in ff.flow.iter().flat_map(|f| f.parameters()) {
        c.command(Command::SetParameter { id, value })
            .map_err(|e| format!("the drive refuses the speed modulation: {e}"))?;
    }
    c.command(Command::SetParameter {
        id: ParamId::CompensationEnabled,
        value: 1.0,
    })
    .map_err(|e| format!("the drive refuses to enable the table: {e}"))
}

/// Runs `scenario` on the plant `plant_rig`, controlled by the configuration of
/// `controller_rig` (the rig file the engineer believes in). Fails before any work if the
/// log would exceed [`most_rows`].
pub fn run(
    plant_rig: &Rig,
    controller_rig: &Rig,
    scenario: &Scenario,
    opt: &RunOptions,
) -> Result<Run, String> {
    run_with_config(plant_rig, &controller_config(controller_rig), scenario, opt)
}

/// Runs `scenario` on the plant `plant_rig` under the controller configuration `config`
/// (a tuned or otherwise non-default controller: other gains, another pressure loop).
pub fn run_with_config(
    plant_rig: &Rig,
    config: &Config,
    scenario: &Scenario,
    opt: &RunOptions,
) -> Result<Run, String> {
    let mut cl =
        ClosedLoop::new(plant_rig, config, scenario, opt.seed).map_err(|e| e.to_string())?;
    cl.plant_mut().set_integrator(opt.integrator);
    if let Some(table) = &opt.compensation {
        load_compensation(&mut cl, table)?;
    }
    let (every, rows) = log_plan(opt.duration_s, opt.log_rate_hz, cl.period_s());
    if rows.is_nan() || rows > most_rows() as f64 {
        return Err(format!(
            "{} s at {} Hz would log {rows:.0} rows; a bench log of its columns holds at most {}",
            opt.duration_s,
            opt.log_rate_hz,
            most_rows()
        ));
    }
    let n_rows = rows as usize;
    let mut log = BenchLog {
        metadata: opt.metadata.clone(),
        ..BenchLog::default()
    };
    let mut cols: [Vec<f64>; 8] = Default::default();
    let mut p_true = Vec::with_capacity(n_rows);
    let mut w_true = Vec::with_capacity(n_rows);
    let bar =
        (opt.progress && opt.duration_s > 20.0).then(|| percent(n_rows as u64, scenario.name));
    let started = Instant::now();
    let cpu_started = thread_cpu_s();
    let mut k = 0u64;
    cl.run(opt.duration_s, every, |s| {
        let t = &s.telemetry;
        log.t_s.push(s.truth.t_s);
        log.p_ref_pa.push(t.p_ref_pa as f64);
        log.p_pa.push(t.p_pa as f64);
        log.speed_rad_s.push(t.speed_rad_s as f64);
        log.iq_a.push(t.iq_a as f64);
        log.id_a.push(t.id_a as f64);
        for (c, v) in cols.iter_mut().zip([
            t.theta_m_rad as f64,
            s.truth.x_m,
            s.truth.p_b_pa,
            t.speed_ref_rad_s as f64,
            t.iq_ref_a as f64,
            t.ud_v as f64,
            t.uq_v as f64,
            t.udc_v as f64,
        ]) {
            c.push(v);
        }
        p_true.push(s.truth.p_a_pa);
        w_true.push(s.truth.omega_m_rad_s);
        k += 1;
        if let Some(b) = &bar {
            if k % 256 == 0 {
                b.set_position(k);
            }
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let wall = started.elapsed().as_secs_f64();
    let cpu = match (cpu_started, thread_cpu_s()) {
        (Some(a), Some(b)) => b - a,
        _ => wall,
    };
    let [theta, x, p_low, w_ref, iq_ref, ud, uq, udc] = cols;
    log.theta_m_rad = Some(theta);
    log.x_m = Some(x);
    log.p_low_pa = Some(p_low);
    log.speed_ref_rad_s = Some(w_ref);
    log.iq_ref_a = Some(iq_ref);
    log.ud_v = Some(ud);
    log.uq_v = Some(uq);
    log.udc_v = Some(udc);
    let steady_from_s = scenario.steady_from_s.min(opt.duration_s / 2.0);
    let (fn_hz, zeta) = absorber_at_mean(cl.plant().absorber(), &log.t_s, &p_true, steady_from_s);
    Ok(Run {
        log,
        p_true_pa: p_true,
        speed_true_rad_s: w_true,
        absorber_fn_hz: fn_hz,
        absorber_zeta: zeta,
        real_time_factor: opt.duration_s / wall.max(1e-9),
        cpu_real_time_factor: opt.duration_s / cpu.max(1e-9),
    })
}

/// The absorber's natural frequency [Hz] and damping ratio [1] at the mean of the true
/// port pressure `p_true` [Pa] from `steady_from_s` on (times `t_s`); zeros without one.
fn absorber_at_mean(
    absorber: &Absorber,
    t_s: &[f64],
    p_true: &[f64],
    steady_from_s: f64,
) -> (f64, f64) {
    let steady: Vec<f64> = t_s
        .iter()
        .zip(p_true)
        .filter(|(t, _)| **t >= steady_from_s)
        .map(|(_, p)| *p)
        .collect();
    let mean = steady.iter().sum::<f64>() / steady.len().max(1) as f64;
    if absorber.enabled {
        (
            absorber.natural_frequency_rad_s(mean) / (2.0 * std::f64::consts::PI),
            absorber.damping_ratio(mean),
        )
    } else {
        (0.0, 0.0)
    }
}

/// The calling thread's CPU time (user and system), if the platform has a thread clock. [s]
#[cfg(unix)]
fn thread_cpu_s() -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes it.
    let r = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (r == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
}

/// The calling thread's CPU time: none without a thread clock. [s]
#[cfg(not(unix))]
fn thread_cpu_s() -> Option<f64> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_logs_the_columns_its_row_bound_counts() {
        let rig = Rig::nominal();
        let scenario = closed_loop::by_name("pressure-hold").unwrap();
        let r = run(
            &rig,
            &rig,
            scenario,
            &RunOptions {
                duration_s: 0.01,
                log_rate_hz: 2000.0,
                seed: 1,
                progress: false,
                metadata: Vec::new(),
                compensation: None,
                integrator: Default::default(),
            },
        )
        .unwrap();
        assert_eq!(r.log.columns().count(), LOGGED_COLUMNS);
    }
}
