//! The bridge's enable sequence: the controller's [`Outputs`] each PWM period turned into
//! the writes an advanced-control timer (the G474's TIM1) needs, in the order that keeps
//! the power stage safe. Hardware-free: the registers are behind [`PowerStage`], which the
//! board implements with its timer and the tests with a model of it.
//!
//! What the order guarantees (the register behaviour is RM0440's, advanced-control timers):
//!
//! - **Bootstrap precharge from the first period.** Compare values are preloaded: a value
//!   written now takes effect at the next update event (the counter peak). In centre-aligned
//!   PWM mode 1 a compare of 0 keeps every high side off and every low side on for the
//!   whole period, which charges the high-side gate drivers' bootstrap capacitors. So
//!   whenever the bridge is off, 0 is written, and the period in which MOE (the main output
//!   enable, TIMx_BDTR.MOE) is set writes 0 again: both the active and the preloaded values
//!   are 0 when the outputs come on, and the controller's own precharge periods (zero
//!   duties) follow. (A 50 % compare written while disabled would switch every high side
//!   for half of that first period, before any capacitor is charged.)
//! - **Never re-enabled into a fault.** A break (gate-driver fault line, phase comparator,
//!   system break, or one forced by software) clears MOE in hardware and sets the break
//!   flags (TIMx_SR.BIF, SBIF) until software clears them. MOE is tracked here in software
//!   and set only on the way from off to on; the flags are read right before it is set and
//!   again right after, and a break seen after setting it clears it at once. A break
//!   between two periods is therefore never undone by the next period's writes: MOE is not
//!   written while on, so a break that fired and released after the flags were read leaves
//!   the outputs off until the next period sees its flag. (Setting MOE while a break input
//!   is still active has no effect in hardware, RM0440; the window this sequence cannot
//!   close is a break that fires and releases between the last read and the write, which
//!   the read after the write catches.)
//! - **A break stays latched until the controller lets go.** After a break the bridge stays
//!   off, whatever the controller asks, until the controller has itself turned the PWM off
//!   (the board's interrupt latches fault 17 on [`BridgeEvent::Break`], which drops the
//!   controller to Disabled), so a fault is never cleared by the hardware alone.

use crate::io::Outputs;
use crate::scaling::duty_to_compare;

/// The timer registers the sequence writes (an advanced-control timer's channels 1‥3,
/// its break flags and MOE).
pub trait PowerStage {
    /// True when a break has fired since the flags were last cleared (TIMx_SR.BIF or
    /// SBIF).
    fn break_flagged(&mut self) -> bool;
    /// Clears the break flags (they are cleared by writing 0; the write leaves every other
    /// status flag as it is).
    fn clear_break_flags(&mut self);
    /// Writes the compare values of phases a, b, c (preloaded: they take effect at the
    /// next update event). [timer ticks]
    fn write_compares(&mut self, compares: [u16; 3]);
    /// Sets or clears the main output enable (TIMx_BDTR.MOE).
    fn set_main_output(&mut self, on: bool);
}

/// What happened at the bridge during one [`BridgeControl::apply`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BridgeEvent {
    /// Nothing new.
    None,
    /// A break fired since the previous call (the outputs are off).
    Break,
}

/// The sequence's state: the timer period, MOE as last written, the latched break.
#[derive(Clone, Copy, Debug)]
pub struct BridgeControl {
    /// Auto-reload value: compare value of duty 1. [timer ticks]
    period_ticks: u16,
    /// MOE as this sequence last set it (a break clears it in hardware; the break flag
    /// says so).
    main_output: bool,
    /// A break was seen and the controller has not turned the PWM off since.
    break_latched: bool,
    /// The last compare values written were 0: written in an earlier period, they are the
    /// active ones now (the update event at the peak precedes every call).
    zero_preloaded: bool,
}

impl BridgeControl {
    /// The sequence for a timer whose auto-reload value is `period_ticks`, with MOE clear
    /// (and compare values not known to be 0: the first enable waits one period for them).
    pub const fn new(period_ticks: u16) -> BridgeControl {
        BridgeControl {
            period_ticks,
            main_output: false,
            break_latched: false,
            zero_preloaded: false,
        }
    }

    /// MOE as this sequence last set it.
    pub fn main_output(&self) -> bool {
        self.main_output
    }

    /// One PWM period: the duties and the enable of `out` to `stage`.
    pub fn apply(&mut self, stage: &mut impl PowerStage, out: &Outputs) -> BridgeEvent {
        let mut event = BridgeEvent::None;
        if self.take_break(stage) {
            event = BridgeEvent::Break;
        }
        if !out.pwm_enabled {
            self.break_latched = false;
        }
        if !out.pwm_enabled || self.break_latched {
            self.off(stage);
        } else if self.main_output {
            let period = self.period_ticks;
            self.write(stage, out.duties.map(|d| duty_to_compare(d, period)));
        } else {
            // Coming on: compare 0 active (written in an earlier period; if not, MOE waits
            // a period for it) and preloaded, the flags once more, MOE, the flags again.
            let zero_active = self.zero_preloaded;
            self.write(stage, [0; 3]);
            if !zero_active {
                return event;
            }
            if self.take_break(stage) {
                self.off(stage);
                return BridgeEvent::Break;
            }
            stage.set_main_output(true);
            self.main_output = true;
            if self.take_break(stage) {
                self.off(stage);
                return BridgeEvent::Break;
            }
        }
        event
    }

    /// Turns all six switches off at once (MOE clear), compares 0 for the next enable.
    pub fn disable(&mut self, stage: &mut impl PowerStage) {
        self.off(stage);
    }

    /// Reads the break flags; a break clears them, latches, and MOE is known off.
    fn take_break(&mut self, stage: &mut impl PowerStage) -> bool {
        if !stage.break_flagged() {
            return false;
        }
        stage.clear_break_flags();
        self.break_latched = true;
        self.main_output = false;
        true
    }

    fn off(&mut self, stage: &mut impl PowerStage) {
        stage.set_main_output(false);
        self.main_output = false;
        self.write(stage, [0; 3]);
    }

    fn write(&mut self, stage: &mut impl PowerStage, compares: [u16; 3]) {
        stage.write_compares(compares);
        self.zero_preloaded = compares == [0; 3];
    }
}

#[cfg(test)]
mod tests;
