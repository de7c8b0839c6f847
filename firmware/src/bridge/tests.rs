//! The sequence against a model of an advanced-control timer (RM0440's behaviour, not the
//! module's): compare values preloaded and made active at the update event (the counter
//! peak, before each control interrupt); a break clears MOE in hardware and sets the flag,
//! which only software clears; while a break source is still active the flag cannot be
//! cleared and MOE cannot be set. Breaks are injected before every register access of a
//! period in turn.

use super::*;
use std::vec::Vec;

/// ARR of 20 kHz centre-aligned PWM at 170 MHz.
const ARR: u16 = 4250;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Op {
    Read(bool),
    Clear,
    Compares([u16; 3]),
    Moe(bool),
}

#[derive(Default)]
struct Timer {
    bif: bool,
    moe: bool,
    preload: [u16; 3],
    active: [u16; 3],
    /// A break source held active (a fault still present).
    source_active: bool,
    /// Register accesses of the current period.
    ops: Vec<Op>,
    /// A break pulse (fires and releases) before this register access of the period.
    pulse_before: Option<usize>,
    /// Active and preloaded compares each time MOE was set from clear.
    moe_set_with: Vec<([u16; 3], [u16; 3])>,
}

impl Timer {
    /// One PWM period: the update event at the peak, then the control interrupt.
    fn period(&mut self, c: &mut BridgeControl, out: &Outputs) -> BridgeEvent {
        self.active = self.preload;
        self.ops.clear();
        let event = c.apply(self, out);
        // A pulse after the period's last access.
        if self.pulse_before.is_some_and(|k| k >= self.ops.len()) {
            self.bif = true;
            self.moe = false;
        }
        event
    }

    fn access(&mut self) {
        if self.pulse_before == Some(self.ops.len()) {
            self.bif = true;
            self.moe = false;
        }
    }
}

impl PowerStage for Timer {
    fn break_flagged(&mut self) -> bool {
        self.access();
        self.ops.push(Op::Read(self.bif));
        self.bif
    }

    fn clear_break_flags(&mut self) {
        self.access();
        self.ops.push(Op::Clear);
        if !self.source_active {
            self.bif = false;
        }
    }

    fn write_compares(&mut self, compares: [u16; 3]) {
        self.access();
        self.ops.push(Op::Compares(compares));
        self.preload = compares;
    }

    fn set_main_output(&mut self, on: bool) {
        self.access();
        if on {
            // The flags were read, and read clear, right before.
            assert_eq!(self.ops.last(), Some(&Op::Read(false)), "{:?}", self.ops);
            if !self.moe {
                self.moe_set_with.push((self.active, self.preload));
            }
        }
        self.ops.push(Op::Moe(on));
        if !(on && self.source_active) {
            self.moe = on;
        }
    }
}

fn on(duties: [f32; 3]) -> Outputs {
    Outputs {
        duties,
        pwm_enabled: true,
    }
}

const DUTIES: [f32; 3] = [0.7, 0.2, 0.5];
/// round(d·ARR) for [`DUTIES`].
const COMPARES: [u16; 3] = [2975, 850, 2125];

/// A timer and sequence after `disabled` periods off (the controller's disabled outputs
/// carry 50 % duties).
fn started(disabled: usize) -> (Timer, BridgeControl) {
    // 50 % in the preload register: not what the board leaves, but what the sequence must
    // not rely on.
    let mut t = Timer {
        preload: [ARR / 2; 3],
        ..Timer::default()
    };
    let mut c = BridgeControl::new(ARR);
    for _ in 0..disabled {
        assert_eq!(t.period(&mut c, &Outputs::DISABLED), BridgeEvent::None);
    }
    (t, c)
}

#[test]
fn moe_is_set_with_compare_zero_active_and_preloaded() {
    let (mut t, mut c) = started(3);
    assert_eq!(t.active, [0; 3]);
    let mut active_with_moe = Vec::new();
    for _ in 0..4 {
        assert_eq!(t.period(&mut c, &on(DUTIES)), BridgeEvent::None);
        active_with_moe.push(t.active);
    }
    // One enable, with every high side off and every low side on in the period MOE comes
    // on and the next: the bootstrap capacitors charge before any high side switches.
    assert_eq!(t.moe_set_with, vec![([0; 3], [0; 3])]);
    assert!(t.moe && c.main_output());
    assert_eq!(
        active_with_moe,
        vec![[0; 3], [0; 3], COMPARES, COMPARES],
        "active compares of the periods from the one MOE is set in"
    );
}

#[test]
fn the_first_interrupt_enabling_at_once_still_starts_from_zero() {
    // With 50 % preloaded, enabling in the very first interrupt would switch the high
    // sides for half of the period MOE comes on in: the sequence writes 0 and waits one.
    let (mut t, mut c) = started(0);
    t.period(&mut c, &on(DUTIES));
    assert!(!t.moe);
    t.period(&mut c, &on(DUTIES));
    assert_eq!(t.moe_set_with, vec![([0; 3], [0; 3])]);
}

/// The register accesses of a period that sets MOE: read, compares 0, read, MOE, read.
const ENABLING_ACCESSES: usize = 5;

#[test]
fn a_break_at_any_point_of_the_enabling_period_leaves_moe_clear() {
    let (mut t, mut c) = started(2);
    t.period(&mut c, &on(DUTIES));
    assert_eq!(t.ops.len(), ENABLING_ACCESSES, "{:?}", t.ops);
    assert!(t.moe);
    for k in 0..ENABLING_ACCESSES {
        let (mut t, mut c) = started(2);
        t.pulse_before = Some(k);
        let event = t.period(&mut c, &on(DUTIES));
        t.pulse_before = None;
        assert_eq!(
            event,
            BridgeEvent::Break,
            "pulse before access {k}: {:?}",
            t.ops
        );
        assert!(!t.moe && !c.main_output(), "pulse before access {k}");
        assert_eq!(t.preload, [0; 3]);
        // The controller still asks for PWM (it has not yet seen fault 17): off.
        for _ in 0..3 {
            assert_eq!(t.period(&mut c, &on(DUTIES)), BridgeEvent::None);
            assert!(!t.moe);
        }
        // It turns the PWM off, then on again: a fresh enable from compare 0.
        t.period(&mut c, &Outputs::DISABLED);
        t.period(&mut c, &on(DUTIES));
        assert!(t.moe);
        assert!(t.moe_set_with.iter().all(|s| *s == ([0; 3], [0; 3])));
    }
}

#[test]
fn a_break_while_running_is_never_undone_by_the_next_writes() {
    // Running: each period reads the flags and writes the compares. A break pulse before
    // either access (or after both) clears MOE in hardware; nothing sets it again, and the
    // next period reports the break.
    for k in 0..=2 {
        let (mut t, mut c) = started(2);
        for _ in 0..3 {
            t.period(&mut c, &on(DUTIES));
        }
        assert!(t.moe);
        let enables = t.moe_set_with.len();
        t.pulse_before = Some(k);
        let first = t.period(&mut c, &on(DUTIES));
        t.pulse_before = None;
        assert!(!t.moe, "pulse before access {k}");
        let second = t.period(&mut c, &on(DUTIES));
        assert_eq!(
            (first, second),
            if k == 0 {
                (BridgeEvent::Break, BridgeEvent::None)
            } else {
                (BridgeEvent::None, BridgeEvent::Break)
            },
            "pulse before access {k}"
        );
        for _ in 0..3 {
            t.period(&mut c, &on(DUTIES));
            assert!(!t.moe);
        }
        assert_eq!(t.moe_set_with.len(), enables, "MOE set again after a break");
    }
}

#[test]
fn a_fault_still_present_keeps_the_bridge_off() {
    let (mut t, mut c) = started(2);
    t.bif = true;
    t.source_active = true;
    for _ in 0..3 {
        // Each attempt: the controller asks, sees the fault, drops the PWM, asks again.
        assert_eq!(t.period(&mut c, &on(DUTIES)), BridgeEvent::Break);
        assert!(!t.moe);
        t.period(&mut c, &Outputs::DISABLED);
    }
    assert!(t.moe_set_with.is_empty());
    // Released: the next enable goes through.
    t.source_active = false;
    t.period(&mut c, &on(DUTIES));
    t.period(&mut c, &Outputs::DISABLED);
    t.period(&mut c, &on(DUTIES));
    assert!(t.moe);
}

#[test]
fn disable_turns_moe_off_and_the_next_enable_precharges() {
    let (mut t, mut c) = started(2);
    for _ in 0..3 {
        t.period(&mut c, &on(DUTIES));
    }
    c.disable(&mut t);
    assert!(!t.moe && !c.main_output());
    assert_eq!(t.preload, [0; 3]);
    t.period(&mut c, &Outputs::DISABLED);
    t.period(&mut c, &on(DUTIES));
    assert_eq!(t.moe_set_with, vec![([0; 3], [0; 3]); 2]);
}
