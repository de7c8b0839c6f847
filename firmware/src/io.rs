//! The seam between the control core and the MCU (or the plant model): what the
//! peripherals give the current-loop ISR each PWM period, and what it drives.
//!
//! The plant model's `sensors::SensorReadings` mirrors [`Measurements`] field for field.

/// What the MCU's peripherals give the current-loop ISR each PWM period.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measurements {
    /// Phase-current ADC results a, b, c: 12-bit right-aligned, 2048 counts = 0 A,
    /// positive = into the motor. [counts]
    pub adc_phase_current: [u16; 3],
    /// DC-link voltage ADC result, 12-bit, 0 counts = 0 V. [counts]
    pub adc_dc_link: u16,
    /// Pressure transducer ADC result after 16x hardware oversampling: 16-bit. [counts]
    pub adc_pressure: u16,
    /// Encoder timer counter (encoder mode, ARR = counts_per_rev − 1, so it wraps once per
    /// revolution). [counts]
    pub encoder_count: u32,
    /// True when the encoder index pulse was captured since the previous sample.
    pub encoder_index: bool,
    /// The counter value the timer captured at the index pulse's edge (valid when
    /// `encoder_index`): ties the counter to the index ([`crate::encoder`]). [counts]
    pub encoder_index_count: u32,
}

impl Default for Measurements {
    /// Mid-scale currents, no voltage, no pressure signal, encoder at 0.
    fn default() -> Self {
        Measurements {
            adc_phase_current: [2048; 3],
            adc_dc_link: 0,
            adc_pressure: 0,
            encoder_count: 0,
            encoder_index: false,
            encoder_index_count: 0,
        }
    }
}

/// What the ISR drives: three duties in [0, 1] (fraction of the PWM period phase x is
/// high) and the bridge enable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outputs {
    /// Duty of phases a, b, c. [1]
    pub duties: [f32; 3],
    /// Bridge enabled (false: all six switches off).
    pub pwm_enabled: bool,
}

impl Outputs {
    /// Bridge off (the duties are not applied: the board's bridge writes compare 0 while
    /// off, [`crate::bridge`]).
    pub const DISABLED: Outputs = Outputs {
        duties: [0.5; 3],
        pwm_enabled: false,
    };
}

impl Default for Outputs {
    fn default() -> Self {
        Outputs::DISABLED
    }
}
