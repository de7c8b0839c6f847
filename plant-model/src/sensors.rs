//! Sensors as the MCU's peripherals see them: phase-current shunts and the DC-link divider
//! into 12-bit ADC channels, the pressure transducer into an oversampled 16-bit result, and
//! the quadrature encoder's counter with its index.
//!
//! Each reading is value + offset + white Gaussian noise, quantised by the ADC (rounded to
//! the nearest count and clipped to its range, as a saturated converter is). The pressure
//! transducer's first-order lag is a state of the plant ([`crate::plant`]); here it is read.
//! The encoder reports ⌊θ_enc/2π·N⌋ mod N with θ_enc = θ_m + offset/p_n, and flags the
//! index when a revolution boundary was crossed since the previous sample.

use crate::rig::SensorParams;
use core::f64::consts::PI;
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// What the MCU's peripherals return for one current-loop sample (the control core's
/// `Measurements`, field for field).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct SensorReadings {
    /// Phase-current ADC results a, b, c. [counts]
    pub adc_phase_current: [u16; 3],
    /// DC-link ADC result. [counts]
    pub adc_dc_link: u16,
    /// Pressure ADC result. [counts]
    pub adc_pressure: u16,
    /// Encoder counter, wrapping once per revolution. [counts]
    pub encoder_count: u32,
    /// Index pulse seen since the previous sample.
    pub encoder_index: bool,
}

/// Sensor models with their noise generator.
#[derive(Clone, Debug)]
pub struct Sensors {
    params: SensorParams,
    pole_pairs: f64,
    rng: Xoshiro256PlusPlus,
    spare_normal: Option<f64>,
    last_revolution: Option<i64>,
}

impl Sensors {
    /// From validated parameters and a noise seed.
    pub fn new(params: &SensorParams, pole_pairs: u32, seed: u64) -> Sensors {
        Sensors {
            params: params.clone(),
            pole_pairs: pole_pairs as f64,
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            spare_normal: None,
            last_revolution: None,
        }
    }

    /// Standard normal deviate (Marsaglia's polar method on the xoshiro stream).
    fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare_normal.take() {
            return z;
        }
        loop {
            let u = 2.0 * unit(self.rng.next_u64()) - 1.0;
            let v = 2.0 * unit(self.rng.next_u64()) - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let f = libm::sqrt(-2.0 * libm::log(s) / s);
                self.spare_normal = Some(v * f);
                return u * f;
            }
        }
    }

    fn noise(&mut self, rms: f64) -> f64 {
        if rms > 0.0 {
            rms * self.normal()
        } else {
            0.0
        }
    }

    /// Samples every sensor: true phase currents `i_abc`, DC link `u_dc`, the transducer's
    /// (lagged) pressure `p_sensed` and the shaft angle `theta_m` (unwrapped).
    pub fn sample(
        &mut self,
        i_abc: &[f64; 3],
        u_dc: f64,
        p_sensed: f64,
        theta_m: f64,
    ) -> SensorReadings {
        let c = self.params.current.clone();
        let mut adc_phase_current = [0u16; 3];
        for ((out, i), off) in adc_phase_current.iter_mut().zip(i_abc).zip(&c.offset_a) {
            let n = self.noise(c.noise_a_rms);
            *out = quantise(c.zero_lsb + (i + off + n) / c.a_per_lsb, c.bits);
        }
        let v = self.params.dc_link.clone();
        let nv = self.noise(v.noise_v_rms);
        let adc_dc_link = quantise((u_dc + nv) / v.v_per_lsb, v.bits);
        let p = self.params.pressure.clone();
        let np = self.noise(p.noise_pa_rms);
        let adc_pressure = quantise(
            p.zero_lsb + (p_sensed + p.offset_pa + np) / p.pa_per_lsb,
            p.bits,
        );

        let e = &self.params.encoder;
        let turns = (theta_m + e.offset_rad / self.pole_pairs) / (2.0 * PI);
        let revolution = libm::floor(turns) as i64;
        let frac = turns - revolution as f64;
        let cpr = e.counts_per_rev;
        let encoder_count = ((frac * cpr as f64) as u32).min(cpr - 1);
        let encoder_index = matches!(self.last_revolution, Some(r) if r != revolution);
        self.last_revolution = Some(revolution);
        SensorReadings {
            adc_phase_current,
            adc_dc_link,
            adc_pressure,
            encoder_count,
            encoder_index,
        }
    }
}

/// Uniform in [0, 1) from the top 53 bits.
fn unit(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Rounds to the nearest count and clips to the converter's range.
pub fn quantise(counts: f64, bits: u32) -> u16 {
    let full = ((1u32 << bits) - 1) as f64;
    let c = libm::round(counts);
    if c.is_nan() || c <= 0.0 {
        0
    } else if c >= full {
        full as u16
    } else {
        c as u16
    }
}
