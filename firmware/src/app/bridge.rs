//! The three-phase bridge: the controller's duties to TIM1 compare values, the bridge
//! enable (master output enable, MOE), and the hardware break.
//!
//! Duty d of a phase is the fraction of the PWM period its high side conducts. In
//! centre-aligned PWM mode 1 the output is active while the counter is below the compare
//! value, and the counter runs 0 → ARR → 0, so compare = d · ARR gives exactly that
//! fraction (computed by the core's fixed-point [`duty_to_compare`], saturating, NaN → 0). Compare values are preloaded and take effect at the next update event (the
//! counter peak), so a period is never cut between two duties.
//!
//! A break (the gate driver's fault line, a phase-current comparator, or a break the
//! firmware forced) clears MOE in hardware. The bridge then stays off, whatever the
//! controller asks, until the controller itself has turned the PWM off (the control
//! interrupt latches fault 17 when it sees the break, which drops the mode to Disabled),
//! so a fault is never cleared by the hardware alone.

use super::board::{PowerStage, PWM_REGS};
use firmware::scaling::duty_to_compare;
use firmware::Outputs;

/// What happened at the bridge during one [`Bridge::apply`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BridgeEvent {
    /// Nothing new.
    None,
    /// The hardware break fired since the previous call.
    Break,
}

/// The bridge driver.
pub struct Bridge {
    stage: PowerStage,
    /// Auto-reload value: compare value of duty 1. [timer ticks]
    period_ticks: u16,
    break_latched: bool,
}

impl Bridge {
    /// Takes over the power stage (left disabled by the board).
    pub fn new(stage: PowerStage) -> Bridge {
        let period_ticks = PWM_REGS.arr().read().arr();
        Bridge {
            stage,
            period_ticks,
            break_latched: false,
        }
    }

    /// Writes the duties and the enable. Called once per PWM period from the control
    /// interrupt.
    pub fn apply(&mut self, out: &Outputs) -> BridgeEvent {
        let mut event = BridgeEvent::None;
        if PWM_REGS.sr().read().bif(0) {
            // Flags are cleared by writing 0; writing 1 leaves the others untouched.
            PWM_REGS.sr().modify(|w| w.set_bif(0, false));
            self.break_latched = true;
            event = BridgeEvent::Break;
        }
        if !out.pwm_enabled {
            self.break_latched = false;
        }
        let enable = out.pwm_enabled && !self.break_latched;
        let duties = if enable { out.duties } else { [0.5; 3] };
        for (ch, duty) in duties.iter().enumerate() {
            let compare = duty_to_compare(*duty, self.period_ticks);
            PWM_REGS.ccr(ch).write(|w| w.set_ccr(compare));
        }
        if self.stage.pwm.get_master_output_enable() != enable {
            self.stage.pwm.set_master_output_enable(enable);
        }
        event
    }

    /// Turns all six switches off at once (MOE = 0).
    pub fn disable(&mut self) {
        self.stage.pwm.set_master_output_enable(false);
    }
}
