//! Faults the fault campaign found the drive blind to, each reproduced on its own in closed
//! loop (the plant's fault models, the firmware's control core) with the detection the
//! control core has now:
//!
//! - an encoder that stops counting (A and B lost) or counts backwards (A and B swapped):
//!   the field stands still or turns the wrong way, the rotor locks to it and the speed
//!   loop holds the q-current reference at its 30 A limit for ever (the campaign saw 26 to
//!   37 A into a locked rotor for the whole 1.5 s watch in 59 of 74 injections) — now the
//!   stall fault (20) after `limits.stall_time_s` at the limit;
//! - a phase-current channel that sticks, and a resistive short from a phase to a DC-link
//!   rail whose current stays below the over-current trip: the three sensed currents no
//!   longer sum to zero — now the current-sum fault (19) in the call that reads it.

use closed_loop::{by_name, controller_config, ClosedLoop};
use firmware::{Command, FaultCode, Measurements, Mode};
use plant_model::faults::{Phase, PlantFaults, Rail, Short, ShortPath};
use plant_model::sensor_faults::{CurrentFault, EncoderFault, SensorFaults};
use plant_model::Rig;

fn holding() -> ClosedLoop {
    let rig = Rig::nominal();
    let scenario = by_name("pressure-hold").expect("scenario");
    let mut l = ClosedLoop::new(&rig, &controller_config(&rig), scenario, 11).expect("loop");
    l.run(0.5, 1000, |_| {});
    assert_eq!(l.controller_mut().fault(), None);
    l
}

/// Runs until a fault latches or `t_end`; the latching sample's time and the time the
/// q-current reference first sat at its limit. [s]
fn until_latched(l: &mut ClosedLoop, t_end: f64) -> (Option<(FaultCode, f64)>, Option<f64>) {
    let limit = l.controller_mut().config().speed.iq_limit_a;
    let mut at_limit = None;
    while l.time_s() < t_end {
        let s = l.step();
        if s.telemetry.iq_ref_a.abs() >= 0.99 * limit {
            at_limit = at_limit.or(Some(s.telemetry.t_s));
        } else {
            at_limit = None;
        }
        if let Some(f) = s.telemetry.fault {
            assert!(!s.outputs.pwm_enabled, "PWM on in the latching call");
            return (Some((f, s.telemetry.t_s)), at_limit);
        }
    }
    (None, at_limit)
}

fn encoder_fault(l: &mut ClosedLoop, e: EncoderFault) {
    l.plant_mut()
        .set_sensor_faults(&SensorFaults {
            encoder: Some(e),
            ..SensorFaults::default()
        })
        .unwrap();
}

#[test]
fn a_stuck_encoder_in_holding_is_a_stall() {
    let mut l = holding();
    encoder_fault(&mut l, EncoderFault::Stuck);
    let (latched, at_limit) = until_latched(&mut l, 3.0);
    let (f, t) = latched.expect("a stuck encoder must not go unnoticed");
    assert_eq!(f, FaultCode::Stall);
    let since = t - at_limit.expect("the reference sat at its limit");
    let stall = f64::from(l.controller_mut().config().limits.stall_time_s);
    println!("stuck encoder: stall latched {since:.4} s after the reference reached its limit");
    // The limit held for the stall time, and not a period longer.
    assert!(
        since >= stall - 1e-6 && since <= stall + 1.0 / 20e3,
        "latched {since} s after the limit"
    );
}

#[test]
fn a_reversed_encoder_in_the_slow_stroke_is_caught() {
    let rig = Rig::nominal();
    let scenario = by_name("slow-stroke").expect("scenario");
    let mut l = ClosedLoop::new(&rig, &controller_config(&rig), scenario, 4).expect("loop");
    l.run(1.0, 1000, |_| {});
    encoder_fault(&mut l, EncoderFault::Reversed);
    let (latched, _) = until_latched(&mut l, 2.5);
    let (f, t) = latched.expect("a reversed encoder must not go unnoticed");
    println!("reversed encoder: {f} after {:.3} s", t - 1.0);
    assert!(
        matches!(f, FaultCode::Stall | FaultCode::EncoderIndexLost),
        "{f}"
    );
}

/// The speed-step scenario's loop, calibrated first (the offsets measured, the encoder
/// aligned) as on the bench, then running at 50 rad/s; the bench PC is the test.
fn calibrated_speed_run() -> ClosedLoop {
    let rig = Rig::nominal();
    let scenario = by_name("speed-step").expect("scenario");
    let mut l = ClosedLoop::new(&rig, &controller_config(&rig), scenario, 5).expect("loop");
    l.set_bench_pc(false);
    l.command(Command::SetMode(Mode::Calibrating)).unwrap();
    while l.time_s() < 1.0 && l.controller_mut().mode() != Mode::Disabled {
        l.step();
        let _ = l.command(Command::Heartbeat);
    }
    assert!(l.controller_mut().is_calibrated());
    l.command(Command::SetSpeed { rad_s: 50.0 }).unwrap();
    l.command(Command::SetMode(Mode::Speed)).unwrap();
    for _ in 0..4000 {
        l.step();
        let _ = l.command(Command::Heartbeat);
    }
    assert_eq!(l.controller_mut().fault(), None);
    l
}

/// Steps until a fault latches (heartbeats from the test), checking that it latches in
/// the very call whose readings sum beyond the level; the call index.
fn sum_trips_in_the_reading_call(l: &mut ClosedLoop, speed: Option<f32>) -> usize {
    let cfg = *l.controller_mut().config();
    let offsets = l.controller_mut().current_offsets();
    let level = cfg.limits.current_sum_a;
    for k in 0..20_000 {
        if let Some(w) = speed {
            if k == 0 {
                l.command(Command::SetSpeed { rad_s: w }).unwrap();
            }
        }
        let _ = l.command(Command::Heartbeat);
        let mut seen = Measurements::default();
        let s = l.step_with(|m| {
            seen = m;
            m
        });
        let sum: f32 = seen
            .adc_phase_current
            .iter()
            .zip(offsets)
            .map(|(c, o)| (f32::from(*c) - o) * cfg.sensors.current_a_per_lsb)
            .sum();
        if sum.abs() > level {
            assert_eq!(
                s.telemetry.fault,
                Some(FaultCode::PhaseCurrentSum),
                "call {k}"
            );
            assert!(!s.outputs.pwm_enabled);
            return k;
        }
        assert_eq!(s.telemetry.fault, None, "call {k}: sum {sum} A");
    }
    panic!("the sum never left {level} A");
}

#[test]
fn a_stuck_current_channel_trips_the_sum_check_in_the_call_that_reads_it() {
    let mut l = calibrated_speed_run();
    l.plant_mut()
        .set_sensor_faults(&SensorFaults {
            current: Some(CurrentFault::Stuck { phase: Phase::A }),
            ..SensorFaults::default()
        })
        .unwrap();
    // Reverse the shaft: the currents swing through the stuck value and away from it.
    let k = sum_trips_in_the_reading_call(&mut l, Some(-50.0));
    println!("stuck channel: the sum check latched {k} calls after the reversal began");
}

#[test]
fn a_resistive_short_to_a_rail_trips_the_sum_check_below_the_over_current_trip() {
    let mut l = calibrated_speed_run();
    // 10 Ω from phase b to the positive rail: (1 − d_b)·280 V / 10 Ω ≈ 14 A drawn through
    // leg b, a third of the over-current trip, leaving the star.
    l.plant_mut()
        .set_faults(&PlantFaults {
            short: Some(Short {
                path: ShortPath::PhaseToRail {
                    phase: Phase::B,
                    rail: Rail::Positive,
                },
                resistance_ohm: 10.0,
                inductance_h: 5e-6,
            }),
            ..PlantFaults::default()
        })
        .unwrap();
    let k = sum_trips_in_the_reading_call(&mut l, None);
    assert!(k <= 1, "latched {k} calls after the short");
    let peak = l.plant().observe().i_bridge_abc_a;
    println!("resistive rail short: latched in call {k}; leg currents then {peak:?} A");
}
