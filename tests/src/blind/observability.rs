//! What the generator measures of its own draws, from the truth it knows and the diagnosis
//! never sees: each hidden effect's signature against the sensor noise, the rule an
//! independent bench's generator keeps its draws by (`shared/data/foreign-logs-2/`).
//!
//! The signature of an effect is the log with it minus the log without it, both free of
//! sensor noise (the converters' and the encoder's quantisation stay), on the same rig,
//! controller and test; in a pair, the other effect is present in both. It is measured as
//! a root-mean-square over the whole log, per logged signal, against that signal's sensor
//! noise as an engineer estimates it from the log itself ([`noise_rms`]); an effect shows
//! when its signature is at least [`SHOWN_RATIO`] times the noise on some signal the log
//! holds.
//!
//! A closed loop can take one of two paths where a small difference tips it (the pressure
//! loop crossing the absorber's precharge chatters or collapses, or not): there any
//! perturbation, however small, makes a large on-minus-off. So the signature must also
//! scale with the effect: at half its departure from the rig ([`super::catalogue::halfway`])
//! it must be between [`HALF_SCALING`] of the full one on the same signal. An effect that
//! fails either is drawn again.

use super::catalogue::halfway;
use super::drawn::Draw;
use host_sim::bench_log::{BenchLog, Signal};

/// How far above the noise an effect must stand on some logged signal to be kept. [1]
pub const SHOWN_RATIO: f64 = 5.0;

/// The signals a signature is measured on: every measured column of a bench log (the
/// references and the shaft angle are the drive's own, not measurements).
pub const MEASURED: [Signal; 8] = [
    Signal::Pressure,
    Signal::PressureLow,
    Signal::PistonPosition,
    Signal::Speed,
    Signal::Iq,
    Signal::Id,
    Signal::Ud,
    Signal::Uq,
];

/// How one hidden effect shows on one signal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shown {
    /// The logged signal.
    pub signal: Signal,
    /// The signature over the noise. [1]
    pub ratio: f64,
    /// The signature at half the effect's departure over the full one (NaN when not
    /// measured). [1]
    pub half_over_full: f64,
}

impl Shown {
    /// Whether it stands [`SHOWN_RATIO`] above the noise and scales with its effect
    /// ([`HALF_SCALING`]).
    pub fn accepted(&self) -> bool {
        self.ratio >= SHOWN_RATIO
            && (HALF_SCALING.0..=HALF_SCALING.1).contains(&self.half_over_full)
    }
}

/// Range of the half-strength signature over the full one, on one signal, for a signature
/// that scales with its effect (0.5 where it is proportional). [1]
pub const HALF_SCALING: (f64, f64) = (0.25, 0.75);

/// Root-mean-square of `a − b`.
fn rms_difference(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()).max(1);
    let sum: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    (sum / n as f64).sqrt()
}

/// The signals `log` holds among [`MEASURED`], with their columns.
fn logged(log: &BenchLog) -> Vec<(Signal, &[f64])> {
    MEASURED
        .iter()
        .filter_map(|&s| log.column(s).map(|c| (s, c)))
        .collect()
}

/// The RMS of the white noise on `y`, from its second differences (which take out any
/// motion slower than a few samples; their variance is 6σ² for white noise): the median
/// absolute second difference, made a standard deviation by 1.4826 (robust to the steps
/// and transients of the test), over √6; a quantised signal whose second differences are
/// mostly zero falls back to their RMS over √6. Never below the quantisation noise of the
/// signal's smallest step, step/√12; differences below 1e-9 of the signal's magnitude are
/// rounding, not noise. [unit of `y`]
pub fn noise_rms(y: &[f64]) -> f64 {
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let eps = 1e-9 * scale;
    let clean = |d: f64| if d.abs() > eps { d.abs() } else { 0.0 };
    let step = y
        .windows(2)
        .map(|w| clean(w[1] - w[0]))
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let mut d2: Vec<f64> = y
        .windows(3)
        .map(|w| clean(w[2] - 2.0 * w[1] + w[0]))
        .collect();
    if d2.is_empty() || !step.is_finite() {
        return 0.0;
    }
    let rms = (d2.iter().map(|d| d * d).sum::<f64>() / d2.len() as f64).sqrt();
    let mid = d2.len() / 2;
    let (_, median, _) = d2.select_nth_unstable_by(mid, f64::total_cmp);
    let sigma = if *median > 0.0 { 1.4826 * *median } else { rms };
    (sigma / 6f64.sqrt()).max(step / 12f64.sqrt())
}

/// The sensor noise of each signal `log` holds among [`MEASURED`] ([`noise_rms`]); a signal
/// without noise (a blocked piston's position) is left out. [unit]
pub fn noise_by_signal(log: &BenchLog) -> Vec<(Signal, f64)> {
    logged(log)
        .into_iter()
        .map(|(s, y)| (s, noise_rms(y)))
        .filter(|(_, n)| *n > 0.0)
        .collect()
}

/// Where the effect whose signature is `with − without` shows, against `noise`: the
/// accepted signal ([`Shown::accepted`]) of the largest ratio, or, when none is, the signal
/// of the largest ratio (`None` when no signal has noise). `half` is the log at half the
/// effect (`None`: not measured).
pub fn shown(
    with: &BenchLog,
    without: &BenchLog,
    half: Option<&BenchLog>,
    noise: &[(Signal, f64)],
) -> Option<Shown> {
    let table: Vec<Shown> = noise
        .iter()
        .filter_map(|&(s, n)| {
            let (w, wo) = (with.column(s)?, without.column(s)?);
            let full = rms_difference(w, wo);
            let half_over_full = half.and_then(|h| h.column(s)).map_or(f64::NAN, |h| {
                rms_difference(h, wo) / full.max(f64::MIN_POSITIVE)
            });
            Some(Shown {
                signal: s,
                ratio: full / n,
                half_over_full,
            })
        })
        .collect();
    let largest = |it: &mut dyn Iterator<Item = &Shown>| {
        it.max_by(|a, b| a.ratio.total_cmp(&b.ratio)).copied()
    };
    largest(&mut table.iter().filter(|s| s.accepted())).or_else(|| largest(&mut table.iter()))
}

/// What the check of one draw measured and produced.
#[derive(Clone, Debug)]
pub struct Checked {
    /// The log the bench records: the truth rig, with noise, every column (the draw's
    /// dropped columns are taken out when it is written).
    pub log: BenchLog,
    /// Per hidden effect, in the draw's order: where it shows.
    pub shown: Vec<Shown>,
    /// The sensor noise of each logged signal. [unit]
    pub noise: Vec<(Signal, f64)>,
}

impl Checked {
    /// Whether every hidden effect is accepted.
    pub fn every_effect_shows(&self) -> bool {
        self.shown.iter().all(Shown::accepted)
    }
}

/// Runs `d` with each of its effects, without it and at half of it, and measures where each
/// shows; the signals counted are those the written log keeps (not the draw's dropped
/// columns). One noisy run (the log) and 1 + 2·(number of effects) noise-free runs; a
/// draw hiding nothing runs once.
pub fn check(d: &Draw) -> Result<Checked, String> {
    let truth = d.truth_rig();
    let log = d.log(&truth, Some(d.noise_seed))?;
    if d.effects.is_empty() {
        return Ok(Checked {
            log,
            shown: Vec::new(),
            noise: Vec::new(),
        });
    }
    let mut kept = log.clone();
    d.structure.drop_columns(&mut kept);
    let noise = noise_by_signal(&kept);
    let clean = d.log(&truth, None)?;
    let mut shown_by_effect = Vec::with_capacity(d.effects.len());
    for (k, effect) in d.effects.iter().enumerate() {
        let without_rig = d.rig_without(k);
        let without = d.log(&without_rig, None)?;
        let mut half_rig = without_rig.clone();
        halfway(effect, &without_rig).apply(&mut half_rig);
        let half = d.log(&half_rig, None)?;
        let s = shown(&clean, &without, Some(&half), &noise).ok_or("no logged signal has noise")?;
        shown_by_effect.push(s);
    }
    Ok(Checked {
        log,
        shown: shown_by_effect,
        noise,
    })
}
