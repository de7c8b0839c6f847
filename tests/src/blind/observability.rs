//! What the blind suite's generator measures of its own draws, from the truth it knows and
//! the diagnosis never sees: each hidden effect's signature against the sensor noise, and,
//! for the lines below the noise per sample (a piston ripple; a dead time without voltage
//! columns), the most any angle-locked model could gain on the log — the bound below which
//! a log cannot tell the effect from `none`.

use super::{Draw, BELOW_NOISE};
use host_sim::bench_log::{BenchLog, Signal};
use plant_model::pump::ripple_order;
use plant_model::{Effect, Rig};

/// `rig` with the white noise of every sensor off (quantisation stays).
fn noise_free(rig: &Rig) -> Rig {
    let mut r = rig.clone();
    r.sensors.current.noise_a_rms = 0.0;
    r.sensors.pressure.noise_pa_rms = 0.0;
    r.sensors.dc_link.noise_v_rms = 0.0;
    r
}

/// Root-mean-square of `a − b` over the rows with `t ≥ t_from`.
fn rms_difference(t: &[f64], a: &[f64], b: &[f64], t_from: f64) -> f64 {
    let (sum, n) = t
        .iter()
        .zip(a.iter().zip(b))
        .filter(|(t, _)| **t >= t_from)
        .fold((0.0, 0usize), |(s, n), (_, (x, y))| {
            (s + (x - y) * (x - y), n + 1)
        });
    (sum / n.max(1) as f64).sqrt()
}

/// One signal's signature of an effect in a closed-loop log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Signature {
    /// RMS of (with effect − without), both noise-free: the effect's own trace. [unit]
    pub effect_rms: f64,
    /// RMS noise of the signal: RMS of the difference of two effect-free runs with
    /// different noise seeds, over √2. [unit]
    pub noise_rms: f64,
    /// Standard deviation of the signal in the truth log (what the fit measure divides
    /// by). [unit]
    pub spread: f64,
}

impl Signature {
    /// Effect over noise. [1]
    pub fn ratio(&self) -> f64 {
        self.effect_rms / self.noise_rms.max(f64::MIN_POSITIVE)
    }

    /// The most the fit percentage 100·(1 − ‖y − ŷ‖/‖y − ȳ‖) can gain when a model that
    /// misses the effect (error ≈ effect + noise) is replaced by one that has it (error ≈
    /// noise). [percentage points]
    pub fn attainable_fit_gain(&self) -> f64 {
        let e = self.effect_rms;
        let n = self.noise_rms;
        100.0 * ((e * e + n * n).sqrt() - n) / self.spread.max(f64::MIN_POSITIVE)
    }
}

/// The signature of `draw`'s effect on `signal`, measured after `t_from` [s]: the
/// noise-free truth log against the noise-free log of the same plant without the effect
/// (the ADCs' and encoder's quantisation stay); the noise from two noisy effect-free runs
/// with different noise seeds.
pub fn signature(d: &Draw, signal: Signal, t_from: f64) -> Result<Signature, String> {
    let with = d.run(&noise_free(&d.truth_rig()), d.noise_seed)?;
    let without = d.run(&noise_free(&d.tolerance_rig), d.noise_seed)?;
    let noisy = d.run(&d.tolerance_rig, d.noise_seed)?;
    let truth = d.run(&d.truth_rig(), d.noise_seed)?;
    let other = d.run(&d.tolerance_rig, d.noise_seed ^ 0x9e37_79b9_7f4a_7c15)?;
    let col = |l: &BenchLog| -> Result<Vec<f64>, String> {
        l.column(signal)
            .map(<[f64]>::to_vec)
            .ok_or_else(|| format!("column {} not logged", signal.name()))
    };
    let (w, wo, n, o) = (col(&with)?, col(&without)?, col(&noisy)?, col(&other)?);
    let y = col(&truth)?;
    let (sum, rows) = truth
        .t_s
        .iter()
        .zip(&y)
        .filter(|(t, _)| **t >= t_from)
        .fold((0.0, 0usize), |(s, n), (_, y)| (s + y, n + 1));
    let mean = vec![sum / rows.max(1) as f64; y.len()];
    Ok(Signature {
        effect_rms: rms_difference(&with.t_s, &w, &wo, t_from),
        noise_rms: rms_difference(&with.t_s, &n, &o, t_from) / 2f64.sqrt(),
        spread: rms_difference(&truth.t_s, &y, &mean, t_from),
    })
}

/// Whether `d` hides a line below the noise per sample: a piston ripple (always), or a dead
/// time whose log has no voltages (its current lines at 6·p_n are a fraction of the
/// current's noise per sample at the low end of its range). Such a draw is judged by
/// [`line_fit_bound`], not by its per-sample signature.
pub fn line_below_noise(d: &Draw) -> bool {
    BELOW_NOISE.contains(&d.truth.effect_name)
        || (d.truth.effect_name == "dead_time" && d.truth.signal != Signal::Uq.name())
}

/// For a draw of [`line_below_noise`], the most a model with the line could gain on the
/// truth's signal or the speed over the log's second half ([`angle_locked_fit_bound`] at the line's
/// orders: the ripple's harmonics, or 6·p_n and 12·p_n for a dead time); `None` for any
/// other draw. When it is below the suite's 10 points, this log does not tell the effect
/// from `none` at the suite's standard. [percentage points]
pub fn line_fit_bound(d: &Draw) -> Result<Option<f64>, String> {
    if !line_below_noise(d) {
        return Ok(None);
    }
    let orders = match d.effect {
        Effect::PistonRipple { pistons, .. } => ripple_orders(pistons),
        _ => {
            let p = d.tolerance_rig.motor.pole_pairs;
            vec![6 * p, 12 * p]
        }
    };
    let signal = Signal::from_name(d.truth.signal)
        .ok_or_else(|| format!("{} is not a bench-log column", d.truth.signal))?;
    // A torque line shows in the q current and, as far as the speed loop lets it through,
    // in the speed: the better of the two (which one depends on the controller's tuning).
    let bound = angle_locked_fit_bound(
        d,
        &[signal, Signal::Speed],
        d.truth.duration_s / 2.0,
        &orders,
    )?;
    Ok(bound.into_iter().reduce(f64::max))
}

/// Every logged signal a diagnosis is scored on (`fit_percent_by_signal` and the voltages
/// and d current the subsystem replays predict).
pub const LOGGED: [Signal; 6] = [
    Signal::Pressure,
    Signal::Speed,
    Signal::Iq,
    Signal::Id,
    Signal::Ud,
    Signal::Uq,
];

/// Harmonics of the piston ripple's fundamental an angle-locked bound fits (the kinematic
/// shape's cusps put nearly all of its power in the first few).
pub const RIPPLE_HARMONICS: u32 = 4;

/// The orders (cycles per shaft revolution) of a `z`-piston pump's ripple up to
/// [`RIPPLE_HARMONICS`].
pub fn ripple_orders(z: u32) -> Vec<u32> {
    (1..=RIPPLE_HARMONICS)
        .map(|k| k * ripple_order(z))
        .collect()
}

/// The most a model could gain on each of `signals` after `t_from` by adding, to a PERFECT
/// effect-free model of the drawn rig (its exact tolerances, noise-free), any periodic
/// function of the logged shaft angle at `orders` (cycles per revolution): the function is
/// fitted by least squares to the very rows it is scored on, so this is an upper bound on
/// what any angle-locked extension can gain on a validation segment, for any parameters of
/// it. [percentage points, per signal]
pub fn angle_locked_fit_bound(
    d: &Draw,
    signals: &[Signal],
    t_from: f64,
    orders: &[u32],
) -> Result<Vec<f64>, String> {
    let truth = d.run(&d.truth_rig(), d.noise_seed)?;
    let perfect = d.run(&noise_free(&d.tolerance_rig), d.noise_seed)?;
    let theta = truth
        .theta_m_rad
        .as_deref()
        .ok_or("the shaft angle is not logged")?;
    let rows: Vec<usize> = (0..truth.t_s.len())
        .filter(|&i| truth.t_s[i] >= t_from && i < perfect.t_s.len())
        .collect();
    let basis = nalgebra::DMatrix::from_fn(rows.len(), 2 * orders.len(), |r, c| {
        let phase = f64::from(orders[c / 2]) * theta[rows[r]];
        if c % 2 == 0 {
            phase.cos()
        } else {
            phase.sin()
        }
    });
    let svd = basis.clone().svd(true, true);
    signals
        .iter()
        .map(|&signal| {
            let missing = || format!("column {} not logged", signal.name());
            let y = truth.column(signal).ok_or_else(missing)?;
            let m = perfect.column(signal).ok_or_else(missing)?;
            let residual =
                nalgebra::DVector::from_iterator(rows.len(), rows.iter().map(|&i| y[i] - m[i]));
            let coefficients = svd.solve(&residual, 1e-12)?;
            let left = &residual - &basis * coefficients;
            let mean = rows.iter().map(|&i| y[i]).sum::<f64>() / rows.len().max(1) as f64;
            let spread = rows
                .iter()
                .map(|&i| (y[i] - mean).powi(2))
                .sum::<f64>()
                .sqrt();
            Ok(100.0 * (residual.norm() - left.norm()) / spread.max(f64::MIN_POSITIVE))
        })
        .collect()
}
