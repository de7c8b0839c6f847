//! The sensor read-out of one PWM period: injected ADC results (phase currents, DC link,
//! pressure) and the encoder counter with its index capture (the counter value latched at
//! the index edge, which the control core ties the counter to), as the control core's
//! [`Measurements`].
//!
//! Both ADCs convert at the same TIM1 trigger (the counter peak). The control interrupt
//! fires at the end of ADC1's sequence (about 4 µs: three phase currents, then the DC
//! link's long sample time); ADC2's 16-fold oversampled pressure conversion takes about
//! 23 µs, so its data register still holds the result of the previous period — a 50 µs
//! delay, negligible for the 1 kHz pressure loop. (At PWM rates above about 44 kHz the
//! pressure conversion outlasts the period and only every other trigger is converted; the
//! value is then two periods old.)

use super::board::regs::{ENCODER_INDEX_CHANNEL, ENCODER_REGS};
use super::board::SensorPeripherals;
use firmware::Measurements;

/// The sensor driver.
pub struct Sensors {
    peripherals: SensorPeripherals,
}

impl Sensors {
    /// Takes over the sensor peripherals.
    pub fn new(peripherals: SensorPeripherals) -> Sensors {
        Sensors { peripherals }
    }

    /// Reads this period's samples. Reading ADC1's injected results also clears its
    /// end-of-sequence flag, which acknowledges the interrupt.
    pub fn sample(&mut self) -> Measurements {
        let [ia, ib, ic, udc] = self.peripherals.currents.read_injected_samples();
        let [pressure] = self.peripherals.pressure.read_injected_samples();
        let encoder_count = ENCODER_REGS.cnt().read();
        let encoder_index = ENCODER_REGS.sr().read().ccif(ENCODER_INDEX_CHANNEL);
        // Reading the capture register also clears the capture flag (no read-modify-write
        // of the status register, which could lose another flag).
        let encoder_index_count = if encoder_index {
            ENCODER_REGS.ccr(ENCODER_INDEX_CHANNEL).read()
        } else {
            0
        };
        Measurements {
            adc_phase_current: [ia, ib, ic],
            adc_dc_link: udc,
            adc_pressure: pressure,
            encoder_count,
            encoder_index,
            encoder_index_count,
        }
    }
}
