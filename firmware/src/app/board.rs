//! The board: every pin, peripheral instance and clock of the NUCLEO-G474RE with a
//! three-phase power stage, in one place. Porting to another board (or an STM32G431)
//! changes this module only; the drivers in [`super::bridge`] and [`super::sensors`] take
//! what [`init`] returns and the register blocks named here. `docs/bring-up.md` is the
//! bench engineer's side of the same choices.
//!
//! # Pin and peripheral map (NUCLEO-G474RE)
//!
//! | function                         | peripheral                 | pin (Nucleo header)  | AF / channel |
//! |----------------------------------|----------------------------|----------------------|--------------|
//! | phase U high / low side          | TIM1 CH1 / CH1N            | PA8 (D7) / PB13 (CN10-30) | AF6 / AF6 |
//! | phase V high / low side          | TIM1 CH2 / CH2N            | PA9 (D8) / PB14 (CN10-28) | AF6 / AF6 |
//! | phase W high / low side          | TIM1 CH3 / CH3N            | PA10 (D2) / PB15 (CN10-26)| AF6 / AF4 |
//! | bridge fault (gate driver, active low) | TIM1 BKIN            | PB12 (CN10-16)       | AF6          |
//! | phase U current                  | ADC1 injected rank 1, COMP3 + | PA0 (A0)          | IN1 (fast)   |
//! | phase V current                  | ADC1 injected rank 2, COMP1 + | PA1 (A1)          | IN2 (fast)   |
//! | phase W current                  | ADC1 injected rank 3, COMP4 + | PB0 (A3)          | IN15 (slow)  |
//! | DC-link voltage divider          | ADC1 injected rank 4       | PC0 (A5)             | IN6 (slow)   |
//! | pressure transducer (16× oversampled) | ADC2 injected rank 1  | PA4 (A2)             | IN17         |
//! | over-current thresholds          | DAC3 CH1 (COMP1/3 −), CH2 (COMP4 −) | internal    | —            |
//! | encoder A / B (quadrature, x4)   | TIM2 CH1 / CH2, encoder mode | PA15 (CN7-17) / PB3 (D3) | AF1 |
//! | encoder index Z                  | TIM2 CH3 input capture     | PB10 (D6)            | AF1          |
//! | CAN RX / TX (to a transceiver)   | FDCAN1                     | PA11 (CN10-14) / PA12 (CN10-12) | AF9 |
//! | status LED LD2                   | GPIO                       | PA5 (D13)            | —            |
//! | embassy time driver              | TIM15                      | —                    | —            |
//! | watchdog                         | IWDG (LSI)                 | —                    | —            |
//! | parameter store                  | FLASH bank 2, its last pages ([`super::param_flash`]) | — | — |
//!
//! Phase W's current is on PB0 (A3), not on PC1 (A4): the G474's comparators take PA0 and
//! PC1 on the same comparator (COMP3), so only PA0/PA1/PB0 give each phase its own.
//!
//! Clocks: 24 MHz HSE crystal (X3 on the Nucleo) → PLL (÷6, ×85, R ÷2) → 170 MHz SYSCLK,
//! boost mode; TIM1 and TIM2 at 170 MHz (the dead time, filters and break delay are
//! computed from the clock the RCC reports, not assumed); ADC1/2 on SYSCLK (÷4 by the
//! driver: 42.5 MHz); FDCAN on HSE (24 MHz, an exact 500 kbit/s).
//!
//! Timing: TIM1 counts centre-aligned (up-down), ARR = 170 MHz / (2·f_PWM) (4250 at
//! 20 kHz). Channel 4 (no pin) compares at ARR − 1 and its reference, routed to TRGO2,
//! starts the injected conversions of both ADCs at the counter peak — the middle of the
//! interval in which all low-side switches conduct, where low-side shunts read the phase
//! currents (the control core keeps at most one phase outside that window and rebuilds
//! it, [`firmware::shunt`]). The repetition counter makes the update event (when the
//! preloaded compare values take effect) happen at the peak only, so each PWM pulse is
//! symmetric.
//!
//! Safe state: the gate driver's fault line and the three phase comparators clear MOE
//! through TIM1's break within the break filter (0.28 µs); a debug halt freezes TIM1 with
//! its outputs disabled (DBGMCU); a panic, a HardFault or a stalled loop force a break in
//! software ([`super::safe_state`]).

use embassy_stm32::adc::{Adc, AdcChannel as _, AdcConfig, Exten, InjectedAdc, SampleTime};
use embassy_stm32::can::config::GlobalFilter;
use embassy_stm32::can::filter::{Action, FilterType, StandardFilter, StandardFilterSlot};
use embassy_stm32::can::{self, CanConfigurator};
use embassy_stm32::comp::{self, Comp, Hysteresis, InvertingInput, OutputPolarity};
use embassy_stm32::dac::{Dac, Value};
use embassy_stm32::flash::{Blocking, Flash};
use embassy_stm32::gpio::OutputType::PushPull;
use embassy_stm32::gpio::{AfType, Flex, Level, Output, Pull, Speed};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::{
    ADC1, ADC2, COMP1, COMP3, COMP4, DAC3, FDCAN1, IWDG, PA0, PA1, PA10, PA15, PA8, PA9, PB0, PB10,
    PB13, PB14, PB15, PB3, TIM1, TIM2,
};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::complementary_pwm::{
    BreakComparatorPolarity, BreakInputPolarity, Ckd, ComplementaryPwm, ComplementaryPwmPin, Mms2,
    Ossi, Ossr,
};
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::low_level::{CountingMode, FilterValue};
use embassy_stm32::timer::qei::{self, Qei, QeiMode};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{BkIn1, BreakInputPin, Ch3, Channel};
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, interrupt, pac, triggers, Peri};
use firmware::can_protocol::{acceptance_filters, NodeId};
use firmware::scaling::comparator_threshold_counts;
use firmware::Config;

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

/// TIM1's break filter: 6 samples at f_DTS/8, 48 dead-time clocks (0.28 µs at 170 MHz,
/// CKD = 1). Longer than the switching ringing a comparator on a shunt sees, far shorter
/// than the 5‥10 µs a power switch survives a short circuit.
const BREAK_FILTER: FilterValue = FilterValue::FDTS_DIV8_N6;
/// [`BREAK_FILTER`] in dead-time clocks.
const BREAK_FILTER_DTS_CLOCKS: u32 = 48;
/// TIM2's input filter on A, B and Z: 8 samples at f_DTS/4, 32 timer clocks (0.19 µs at
/// 170 MHz). Rejects glitches from the bridge's switching edges; passes the 1.05 µs
/// between quadrature edges at the 600 rad/s plausibility limit (10 000 counts/rev).
const ENCODER_FILTER: FilterValue = FilterValue::FDTS_DIV4_N8;
/// The comparators of phases U, V, W as TIM1 break sources (BKCMPxE, x = index + 1):
/// COMP3, COMP1, COMP4.
const BREAK_COMPARATORS: [usize; 3] = [2, 0, 3];

bind_interrupts!(pub struct Irqs {
    FDCAN1_IT0 => can::IT0InterruptHandler<FDCAN1>;
    FDCAN1_IT1 => can::IT1InterruptHandler<FDCAN1>;
    COMP1_2_3 => comp::InterruptHandler<COMP1>, comp::InterruptHandler<COMP3>;
    COMP4_5_6 => comp::InterruptHandler<COMP4>;
});

/// The current-loop interrupt: ADC1 and ADC2 share this vector; only ADC1's
/// end-of-injected-sequence interrupt is enabled.
#[interrupt]
fn ADC1_2() {
    super::control::on_current_sample_interrupt();
}

/// The phase-current comparators into TIM1's break, and their thresholds (kept alive:
/// dropping a driver disables its peripheral).
pub struct OverCurrentTrip {
    _u: Comp<'static, COMP3>,
    _v: Comp<'static, COMP1>,
    _w: Comp<'static, COMP4>,
    _thresholds: Dac<'static, embassy_stm32::mode::Blocking>,
}

/// What the control interrupt owns.
pub struct PowerStage {
    /// TIM1 in complementary centre-aligned PWM.
    pub pwm: ComplementaryPwm<'static, PwmTimer>,
    /// The BKIN pin (kept alive so it stays in its alternate function).
    pub _break_pin: Flex<'static>,
    /// The hardware over-current trip.
    pub _trip: OverCurrentTrip,
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

/// The power stage's timing as set up, for the start-up log and the bench (a scope should
/// show these numbers).
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct StageTiming {
    /// TIM1's clock as the RCC reports it. [Hz]
    pub timer_hz: u32,
    /// Dead time the timer inserts. [ns]
    pub dead_time_ns: u32,
    /// Break filter delay. [ns]
    pub break_filter_ns: u32,
    /// DAC3 code of the comparators' threshold. [counts]
    pub trip_code: u16,
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
    /// For the parameter store; `None` when the flash is not in dual-bank mode (option bit
    /// DBANK cleared), where the driver's page geometry would be wrong.
    pub flash: Option<Flash<'static, Blocking>>,
    /// The previous run ended in an independent-watchdog reset.
    pub watchdog_reset: bool,
    /// The power stage's timing.
    pub timing: StageTiming,
}

/// Brings up clocks and peripherals. The bridge comes up disabled (MOE = 0, all six
/// switches off) and stays so until the control interrupt enables it.
///
/// `pwm_hz` is the PWM (= current-loop) rate; `cfg` gives the encoder resolution and the
/// current sensor's scaling with the hardware trip level; `node` the CAN node whose
/// commands pass the acceptance filter.
pub fn init(pwm_hz: u32, cfg: &Config, node: NodeId) -> Board {
    let mut p = embassy_stm32::init(clock_config());
    let watchdog_reset = take_watchdog_reset();
    super::safe_state::freeze_in_debug_halt();

    let (pwm, timing_without_trip) = power_stage(
        p.TIM1,
        (p.PA8, p.PB13),
        (p.PA9, p.PB14),
        (p.PA10, p.PB15),
        pwm_hz,
    );
    let (trip, trip_code) = over_current_trip(
        (p.COMP3, p.COMP1, p.COMP4),
        p.PA0.reborrow(),
        p.PA1.reborrow(),
        p.PB0.reborrow(),
        p.DAC3,
        cfg,
    );
    let mut power = PowerStage {
        pwm,
        _break_pin: break_input(p.PB12),
        _trip: trip,
    };
    enable_break(&mut power.pwm);
    let timing = StageTiming {
        trip_code,
        ..timing_without_trip
    };

    // Phase currents and DC link on ADC1, 12-bit, one injected sequence per PWM period.
    // Sample times: the phase currents come from low-impedance amplifiers (6.5 cycles,
    // 0.15 µs, on the fast channels; 12.5 on phase W's slow channel); the DC-link divider
    // is a high-impedance source (92.5 cycles, 2.2 µs: a few tens of kΩ settle to ½ LSB on
    // the ADC's 5 pF). The whole sequence ends 4.0 µs after the peak.
    let adc1 = Adc::new(p.ADC1, AdcConfig::default());
    let currents = adc1.setup_injected_conversions(
        [
            (p.PA0.degrade_adc(), SampleTime::CYCLES6_5),
            (p.PA1.degrade_adc(), SampleTime::CYCLES6_5),
            (p.PB0.degrade_adc(), SampleTime::CYCLES12_5),
            (p.PC0.degrade_adc(), SampleTime::CYCLES92_5),
        ],
        triggers::TIM1_TRGO2,
        Exten::FALLING_EDGE,
        true,
    );

    // Pressure on ADC2: 16 conversions summed (ratio 16, no shift) = 16-bit result; the
    // oversampling applies to the injected group (JOVSE) and is set while ADC2 is idle.
    // 47.5 cycles for the transducer's filter output: 16 × 60 cycles = 22.6 µs, inside a
    // 20 kHz period.
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
        [(p.PA4.degrade_adc(), SampleTime::CYCLES47_5)],
        triggers::TIM1_TRGO2,
        Exten::FALLING_EDGE,
        false,
    );

    let (encoder, index_pin) = encoder(
        p.TIM2,
        p.PA15,
        p.PB3,
        p.PB10,
        cfg.sensors.encoder_counts_per_rev,
    );

    let mut can = CanConfigurator::new(p.FDCAN1, p.PA11, p.PA12, Irqs);
    can.set_bitrate(CAN_BITRATE);
    // Only this node's commands reach the receive FIFO; everything else, remote and
    // extended frames included, is dropped by the controller.
    let slots = [StandardFilterSlot::_0, StandardFilterSlot::_1];
    for (slot, (id, mask)) in slots.into_iter().zip(acceptance_filters(node)) {
        let filter = StandardFilter {
            filter: FilterType::BitMask { filter: id, mask },
            action: Action::StoreInFifo0,
        };
        can.properties().set_standard_filter(slot, filter);
    }
    can.set_config(can.config().set_global_filter(GlobalFilter::reject_all()));

    // Nothing may delay the current loop but short critical sections: every other
    // interrupt runs below it.
    interrupt::FDCAN1_IT0.set_priority(Priority::P3);
    interrupt::FDCAN1_IT1.set_priority(Priority::P3);
    interrupt::COMP1_2_3.set_priority(Priority::P3);
    interrupt::COMP4_5_6.set_priority(Priority::P3);
    interrupt::TIM1_BRK_TIM15.set_priority(Priority::P2);

    // The driver panics on a single-bank part; check the option bit first.
    let flash = pac::FLASH
        .optr()
        .read()
        .dbank()
        .then(|| Flash::new_blocking(p.FLASH));

    Board {
        power,
        sensors: SensorPeripherals {
            currents,
            pressure,
            _encoder: encoder,
            _index_pin: index_pin,
        },
        can,
        watchdog: IndependentWatchdog::new(p.IWDG, WATCHDOG_TIMEOUT_US),
        led: Output::new(p.PA5, Level::Low, Speed::Low),
        flash,
        watchdog_reset,
        timing,
    }
}

/// TIM1 in complementary centre-aligned PWM with the outputs off, both switches of every
/// phase idle off, the dead time from the timer clock the RCC reports, and the ADC trigger
/// at the counter peak; returns the timing (the trip code still 0).
fn power_stage(
    tim: Peri<'static, TIM1>,
    u: (Peri<'static, PA8>, Peri<'static, PB13>),
    v: (Peri<'static, PA9>, Peri<'static, PB14>),
    w: (Peri<'static, PA10>, Peri<'static, PB15>),
    pwm_hz: u32,
) -> (ComplementaryPwm<'static, TIM1>, StageTiming) {
    // Pins first in their safe state, timer next, outputs disabled at once.
    let mut pwm = ComplementaryPwm::new(
        tim,
        Some(PwmPin::new(u.0, PushPull)),
        Some(ComplementaryPwmPin::new(u.1, PushPull)),
        Some(PwmPin::new(v.0, PushPull)),
        Some(ComplementaryPwmPin::new(v.1, PushPull)),
        Some(PwmPin::new(w.0, PushPull)),
        Some(ComplementaryPwmPin::new(w.1, PushPull)),
        None,
        None,
        Hertz(pwm_hz),
        CountingMode::CenterAlignedUpInterrupts,
    );
    pwm.set_master_output_enable(false);
    // Update events at the counter peak only (see the module docs); must follow the
    // timer start within half a PWM period, so it comes first.
    pwm.set_repetition_counter(1);
    // MOE = 0 (software, break or debug halt): drive both gates of every phase to their
    // idle level, which is "off" for both switches.
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
    let timer_hz = embassy_stm32::rcc::frequency::<TIM1>().0;
    let dead_ticks = libm::roundf(DEAD_TIME_S * timer_hz as f32) as u16;
    pwm.set_dead_time(dead_ticks);
    for ch in [Channel::Ch1, Channel::Ch2, Channel::Ch3] {
        pwm.set_duty(ch, pwm.get_max_duty() / 2);
        pwm.enable(ch);
    }
    // ADC trigger: OC4REF falls as the counter passes ARR − 1 on its way up.
    let arr = PWM_REGS.arr().read().arr();
    PWM_REGS.ccr(3).write(|w| w.set_ccr(arr.saturating_sub(1)));
    pwm.set_mms2(Mms2::COMPARE_OC4);

    // What the timer really does, read back: the dead-time generator and the break filter
    // both count the dead-time clock, the timer clock divided by CKD.
    let ckd = match PWM_REGS.cr1().read().ckd() {
        Ckd::DIV1 => 1,
        Ckd::DIV2 => 2,
        _ => 4,
    };
    let ns = |clocks: u32| (u64::from(clocks) * 1_000_000_000 / u64::from(timer_hz.max(1))) as u32;
    let dead_clocks = dead_time_dts(PWM_REGS.bdtr().read().dtg()) * ckd;
    let timing = StageTiming {
        timer_hz,
        dead_time_ns: ns(dead_clocks),
        break_filter_ns: ns(BREAK_FILTER_DTS_CLOCKS * ckd),
        trip_code: 0,
    };
    (pwm, timing)
}

/// Dead time of BDTR.DTG = `dtg`, in dead-time clocks (RM0440, TIMx_BDTR: four ranges).
fn dead_time_dts(dtg: u8) -> u32 {
    let dtg = u32::from(dtg);
    match dtg >> 5 {
        0..=3 => dtg,
        4 | 5 => (64 + (dtg & 0x3F)) * 2,
        6 => (32 + (dtg & 0x1F)) * 8,
        _ => (32 + (dtg & 0x1F)) * 16,
    }
}

/// The three phase comparators, each phase's amplified shunt signal against one DAC3
/// threshold (COMP1 and COMP3 compare with DAC3 CH1, COMP4 with CH2, set to the same
/// code). Low-side shunts see a phase's current while its low side conducts; a short or a
/// shoot-through drives a large current *out of* the motor terminal through that switch,
/// which reads far below the zero, so each comparator trips on a reading below
/// `zero − limits.hardware_over_current_a` (output inverted: high = over-current). One
/// comparator per phase leaves the opposite direction to the software trip (it shows on
/// another phase's low side in the same period); a short from a motor terminal to the
/// negative rail bypasses every shunt and is the gate driver's desaturation detection's
/// to catch (its fault line is BKIN).
fn over_current_trip(
    comps: (
        Peri<'static, COMP3>,
        Peri<'static, COMP1>,
        Peri<'static, COMP4>,
    ),
    u: Peri<'_, PA0>,
    v: Peri<'_, PA1>,
    w: Peri<'_, PB0>,
    dac3: Peri<'static, DAC3>,
    cfg: &Config,
) -> (OverCurrentTrip, u16) {
    let code = comparator_threshold_counts(
        cfg.sensors.current_zero_lsb,
        cfg.sensors.current_a_per_lsb,
        cfg.limits.hardware_over_current_a,
    );
    let mut thresholds = Dac::<embassy_stm32::mode::Blocking>::new_internal(dac3);
    thresholds.ch1().set(Value::Bit12Right(code));
    thresholds.ch2().set(Value::Bit12Right(code));
    let config = comp::Config {
        inverting_input: InvertingInput::Dac1,
        output_polarity: OutputPolarity::Inverted,
        hysteresis: Hysteresis::Hyst20M,
        ..comp::Config::default()
    };
    let trip = OverCurrentTrip {
        _u: Comp::new(comps.0, u, Irqs, config),
        _v: Comp::new(comps.1, v, Irqs, config),
        _w: Comp::new(comps.2, w, Irqs, config),
        _thresholds: thresholds,
    };
    (trip, code)
}

/// Arms TIM1's break: the gate driver's fault line (BKIN, active low) and the three
/// comparators (active high) clear MOE within the break filter, independent of software;
/// AOE off, so only software re-enables the bridge. Whatever the comparators and the DAC
/// did while they started is cleared from the break flag before the control interrupt
/// can see it; a fault still present at that point breaks again at once.
fn enable_break(pwm: &mut ComplementaryPwm<'static, TIM1>) {
    pwm.set_break_input_pin_enable(true);
    pwm.set_break_polarity(BreakInputPolarity::ACTIVE_LOW);
    for index in BREAK_COMPARATORS {
        // Inverted against BKP = active low: a comparator output high breaks.
        pwm.set_break_comparator_polarity(index, BreakComparatorPolarity::INVERTED);
        pwm.set_break_comparator_enable(index, true);
    }
    pwm.set_break_filter(BREAK_FILTER);
    pwm.set_automatic_output_enable(false);
    // The DAC and the comparators settle in a few µs (DAC: ≤ 7.5 µs to its first output).
    cortex_m::asm::delay(20 * 170);
    PWM_REGS.sr().modify(|w| w.set_bif(0, false));
    pwm.set_break_enable(true);
}

/// Live levels of the break sources: bit 0‥2 the comparators of phases U, V, W above
/// their trip level, bit 3 the gate driver's fault line asserted (BKIN low). A break
/// whose sources have all gone is 0 — a forced break, or a short one.
pub fn break_sources() -> u8 {
    let comparators = [pac::COMP3, pac::COMP1, pac::COMP4];
    let mut bits = 0u8;
    for (k, c) in comparators.iter().enumerate() {
        if c.csr().read().value() {
            bits |= 1 << k;
        }
    }
    if pac::GPIOB.idr().read().idr(12) == pac::gpio::vals::Idr::LOW {
        bits |= 1 << 3;
    }
    bits
}

/// The encoder: x4 quadrature on TIM2, wrapping once per revolution, the index pulse
/// captured on CH3 (the capture flag is polled by the control interrupt), a digital filter
/// on all three inputs.
fn encoder(
    tim: Peri<'static, TIM2>,
    a: Peri<'static, PA15>,
    b: Peri<'static, PB3>,
    z: Peri<'static, PB10>,
    counts_per_rev: u32,
) -> (Qei<'static, TIM2>, CapturePin<'static, TIM2, Ch3>) {
    let encoder = Qei::new(
        tim,
        a,
        b,
        qei::Config {
            ch1_pull: Pull::None,
            ch2_pull: Pull::None,
            mode: QeiMode::Mode3,
            auto_reload: u16::MAX,
        },
    );
    ENCODER_REGS
        .arr()
        .write_value(counts_per_rev.saturating_sub(1).max(1));
    ENCODER_REGS.cnt().write_value(0);
    let index_pin = CapturePin::new(z, Pull::None);
    ENCODER_REGS.ccmr_input(0).modify(|w| {
        w.set_icf(0, ENCODER_FILTER);
        w.set_icf(1, ENCODER_FILTER);
    });
    ENCODER_REGS.ccmr_input(1).modify(|w| {
        // Direct mapping: IC3 on TI3 (the metapac calls it TI4 for every channel).
        w.set_ccs(0, pac::timer::vals::CcmrInputCcs::TI4);
        w.set_icf(0, ENCODER_FILTER);
    });
    ENCODER_REGS.ccer().modify(|w| {
        w.set_ccp(ENCODER_INDEX_CHANNEL, false);
        w.set_cce(ENCODER_INDEX_CHANNEL, true);
    });
    (encoder, index_pin)
}

/// True when the previous run ended in an independent-watchdog reset; clears the reset
/// flags, so the next boot tells its own story.
fn take_watchdog_reset() -> bool {
    let watchdog = pac::RCC.csr().read().iwdgrstf();
    pac::RCC.csr().modify(|w| w.set_rmvf(true));
    watchdog
}

/// Enables the current-loop interrupt at the highest priority, on a clean flag: ADC1
/// has been converting at every PWM peak since the timer started, so its end-of-sequence
/// flag is set; enabled with it, the handler would run at once, at a random point of the
/// period, and its overrun check would latch a spurious watchdog fault.
pub fn enable_current_loop_interrupt() {
    interrupt::ADC1_2.set_priority(Priority::P0);
    // Write-one-to-clear: only JEOS.
    CURRENT_ADC_REGS.isr().write(|w| w.set_jeos(true));
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
