//! The plant's faults against independent numbers: R-L step responses of the confined
//! winding and of a short circuit's path, the hardware break's instant, the bus's lag, a
//! relief valve's cracking plus its flow, orifice flow, and energy bookkeeping; and the
//! sensors' faults as the peripherals would report them.

mod common;
use common::{quiet, speed_drive};
use plant_model::faults::{
    Phase, PlantFaults, Rail, Short, ShortPath, SupplyFault, ORIFICE_DISCHARGE_COEFFICIENT,
    PUMP_MANIFOLD_VOLUME_M3,
};
use plant_model::sensor_faults::{CurrentFault, EncoderFault, PressureFault, SensorFaults};
use plant_model::{InitialConditions, Inputs, Plant, Rig};
use std::f64::consts::PI;

const SQRT3: f64 = 1.732_050_807_568_877_2;

#[test]
fn an_open_phase_leaves_one_rl_line_between_the_other_two() {
    // Phase a open, rotor held at θ_e = π/2, where the b–c line direction n_a = β is the d
    // axis: the line is L_d in series with 2·R_s seen from the terminals, and it makes no
    // torque. b and c driven 2δ·U_dc apart: v_n = 2δ·U_dc/√3,
    // i(t) = v_n/R_s·(1 − e^{−t·R_s/L_d}), i_b = −i_c = (√3/2)·i, i_a = 0.
    let mut rig = quiet(Rig::nominal());
    rig.shaft.static_nm = 1e3;
    rig.shaft.coulomb_nm = 1e3;
    let init = InitialConditions {
        theta_m_rad: PI / 8.0,
        ..InitialConditions::at_rest(&rig)
    };
    let mut plant = Plant::new(&rig, &init, 1).unwrap();
    plant
        .set_faults(&PlantFaults {
            open_phase: Some(Phase::A),
            ..PlantFaults::default()
        })
        .unwrap();
    let (r, l, u) = (rig.motor.r_s_ohm, rig.motor.l_d_h, rig.inverter.u_dc_v);
    let delta = 0.01;
    let v_n = 2.0 * delta * u / SQRT3;
    let duties = [0.5, 0.5 + delta, 0.5 - delta];
    let t_end = l / r;
    let n = (t_end / 50e-6).round() as usize;
    for _ in 0..n {
        plant.advance(50e-6, &Inputs::duties(duties, true));
    }
    let o = plant.observe();
    let t = n as f64 * 50e-6;
    let i = v_n / r * (1.0 - (-t * r / l).exp());
    assert!(o.i_abc_a[0].abs() < 1e-9, "i_a {}", o.i_abc_a[0]);
    assert!(
        (o.i_abc_a[1] - 0.5 * SQRT3 * i).abs() < 2e-3 * i,
        "i_b {} vs {}",
        o.i_abc_a[1],
        0.5 * SQRT3 * i
    );
    assert!((o.i_abc_a[1] + o.i_abc_a[2]).abs() < 1e-9);
    assert!(o.i_q_a.abs() < 1e-9 * i, "no torque current: {}", o.i_q_a);
    assert_eq!(o.omega_m_rad_s, 0.0);
    // The sensors read what flows: nothing on a.
    let r0 = plant.sample();
    assert_eq!(r0.adc_phase_current[0], 2048);
}

#[test]
fn opening_a_phase_removes_its_current_and_books_the_arc() {
    let rig = quiet(Rig::nominal());
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
    // Some current in every phase: a d-axis vector at θ_e = 0.3.
    let (s, c) = 0.3f64.sin_cos();
    let duties = [
        0.5 + 5.0 * c / 280.0,
        0.5 + 5.0 * (-0.5 * c + 0.5 * SQRT3 * s) / 280.0,
        0.5 + 5.0 * (-0.5 * c - 0.5 * SQRT3 * s) / 280.0,
    ];
    for _ in 0..100 {
        plant.advance(50e-6, &Inputs::duties(duties, true));
    }
    let before = plant.observe();
    assert!(before.i_abc_a[2].abs() > 0.5);
    plant
        .set_faults(&PlantFaults {
            open_phase: Some(Phase::C),
            ..PlantFaults::default()
        })
        .unwrap();
    let after = plant.observe();
    assert!(after.i_abc_a[2].abs() < 1e-12);
    // Current continuity in the phases that stay connected is not required (the arc), but
    // the energy balance must close.
    for _ in 0..200 {
        plant.advance(50e-6, &Inputs::duties(duties, true));
    }
    let e = plant.energy();
    assert!(
        e.residual_j().abs() < 1e-6 * e.input_j.abs().max(1e-3),
        "{e:?}"
    );
}

#[test]
fn a_rail_short_draws_its_rl_current_through_the_leg_until_the_break() {
    let rig = quiet(Rig::nominal());
    let short = Short {
        path: ShortPath::PhaseToRail {
            phase: Phase::B,
            rail: Rail::Positive,
        },
        resistance_ohm: 0.05,
        inductance_h: 2e-6,
    };
    let faults = PlantFaults {
        short: Some(short),
        ..PlantFaults::default()
    };
    let tau: f64 = 2e-6 / 0.05;
    let steady = 0.5 * 280.0 / 0.05;
    // No break: after one 50 µs period at duty 0.5 the leg sinks 2800·(1 − e^{−1.25}) A.
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
    plant.set_faults(&faults).unwrap();
    plant.advance(50e-6, &Inputs::duties([0.5; 3], true));
    let o = plant.observe();
    let expected = -steady * (1.0 - (-50e-6 / tau).exp());
    assert!(
        (o.i_bridge_abc_a[1] - expected).abs() < 1e-6 * steady,
        "{} vs {expected}",
        o.i_bridge_abc_a[1]
    );
    assert!(!plant.take_break_event());
    // Break armed at 48 A: it trips when the path current reaches 48 A,
    // t* = −τ·ln(1 − 48/2800), and from there the current free-wheels with τ.
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
    plant.set_faults(&faults).unwrap();
    plant.set_hardware_break(Some(48.0));
    plant.set_current_watch(Some(45.0));
    plant.advance(50e-6, &Inputs::duties([0.5; 3], true));
    assert!(plant.take_break_event());
    assert!(plant.break_latched());
    let t_star = -tau * (1.0 - 48.0 / steady).ln();
    let expected = -48.0 * (-(50e-6 - t_star) / tau).exp();
    let o = plant.observe();
    assert!(
        (o.i_bridge_abc_a[1] - expected).abs() < 0.05,
        "{} vs {expected}",
        o.i_bridge_abc_a[1]
    );
    let w = plant.take_current_watch();
    assert!(w.peak_a <= 48.5, "peak {}", w.peak_a);
    // Above 45 A from 45/2800 of the rise to 45/48 of the decay: a few µs.
    let above = tau * (48.0f64 / 45.0).ln() + t_star - (-tau * (1.0 - 45.0 / steady).ln());
    assert!(
        (w.time_above_s - above).abs() < 1e-7,
        "{} vs {above}",
        w.time_above_s
    );
    // The gates stay off while the software still enables them; its disabling clears it.
    plant.advance(50e-6, &Inputs::duties([0.5; 3], true));
    assert!(plant.break_latched());
    plant.advance(50e-6, &Inputs::duties([0.5; 3], false));
    assert!(!plant.break_latched());
}

#[test]
fn a_phase_to_phase_short_carries_the_duty_difference_and_brakes_the_shaft_when_off() {
    let rig = quiet(Rig::nominal());
    let short = Short {
        path: ShortPath::PhaseToPhase {
            from: Phase::A,
            to: Phase::C,
        },
        resistance_ohm: 0.5,
        inductance_h: 5e-6,
    };
    let init = InitialConditions {
        omega_rad_s: 100.0,
        ..InitialConditions::at_rest(&rig)
    };
    let mut plant = Plant::new(&rig, &init, 1).unwrap();
    plant
        .set_faults(&PlantFaults {
            short: Some(short),
            ..PlantFaults::default()
        })
        .unwrap();
    // Bridge on, legs 0.52 and 0.48: 11.2 V across 0.5 Ω, τ = 10 µs: 22.4 A at 1 ms.
    let duties = [0.52, 0.5, 0.48];
    for _ in 0..20 {
        plant.advance(50e-6, &Inputs::duties(duties, true));
    }
    let o = plant.observe();
    let i_f = 0.04 * 280.0 / 0.5;
    let got = o.i_bridge_abc_a[0] - o.i_abc_a[0];
    assert!((got - i_f).abs() < 1e-6 * i_f, "{got} vs {i_f}");
    assert!((o.i_bridge_abc_a[2] - o.i_abc_a[2] + i_f).abs() < 1e-6 * i_f);
    // Bridge off: the path current is gone at once, the short brakes the turning shaft
    // through the a–c line (b floating), and the sensors see none of that.
    let w0 = plant.observe().omega_m_rad_s;
    for _ in 0..200 {
        plant.advance(50e-6, &Inputs::duties([0.5; 3], false));
    }
    let o = plant.observe();
    assert!(o.i_abc_a[1].abs() < 1e-9, "b floats: {}", o.i_abc_a[1]);
    assert!((o.i_abc_a[0] + o.i_abc_a[2]).abs() < 1e-9);
    assert!(
        o.torque_em_nm.abs() > 0.01,
        "braking torque {}",
        o.torque_em_nm
    );
    for k in 0..3 {
        assert!((o.i_bridge_abc_a[k] - o.i_abc_a[k]).abs() < 1e-12);
    }
    assert!(o.omega_m_rad_s < w0);
    let e = plant.energy();
    assert!(
        e.residual_j().abs() < 1e-4 * e.copper_loss_j.max(1e-3),
        "{e:?}"
    );
}

#[test]
fn the_bus_sags_with_its_time_constant_and_the_adc_reads_it() {
    let rig = quiet(Rig::nominal());
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
    plant
        .set_faults(&PlantFaults {
            supply: Some(SupplyFault::Step {
                to_v: 150.0,
                time_constant_s: 2e-3,
            }),
            ..PlantFaults::default()
        })
        .unwrap();
    for _ in 0..40 {
        plant.advance(50e-6, &Inputs::duties([0.5; 3], false));
    }
    let expected = 150.0 + 130.0 * (-1.0f64).exp();
    let o = plant.observe();
    assert!((o.u_dc_v - expected).abs() < 1e-9, "{}", o.u_dc_v);
    let counts = plant.sample().adc_dc_link;
    assert_eq!(counts, (expected / 0.1).round() as u16);
}

/// Port A behind a stuck relief valve keeps rising where a working one would hold
/// cracking + Q/G (less the leakage): the pump at a prescribed speed into the blocked
/// cylinder, no absorber.
#[test]
fn a_stuck_relief_valve_lets_the_pressure_pass_its_setting() {
    let mut rig = quiet(Rig::nominal());
    rig.cylinder.blocked = true;
    rig.absorber.enabled = false;
    let omega = 100.0;
    let q = rig.pump.displacement_m3_per_rev / (2.0 * PI) * omega;
    let g = rig.fill.relief_conductance_m3_s_pa;
    let crack = rig.fill.relief_cracking_pa;
    let run = |stuck: bool| {
        let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 20e6), 1).unwrap();
        plant
            .set_faults(&PlantFaults {
                relief_stuck_closed: stuck,
                ..PlantFaults::default()
            })
            .unwrap();
        plant.advance(0.5, &speed_drive(omega));
        plant.observe()
    };
    let ok = run(false);
    let fill = ok.p_fill_pa;
    let leak = 3e-13;
    // Steady: Q = G·(p − fill − crack) + leakage·p (approximately, leakage to p_B ≈ fill).
    let p_ss = (q + g * (fill + crack) + leak * fill) / (g + leak);
    assert!(
        (ok.p_a_pa - p_ss).abs() < 0.01 * (p_ss - crack),
        "{} vs {p_ss}",
        ok.p_a_pa
    );
    let stuck = run(true);
    assert!(stuck.p_a_pa > p_ss + 5e6, "stuck: {}", stuck.p_a_pa);
}

#[test]
fn a_burst_line_drains_port_a_through_its_orifice() {
    let mut rig = quiet(Rig::nominal());
    rig.cylinder.blocked = true;
    rig.absorber.enabled = false;
    let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 5e6), 1).unwrap();
    let area = 0.1e-6;
    plant
        .set_faults(&PlantFaults {
            burst_area_m2: area,
            ..PlantFaults::default()
        })
        .unwrap();
    let dt = 1e-4;
    let a = plant.observe().p_a_pa;
    plant.advance(dt, &speed_drive(0.0));
    let b = plant.observe().p_a_pa;
    let p = 0.5 * (a + b);
    let q = ORIFICE_DISCHARGE_COEFFICIENT * area * (2.0 * p / 870.0).sqrt() + 3e-13 * (p - 0.5e6);
    let expected = -q * 6.5e8 / 450e-6;
    assert!(
        ((b - a) / dt - expected).abs() < 0.01 * expected.abs(),
        "{} vs {expected}",
        (b - a) / dt
    );
}

#[test]
fn a_blocked_pump_port_pressurises_the_manifold_alone_up_to_its_relief() {
    let mut rig = quiet(Rig::nominal());
    rig.cylinder.blocked = true;
    let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 5e6), 1).unwrap();
    plant
        .set_faults(&PlantFaults {
            pump_port_blocked: true,
            ..PlantFaults::default()
        })
        .unwrap();
    let omega = 20.0;
    let q = rig.pump.displacement_m3_per_rev / (2.0 * PI) * omega;
    // First: the manifold's 20 cm³ alone takes the flow.
    let dt = 1e-4;
    let a = plant.observe();
    plant.advance(dt, &speed_drive(omega));
    // Imposing the speed gave the shaft ½·J·ω² = 0.16 J outside the books (a replay's
    // prescribed motion); from there the balance must not move.
    let offset = plant.energy().residual_j();
    let b = plant.observe();
    let p = 0.5 * (a.p_pump_pa + b.p_pump_pa);
    // Less the pump's internal (to port B) and external (to the case) leakage.
    let leak = 1e-13 * (p - a.p_b_pa) + 1e-13 * (p - a.p_fill_pa);
    let expected = (q - leak) * 6.5e8 / PUMP_MANIFOLD_VOLUME_M3;
    let got = (b.p_pump_pa - a.p_pump_pa) / dt;
    assert!(
        (got - expected).abs() < 0.005 * expected,
        "{got} vs {expected}"
    );
    // Port A loses only its cylinder leakage, β/V·C·Δp·dt ≈ 65 Pa in 0.1 ms.
    assert!(
        (b.p_a_pa - a.p_a_pa).abs() < 200.0,
        "port A must not see it"
    );
    // Then the manifold's relief valve holds it near its setting, port A untouched.
    plant.advance(0.3, &speed_drive(omega));
    let o = plant.observe();
    let crack = rig.fill.relief_cracking_pa;
    let top = crack + o.p_fill_pa + q / rig.fill.relief_conductance_m3_s_pa;
    assert!(
        o.p_pump_pa > crack && o.p_pump_pa <= top,
        "manifold {} Pa, relief {crack}..{top}",
        o.p_pump_pa
    );
    assert!((o.p_a_pa - 5e6).abs() < 0.1e6, "port A {}", o.p_a_pa);
    // Torque follows the manifold's pressure.
    let t = rig.pump.displacement_m3_per_rev / (2.0 * PI) * (o.p_pump_pa - o.p_b_pa);
    assert!((o.torque_pump_nm - t).abs() < 1e-9 * t);
    let e = plant.energy();
    assert!(
        (e.residual_j() - offset).abs() < 1e-6 * e.input_j,
        "{e:?}, offset {offset} J"
    );
}

#[test]
fn encoder_faults_read_like_the_timer() {
    let rig = quiet(Rig::nominal());
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
    let turn = |plant: &mut Plant, rad: f64| {
        plant.shift_shaft_angle(rad);
        plant.sample()
    };
    let rad_per_count = 2.0 * PI / 10_000.0;
    let c0 = turn(&mut plant, 0.1).encoder_count;
    assert_eq!(c0, (0.1 / rad_per_count) as u32);
    // Lost counts: short by 60 from then on.
    let set = |plant: &mut Plant, e: Option<EncoderFault>| {
        plant
            .set_sensor_faults(&SensorFaults {
                encoder: e,
                ..SensorFaults::default()
            })
            .unwrap()
    };
    // Lost counts: the counter misses at most two edges per sample until 60 are gone.
    set(&mut plant, Some(EncoderFault::LostCounts { counts: 60 }));
    let c = turn(&mut plant, 100.0 * rad_per_count).encoder_count;
    assert_eq!(c, c0 + 100 - 2);
    for _ in 0..40 {
        turn(&mut plant, 0.0);
    }
    assert_eq!(turn(&mut plant, 0.0).encoder_count, c0 + 100 - 60);
    // Reversed from here: no jump, then counting down as the shaft turns on.
    set(&mut plant, None);
    let c1 = turn(&mut plant, 0.0).encoder_count;
    set(&mut plant, Some(EncoderFault::Reversed));
    assert_eq!(turn(&mut plant, 0.0).encoder_count, c1);
    assert_eq!(
        turn(&mut plant, 50.0 * rad_per_count).encoder_count,
        c1 - 50
    );
    // Stuck: frozen while the shaft turns.
    set(&mut plant, Some(EncoderFault::Stuck));
    let s = turn(&mut plant, 0.0).encoder_count;
    assert_eq!(turn(&mut plant, 1.0).encoder_count, s);
    // Lost index: a whole revolution passes without it.
    set(&mut plant, Some(EncoderFault::LostIndex));
    let mut seen = false;
    for _ in 0..20 {
        seen |= turn(&mut plant, 0.5).encoder_index;
    }
    assert!(!seen);
    set(&mut plant, None);
    let mut seen = false;
    for _ in 0..20 {
        seen |= turn(&mut plant, 0.5).encoder_index;
    }
    assert!(seen);
}

#[test]
fn transducer_and_current_channel_faults_read_like_the_adc() {
    let rig = quiet(Rig::nominal());
    let mut plant = Plant::new(&rig, &InitialConditions::holding(&rig, 5e6), 1).unwrap();
    let zero = rig.sensors.pressure.zero_lsb;
    let lsb = rig.sensors.pressure.pa_per_lsb;
    let at_5mpa = plant.sample().adc_pressure;
    assert_eq!(at_5mpa, (zero + 5e6 / lsb).round() as u16);
    let set_p = |plant: &mut Plant, p: Option<PressureFault>| {
        plant
            .set_sensor_faults(&SensorFaults {
                pressure: p,
                ..SensorFaults::default()
            })
            .unwrap()
    };
    set_p(&mut plant, Some(PressureFault::OpenWire));
    assert!(plant.sample().adc_pressure < 10);
    set_p(&mut plant, Some(PressureFault::Short));
    assert_eq!(plant.sample().adc_pressure, u16::MAX);
    set_p(&mut plant, Some(PressureFault::Drift { pa_per_s: 1e6 }));
    let first = plant.sample().adc_pressure;
    plant.advance(0.1, &speed_drive(0.0));
    let p_now = plant.observe().p_a_pa;
    let drifted = plant.sample().adc_pressure;
    assert_eq!(first, at_5mpa);
    assert_eq!(drifted, (zero + (p_now + 0.1e6) / lsb).round() as u16);
    // Current channel b: gain 1.5, then clipped at 2 A, then stuck (rotor held).
    let mut rig = rig;
    rig.shaft.static_nm = 1e3;
    rig.shaft.coulomb_nm = 1e3;
    let mut plant = Plant::new(&rig, &InitialConditions::at_rest(&rig), 1).unwrap();
    for _ in 0..300 {
        plant.advance(50e-6, &Inputs::duties([0.5, 0.52, 0.48], true));
    }
    let i_b = plant.observe().i_abc_a[1];
    assert!(i_b > 3.0);
    let a_per_lsb = rig.sensors.current.a_per_lsb;
    let read_b = |plant: &mut Plant, f: CurrentFault| {
        plant
            .set_sensor_faults(&SensorFaults {
                current: Some(f),
                ..SensorFaults::default()
            })
            .unwrap();
        plant.sample().adc_phase_current[1]
    };
    let counts = |i: f64| (2048.0 + i / a_per_lsb).round() as u16;
    assert_eq!(
        read_b(
            &mut plant,
            CurrentFault::GainError {
                phase: Phase::B,
                gain: 1.5
            }
        ),
        counts(1.5 * i_b)
    );
    assert_eq!(
        read_b(
            &mut plant,
            CurrentFault::Saturation {
                phase: Phase::B,
                limit_a: 2.0
            }
        ),
        counts(2.0)
    );
    let stuck = read_b(&mut plant, CurrentFault::Stuck { phase: Phase::B });
    for _ in 0..100 {
        plant.advance(50e-6, &Inputs::duties([0.5; 3], true));
    }
    assert_eq!(plant.sample().adc_phase_current[1], stuck);
    assert_ne!(counts(plant.observe().i_abc_a[1]), stuck);
}

#[test]
fn a_rail_short_on_a_turning_motor_brakes_it_through_the_short_not_the_leg() {
    // Gates off, shaft at 200 rad/s, phase b shorted to the positive rail: b's pole sits at
    // U_dc, so every positive line EMF drives current through the short and the other
    // legs' upper diodes. Phase b's current into the motor comes from the short (its leg's
    // upper diode is reverse biased): the sensor on leg b reads nothing of it.
    let rig = quiet(Rig::nominal());
    let init = InitialConditions {
        omega_rad_s: 200.0,
        ..InitialConditions::at_rest(&rig)
    };
    let mut plant = Plant::new(&rig, &init, 1).unwrap();
    plant
        .set_faults(&PlantFaults {
            short: Some(Short {
                path: ShortPath::PhaseToRail {
                    phase: Phase::B,
                    rail: Rail::Positive,
                },
                resistance_ohm: 0.5,
                inductance_h: 5e-6,
            }),
            ..PlantFaults::default()
        })
        .unwrap();
    let mut fed_by_short = 0;
    let mut braking = 0.0;
    for _ in 0..400 {
        plant.advance(50e-6, &Inputs::duties([0.5; 3], false));
        let o = plant.observe();
        braking += o.torque_em_nm * 50e-6;
        if o.i_abc_a[1] > 1.0 {
            fed_by_short += 1;
            assert!(
                o.i_bridge_abc_a[1].abs() < 1e-9,
                "leg b {}",
                o.i_bridge_abc_a[1]
            );
        }
        if o.i_abc_a[1] < -1.0 {
            assert!((o.i_bridge_abc_a[1] - o.i_abc_a[1]).abs() < 1e-9);
        }
    }
    assert!(fed_by_short > 10, "phase b never fed by the short");
    assert!(braking < -1e-3, "no braking: {braking} N·m·s");
    assert!(plant.observe().omega_m_rad_s < 200.0);
}
