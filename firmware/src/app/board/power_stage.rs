//! The three-phase power stage: TIM1 in complementary centre-aligned PWM with its dead
//! time and ADC trigger, the hardware over-current trip (three comparators on DAC3
//! thresholds) and the gate driver's fault line into TIM1's break, and the timing read
//! back from the timer (see the board's module docs for the counter and update-event
//! choices).

use embassy_stm32::comp::{self, Comp, Hysteresis, InvertingInput, OutputPolarity};
use embassy_stm32::dac::{Dac, Value};
use embassy_stm32::gpio::OutputType::PushPull;
use embassy_stm32::gpio::{AfType, Flex, Pull};
use embassy_stm32::pac::timer::vals::Urs;
use embassy_stm32::peripherals::{
    COMP1, COMP3, COMP4, DAC3, PA0, PA1, PA10, PA8, PA9, PB0, PB13, PB14, PB15, TIM1,
};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::complementary_pwm::{
    BreakComparatorPolarity, BreakInputPolarity, Ckd, ComplementaryPwm, ComplementaryPwmPin, Mms2,
    Ossi, Ossr,
};
use embassy_stm32::timer::low_level::{CountingMode, FilterValue};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{BkIn1, BreakInputPin, Channel};
use embassy_stm32::Peri;
use firmware::scaling::{centre_aligned_arr, centre_aligned_pwm_hz, comparator_threshold_counts};
use firmware::Config;

use super::breaks::clear_break_flags;
use super::irqs::Irqs;
use super::regs::{PwmTimer, PWM_REGS};

/// Dead time between a phase's high- and low-side switch, set by the power stage's
/// switches and gate driver. [s]
pub const DEAD_TIME_S: f32 = 500e-9;
/// TIM1's break filter: 6 samples at f_DTS/8, 48 dead-time clocks (0.28 µs at 170 MHz,
/// CKD = 1). Longer than the switching ringing a comparator on a shunt sees, far shorter
/// than the 5‥10 µs a power switch survives a short circuit.
const BREAK_FILTER: FilterValue = FilterValue::FDTS_DIV8_N6;
/// [`BREAK_FILTER`] in dead-time clocks.
const BREAK_FILTER_DTS_CLOCKS: u32 = 48;
/// The comparators of phases U, V, W as TIM1 break sources (BKCMPxE, x = index + 1):
/// COMP3, COMP1, COMP4.
const BREAK_COMPARATORS: [usize; 3] = [2, 0, 3];

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

/// The power stage's timing as set up, for the start-up log and the bench (a scope should
/// show these numbers).
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct StageTiming {
    /// TIM1's clock as the RCC reports it. [Hz]
    pub timer_hz: u32,
    /// TIM1's auto-reload value. [timer ticks]
    pub arr: u16,
    /// The PWM rate that gives: timer clock / (2·ARR). [Hz]
    pub pwm_hz: f32,
    /// Dead time the timer inserts. [ns]
    pub dead_time_ns: u32,
    /// Break filter delay. [ns]
    pub break_filter_ns: u32,
    /// DAC3 code of the comparators' threshold. [counts]
    pub trip_code: u16,
}

/// TIM1 in complementary centre-aligned PWM with the outputs off and compare 0 (low sides
/// on once MOE is set: the bootstrap precharge), both switches of every phase idle off,
/// ARR and the repetition counter set with the counter stopped, the dead time from the
/// timer clock the RCC reports, and the ADC trigger at the counter peak; returns the
/// timing (the trip code still 0).
pub(super) fn power_stage(
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
    // The driver has started the counter. Stop it, set ARR and RCR, load them (and the
    // compare values below) with a software update, which also resets the counter and
    // the repetition counter, then start it again: RCR written before the start puts the
    // update events at the counter peak (see the module docs).
    PWM_REGS.cr1().modify(|w| w.set_cen(false));
    let timer_hz = embassy_stm32::rcc::frequency::<TIM1>().0;
    let arr = match centre_aligned_arr(timer_hz, pwm_hz) {
        Some(arr) => arr,
        None => defmt::panic!("PWM at {} Hz is out of TIM1's range", pwm_hz),
    };
    PWM_REGS.psc().write_value(0);
    PWM_REGS.arr().write(|w| w.set_arr(arr));
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
    let dead_ticks = libm::roundf(DEAD_TIME_S * timer_hz as f32) as u16;
    pwm.set_dead_time(dead_ticks);
    for (k, ch) in [Channel::Ch1, Channel::Ch2, Channel::Ch3]
        .into_iter()
        .enumerate()
    {
        PWM_REGS.ccr(k).write(|w| w.set_ccr(0));
        pwm.enable(ch);
    }
    // ADC trigger: OC4REF falls as the counter passes ARR − 1 on its way up.
    PWM_REGS.ccr(3).write(|w| w.set_ccr(arr.saturating_sub(1)));
    pwm.set_mms2(Mms2::COMPARE_OC4);
    PWM_REGS.cr1().modify(|w| w.set_urs(Urs::COUNTER_ONLY));
    PWM_REGS.egr().write(|w| w.set_ug(true));
    PWM_REGS.cr1().modify(|w| {
        w.set_urs(Urs::ANY_EVENT);
        w.set_cen(true);
    });

    // What the timer really does, read back: the dead-time generator and the break filter
    // both count the dead-time clock, the timer clock divided by CKD.
    let ckd = match PWM_REGS.cr1().read().ckd() {
        Ckd::DIV1 => 1,
        Ckd::DIV2 => 2,
        _ => 4,
    };
    let ns = |clocks: u32| (u64::from(clocks) * 1_000_000_000 / u64::from(timer_hz.max(1))) as u32;
    let dead_clocks = dead_time_dts(PWM_REGS.bdtr().read().dtg()) * ckd;
    let arr = PWM_REGS.arr().read().arr();
    let timing = StageTiming {
        timer_hz,
        arr,
        pwm_hz: centre_aligned_pwm_hz(timer_hz, arr),
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
pub(super) fn over_current_trip(
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
/// did while they started is cleared from the break flags before the control interrupt
/// can see it; a fault still present at that point breaks again at once (the flags cannot
/// be cleared while a break input is active, RM0440).
pub(super) fn enable_break(pwm: &mut ComplementaryPwm<'static, TIM1>) {
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
    clear_break_flags();
    pwm.set_break_enable(true);
}

/// Puts a TIM1 break-input pin in its alternate function with a pull-up (an open-drain
/// fault line reads "no fault" when released).
pub(super) fn break_input<P: BreakInputPin<PwmTimer, BkIn1>>(
    pin: Peri<'static, P>,
) -> Flex<'static> {
    let af = pin.af_num();
    let mut flex = Flex::new(pin);
    flex.set_as_af_unchecked(af, AfType::input(Pull::Up));
    flex
}
