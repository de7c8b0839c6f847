//! Sensors as the MCU's peripherals see them: phase-current shunts and the DC-link divider
//! into 12-bit ADC channels, the pressure transducer into an oversampled 16-bit result, and
//! the quadrature encoder's counter with its index.
//!
//! Each reading is value + offset + white Gaussian noise, quantised by the ADC (rounded to
//! the nearest count and clipped to its range, as a saturated converter is). The pressure
//! transducer's first-order lag is a state of the plant ([`crate::plant`]); here it is read.
//! The encoder reports ⌊θ_enc/2π·N⌋ mod N with θ_enc = θ_m + offset/p_n, and flags the
//! index when a revolution boundary was crossed since the previous sample.
//!
//! The sensors' faults ([`crate::sensor_faults`]) are applied here, to the readings.

use crate::gaussian::NormalStream;
use crate::rig::SensorParams;
use crate::sensor_faults::{
    CurrentFault, EncoderFault, PressureFault, SensorFaultState, SensorFaults,
    LOST_COUNTS_PER_SAMPLE,
};
use core::f64::consts::PI;

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
    normals: NormalStream,
    last_revolution: Option<i64>,
    faults: SensorFaults,
    fault_state: SensorFaultState,
    /// A fault or its remembered state is in force (else the readings take the plain path).
    faulty: bool,
}

impl Sensors {
    /// From validated parameters and a noise seed.
    pub fn new(params: &SensorParams, pole_pairs: u32, seed: u64) -> Sensors {
        Sensors {
            params: params.clone(),
            pole_pairs: pole_pairs as f64,
            normals: NormalStream::new(seed),
            last_revolution: None,
            faults: SensorFaults::default(),
            fault_state: SensorFaultState::default(),
            faulty: false,
        }
    }

    /// The faults in force.
    pub fn faults(&self) -> SensorFaults {
        self.faults
    }

    /// Switches the sensors' faults (validated by the caller). A fault that freezes a
    /// value freezes the next reading's; lost counts are lost at once; removing an encoder
    /// fault re-references the counter (the repair includes re-homing the count, as an
    /// index reconciliation or an alignment would).
    pub fn set_faults(&mut self, faults: SensorFaults) {
        let st = &mut self.fault_state;
        if faults.encoder != self.faults.encoder {
            st.encoder_hold = None;
            match faults.encoder {
                None => {
                    st.encoder_offset = 0;
                    st.encoder_losing = 0;
                }
                Some(EncoderFault::LostCounts { counts }) => st.encoder_losing = i64::from(counts),
                _ => {}
            }
        }
        if faults.pressure != self.faults.pressure {
            st.pressure_hold = None;
            st.drift_since_s = None;
        }
        if faults.current != self.faults.current {
            st.current_hold = None;
        }
        self.faults = faults;
        self.faulty =
            faults != SensorFaults::default() || self.fault_state != SensorFaultState::default();
    }

    /// Samples every sensor at time `t_s`: the currents through the current sensors `i_abc`
    /// (the bridge legs'), DC link `u_dc`, the transducer's (lagged) pressure `p_sensed` and
    /// the shaft angle `theta_m` (unwrapped).
    pub fn sample(
        &mut self,
        t_s: f64,
        i_abc: &[f64; 3],
        u_dc: f64,
        p_sensed: f64,
        theta_m: f64,
    ) -> SensorReadings {
        if self.faulty {
            self.sample_with::<true>(t_s, i_abc, u_dc, p_sensed, theta_m)
        } else {
            self.sample_with::<false>(t_s, i_abc, u_dc, p_sensed, theta_m)
        }
    }

    /// [`Sensors::sample`] with the faults' terms (`FAULTY`) or without them compiled in.
    #[inline(always)]
    fn sample_with<const FAULTY: bool>(
        &mut self,
        t_s: f64,
        i_abc: &[f64; 3],
        u_dc: f64,
        p_sensed: f64,
        theta_m: f64,
    ) -> SensorReadings {
        let c = &self.params.current;
        let mut adc_phase_current = [0u16; 3];
        for (k, ((out, i), off)) in adc_phase_current
            .iter_mut()
            .zip(i_abc)
            .zip(&c.offset_a)
            .enumerate()
        {
            let n = noise(&mut self.normals, c.noise_a_rms);
            if !FAULTY || self.faults.current.is_none() {
                *out = quantise(c.zero_lsb + (i + off + n) / c.a_per_lsb, c.bits);
                continue;
            }
            let (gain, limit) = match self.faults.current {
                Some(CurrentFault::GainError { phase, gain }) if phase.index() == k => {
                    (gain, f64::INFINITY)
                }
                Some(CurrentFault::Saturation { phase, limit_a }) if phase.index() == k => {
                    (1.0, limit_a)
                }
                _ => (1.0, f64::INFINITY),
            };
            let sensed = (gain * (i + off + n)).clamp(-limit, limit);
            *out = quantise(c.zero_lsb + sensed / c.a_per_lsb, c.bits);
            if let Some(CurrentFault::Stuck { phase }) = self.faults.current {
                if phase.index() == k {
                    *out = *self.fault_state.current_hold.get_or_insert(*out);
                }
            }
        }
        let v = &self.params.dc_link;
        let nv = noise(&mut self.normals, v.noise_v_rms);
        let adc_dc_link = quantise((u_dc + nv) / v.v_per_lsb, v.bits);
        let adc_pressure = if FAULTY {
            self.pressure_reading(t_s, p_sensed)
        } else {
            let p = &self.params.pressure;
            let np = noise(&mut self.normals, p.noise_pa_rms);
            quantise(
                p.zero_lsb + (p_sensed + p.offset_pa + np) / p.pa_per_lsb,
                p.bits,
            )
        };

        let e = &self.params.encoder;
        let turns = (theta_m + e.offset_rad / self.pole_pairs) / (2.0 * PI);
        let revolution = libm::floor(turns) as i64;
        let frac = turns - revolution as f64;
        let cpr = e.counts_per_rev;
        let count = ((frac * cpr as f64) as u32).min(cpr - 1);
        let index = matches!(self.last_revolution, Some(r) if r != revolution);
        self.last_revolution = Some(revolution);
        let (encoder_count, encoder_index) = if FAULTY {
            self.encoder_reading(count, index)
        } else {
            (count, index)
        };
        SensorReadings {
            adc_phase_current,
            adc_dc_link,
            adc_pressure,
            encoder_count,
            encoder_index,
        }
    }
}

impl Sensors {
    /// The transducer's ADC result for the (lagged) pressure `p_sensed` at `t_s`, with the
    /// transducer's fault. [counts]
    fn pressure_reading(&mut self, t_s: f64, p_sensed: f64) -> u16 {
        let p = &self.params.pressure;
        let np = noise(&mut self.normals, p.noise_pa_rms);
        let full = ((1u32 << p.bits) - 1) as f64;
        let st = &mut self.fault_state;
        let sensed = match self.faults.pressure {
            None => p_sensed,
            Some(PressureFault::OpenWire) => {
                // No loop current: the shunt's 0 V and the converter's own noise (±2 counts).
                return quantise(libm::fabs(2.0 * np / p.noise_pa_rms.max(1.0)), p.bits);
            }
            Some(PressureFault::Short) => return full as u16,
            Some(PressureFault::Stuck) => *st.pressure_hold.get_or_insert(p_sensed),
            Some(PressureFault::Drift { pa_per_s }) => {
                let since = *st.drift_since_s.get_or_insert(t_s);
                p_sensed + pa_per_s * (t_s - since)
            }
            Some(PressureFault::NoiseBurst { rms_pa }) => {
                p_sensed + noise(&mut self.normals, rms_pa)
            }
        };
        quantise(
            p.zero_lsb + (sensed + p.offset_pa + np) / p.pa_per_lsb,
            p.bits,
        )
    }

    /// The counter and index as the timer reports them for the true `count` and `index`,
    /// with the encoder's fault.
    fn encoder_reading(&mut self, count: u32, index: bool) -> (u32, bool) {
        let n = i64::from(self.params.encoder.counts_per_rev.max(1));
        let wrap = |c: i64| c.rem_euclid(n) as u32;
        let st = &mut self.fault_state;
        if st.encoder_losing != 0 {
            let lost = st
                .encoder_losing
                .clamp(-LOST_COUNTS_PER_SAMPLE, LOST_COUNTS_PER_SAMPLE);
            st.encoder_losing -= lost;
            st.encoder_offset -= lost;
        }
        let (raw, index) = match self.faults.encoder {
            None | Some(EncoderFault::LostCounts { .. }) => (i64::from(count), index),
            Some(EncoderFault::NoiseBurst { counts_rms }) => {
                let spurious = libm::round(counts_rms * self.normals.next()) as i64;
                let st = &mut self.fault_state;
                st.encoder_offset += spurious;
                (i64::from(count), index)
            }
            Some(EncoderFault::Stuck) => {
                let held = *st
                    .encoder_hold
                    .get_or_insert(wrap(i64::from(count) + st.encoder_offset));
                return (held, index);
            }
            Some(EncoderFault::LostIndex) => (i64::from(count), false),
            Some(EncoderFault::Reversed) => {
                let at = *st.encoder_hold.get_or_insert(count);
                (2 * i64::from(at) - i64::from(count), index)
            }
        };
        (wrap(raw + self.fault_state.encoder_offset), index)
    }
}

/// White Gaussian noise of `rms` from `normals` (no draw when `rms` is zero).
#[inline(always)]
fn noise(normals: &mut NormalStream, rms: f64) -> f64 {
    if rms > 0.0 {
        rms * normals.next()
    } else {
        0.0
    }
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
