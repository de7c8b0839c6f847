//! The board: every pin, peripheral instance and clock of the NUCLEO-G474RE with a
//! three-phase power stage, in one place. Porting to another board (or an STM32G431)
//! changes this module only; the drivers in [`super::bridge`] and [`super::sensors`] take
//! what [`init`] returns and the register blocks named here.
//!
//! # Pin and peripheral map (NUCLEO-G474RE)
//!
//! | function                         | peripheral                 | pin (Nucleo header)  | AF / channel |
//! |----------------------------------|----------------------------|----------------------|--------------|
//! | phase U high / low side          | TIM1 CH1 / CH1N            | PA8 (D7) / PB13 (CN10-30) | AF6 / AF6 |
//! | phase V high / low side          | TIM1 CH2 / CH2N            | PA9 (D8) / PB14 (CN10-28) | AF6 / AF6 |
//! | phase W high / low side          | TIM1 CH3 / CH3N            | PA10 (D2) / PB15 (CN10-26)| AF6 / AF4 |
//! | bridge fault (gate driver, active low) | TIM1 BKIN            | PB12 (CN10-16)       | AF6          |
//! | phase U current                  | ADC1 injected rank 1       | PA0 (A0)             | IN1          |
//! | phase V current                  | ADC1 injected rank 2       | PA1 (A1)             | IN2          |
//! | phase W current                  | ADC1 injected rank 3       | PC1 (A4)             | IN7          |
//! | DC-link voltage divider          | ADC1 injected rank 4       | PC0 (A5)             | IN6          |
//! | pressure transducer (16× oversampled) | ADC2 injected rank 1  | PA4 (A2)             | IN17         |
//! | encoder A / B (quadrature, x4)   | TIM2 CH1 / CH2, encoder mode | PA15 (CN7-17) / PB3 (D3) | AF1 |
//! | encoder index Z                  | TIM2 CH3 input capture     | PB10 (D6)            | AF1          |
//! | CAN RX / TX (to a transceiver)   | FDCAN1                     | PA11 (CN10-14) / PA12 (CN10-12) | AF9 |
//! | status LED LD2                   | GPIO                       | PA5 (D13)            | —            |
//! | embassy time driver              | TIM15                      | —                    | —            |
//! | watchdog                         | IWDG (LSI)                 | —                    | —            |
//! | parameter store                  | FLASH, last two 4 KiB pages (0x0807_E000‥0x0807_FFFF) | — | — |
//!
//! Clocks: 24 MHz HSE crystal (X3 on the Nucleo) → PLL (÷6, ×85, R ÷2) → 170 MHz SYSCLK,
//! boost mode; TIM1 and TIM2 at 170 MHz; ADC1/2 on SYSCLK (÷4 by the driver: 42.5 MHz);
//! FDCAN on HSE (24 MHz, an exact 500 kbit/s).
//!
//! Timing: TIM1 counts centre-aligned (up-down), ARR = 170 MHz / (2·f_PWM) (4250 at
//! 20 kHz). Channel 4 (no pin) compares at ARR − 1 and its reference, routed to TRGO2,
//! starts the injected conversions of both ADCs at the counter peak — the middle of the
//! interval in which all low-side switches conduct, where low-side shunts read the phase
//! currents. The repetition counter makes the update event (when the preloaded compare
//! values take effect) happen at the peak only, so each PWM pulse is symmetric.

use embassy_stm32::adc::{Adc, AdcChannel as _, AdcConfig, Exten, InjectedAdc, SampleTime};
use embassy_stm32::can::{self, CanConfigurator};
use embassy_stm32::flash::{Blocking, Flash};
use embassy_stm32::gpio::OutputType::PushPull;
use embassy_stm32::gpio::{AfType, Flex, Level, Output, Pull, Speed};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::{ADC1, ADC2, FDCAN1, IWDG, TIM1, TIM2};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::complementary_pwm::{
    BreakInputPolarity, ComplementaryPwm, ComplementaryPwmPin, Mms2, Ossi, Ossr,
};
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::low_level::{CountingMode, FilterValue};
use embassy_stm32::timer::qei::{self, Qei, QeiMode};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{BkIn1, BreakInputPin, Ch3, Channel};
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, interrupt, pac, triggers, Peri};

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

/// Dead time between a phase's high- and low-side switch, set by the power stage's
/// switches and gate driver. [s]
pub const DEAD_TIME_S: f32 = 500e-9;
/// CAN bit rate. [bit/s]
pub const CAN_BITRATE: u32 = 500_000;
/// Node number of this drive on the CAN bus (0‥15).
pub const CAN_NODE: u8 = 1;
/// Independent-watchdog timeout. [µs]
pub const WATCHDOG_TIMEOUT_US: u32 = 20_000;
/// Timer clock of TIM1 and TIM2 (APB2/APB1 undivided at 170 MHz). [Hz]
pub const TIMER_CLOCK_HZ: u32 = 170_000_000;

bind_interrupts!(pub struct Irqs {
    FDCAN1_IT0 => can::IT0InterruptHandler<FDCAN1>;
    FDCAN1_IT1 => can::IT1InterruptHandler<FDCAN1>;
});

/// The current-loop interrupt: ADC1 and ADC2 share this vector; only ADC1's
/// end-of-injected-sequence interrupt is enabled.
#[interrupt]
fn ADC1_2() {
    super::control::on_current_sample_interrupt();
}

/// What the control interrupt owns.
pub struct PowerStage {
    /// TIM1 in complementary centre-aligned PWM.
    pub pwm: ComplementaryPwm<'static, PwmTimer>,
    /// The BKIN pin (kept alive so it stays in its alternate function).
    pub _break_pin: Flex<'static>,
}

/// Sensor peripherals read by the control interrupt.
pub struct SensorPeripherals {
    /// Phase currents a, b, c and DC link, injected ranks 1‥4.
    pub currents: InjectedAdc<'static, CurrentAdc, 4>,
    /// Pressure, injected rank 1, 16× oversampled to 16 bits.
    pub pressure: InjectedAdc<'static, PressureAdc, 1>,
    /// Encoder timer (the driver keeps the A/B pins in their alternate function).
    pub _encoder: Qei<'static, EncoderTimer>,
    /// The index pin (kept alive so it stays in its alternate function).
    pub _index_pin: CapturePin<'static, EncoderTimer, Ch3>,
}

/// Everything [`init`] brings up.
pub struct Board {
    /// For the control interrupt.
    pub power: PowerStage,
    /// For the control interrupt.
    pub sensors: SensorPeripherals,
    /// For the CAN task.
    pub can: CanConfigurator<'static>,
    /// For the supervision task (not yet started).
    pub watchdog: IndependentWatchdog<'static, IWDG>,
    /// For the supervision task.
    pub led: Output<'static>,
    /// For the parameter store (the last two pages, see [`super::param_flash`]).
    pub flash: Flash<'static, Blocking>,
}

/// Brings up clocks and peripherals. The bridge comes up disabled (MOE = 0, all six
/// switches off) and stays so until the control interrupt enables it.
///
/// `pwm_hz` is the PWM (= current-loop) rate, `encoder_counts_per_rev` the quadrature
/// counts per mechanical revolution (4 × lines).
pub fn init(pwm_hz: u32, encoder_counts_per_rev: u32) -> Board {
    let p = embassy_stm32::init(clock_config());

    // Power stage. Pins first in their safe state, timer next, outputs disabled at once.
    let mut pwm = ComplementaryPwm::new(
        p.TIM1,
        Some(PwmPin::new(p.PA8, PushPull)),
        Some(ComplementaryPwmPin::new(p.PB13, PushPull)),
        Some(PwmPin::new(p.PA9, PushPull)),
        Some(ComplementaryPwmPin::new(p.PB14, PushPull)),
        Some(PwmPin::new(p.PA10, PushPull)),
        Some(ComplementaryPwmPin::new(p.PB15, PushPull)),
        None,
        None,
        Hertz(pwm_hz),
        CountingMode::CenterAlignedUpInterrupts,
    );
    pwm.set_master_output_enable(false);
    // Update events at the counter peak only (see the module docs); must follow the
    // timer start within half a PWM period, so it comes first.
    pwm.set_repetition_counter(1);
    // MOE = 0 (software or break): drive both gates of every phase to their idle level,
    // which is "off" for both switches.
    pwm.set_off_state_selection_idle(Ossi::IDLE_LEVEL);
    pwm.set_off_state_selection_run(Ossr::IDLE_LEVEL);
    // Idle level 0 on both outputs of every phase (the driver's `IdlePolarity` always
    // makes one of the pair active, which would turn a switch on).
    PWM_REGS.cr2().modify(|w| {
        for ch in 0..3 {
            w.set_ois(ch, false);
            w.set_oisn(ch, false);
        }
    });
    let dead_ticks = libm::roundf(DEAD_TIME_S * TIMER_CLOCK_HZ as f32) as u16;
    pwm.set_dead_time(dead_ticks);
    // Hardware protection: the gate driver's fault line (active low) on BKIN clears MOE
    // within a few timer clocks, independent of software; AOE off, so only software
    // re-enables the bridge.
    let break_pin = break_input(p.PB12);
    pwm.set_break_input_pin_enable(true);
    pwm.set_break_polarity(BreakInputPolarity::ACTIVE_LOW);
    pwm.set_break_filter(FilterValue::FCK_INT_N8);
    pwm.set_automatic_output_enable(false);
    pwm.set_break_enable(true);
    for ch in [Channel::Ch1, Channel::Ch2, Channel::Ch3] {
        pwm.set_duty(ch, pwm.get_max_duty() / 2);
        pwm.enable(ch);
    }
    // ADC trigger: OC4REF falls as the counter passes ARR − 1 on its way up.
    let arr = PWM_REGS.arr().read().arr();
    PWM_REGS.ccr(3).write(|w| w.set_ccr(arr.saturating_sub(1)));
    pwm.set_mms2(Mms2::COMPARE_OC4);

    // Phase currents and DC link on ADC1, 12-bit, one injected sequence per PWM period.
    let adc1 = Adc::new(p.ADC1, AdcConfig::default());
    let currents = adc1.setup_injected_conversions(
        [
            (p.PA0.degrade_adc(), SampleTime::CYCLES6_5),
            (p.PA1.degrade_adc(), SampleTime::CYCLES6_5),
            (p.PC1.degrade_adc(), SampleTime::CYCLES6_5),
            (p.PC0.degrade_adc(), SampleTime::CYCLES24_5),
        ],
        triggers::TIM1_TRGO2,
        Exten::FALLING_EDGE,
        true,
    );

    // Pressure on ADC2: 16 conversions summed (ratio 16, no shift) = 16-bit result; the
    // oversampling applies to the injected group (JOVSE) and is set while ADC2 is idle.
    let adc2 = Adc::new(
        p.ADC2,
        AdcConfig {
            oversampling_ratio: Some(3),
            oversampling_shift: Some(0),
            ..AdcConfig::default()
        },
    );
    PRESSURE_ADC_REGS.cfgr2().modify(|w| w.set_jovse(true));
    let pressure = adc2.setup_injected_conversions(
        [(p.PA4.degrade_adc(), SampleTime::CYCLES24_5)],
        triggers::TIM1_TRGO2,
        Exten::FALLING_EDGE,
        false,
    );

    // Encoder: x4 quadrature on TIM2, wrapping once per revolution; the index pulse is
    // captured on CH3 (the capture flag is polled by the control interrupt).
    let encoder = Qei::new(
        p.TIM2,
        p.PA15,
        p.PB3,
        qei::Config {
            ch1_pull: Pull::None,
            ch2_pull: Pull::None,
            mode: QeiMode::Mode3,
            auto_reload: u16::MAX,
        },
    );
    ENCODER_REGS
        .arr()
        .write_value(encoder_counts_per_rev.saturating_sub(1).max(1));
    ENCODER_REGS.cnt().write_value(0);
    let index_pin = CapturePin::new(p.PB10, Pull::None);
    ENCODER_REGS
        .ccmr_input(1)
        .modify(|w| w.set_ccs(0, pac::timer::vals::CcmrInputCcs::TI4));
    ENCODER_REGS.ccer().modify(|w| {
        w.set_ccp(ENCODER_INDEX_CHANNEL, false);
        w.set_cce(ENCODER_INDEX_CHANNEL, true);
    });

    let mut can = CanConfigurator::new(p.FDCAN1, p.PA11, p.PA12, Irqs);
    can.set_bitrate(CAN_BITRATE);

    // Nothing may delay the current loop but short critical sections: every other
    // interrupt runs below it.
    interrupt::FDCAN1_IT0.set_priority(Priority::P3);
    interrupt::FDCAN1_IT1.set_priority(Priority::P3);
    interrupt::TIM1_BRK_TIM15.set_priority(Priority::P2);

    Board {
        power: PowerStage {
            pwm,
            _break_pin: break_pin,
        },
        sensors: SensorPeripherals {
            currents,
            pressure,
            _encoder: encoder,
            _index_pin: index_pin,
        },
        can,
        watchdog: IndependentWatchdog::new(p.IWDG, WATCHDOG_TIMEOUT_US),
        led: Output::new(p.PA5, Level::Low, Speed::Low),
        flash: Flash::new_blocking(p.FLASH),
    }
}

/// Enables the current-loop interrupt at the highest priority.
pub fn enable_current_loop_interrupt() {
    interrupt::ADC1_2.set_priority(Priority::P0);
    interrupt::ADC1_2.unpend();
    // SAFETY: the handler only touches state installed before this call, through a
    // critical-section mutex.
    unsafe { interrupt::ADC1_2.enable() };
}

fn clock_config() -> embassy_stm32::Config {
    use embassy_stm32::rcc::{
        mux, Hse, HseMode, Pll, PllMul, PllPreDiv, PllRDiv, PllSource, Sysclk,
    };
    let mut config = embassy_stm32::Config::default();
    config.rcc.hse = Some(Hse {
        freq: Hertz::mhz(24),
        mode: HseMode::Oscillator,
    });
    config.rcc.pll = Some(Pll {
        source: PllSource::HSE,
        prediv: PllPreDiv::DIV6,
        mul: PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(PllRDiv::DIV2),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.boost = true;
    config.rcc.mux.adc12sel = mux::Adcsel::SYS;
    config.rcc.mux.fdcansel = mux::Fdcansel::HSE;
    config
}

/// Puts a TIM1 break-input pin in its alternate function with a pull-up (an open-drain
/// fault line reads "no fault" when released).
fn break_input<P: BreakInputPin<PwmTimer, BkIn1>>(pin: Peri<'static, P>) -> Flex<'static> {
    let af = pin.af_num();
    let mut flex = Flex::new(pin);
    flex.set_as_af_unchecked(af, AfType::input(Pull::Up));
    flex
}
