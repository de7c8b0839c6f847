//! Fixed-point conversions at the peripheral boundary: raw ADC results to normalised
//! fractions of full scale, and duties to timer compare values.
//!
//! The control core computes in f32 (the Cortex-M4F has a single-precision FPU), but the
//! peripherals speak integers. These helpers make the two integer interfaces exact and
//! saturating with the `fixed` crate: a 12-bit right-aligned ADC result is exactly a U0F16
//! fraction once shifted by four bits, a bipolar current reading about its zero is an
//! I1F15, and a duty in [0, 1] is a U1F15 whose product with the timer period rounds
//! correctly and never exceeds the period.

use fixed::types::{I1F15, U0F16, U1F15};

/// A 12-bit right-aligned ADC result as a fraction of full scale (4095 → 0.99976).
#[inline]
pub fn adc12_fraction(counts: u16) -> U0F16 {
    U0F16::from_bits(counts.min(4095) << 4)
}

/// A 16-bit (oversampled) ADC result as a fraction of full scale.
#[inline]
pub fn adc16_fraction(counts: u16) -> U0F16 {
    U0F16::from_bits(counts)
}

/// A bipolar 12-bit reading about `zero` as a signed fraction of half scale (±2048 counts
/// → ±1, saturating just below +1).
#[inline]
pub fn adc12_bipolar(counts: u16, zero: u16) -> I1F15 {
    let d = (counts.min(4095) as i32 - zero.min(4095) as i32) << 4;
    I1F15::from_bits(d.clamp(i16::MIN as i32, i16::MAX as i32) as i16)
}

/// Timer compare value for `duty` (clamped to [0, 1]; NaN → 0) with `period` ticks
/// (the timer's ARR for centre-aligned PWM): round(duty·period), at most `period`.
#[inline]
pub fn duty_to_compare(duty: f32, period: u16) -> u16 {
    let d = if duty.is_nan() {
        0.0
    } else {
        duty.clamp(0.0, 1.0)
    };
    let d = U1F15::saturating_from_num(d);
    let product = d.to_bits() as u32 * period as u32 + (1 << 14);
    ((product >> 15) as u16).min(period)
}

/// Auto-reload value of a centre-aligned PWM timer at `timer_hz` [Hz] for `pwm_hz` [Hz]:
/// the counter runs 0 → ARR → 0, 2·ARR timer clocks per PWM period (RM0440, centre-aligned
/// counting), so ARR = timer_hz / (2·pwm_hz), rounded to the nearest period. `None` when it
/// does not fit the 16-bit register or is below 2.
pub fn centre_aligned_arr(timer_hz: u32, pwm_hz: u32) -> Option<u16> {
    let twice = 2 * u64::from(pwm_hz);
    if twice == 0 {
        return None;
    }
    let arr = (u64::from(timer_hz) + twice / 2) / twice;
    u16::try_from(arr).ok().filter(|a| *a >= 2)
}

/// The PWM rate a centre-aligned timer at `timer_hz` [Hz] runs at with auto-reload value
/// `arr`. [Hz]
pub fn centre_aligned_pwm_hz(timer_hz: u32, arr: u16) -> f32 {
    timer_hz as f32 / (2.0 * f32::from(arr.max(1)))
}

/// The 12-bit code of a threshold that a phase-current reading crosses at `trip_a` [A]
/// flowing out of the motor terminal (negative in the current convention), for readings
/// `zero_lsb` [counts] at 0 A and `a_per_lsb` [A/count]: `zero − trip/a_per_lsb`, rounded,
/// within 0‥4095 (a DAC sharing the ADC's reference compares in the same counts).
pub fn comparator_threshold_counts(zero_lsb: f32, a_per_lsb: f32, trip_a: f32) -> u16 {
    let code = libm::roundf(zero_lsb - trip_a / a_per_lsb);
    if code.is_nan() {
        0
    } else {
        code.clamp(0.0, 4095.0) as u16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adc_fractions() {
        assert_eq!(adc12_fraction(0).to_num::<f32>(), 0.0);
        assert_eq!(adc12_fraction(2048).to_num::<f32>(), 0.5);
        assert_eq!(adc16_fraction(32768).to_num::<f32>(), 0.5);
        assert_eq!(adc12_bipolar(2048, 2048).to_num::<f32>(), 0.0);
        assert_eq!(adc12_bipolar(1024, 2048).to_num::<f32>(), -0.5);
        assert_eq!(adc12_bipolar(0, 2048).to_num::<f32>(), -1.0);
        assert!(adc12_bipolar(4095, 2048).to_num::<f32>() < 1.0);
        // Phase current: fraction of half scale × 50 A (100 A over 4096 counts).
        let i = adc12_bipolar(2048 + 410, 2048).to_num::<f32>() * 50.0;
        assert!((i - 410.0 * 100.0 / 4096.0).abs() < 1e-3);
    }

    #[test]
    fn comparator_thresholds_sit_below_the_zero_by_the_trip_current() {
        // 47 A at 100 A / 4096 counts is 1925.12 counts below mid-scale 2048: 123.
        assert_eq!(
            comparator_threshold_counts(2048.0, 100.0 / 4096.0, 47.0),
            123
        );
        assert_eq!(
            comparator_threshold_counts(2048.0, 100.0 / 4096.0, 0.0),
            2048
        );
        // Beyond the converter's range, or nonsense: clamped.
        assert_eq!(comparator_threshold_counts(2048.0, 100.0 / 4096.0, 60.0), 0);
        assert_eq!(comparator_threshold_counts(2048.0, 0.0, 1.0), 0);
        assert_eq!(comparator_threshold_counts(f32::NAN, 1.0, 1.0), 0);
    }

    #[test]
    fn the_centre_aligned_period_is_twice_the_auto_reload_value() {
        // 170 MHz / (2 · 20 kHz) = 4250 exactly; the edge-aligned formula's
        // clocks − 1 = 4249 would give 170e6 / 8498 = 20 004.7 Hz.
        assert_eq!(centre_aligned_arr(170_000_000, 20_000), Some(4250));
        assert_eq!(centre_aligned_pwm_hz(170_000_000, 4250), 20_000.0);
        assert!((centre_aligned_pwm_hz(170_000_000, 4249) - 20_004.7).abs() < 0.05);
        // 16 kHz: 5312.5 rounds to 5313 (15 998.5 Hz, the nearest).
        assert_eq!(centre_aligned_arr(170_000_000, 16_000), Some(5313));
        // Too slow for 16 bits, too fast, or no rate at all.
        assert_eq!(centre_aligned_arr(170_000_000, 1_000), None);
        assert_eq!(centre_aligned_arr(170_000_000, 100_000_000), None);
        assert_eq!(centre_aligned_arr(170_000_000, 0), None);
    }

    #[test]
    fn compare_values_round_and_saturate() {
        for period in [1u16, 100, 4250, 8500, 65535] {
            for k in 0..=64 {
                let duty = k as f32 / 64.0;
                let want = libm::roundf(duty * period as f32);
                let got = duty_to_compare(duty, period) as f32;
                assert!(
                    (got - want).abs() <= 1.0,
                    "{duty} {period}: {got} vs {want}"
                );
                assert!(got <= period as f32);
            }
        }
        assert_eq!(duty_to_compare(1.0, 8500), 8500);
        assert_eq!(duty_to_compare(2.0, 8500), 8500);
        assert_eq!(duty_to_compare(-1.0, 8500), 0);
        assert_eq!(duty_to_compare(f32::NAN, 8500), 0);
        assert_eq!(duty_to_compare(0.5, 8500), 4250);
    }
}
