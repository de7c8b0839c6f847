//! The campaign's fault classes and how one fault of a class is drawn: each a fault the
//! plant ([`plant_model::faults`]), its sensors ([`plant_model::sensor_faults`]), the CAN bus
//! ([`super::bus`]) or the application (the watchdog path) can produce, with its parameters
//! drawn over the range a drive meets — on both sides of the drive's trip levels, so that
//! some faults are visible to it and some are not.

use super::bus::{Babbler, DRIVE_NODE};
use super::rng::Rng;
use firmware::can_protocol::{encode_command, Frame, NodeId, Request};
use firmware::parameters::ParamId;
use plant_model::faults::{Phase, PlantFaults, Rail, Short, ShortPath, SupplyFault};
use plant_model::sensor_faults::{CurrentFault, EncoderFault, PressureFault, SensorFaults};

/// A fault class of the campaign.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// A motor phase open.
    PhaseOpen,
    /// A short between two phases.
    PhaseToPhaseShort,
    /// A phase shorted to a DC-link rail.
    PhaseToRailShort,
    /// The supply sags.
    DcLinkSag,
    /// The supply surges.
    DcLinkSurge,
    /// Rectifier ripple on the bus.
    SupplyRipple,
    /// Encoder counts lost.
    EncoderLostCounts,
    /// Spurious encoder edges.
    EncoderNoiseBurst,
    /// Encoder counter stopped.
    EncoderStuck,
    /// Encoder index lost.
    EncoderLostIndex,
    /// Encoder A/B swapped.
    EncoderReversed,
    /// Transducer loop open.
    PressureOpenWire,
    /// Transducer output shorted.
    PressureShort,
    /// Transducer output frozen.
    PressureStuck,
    /// Transducer offset drifting.
    PressureDrift,
    /// Interference on the transducer.
    PressureNoiseBurst,
    /// A current channel frozen.
    CurrentStuck,
    /// A current channel's gain off.
    CurrentGainError,
    /// A current channel clipping.
    CurrentSaturation,
    /// Port A's relief valve stuck closed.
    ReliefStuckClosed,
    /// A burst line from port A.
    BurstLine,
    /// The pump's delivery port blocked.
    BlockedPumpPort,
    /// A node flooding the bus at its full rate.
    CanFlood,
    /// Malformed frames.
    CanGarbage,
    /// Setpoints and parameters beyond their bounds.
    OutOfRangeSetpoints,
    /// Parameters set to their bounds while running.
    ParameterBounds,
    /// The bench PC falls silent.
    CommandTimeout,
    /// The control loop overran (the application's watchdog path).
    ControlOverrun,
}

impl Class {
    /// Every class, in table order.
    pub const ALL: [Class; 28] = [
        Class::PhaseOpen,
        Class::PhaseToPhaseShort,
        Class::PhaseToRailShort,
        Class::DcLinkSag,
        Class::DcLinkSurge,
        Class::SupplyRipple,
        Class::EncoderLostCounts,
        Class::EncoderNoiseBurst,
        Class::EncoderStuck,
        Class::EncoderLostIndex,
        Class::EncoderReversed,
        Class::PressureOpenWire,
        Class::PressureShort,
        Class::PressureStuck,
        Class::PressureDrift,
        Class::PressureNoiseBurst,
        Class::CurrentStuck,
        Class::CurrentGainError,
        Class::CurrentSaturation,
        Class::ReliefStuckClosed,
        Class::BurstLine,
        Class::BlockedPumpPort,
        Class::CanFlood,
        Class::CanGarbage,
        Class::OutOfRangeSetpoints,
        Class::ParameterBounds,
        Class::CommandTimeout,
        Class::ControlOverrun,
    ];

    /// Short name for the table.
    pub fn name(self) -> &'static str {
        match self {
            Class::PhaseOpen => "phase open",
            Class::PhaseToPhaseShort => "phase-phase short",
            Class::PhaseToRailShort => "phase-rail short",
            Class::DcLinkSag => "DC link sag",
            Class::DcLinkSurge => "DC link surge",
            Class::SupplyRipple => "supply ripple",
            Class::EncoderLostCounts => "enc lost counts",
            Class::EncoderNoiseBurst => "enc noise burst",
            Class::EncoderStuck => "enc stuck count",
            Class::EncoderLostIndex => "enc lost index",
            Class::EncoderReversed => "enc reversed",
            Class::PressureOpenWire => "p open wire",
            Class::PressureShort => "p short",
            Class::PressureStuck => "p stuck",
            Class::PressureDrift => "p drift",
            Class::PressureNoiseBurst => "p noise burst",
            Class::CurrentStuck => "i stuck channel",
            Class::CurrentGainError => "i gain error",
            Class::CurrentSaturation => "i saturation",
            Class::ReliefStuckClosed => "relief stuck shut",
            Class::BurstLine => "burst line",
            Class::BlockedPumpPort => "blocked pump port",
            Class::CanFlood => "CAN flood",
            Class::CanGarbage => "CAN garbage",
            Class::OutOfRangeSetpoints => "out-of-range cmds",
            Class::ParameterBounds => "params at bounds",
            Class::CommandTimeout => "command timeout",
            Class::ControlOverrun => "control overrun",
        }
    }
}

/// How a fault is put into the loop.
#[derive(Clone, Debug)]
pub enum Injection {
    /// A fault of the plant.
    Plant(PlantFaults),
    /// A fault of the sensors.
    Sensor(SensorFaults),
    /// A node flooding the bus for `duration_s`.
    Flood {
        /// Its frame.
        frame: Frame,
        /// How long. [s]
        duration_s: f64,
    },
    /// Malformed frames at `rate_hz` for `duration_s`.
    Garbage {
        /// Mean rate. [frames/s]
        rate_hz: f64,
        /// How long. [s]
        duration_s: f64,
    },
    /// Frames from the bench PC whose values are out of range.
    Frames(Vec<Frame>),
    /// One parameter set to a bound through the bus.
    Parameter {
        /// Which.
        id: ParamId,
        /// To what. [its unit]
        value: f32,
    },
    /// The bench PC sends nothing for `duration_s`.
    Silence {
        /// How long. [s]
        duration_s: f64,
    },
    /// The application reports a control-loop overrun.
    Overrun,
}

/// One fault of the campaign.
#[derive(Clone, Debug)]
pub struct Fault {
    /// Its class.
    pub class: Class,
    /// How it is injected.
    pub injection: Injection,
    /// The cause ends by itself after this long (a burst); otherwise it lasts until the
    /// repair. [s]
    pub lasts_s: Option<f64>,
    /// Its parameters, for the table's notes.
    pub description: String,
}

fn plant(f: PlantFaults) -> Injection {
    Injection::Plant(f)
}

fn sensor(f: SensorFaults) -> Injection {
    Injection::Sensor(f)
}

fn phase(rng: &mut Rng) -> Phase {
    Phase::ALL[rng.below(3)]
}

/// A drawn fault: its injection, how long it lasts before its repair, and its description.
type Drawn = (Injection, Option<f64>, String);

/// Draws a fault of `class`.
pub fn draw(class: Class, rng: &mut Rng) -> Fault {
    let (injection, lasts_s, description) = match class {
        Class::PhaseOpen | Class::PhaseToPhaseShort | Class::PhaseToRailShort => {
            winding_fault(class, rng)
        }
        Class::DcLinkSag | Class::DcLinkSurge | Class::SupplyRipple => supply_fault(class, rng),
        Class::EncoderLostCounts
        | Class::EncoderNoiseBurst
        | Class::EncoderStuck
        | Class::EncoderLostIndex
        | Class::EncoderReversed => encoder_fault(class, rng),
        Class::PressureOpenWire
        | Class::PressureShort
        | Class::PressureStuck
        | Class::PressureDrift
        | Class::PressureNoiseBurst => pressure_sensor_fault(class, rng),
        Class::CurrentStuck | Class::CurrentGainError | Class::CurrentSaturation => {
            current_sensor_fault(class, rng)
        }
        Class::ReliefStuckClosed | Class::BurstLine | Class::BlockedPumpPort => {
            hydraulic_fault(class, rng)
        }
        Class::CanFlood
        | Class::CanGarbage
        | Class::OutOfRangeSetpoints
        | Class::ParameterBounds
        | Class::CommandTimeout
        | Class::ControlOverrun => command_fault(class, rng),
    };
    Fault {
        class,
        injection,
        lasts_s,
        description,
    }
}

/// Draws `class`, an open phase or a short from a phase.
fn winding_fault(class: Class, rng: &mut Rng) -> Drawn {
    match class {
        Class::PhaseOpen => {
            let p = phase(rng);
            let f = PlantFaults {
                open_phase: Some(p),
                ..PlantFaults::default()
            };
            (plant(f), None, format!("phase {p:?}"))
        }
        _ => {
            let from = phase(rng);
            let path = if class == Class::PhaseToPhaseShort {
                let to = if rng.below(2) == 0 {
                    from.next()
                } else {
                    from.next().next()
                };
                ShortPath::PhaseToPhase { from, to }
            } else {
                let rail = if rng.below(2) == 0 {
                    Rail::Positive
                } else {
                    Rail::Negative
                };
                ShortPath::PhaseToRail { phase: from, rail }
            };
            // From a bolted short to a resistive insulation fault whose current stays
            // below the over-current trip.
            let r = rng.log_uniform(0.02, 20.0);
            let l = rng.log_uniform(1e-6, 10e-6);
            let f = PlantFaults {
                short: Some(Short {
                    path,
                    resistance_ohm: r,
                    inductance_h: l,
                }),
                ..PlantFaults::default()
            };
            (
                plant(f),
                None,
                format!("{path:?}, {r:.3} Ω, {:.1} µH", l * 1e6),
            )
        }
    }
}

/// Draws `class`, a DC link that sags, surges or ripples.
fn supply_fault(class: Class, rng: &mut Rng) -> Drawn {
    match class {
        Class::DcLinkSag | Class::DcLinkSurge => {
            let to_v = if class == Class::DcLinkSag {
                rng.uniform(100.0, 260.0)
            } else {
                rng.uniform(300.0, 420.0)
            };
            let tau = rng.log_uniform(1e-3, 20e-3);
            let f = PlantFaults {
                supply: Some(SupplyFault::Step {
                    to_v,
                    time_constant_s: tau,
                }),
                ..PlantFaults::default()
            };
            (
                plant(f),
                None,
                format!("to {to_v:.0} V, τ {:.1} ms", tau * 1e3),
            )
        }
        _ => {
            let a = rng.uniform(10.0, 120.0);
            let hz = if rng.below(2) == 0 { 100.0 } else { 300.0 };
            let f = PlantFaults {
                supply: Some(SupplyFault::Ripple {
                    amplitude_v: a,
                    frequency_hz: hz,
                }),
                ..PlantFaults::default()
            };
            (plant(f), None, format!("{a:.0} V at {hz:.0} Hz"))
        }
    }
}

/// Draws `class`, an encoder fault.
fn encoder_fault(class: Class, rng: &mut Rng) -> Drawn {
    match class {
        Class::EncoderLostCounts => {
            let n = rng.uniform(1.0, 400.0) as i32 * if rng.below(2) == 0 { 1 } else { -1 };
            (
                sensor(SensorFaults {
                    encoder: Some(EncoderFault::LostCounts { counts: n }),
                    ..SensorFaults::default()
                }),
                None,
                format!("{n} counts"),
            )
        }
        Class::EncoderNoiseBurst => {
            let rms = rng.log_uniform(0.5, 80.0);
            let d = rng.uniform(1e-3, 20e-3);
            (
                sensor(SensorFaults {
                    encoder: Some(EncoderFault::NoiseBurst { counts_rms: rms }),
                    ..SensorFaults::default()
                }),
                Some(d),
                format!("{rms:.1} counts rms for {:.1} ms", d * 1e3),
            )
        }
        _ => {
            let e = match class {
                Class::EncoderStuck => EncoderFault::Stuck,
                Class::EncoderLostIndex => EncoderFault::LostIndex,
                _ => EncoderFault::Reversed,
            };
            (
                sensor(SensorFaults {
                    encoder: Some(e),
                    ..SensorFaults::default()
                }),
                None,
                String::new(),
            )
        }
    }
}

/// Draws `class`, a pressure transducer fault.
fn pressure_sensor_fault(class: Class, rng: &mut Rng) -> Drawn {
    match class {
        Class::PressureOpenWire | Class::PressureShort | Class::PressureStuck => {
            let p = match class {
                Class::PressureOpenWire => PressureFault::OpenWire,
                Class::PressureShort => PressureFault::Short,
                _ => PressureFault::Stuck,
            };
            (
                sensor(SensorFaults {
                    pressure: Some(p),
                    ..SensorFaults::default()
                }),
                None,
                String::new(),
            )
        }
        Class::PressureDrift => {
            let rate = rng.log_uniform(0.05e6, 5e6) * if rng.below(2) == 0 { 1.0 } else { -1.0 };
            (
                sensor(SensorFaults {
                    pressure: Some(PressureFault::Drift { pa_per_s: rate }),
                    ..SensorFaults::default()
                }),
                None,
                format!("{:+.2} MPa/s", rate / 1e6),
            )
        }
        _ => {
            let rms = rng.log_uniform(10e3, 10e6);
            let d = rng.uniform(1e-3, 50e-3);
            (
                sensor(SensorFaults {
                    pressure: Some(PressureFault::NoiseBurst { rms_pa: rms }),
                    ..SensorFaults::default()
                }),
                Some(d),
                format!("{:.3} MPa rms for {:.1} ms", rms / 1e6, d * 1e3),
            )
        }
    }
}

/// Draws `class`, a phase-current sensor fault.
fn current_sensor_fault(class: Class, rng: &mut Rng) -> Drawn {
    let p = phase(rng);
    let (c, text) = match class {
        Class::CurrentStuck => (CurrentFault::Stuck { phase: p }, format!("{p:?}")),
        Class::CurrentGainError => {
            let g = rng.uniform(0.3, 1.7);
            (
                CurrentFault::GainError { phase: p, gain: g },
                format!("{p:?} gain {g:.2}"),
            )
        }
        _ => {
            let l = rng.uniform(1.0, 40.0);
            (
                CurrentFault::Saturation {
                    phase: p,
                    limit_a: l,
                },
                format!("{p:?} at ±{l:.1} A"),
            )
        }
    };
    (
        sensor(SensorFaults {
            current: Some(c),
            ..SensorFaults::default()
        }),
        None,
        text,
    )
}

/// Draws `class`, a hydraulic fault.
fn hydraulic_fault(class: Class, rng: &mut Rng) -> Drawn {
    match class {
        Class::ReliefStuckClosed => (
            plant(PlantFaults {
                relief_stuck_closed: true,
                ..PlantFaults::default()
            }),
            None,
            String::new(),
        ),
        Class::BurstLine => {
            let a = rng.log_uniform(0.01e-6, 2e-6);
            (
                plant(PlantFaults {
                    burst_area_m2: a,
                    ..PlantFaults::default()
                }),
                None,
                format!("{:.3} mm²", a * 1e6),
            )
        }
        _ => (
            plant(PlantFaults {
                pump_port_blocked: true,
                ..PlantFaults::default()
            }),
            None,
            String::new(),
        ),
    }
}

/// Draws `class`, a fault on the CAN bus or in the control task.
fn command_fault(class: Class, rng: &mut Rng) -> Drawn {
    let node = NodeId::new(DRIVE_NODE).unwrap_or_else(|_| unreachable!("node 1 is valid"));
    match class {
        Class::CanFlood => {
            // Any identifier: below the PC's commands it starves them, above it does not.
            let id = rng.below(0x800) as u16;
            let len = rng.below(9);
            let bytes = [0xA5u8; 8];
            let d = rng.uniform(0.05, 0.3);
            let frame = Frame::new(id, &bytes[..len]).unwrap_or_else(|_| unreachable!());
            (
                Injection::Flood {
                    frame,
                    duration_s: d,
                },
                Some(d),
                format!("id {id:#05x} dlc {len} for {:.0} ms", d * 1e3),
            )
        }
        Class::CanGarbage => {
            let rate = rng.uniform(500.0, 8000.0);
            let d = rng.uniform(0.02, 0.2);
            (
                Injection::Garbage {
                    rate_hz: rate,
                    duration_s: d,
                },
                Some(d),
                format!("{rate:.0} frames/s for {:.0} ms", d * 1e3),
            )
        }
        Class::OutOfRangeSetpoints => {
            let n = 1 + rng.below(20);
            let frames = (0..n).map(|_| out_of_range(rng, node)).collect();
            (Injection::Frames(frames), Some(0.0), format!("{n} frames"))
        }
        Class::ParameterBounds => {
            let live: Vec<ParamId> = ParamId::ALL
                .iter()
                .copied()
                .filter(|p| !p.needs_disabled())
                .collect();
            let id = live[rng.below(live.len())];
            let value = if rng.below(2) == 0 {
                id.min()
            } else {
                id.max()
            };
            (
                Injection::Parameter { id, value },
                None,
                format!("{} = {value}", id.name()),
            )
        }
        Class::CommandTimeout => {
            let d = rng.uniform(0.05, 0.4);
            (
                Injection::Silence { duration_s: d },
                Some(d),
                format!("silent {:.0} ms", d * 1e3),
            )
        }
        _ => (Injection::Overrun, Some(0.0), String::new()),
    }
}

/// A command frame whose value no drive may take: a setpoint beyond its bounds, a
/// parameter beyond its bounds or not a number.
fn out_of_range(rng: &mut Rng, node: NodeId) -> Frame {
    let request = match rng.below(4) {
        0 => Request::SetPressure {
            pa: if rng.below(2) == 0 {
                -(1 + rng.below(1 << 30) as i32)
            } else {
                18_000_001 + rng.below(1 << 30) as i32
            },
        },
        1 => Request::SetSpeed {
            mrad_s: (200_001 + rng.below(1 << 30) as i32) * if rng.below(2) == 0 { 1 } else { -1 },
        },
        2 => {
            let id = ParamId::ALL[rng.below(ParamId::ALL.len())];
            let value = match rng.below(4) {
                0 => f32::NAN,
                1 => f32::INFINITY,
                2 => id.max() * 2.0 + 1.0,
                _ => id.min() - 1.0 - id.min().abs(),
            };
            Request::SetParameter { id, value }
        }
        _ => Request::StepTest {
            target: firmware::step_test::StepLoop::Pressure,
            amplitude: 1e9,
            duration_ms: 100,
        },
    };
    encode_command(&request, node)
}

/// The flood's babbler for a fault injected at `t_s`.
pub fn babbler(frame: Frame, t_s: f64, duration_s: f64) -> Babbler {
    Babbler {
        frame,
        until_s: t_s + duration_s,
    }
}
