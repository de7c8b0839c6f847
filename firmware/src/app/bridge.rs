//! The three-phase bridge: TIM1's registers under the enable sequence of
//! [`firmware::bridge`] (compare values, break flags, MOE), called once per PWM period by
//! the control interrupt.
//!
//! Duty d of a phase is the fraction of the PWM period its high side conducts. In
//! centre-aligned PWM mode 1 the output is active while the counter is below the compare
//! value, and the counter runs 0 → ARR → 0, so compare = d · ARR gives exactly that
//! fraction (the core's fixed-point [`firmware::scaling::duty_to_compare`], saturating,
//! NaN → 0). Compare values are preloaded and take effect at the next update event (the
//! counter peak), so a period is never cut between two duties. While the bridge is off the
//! compare values are 0, so the period in which MOE is set keeps every high side off and
//! charges the bootstrap capacitors; the sequence, its break handling and MOE tracked in
//! software are the hardware-free [`firmware::bridge::BridgeControl`], tested on the host.

use super::board::breaks::{break_flags, clear_break_flags};
use super::board::power_stage::PowerStage as Stage;
use super::board::regs::PWM_REGS;
use firmware::bridge::{BridgeControl, PowerStage};
use firmware::Outputs;

pub use firmware::bridge::BridgeEvent;

/// TIM1 as the enable sequence writes it.
struct Registers {
    stage: Stage,
    /// The last break flags read included the system break (lockup, ECC).
    system_break: bool,
}

impl PowerStage for Registers {
    #[inline]
    fn break_flagged(&mut self) -> bool {
        match break_flags() {
            Some(system) => {
                self.system_break |= system;
                true
            }
            None => false,
        }
    }

    #[inline]
    fn clear_break_flags(&mut self) {
        clear_break_flags();
    }

    #[inline]
    fn write_compares(&mut self, compares: [u16; 3]) {
        for (ch, compare) in compares.iter().enumerate() {
            PWM_REGS.ccr(ch).write(|w| w.set_ccr(*compare));
        }
    }

    #[inline]
    fn set_main_output(&mut self, on: bool) {
        self.stage.pwm.set_master_output_enable(on);
    }
}

/// The bridge driver.
pub struct Bridge {
    registers: Registers,
    control: BridgeControl,
}

impl Bridge {
    /// Takes over the power stage (left disabled by the board, compare values 0).
    pub fn new(stage: Stage) -> Bridge {
        let period_ticks = PWM_REGS.arr().read().arr();
        Bridge {
            registers: Registers {
                stage,
                system_break: false,
            },
            control: BridgeControl::new(period_ticks),
        }
    }

    /// Writes the duties and the enable. Called once per PWM period from the control
    /// interrupt.
    #[inline]
    pub fn apply(&mut self, out: &Outputs) -> BridgeEvent {
        self.control.apply(&mut self.registers, out)
    }

    /// MOE as the sequence last set it.
    pub fn enabled(&self) -> bool {
        self.control.main_output()
    }

    /// Whether the breaks seen since the last call included a system break; clears it.
    pub fn take_system_break(&mut self) -> bool {
        core::mem::take(&mut self.registers.system_break)
    }

    /// Turns all six switches off at once (MOE = 0).
    pub fn disable(&mut self) {
        self.control.disable(&mut self.registers);
    }
}
