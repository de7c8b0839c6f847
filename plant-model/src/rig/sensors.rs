//! The sensors' parameters: phase-current and pressure transducers, the DC-link voltage
//! divider, the encoder (scale, noise, offset, lag, ADC resolution).

/// Phase-current sensing: shunt amplifiers into 12-bit ADC channels.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CurrentSensorParams {
    /// Scale. [A/LSB]
    pub a_per_lsb: f64,
    /// ADC count at zero current. [LSB]
    pub zero_lsb: f64,
    /// ADC resolution. [bit]
    pub bits: u32,
    /// Offset error per phase a, b, c (effect `current_sensor_offset` on phase a). [A]
    pub offset_a: [f64; 3],
    /// White noise, rms, per sample. [A]
    pub noise_a_rms: f64,
}

/// Pressure transducer on port A into an oversampled 16-bit ADC result.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PressureSensorParams {
    /// Scale. [Pa/LSB]
    pub pa_per_lsb: f64,
    /// ADC count at zero gauge pressure. [LSB]
    pub zero_lsb: f64,
    /// ADC resolution after oversampling. [bit]
    pub bits: u32,
    /// Offset error. [Pa]
    pub offset_pa: f64,
    /// White noise, rms, per sample. [Pa]
    pub noise_pa_rms: f64,
    /// First-order lag time constant; 0 is off. [s]
    pub lag_time_constant_s: f64,
}

/// DC-link voltage divider into a 12-bit ADC channel.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct VoltageSensorParams {
    /// Scale. [V/LSB]
    pub v_per_lsb: f64,
    /// ADC resolution. [bit]
    pub bits: u32,
    /// White noise, rms, per sample. [V]
    pub noise_v_rms: f64,
}

/// Incremental quadrature encoder with index.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EncoderParams {
    /// Counts per mechanical revolution (4 × lines). [1]
    pub counts_per_rev: u32,
    /// Electrical angle by which the encoder's zero leads the rotor d-axis: the controller
    /// computes θ_e = p_n·θ_count − offset. [rad]
    pub offset_rad: f64,
}

/// All sensors.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SensorParams {
    /// Phase currents.
    pub current: CurrentSensorParams,
    /// Port-A pressure.
    pub pressure: PressureSensorParams,
    /// DC link.
    pub dc_link: VoltageSensorParams,
    /// Shaft encoder.
    pub encoder: EncoderParams,
}
