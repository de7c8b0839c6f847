//! Property tests of the control step (proptest): for any measurement — every ADC count and
//! encoder reading the hardware can deliver, and at the loops' own inputs any `f32`, NaN
//! and infinities included — and any command, accepted or refused, the step never panics
//! and returns finite duties in [0, 1] (the loops: finite outputs within their limits).
//!
//! The controller is taken from where the drive really runs (disabled, holding pressure,
//! running a speed step, commissioning), each state reached by the closed loop against the
//! plant, then fed arbitrary events.

use closed_loop::commissioning::nameplate_config;
use closed_loop::{by_name, controller_config, ClosedLoop};
use firmware::controller::Command;
use firmware::current_loop::CurrentLoop;
use firmware::parameters::ParamId;
use firmware::pi::Pi;
use firmware::pressure_loop::PressureLoop;
use firmware::speed_loop::SpeedLoop;
use firmware::step_test::StepLoop;
use firmware::svpwm::modulate;
use firmware::transforms::{AlphaBeta, Dq};
use firmware::{Config, Controller, Measurements, Mode};
use plant_model::Rig;
use proptest::prelude::*;
use std::sync::OnceLock;

/// The controller after `t` [s] of `scenario` on the nominal rig.
fn running(scenario: &str, t: f64) -> Controller {
    let rig = Rig::nominal();
    let sc = by_name(scenario).expect("a scenario");
    let mut cl = ClosedLoop::new(&rig, &controller_config(&rig), sc, 1).expect("closed loop");
    cl.run(t, 1_000_000, |_| {});
    cl.controller_mut().clone()
}

/// Controllers in each state the drive runs in: disabled, holding pressure, in a speed
/// step, and commissioning (identification under way).
fn states() -> &'static [(&'static str, Controller)] {
    static S: OnceLock<Vec<(&'static str, Controller)>> = OnceLock::new();
    S.get_or_init(|| {
        let rig = Rig::nominal();
        let mut commissioning = Controller::new(&nameplate_config(&rig));
        let _ = commissioning.command(Command::Commission);
        let hold = running("pressure-hold", 0.5);
        let speed = running("speed-step", 0.15);
        assert_eq!(
            hold.mode(),
            Mode::Pressure,
            "the hold runs in pressure mode"
        );
        assert_eq!(speed.mode(), Mode::Speed, "the step runs in speed mode");
        vec![
            ("disabled", Controller::new(&Config::nominal())),
            ("pressure hold", hold),
            ("speed step", speed),
            ("commissioning", commissioning),
        ]
    })
}

/// Any measurement the board can deliver (ADC registers are 16 bits wide whatever the
/// resolution, the encoder timer 32).
fn measurement() -> impl Strategy<Value = Measurements> {
    (
        any::<[u16; 3]>(),
        any::<u16>(),
        any::<u16>(),
        any::<u32>(),
        any::<bool>(),
        any::<u32>(),
    )
        .prop_map(|(i, udc, p, enc, idx, idx_count)| Measurements {
            adc_phase_current: i,
            adc_dc_link: udc,
            adc_pressure: p,
            encoder_count: enc,
            encoder_index: idx,
            encoder_index_count: idx_count,
        })
}

/// Any `f32`: NaN, infinities, subnormals, zeros of both signs.
fn any_f32() -> impl Strategy<Value = f32> {
    proptest::num::f32::ANY
}

/// Any finite `f32` (gains come from validated parameters, never NaN).
fn finite_f32() -> impl Strategy<Value = f32> {
    any_f32().prop_filter("finite", |x| x.is_finite())
}

fn mode() -> impl Strategy<Value = Mode> {
    prop_oneof![
        Just(Mode::Disabled),
        Just(Mode::Calibrating),
        Just(Mode::Speed),
        Just(Mode::Pressure)
    ]
}

/// Any command with any values (most are refused; some are accepted and change the state).
fn command() -> impl Strategy<Value = Command> {
    let id = (0..ParamId::ALL.len()).prop_map(|k| ParamId::ALL[k]);
    let target = prop_oneof![
        Just(StepLoop::Current),
        Just(StepLoop::Speed),
        Just(StepLoop::Pressure)
    ];
    prop_oneof![
        mode().prop_map(Command::SetMode),
        any_f32().prop_map(|pa| Command::SetPressure { pa }),
        (-6e6f32..6e6).prop_map(|pa| Command::SetPressure { pa }),
        any_f32().prop_map(|rad_s| Command::SetSpeed { rad_s }),
        (-250f32..250.0).prop_map(|rad_s| Command::SetSpeed { rad_s }),
        Just(Command::ClearFaults),
        Just(Command::Heartbeat),
        Just(Command::Commission),
        (id, any_f32()).prop_map(|(id, value)| Command::SetParameter { id, value }),
        (target, any_f32(), any_f32()).prop_map(|(target, amplitude, duration_s)| {
            Command::StepTest {
                target,
                amplitude,
                duration_s,
            }
        }),
    ]
}

#[derive(Clone, Debug)]
enum Event {
    Sample(Measurements),
    /// A run of samples repeating one measurement (a held fault condition).
    Hold(Measurements, u16),
    Do(Command),
}

fn event() -> impl Strategy<Value = Event> {
    prop_oneof![
        4 => measurement().prop_map(Event::Sample),
        1 => (measurement(), 1u16..400).prop_map(|(m, n)| Event::Hold(m, n)),
        2 => command().prop_map(Event::Do),
    ]
}

fn duties_ok(d: &[f32; 3]) -> bool {
    d.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, ..ProptestConfig::default() })]

    #[test]
    fn the_controller_step_gives_finite_duties_in_0_1(
        events in proptest::collection::vec(event(), 1..48),
        which in 0usize..4,
    ) {
        let (name, start) = &states()[which];
        let mut c = start.clone();
        for e in &events {
            let samples = match e {
                Event::Sample(m) => vec![*m],
                Event::Hold(m, n) => vec![*m; usize::from(*n)],
                Event::Do(cmd) => {
                    let _ = c.command(*cmd);
                    Vec::new()
                }
            };
            for m in samples {
                let out = c.on_current_sample(&m);
                prop_assert!(duties_ok(&out.duties), "{name}: {:?} after {e:?}", out.duties);
            }
            let t = c.telemetry();
            prop_assert!(t.t_s.is_finite(), "{name}: telemetry time {}", t.t_s);
        }
    }

    #[test]
    fn the_current_loop_step_gives_finite_duties_in_0_1(
        m in measurement(),
        theta in any_f32(),
        d in any_f32(),
        q in any_f32(),
        omega in any_f32(),
    ) {
        let mut l = CurrentLoop::new(&Config::nominal());
        for _ in 0..3 {
            let s = l.step(&m, theta, Dq { d, q }, omega, 0.0);
            prop_assert!(duties_ok(&s.duties), "{:?}", s.duties);
        }
    }

    #[test]
    fn modulation_gives_finite_duties_in_0_1(alpha in any_f32(), beta in any_f32(), udc in any_f32()) {
        let m = modulate(AlphaBeta { alpha, beta }, udc);
        prop_assert!(duties_ok(&m.duties), "{:?}", m.duties);
    }

    #[test]
    fn the_outer_loops_give_finite_references_within_their_limits(
        inputs in proptest::collection::vec((0f32..1.0, any_f32(), any_f32()), 1..32),
    ) {
        // References as accepted commands set them (within their bounds); measurements any.
        let cfg = Config::nominal();
        let (p_lo, p_hi) = (cfg.pressure.setpoint_min_pa, cfg.pressure.setpoint_max_pa);
        let w_max = cfg.speed.speed_limit_rad_s;
        let mut speed = SpeedLoop::new(&cfg);
        let mut pressure = PressureLoop::new(&cfg);
        for (r, p_meas, w_meas) in inputs {
            pressure.set_target(p_lo + r * (p_hi - p_lo));
            let w = pressure.step(p_meas);
            prop_assert!(w.is_finite() && w.abs() <= w_max, "speed ref {w}");
            let iq = speed.step(w_max * (2.0 * r - 1.0), w_meas);
            prop_assert!(iq.is_finite() && iq.abs() <= cfg.speed.iq_limit_a, "iq ref {iq}");
        }
    }

    #[test]
    fn a_pi_step_is_finite_and_within_its_limits(
        gains in (finite_f32(), finite_f32()),
        inputs in proptest::collection::vec((any_f32(), any_f32()), 1..16),
    ) {
        let mut pi = Pi::new(1.0, 10.0, 1e-4, -5.0, 5.0);
        pi.set_gains(gains.0, gains.1);
        for (e, ff) in inputs {
            let y = pi.step(e, ff);
            prop_assert!(y.is_finite() && (-5.0..=5.0).contains(&y), "{y}");
        }
    }
}
