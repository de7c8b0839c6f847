//! One injection: a fault put into a running bench at its instant, the drive watched
//! against the rules ([`super::spec`]) and the safety invariants every PWM period, the
//! cause removed, the fault cleared over the bus and the drive restarted.
//!
//! Measured and judged for every injection:
//! - the first rule to fire and the code latched, with the delay between them against the
//!   rule's deadline (detected, late, missed, wrong code; or, when no rule fires, rode
//!   through or an unpredicted trip);
//! - PWM off in every call from the latch until the clear;
//! - the longest run of time a bridge current spent above the over-current trip level,
//!   against one PWM period;
//! - the largest pressure anywhere in the circuit against the relief valve's setting (its
//!   cracking pressure above the fill side plus its override at the pump's largest flow);
//! - no NaN in the duties or the telemetry;
//! - a clear sent while the cause is still there (refused when the drive still sees it);
//! - after the repair: ClearFaults and the scenario's mode over the bus, then the drive
//!   runs 0.2 s without a fault.

use super::bench::{Bench, ScenarioId};
use super::bus::Garbage;
use super::catalogue::{babbler, Class, Fault, Injection};
use super::spec::Fired;
use firmware::can_protocol::Request;
use firmware::{FaultCode, Mode, TelemetryFrame};
use plant_model::{PlantFaults, Rig, SensorFaults};

/// How long the drive is watched after a latch before the repair. [s]
const AFTER_LATCH_S: f64 = 0.03;
/// Time from the repair to the clear (the bus voltage's recovery, 5 ms time constant). [s]
const SETTLE_S: f64 = 0.03;
/// How long the restarted drive must run. [s]
const RECOVERY_S: f64 = 0.2;
/// When the clear attempted while the cause is present is sent after the latch. [s]
const CLEAR_PROBE_S: f64 = 0.01;

/// What became of one injection.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Verdict {
    /// A rule fired and a code answering it latched in time.
    Detected,
    /// Latched with a right code, after the deadline.
    Late,
    /// A rule fired and nothing latched.
    Missed,
    /// A code that answers none of the rules that fired.
    WrongCode,
    /// No rule fired and nothing latched.
    RodeThrough,
    /// Nothing fired but the drive latched (commissioning's own checks among them).
    Unpredicted,
}

/// The record of one injection.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The case's index in the plan.
    pub index: usize,
    /// The fault class.
    pub class: Class,
    /// The scenario.
    pub scenario: ScenarioId,
    /// The fault's parameters.
    pub description: String,
    /// The injection instant. [s]
    pub t_inject_s: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// The first rule that fired.
    pub rule: Option<&'static str>,
    /// The code latched.
    pub latched: Option<FaultCode>,
    /// Injection to latch. [s]
    pub detect_s: Option<f64>,
    /// First rule to latch. [s]
    pub from_visible_s: Option<f64>,
    /// PWM found on after the latch, before the clear.
    pub pwm_after_latch: bool,
    /// Longest run above the over-current level. [s]
    pub over_current_s: f64,
    /// Largest bridge current. [A]
    pub peak_current_a: f64,
    /// Largest pressure in the circuit. [Pa]
    pub peak_pressure_pa: f64,
    /// The pressure limit it is held to. [Pa]
    pub pressure_limit_pa: f64,
    /// A NaN in the duties or the telemetry.
    pub nan: bool,
    /// A clear sent with the cause present: refused?
    pub clear_refused: Option<bool>,
    /// Restarted and ran after the repair.
    pub recovered: bool,
    /// Why not, if not.
    pub recovery_note: String,
    /// Largest difference of port A's pressure from the fault-free twin's while the
    /// fault acted and nothing was latched. [Pa]
    pub pressure_error_pa: f64,
    /// The same for the shaft speed. [rad/s]
    pub speed_error_rad_s: f64,
    /// PWM still on at the end of the watch.
    pub running_at_end: bool,
    /// Rejects the drive sent for frames addressed to another node.
    pub foreign_replies: u32,
}

impl Outcome {
    /// True when every invariant held and the verdict is not a failure.
    pub fn passed(&self) -> bool {
        !matches!(
            self.verdict,
            Verdict::Late | Verdict::Missed | Verdict::WrongCode
        ) && self.invariants_held()
    }

    /// True when the safety invariants held.
    pub fn invariants_held(&self) -> bool {
        !self.pwm_after_latch
            && self.foreign_replies == 0
            && self.over_current_s <= PWM_PERIOD_S * 1.0001
            && self.peak_pressure_pa <= self.pressure_limit_pa
            && !self.nan
            && self.recovered
    }
}

/// The PWM period the invariants are stated in. [s]
pub const PWM_PERIOD_S: f64 = 50e-6;

/// How long the drive is watched after the injection at most (the index checks need a
/// revolution: about 1.1 s in holding). [s]
fn watch_s(class: Class) -> f64 {
    match class {
        Class::EncoderLostCounts
        | Class::EncoderNoiseBurst
        | Class::EncoderStuck
        | Class::EncoderLostIndex
        | Class::EncoderReversed => 1.5,
        Class::PressureStuck
        | Class::PressureDrift
        | Class::ReliefStuckClosed
        | Class::BurstLine
        | Class::BlockedPumpPort
        | Class::PhaseOpen
        | Class::CurrentGainError
        | Class::CurrentSaturation
        | Class::CurrentStuck => 1.0,
        Class::CommandTimeout | Class::CanFlood | Class::CanGarbage => 0.45,
        _ => 0.3,
    }
}

/// The relief valve's setting: cracking above the fill side, plus its override at the
/// pump's flow at the over-speed level (the largest the drive lets it turn). [Pa]
pub fn pressure_limit_pa(rig: &Rig, over_speed_rad_s: f64) -> f64 {
    let q = rig.pump.displacement_m3_per_rev / std::f64::consts::TAU * over_speed_rad_s;
    rig.fill.pressure_pa + rig.fill.relief_cracking_pa + q / rig.fill.relief_conductance_m3_s_pa
}

fn has_nan(t: &TelemetryFrame, duties: &[f32; 3]) -> bool {
    let f = [
        t.p_ref_pa,
        t.p_pa,
        t.speed_rad_s,
        t.iq_a,
        t.id_a,
        t.theta_m_rad,
        t.speed_ref_rad_s,
        t.iq_ref_a,
        t.ud_v,
        t.uq_v,
        t.udc_v,
    ];
    f.iter().chain(duties).any(|x| x.is_nan()) || t.t_s.is_nan()
}

/// Puts `fault` into `b` now.
fn inject(b: &mut Bench, fault: &Fault, seed: u64) -> Option<(firmware::parameters::ParamId, f32)> {
    let t = b.time_s();
    match &fault.injection {
        Injection::Plant(f) => {
            b.cl.plant_mut()
                .set_faults(f)
                .unwrap_or_else(|e| panic!("{e}"))
        }
        Injection::Sensor(f) => {
            b.cl.plant_mut()
                .set_sensor_faults(f)
                .unwrap_or_else(|e| panic!("{e}"))
        }
        Injection::Flood { frame, duration_s } => {
            b.bus.babbler = Some(babbler(*frame, t, *duration_s));
        }
        Injection::Garbage {
            rate_hz,
            duration_s,
        } => b.bus.garbage = Some(Garbage::new(*rate_hz, t, t + duration_s, seed)),
        Injection::Frames(frames) => {
            for f in frames {
                b.bus.pc_send_frame(*f);
            }
        }
        Injection::Parameter { id, value } => {
            let before = b.cl.controller_mut().parameter(*id);
            b.bus.pc_send(&Request::SetParameter {
                id: *id,
                value: *value,
            });
            return Some((*id, before));
        }
        Injection::Silence { duration_s } => b.silent_until_s = t + duration_s,
        Injection::Overrun => {
            b.cl.controller_mut().report_overrun();
            b.spec.overrun(b.calls);
        }
    }
    None
}

/// Removes the cause (the repair); a parameter goes back to its value.
fn repair(b: &mut Bench, restore: Option<(firmware::parameters::ParamId, f32)>) {
    let _ = b.cl.plant_mut().set_faults(&PlantFaults::default());
    let _ = b.cl.plant_mut().set_sensor_faults(&SensorFaults::default());
    b.bus.babbler = None;
    b.bus.garbage = None;
    b.silent_until_s = 0.0;
    if let Some((id, value)) = restore {
        b.bus.pc_send(&Request::SetParameter { id, value });
    }
}

/// Ends a transient cause (a burst's end) without touching a lasting one.
fn end_transient(b: &mut Bench, fault: &Fault) {
    match fault.injection {
        Injection::Sensor(_) => {
            let _ = b.cl.plant_mut().set_sensor_faults(&SensorFaults::default());
        }
        Injection::Plant(_) => {
            let _ = b.cl.plant_mut().set_faults(&PlantFaults::default());
        }
        _ => {}
    }
}

/// Runs `fault` on a copy of `base` (already at the injection instant).
pub fn run_case(base: &Bench, index: usize, fault: &Fault, seed: u64) -> Outcome {
    let mut b = base.clone();
    let rig = Rig::nominal();
    let limits = b.config.limits;
    let t0 = b.time_s();
    let call0 = b.calls;
    // The same bench without the fault, step for step: what the fault changed.
    let mut twin = b.clone();
    let restore = inject(&mut b, fault, seed);
    b.spec.injected();
    let mut o = Outcome {
        index,
        class: fault.class,
        scenario: b.scenario,
        description: fault.description.clone(),
        t_inject_s: t0,
        verdict: Verdict::RodeThrough,
        rule: None,
        latched: None,
        detect_s: None,
        from_visible_s: None,
        pwm_after_latch: false,
        over_current_s: 0.0,
        peak_current_a: 0.0,
        peak_pressure_pa: 0.0,
        pressure_limit_pa: pressure_limit_pa(&rig, f64::from(limits.over_speed_rad_s)),
        nan: false,
        clear_refused: None,
        recovered: false,
        recovery_note: String::new(),
        pressure_error_pa: 0.0,
        speed_error_rad_s: 0.0,
        running_at_end: false,
        foreign_replies: 0,
    };
    let foreign0 = b.bus.rx.foreign_replies;
    let mut fired: Vec<Fired> = Vec::new();
    let mut latch_call: Option<u64> = None;
    let mut run_above = 0.0f64;
    let mut transient_over = fault.lasts_s.is_none();
    let t_end = t0 + watch_s(fault.class);
    let mut clear_probe_sent = false;
    let mut last_pwm = true;
    while b.time_s() < t_end {
        if !transient_over && b.time_s() >= t0 + fault.lasts_s.unwrap_or(0.0) {
            end_transient(&mut b, fault);
            transient_over = true;
        }
        let step = b.period();
        let call = b.calls - 1 - call0;
        let s = &step.sample;
        fired.extend(step.fired.iter().map(|f| Fired { period: call, ..*f }));
        // Invariants.
        o.nan |= has_nan(&s.telemetry, &s.outputs.duties);
        o.peak_current_a = o.peak_current_a.max(step.watch.peak_a);
        if step.watch.time_above_s > 0.0 {
            run_above += step.watch.time_above_s;
            o.over_current_s = o.over_current_s.max(run_above);
        } else {
            run_above = 0.0;
        }
        let t = &s.truth;
        o.peak_pressure_pa = o
            .peak_pressure_pa
            .max(t.p_a_pa)
            .max(t.p_b_pa)
            .max(t.p_pump_pa);
        if latch_call.is_none() {
            let u = twin.period().sample.truth;
            o.pressure_error_pa = o.pressure_error_pa.max((t.p_a_pa - u.p_a_pa).abs());
            o.speed_error_rad_s = o
                .speed_error_rad_s
                .max((t.omega_m_rad_s - u.omega_m_rad_s).abs());
        }
        last_pwm = s.outputs.pwm_enabled;
        if let (None, Some(code)) = (latch_call, s.telemetry.fault) {
            latch_call = Some(call);
            o.latched = Some(code);
            o.detect_s = Some(b.time_s() - PWM_PERIOD_S - t0);
        }
        // From the latching call on, until the clear, the bridge stays off.
        o.pwm_after_latch |= latch_call.is_some() && s.outputs.pwm_enabled;
        if let Some(l) = latch_call {
            let since = (call - l) as f64 * PWM_PERIOD_S;
            // A clear with the cause still there (a lasting cause only).
            if !clear_probe_sent && since >= CLEAR_PROBE_S && fault.lasts_s.is_none() {
                b.bus.pc_send(&Request::ClearFaults);
                clear_probe_sent = true;
            }
            // Served within a frame time; read back 2 ms later.
            if clear_probe_sent && o.clear_refused.is_none() && since >= CLEAR_PROBE_S + 2e-3 {
                o.clear_refused = Some(b.cl.controller_mut().fault().is_some());
            }
            if since >= AFTER_LATCH_S {
                break;
            }
        }
    }
    o.running_at_end = last_pwm && latch_call.is_none();
    o.foreign_replies = b.bus.rx.foreign_replies - foreign0;
    judge(&mut o, &fired, latch_call);
    recover(&mut b, &mut o, restore, latch_call.is_some());
    o
}

/// The verdict from the rules that fired and the latch.
/// The verdict from the rules that fired and the latch: the first rule that requires a
/// code sets the deadline; a code answering any rule fired by then (one that only permits
/// it included) is a right code.
fn judge(o: &mut Outcome, fired: &[Fired], latch: Option<u64>) {
    let first_must = fired.iter().find(|f| f.must);
    o.rule = first_must.or(fired.first()).map(|f| f.rule);
    let (Some(l), Some(code)) = (latch, o.latched) else {
        o.verdict = if first_must.is_some() {
            Verdict::Missed
        } else {
            Verdict::RodeThrough
        };
        return;
    };
    let answering = fired
        .iter()
        .filter(|f| f.period <= l && f.codes.contains(&code))
        .min_by_key(|f| f.period);
    let Some(a) = answering else {
        o.verdict = if first_must.is_some() {
            Verdict::WrongCode
        } else {
            Verdict::Unpredicted
        };
        return;
    };
    if a.must {
        o.from_visible_s = Some((l - a.period) as f64 * PWM_PERIOD_S);
    }
    o.verdict = match first_must {
        Some(m) if l > m.period.saturating_add(m.deadline) => Verdict::Late,
        _ => Verdict::Detected,
    };
}

/// The repair, the clear and the restart over the bus, then the drive must run.
fn recover(
    b: &mut Bench,
    o: &mut Outcome,
    restore: Option<(firmware::parameters::ParamId, f32)>,
    latched: bool,
) {
    repair(b, restore);
    let t = b.time_s();
    b.run_to(t + SETTLE_S);
    // A commissioning sequence still running is stopped: the restart is in Speed mode.
    if b.scenario == ScenarioId::Commissioning {
        b.bus.pc_send(&Request::SetMode(Mode::Disabled));
    }
    if latched || b.cl.controller_mut().fault().is_some() {
        b.bus.pc_send(&Request::ClearFaults);
    }
    let mode_now = b.cl.controller_mut().mode();
    if !mode_now.is_active() || b.scenario == ScenarioId::Commissioning {
        for r in b.restart_requests() {
            b.bus.pc_send(&r);
        }
    }
    let t = b.time_s();
    let (mut on, mut n) = (0u32, 0u32);
    let mut fault = None;
    while b.time_s() < t + RECOVERY_S {
        let step = b.period();
        let s = &step.sample;
        o.nan |= has_nan(&s.telemetry, &s.outputs.duties);
        n += 1;
        // The first 5 ms carry the clear and the restart over the bus.
        if b.time_s() > t + 5e-3 {
            on += u32::from(s.outputs.pwm_enabled);
            fault = fault.or(s.telemetry.fault);
        }
    }
    let wanted = n.saturating_sub(100);
    o.recovered = fault.is_none() && on + 2 >= wanted;
    if !o.recovered {
        o.recovery_note = match fault {
            Some(f) => format!("tripped again: {f}"),
            None => format!("PWM on {on} of {wanted} calls"),
        };
    }
}
