//! Faults of the sensors, as the MCU's peripherals would see them, switched on and off
//! while a run goes on ([`crate::Plant::set_sensor_faults`]). One fault per sensor at a
//! time; [`crate::sensors::Sensors`] applies them to its readings.
//!
//! # Encoder (quadrature A/B with an index Z, counted by the timer)
//!
//! - **Lost counts**: edges the counter missed (edges faster than its input filter during a
//!   disturbance), at most [`LOST_COUNTS_PER_SAMPLE`] per sample until `counts` are gone:
//!   the count is short by them from then on. Counts lost are not found again; only a
//!   re-reference (the index, an alignment) removes the offset.
//! - **Noise burst**: spurious edges from interference on A/B while it lasts: each sample
//!   the counter gains or loses a Gaussian number of counts (rms `counts_rms`), which stay.
//! - **Stuck count**: A and B lost (a broken wire, a dead line receiver): the counter stops;
//!   the index, on its own pair, still arrives where the shaft is.
//! - **Lost index**: the index pulse never comes.
//! - **Reversed wiring**: A and B swapped: from the swap on the counter counts the other
//!   way (it does not jump), so it reads 2·c_swap − c.
//!
//! # Pressure transducer (4–20 mA into a shunt and the 16× oversampled ADC)
//!
//! - **Open wire**: no loop current: the ADC reads the shunt's 0 V (its own noise only).
//! - **Short**: the transmitter's output shorted to its supply: the loop current runs into
//!   the supply's limit above 20 mA and the ADC reads full scale.
//! - **Stuck**: the transmitter's output frozen at the pressure it read when the fault
//!   came (a seized diaphragm, a hung sensor ASIC); the wire's noise is still there.
//! - **Drift**: an offset growing at `pa_per_s` (a failing strain gauge, temperature).
//! - **Noise burst**: extra Gaussian noise of rms `rms_pa` (interference) while it lasts.
//!
//! # Phase-current channel (shunt amplifier into the 12-bit ADC)
//!
//! - **Stuck**: the channel's result frozen (a hung sample-and-hold, a dead amplifier).
//! - **Gain error**: the channel reads `gain` times its current (a drifted shunt or
//!   amplifier gain).
//! - **Saturation**: the amplifier clips at ±`limit_a` (a supply rail lost, a wrong gain
//!   setting), below the ADC's own range.

use crate::faults::Phase;

/// Most edges the counter misses per sample. [counts]
pub const LOST_COUNTS_PER_SAMPLE: i64 = 2;

/// A fault of the encoder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EncoderFault {
    /// The counter missed `counts` edges (negative: gained). [counts]
    LostCounts {
        /// Counts missed. [counts]
        counts: i32,
    },
    /// Spurious edges each sample while it lasts. [counts rms per sample]
    NoiseBurst {
        /// Counts gained or lost per sample, rms. [counts]
        counts_rms: f64,
    },
    /// The counter stops (A and B lost).
    Stuck,
    /// The index pulse is lost.
    LostIndex,
    /// A and B swapped.
    Reversed,
}

/// A fault of the pressure transducer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PressureFault {
    /// No loop current.
    OpenWire,
    /// Output shorted to the supply.
    Short,
    /// Output frozen.
    Stuck,
    /// Offset growing at `pa_per_s`. [Pa/s]
    Drift {
        /// Drift rate. [Pa/s]
        pa_per_s: f64,
    },
    /// Extra noise. [Pa rms]
    NoiseBurst {
        /// Noise rms. [Pa]
        rms_pa: f64,
    },
}

/// A fault of one phase-current channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CurrentFault {
    /// The channel's result frozen.
    Stuck {
        /// The channel.
        phase: Phase,
    },
    /// The channel reads `gain` times its current.
    GainError {
        /// The channel.
        phase: Phase,
        /// Gain. [1]
        gain: f64,
    },
    /// The channel's amplifier clips at ±`limit_a`.
    Saturation {
        /// The channel.
        phase: Phase,
        /// Clipping level. [A]
        limit_a: f64,
    },
}

/// The sensors' faults (none by default).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SensorFaults {
    /// Encoder fault.
    pub encoder: Option<EncoderFault>,
    /// Pressure transducer fault.
    pub pressure: Option<PressureFault>,
    /// Phase-current channel fault.
    pub current: Option<CurrentFault>,
}

impl SensorFaults {
    /// Checks the values; `Err` names the offending field.
    pub fn validate(&self) -> Result<(), &'static str> {
        if let Some(EncoderFault::NoiseBurst { counts_rms }) = self.encoder {
            if !(counts_rms.is_finite() && counts_rms >= 0.0) {
                return Err("encoder.counts_rms must be finite and >= 0");
            }
        }
        match self.pressure {
            Some(PressureFault::Drift { pa_per_s }) if !pa_per_s.is_finite() => {
                return Err("pressure.pa_per_s must be finite");
            }
            Some(PressureFault::NoiseBurst { rms_pa })
                if !(rms_pa.is_finite() && rms_pa >= 0.0) =>
            {
                return Err("pressure.rms_pa must be finite and >= 0");
            }
            _ => {}
        }
        match self.current {
            Some(CurrentFault::GainError { gain, .. }) if !gain.is_finite() => {
                Err("current.gain must be finite")
            }
            Some(CurrentFault::Saturation { limit_a, .. })
                if !(limit_a.is_finite() && limit_a >= 0.0) =>
            {
                Err("current.limit_a must be finite and >= 0")
            }
            _ => Ok(()),
        }
    }
}

/// What the faults need to remember between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorFaultState {
    /// Counts the counter is off by (lost counts, noise bursts). [counts]
    pub encoder_offset: i64,
    /// Counts still to be lost. [counts]
    pub encoder_losing: i64,
    /// The count the counter stopped at, or swapped at. [counts]
    pub encoder_hold: Option<u32>,
    /// The transducer's frozen pressure. [Pa]
    pub pressure_hold: Option<f64>,
    /// Time the drift started. [s]
    pub drift_since_s: Option<f64>,
    /// The current channel's frozen result. [counts]
    pub current_hold: Option<u16>,
}
