//! The bench's own extra sensors, which the drive does not read: the low-side pressure
//! transducer (`p_low_pa`) and the piston's linear encoder (`x_m`). The closed loop gives
//! their true values; a bench logs them through a transducer like the drive's own (its
//! scale, white noise and zero error) and a 1 µm linear scale, and so does the generator.

use host_sim::bench_log::BenchLog;
use plant_model::Rig;
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Resolution of the piston's linear scale (a glass or magnetic scale of an ordinary
/// bench). [m]
pub const POSITION_RESOLUTION_M: f64 = 1e-6;

/// The low-side transducer of one bench.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LowSideTransducer {
    /// Zero error, within the data sheet's 0.1 % of a 25 MPa span. [Pa]
    pub offset_pa: f64,
    /// White noise, rms. [Pa]
    pub noise_pa_rms: f64,
    /// Scale of its converter. [Pa/LSB]
    pub pa_per_lsb: f64,
}

impl LowSideTransducer {
    /// The drive's own pressure transducer type (`rig.sensors.pressure`) with the zero
    /// error `offset_pa` [Pa].
    pub fn like_the_drives(rig: &Rig, offset_pa: f64) -> LowSideTransducer {
        let p = &rig.sensors.pressure;
        LowSideTransducer {
            offset_pa,
            noise_pa_rms: p.noise_pa_rms,
            pa_per_lsb: p.pa_per_lsb,
        }
    }
}

/// Standard normal deviates by the Box–Muller transform of the seeded xoshiro stream.
struct Gauss(Xoshiro256PlusPlus);

impl Gauss {
    fn unit(&mut self) -> f64 {
        ((self.0.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        let (u, v) = (self.unit(), self.unit());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// `value` rounded to whole steps of `step`.
fn quantise(value: f64, step: f64) -> f64 {
    (value / step).round() * step
}

/// Replaces the true `p_low_pa` and `x_m` of `log` by what the bench's sensors read:
/// the transducer `low` (its white noise seeded by `noise_seed`, none when `None`) and the
/// linear scale.
pub fn read_through(log: &mut BenchLog, low: &LowSideTransducer, noise_seed: Option<u64>) {
    let mut gauss = noise_seed.map(|s| Gauss(Xoshiro256PlusPlus::seed_from_u64(s)));
    if let Some(p) = log.p_low_pa.as_mut() {
        for v in p.iter_mut() {
            let noise = gauss.as_mut().map_or(0.0, |g| low.noise_pa_rms * g.next());
            *v = quantise(*v + low.offset_pa + noise, low.pa_per_lsb);
        }
    }
    if let Some(x) = log.x_m.as_mut() {
        for v in x.iter_mut() {
            *v = quantise(*v, POSITION_RESOLUTION_M);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_transducer_adds_its_noise_offset_and_steps() {
        let low = LowSideTransducer {
            offset_pa: 1e4,
            noise_pa_rms: 1e3,
            pa_per_lsb: 500.0,
        };
        let n = 20_000;
        let mut log = BenchLog {
            p_low_pa: Some(vec![5e5; n]),
            x_m: Some(vec![1.2344e-3; n]),
            ..BenchLog::default()
        };
        read_through(&mut log, &low, Some(7));
        let p = log.p_low_pa.expect("kept");
        let mean = p.iter().sum::<f64>() / n as f64;
        let rms = (p.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        // Mean: the offset (±3σ/√n of the noise); spread: the noise and the steps'
        // uniform error, √(1000² + 500²/12) = 1010 Pa, within 3 %.
        assert!((mean - 5.1e5).abs() < 30.0, "{mean}");
        assert!((rms / 1010.3 - 1.0).abs() < 0.03, "{rms}");
        assert!(p.iter().all(|v| (v / 500.0).fract() == 0.0));
        assert!((log.x_m.expect("kept")[0] - 1.234e-3).abs() < 1e-12);
    }
}
