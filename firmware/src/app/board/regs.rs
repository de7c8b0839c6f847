//! The peripheral instances the drive uses for its power stage and sensors, and their
//! register blocks: the lowest layer of the board, which the board's bring-up, the
//! application's drivers ([`super::super::bridge`], [`super::super::sensors`]) and the
//! safe state ([`super::super::safe_state`]) all read and write through.

use embassy_stm32::pac;
use embassy_stm32::peripherals::{ADC1, ADC2, TIM1, TIM2};

/// Timer of the power stage (advanced-control timer with complementary outputs).
pub type PwmTimer = TIM1;
/// ADC converting the phase currents and the DC link (interrupt source of the loop).
pub type CurrentAdc = ADC1;
/// ADC converting the pressure transducer.
pub type PressureAdc = ADC2;
/// Timer in encoder mode.
pub type EncoderTimer = TIM2;

/// Register block of [`PwmTimer`].
pub const PWM_REGS: pac::timer::TimAdv = pac::TIM1;
/// Register block of [`CurrentAdc`].
pub const CURRENT_ADC_REGS: pac::adc::Adc = pac::ADC1;
/// Register block of [`PressureAdc`].
pub const PRESSURE_ADC_REGS: pac::adc::Adc = pac::ADC2;
/// Register block of [`EncoderTimer`] (32-bit counter).
pub const ENCODER_REGS: pac::timer::TimGp32 = pac::TIM2;
/// Index of the encoder timer's channel that captures the index pulse (CH3).
pub const ENCODER_INDEX_CHANNEL: usize = 2;
