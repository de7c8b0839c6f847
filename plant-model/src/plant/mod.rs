//! The whole actuator: composition of the component models, its state, the integrator, and
//! the energy bookkeeping.
//!
//! # The one seam
//! [`Plant::advance`] holds the inputs (inverter duties and enable, zero-order hold over one
//! PWM period) and integrates; [`Plant::sample`] returns what the MCU's peripherals read.
//! Nothing else crosses to the controller. For subsystem replay (diagnosis) the drive can
//! instead prescribe the d-q currents or the shaft speed, and the piston's motion.
//!
//! # Hydraulic circuit (Figure 1)
//! Port A of the pump, its line and cylinder chamber 1 form one pressure node p_A with the
//! pulsation absorber on it; port B, its line and chamber 2 the node p_B. Each node has a
//! check valve from the fill accumulator and a relief valve back to it; the pump case drains
//! external leakage to the fill accumulator too, so the circuit is closed and oil is
//! conserved.
//!
//! # Integration
//! A fixed step h = dt/⌈dt/h_max⌉ inside each call, h_max = 50 µs by default (one step per
//! 20 kHz PWM period), by one of two schemes ([`Integrator`]):
//! - the exponential scheme ([`exponential`], the default): the winding currents and the
//!   hydraulic block (port A, the absorber's inlet, port B, the payload) solved exactly over
//!   the step, the slow rest by third-order exponential Adams–Bashforth, one evaluation of
//!   the model per step;
//! - classical RK4 over the whole state ([`rk4`]), the scheme before it: the accuracy
//!   reference at a quarter of the step, and the path of the faulted plant and of the
//!   replays' prescribed currents, speed and piston.
//!
//! Both locate the switching events inside a step (stick/slip, poppet closure, end stops) by
//! regula falsi and handle the discontinuities at the located instant by projection (their
//! energy is booked, see below), so neither integrates across a switching surface with a
//! stale sign. The transducer's first-order lag is filtered exactly after each step
//! (`Plant::filter_pressure_sensor`), stable for any time constant. The fine-step
//! comparison is in this crate's tests (`integration_error_against_fine_step`), the closed
//! loop's in `tests/tests/integrator_accuracy.rs`.
//!
//! Everything that depends on the shaft angle alone (rotor phasors, magnet-flux harmonics,
//! cogging, the pump's displacement factor) is kept for the step's end state, where
//! `sample`, `observe`, the projection and the next step all read it; the phasors are carried
//! from step to step by rotation (a Taylor series exact to rounding for the ≤ 0.1 rad a step
//! turns), recomputed from the angle every 1024 steps — no `sincos` in the steady loop.
//!
//! # Energy
//! Input, losses and the work of projections are integrated as extra states with the same
//! scheme, the stored energy is a function of the state, so
//! `input − Δstored − losses − external work − projection losses` must vanish up to the
//! constant-β approximation of oil compression energy (order p/2β of the boundary work).

use crate::accumulator::ATMOSPHERE_PA;
use crate::accumulator::{Absorber, GasCharge};
use crate::cylinder::Cylinder;
use crate::faults::{DcLink, PlantFaults, PUMP_MANIFOLD_VOLUME_M3};
use crate::friction::{Friction, Slip};
use crate::inverter::{dq_to_abc, pole_to_dq, Inverter};
use crate::motor::{MagnetFlux, Motor, Phasor};
use crate::pump::Pump;
use crate::rig::{Rig, RigError};
use crate::sensors::{SensorReadings, Sensors};
use crate::valves::Valve;

mod exponential;
mod faulted;
mod rk4;
pub use faulted::CurrentWatch;

/// State indices.
mod ix {
    pub const ID: usize = 0;
    pub const IQ: usize = 1;
    pub const THETA: usize = 2;
    pub const OMEGA: usize = 3;
    pub const PA: usize = 4;
    pub const PB: usize = 5;
    pub const X: usize = 6;
    pub const V: usize = 7;
    pub const ABS_OIL: usize = 8;
    pub const ABS_Q: usize = 9;
    pub const FILL_OIL: usize = 10;
    pub const P_SENSOR: usize = 11;
    pub const E_IN: usize = 12;
    pub const E_CU: usize = 13;
    pub const E_MECH: usize = 14;
    pub const E_HYD: usize = 15;
    pub const E_EXT: usize = 16;
    /// Absolute gas pressure of the absorber.
    pub const ABS_PGAS: usize = 17;
    /// Absolute gas pressure of the fill accumulator.
    pub const FILL_PGAS: usize = 18;
    /// Pressure of the pump's manifold: port A's while the port is open, a node of its own
    /// while it is blocked ([`crate::faults`]).
    pub const PP: usize = 19;
    pub const N: usize = 20;
}

type Vector = [f64; ix::N];

/// Events handled inside one step before the rest of it is taken plainly.
const MAX_EVENTS_PER_STEP: usize = 6;
/// Most refinements of an event's time.
const EVENT_REFINEMENTS: usize = 30;
/// Event time located to this fraction of a step (50 ps at 50 µs).
const EVENT_TOLERANCE: f64 = 1e-6;

/// How the shaft is driven during a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// The inverter, with three duties in [0, 1] held over the step, and the bridge enable.
    Inverter {
        /// Duty of phases a, b, c. [1]
        duties: [f64; 3],
        /// Gate drivers enabled; disabled, the bridge's diodes let the currents die out.
        enabled: bool,
    },
    /// Prescribed d-q currents (motor-and-shaft replay from logged currents). [A]
    Currents {
        /// i_d. [A]
        i_d: f64,
        /// i_q. [A]
        i_q: f64,
    },
    /// Prescribed shaft speed (hydraulics replay from logged speed). [rad/s]
    ShaftSpeed {
        /// ω_m. [rad/s]
        omega_rad_s: f64,
    },
}

/// Inputs held over one call of [`Plant::advance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    /// What drives the shaft.
    pub drive: Drive,
    /// Prescribed piston position and velocity (hydraulics replay); `None`: the force
    /// balance moves it (or it is blocked). [m], [m/s]
    pub piston: Option<(f64, f64)>,
    /// External load force on the piston, positive towards +x (F_L of eq. 12 with the
    /// opposite sign). [N]
    pub external_force_n: f64,
    /// External torque on the shaft, positive in the direction of rotation (a replay's
    /// tracking correction; 0 on a real rig). [N·m]
    pub external_torque_nm: f64,
}

impl Inputs {
    /// Inverter drive with the given duties, bridge enabled, no external force.
    pub fn duties(duties: [f64; 3], enabled: bool) -> Inputs {
        Inputs {
            drive: Drive::Inverter { duties, enabled },
            piston: None,
            external_force_n: 0.0,
            external_torque_nm: 0.0,
        }
    }
}

/// The integration scheme of [`Plant::advance`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Integrator {
    /// The default ([`exponential`] module): the winding currents and the port-A node with
    /// the absorber's inlet solved exactly over each step, the rest by second-order
    /// exponential Adams–Bashforth, one model evaluation per step.
    #[default]
    Exponential,
    /// Classical fourth-order Runge–Kutta over the whole state ([`rk4`] module), `substeps`
    /// equal steps per step of the rig (1: the plant's integrator before the exponential
    /// scheme; 4: the accuracy reference at a quarter of the step).
    Rk4 {
        /// Steps per step of the rig (1 to 64).
        substeps: u32,
    },
}

/// Most RK4 substeps per step of the rig.
const MAX_SUBSTEPS: u32 = 64;

impl Integrator {
    /// The names [`Integrator::from_name`] takes, with what each is.
    pub const NAMES: [(&'static str, &'static str); 3] = [
        (
            "exponential",
            "exact linear blocks + exponential Adams–Bashforth 2, the default",
        ),
        ("rk4", "classical Runge–Kutta at the step of the rig"),
        (
            "rk4-quarter",
            "classical Runge–Kutta at a quarter of it, the accuracy reference",
        ),
    ];

    /// By name (one of [`Integrator::NAMES`]).
    pub fn from_name(name: &str) -> Option<Integrator> {
        match name {
            "exponential" => Some(Integrator::Exponential),
            "rk4" => Some(Integrator::Rk4 { substeps: 1 }),
            "rk4-quarter" => Some(Integrator::Rk4 { substeps: 4 }),
            _ => None,
        }
    }

    /// Its name: one of [`Integrator::NAMES`], or `rk4/N` for other substeps.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Exponential => "exponential",
            Integrator::Rk4 { substeps: 1 } => "rk4",
            Integrator::Rk4 { substeps: 4 } => "rk4-quarter",
            Integrator::Rk4 { .. } => "rk4/N",
        }
    }
}

/// Initial conditions of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialConditions {
    /// Port-A pressure; the absorber starts in equilibrium with it. [Pa]
    pub p_a_pa: f64,
    /// Port-B pressure. [Pa]
    pub p_b_pa: f64,
    /// Piston position. [m]
    pub x_m: f64,
    /// Shaft speed. [rad/s]
    pub omega_rad_s: f64,
    /// Shaft angle. [rad]
    pub theta_m_rad: f64,
}

impl InitialConditions {
    /// Everything at rest at the fill pressure of `rig`.
    pub fn at_rest(rig: &Rig) -> InitialConditions {
        InitialConditions {
            p_a_pa: rig.fill.pressure_pa,
            p_b_pa: rig.fill.pressure_pa,
            x_m: 0.0,
            omega_rad_s: 0.0,
            theta_m_rad: 0.0,
        }
    }

    /// At rest with port A at `p_a_pa` (pressure holding starts here).
    pub fn holding(rig: &Rig, p_a_pa: f64) -> InitialConditions {
        InitialConditions {
            p_a_pa,
            ..InitialConditions::at_rest(rig)
        }
    }
}

/// Physical quantities of the plant at one instant (true values, not measurements).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Observables {
    /// Time since the start. [s]
    pub t_s: f64,
    /// d-axis current. [A]
    pub i_d_a: f64,
    /// q-axis current. [A]
    pub i_q_a: f64,
    /// Phase currents a, b, c. [A]
    pub i_abc_a: [f64; 3],
    /// Currents through the bridge legs and the current sensors a, b, c: the phase
    /// currents plus a short circuit's path current ([`crate::faults`]). [A]
    pub i_bridge_abc_a: [f64; 3],
    /// DC-link voltage. [V]
    pub u_dc_v: f64,
    /// d-axis voltage applied by the inverter. [V]
    pub u_d_v: f64,
    /// q-axis voltage applied by the inverter. [V]
    pub u_q_v: f64,
    /// Shaft angle, unwrapped. [rad]
    pub theta_m_rad: f64,
    /// Shaft speed. [rad/s]
    pub omega_m_rad_s: f64,
    /// Electromagnetic torque. [N·m]
    pub torque_em_nm: f64,
    /// Cogging torque. [N·m]
    pub torque_cogging_nm: f64,
    /// Hydraulic load torque of the pump. [N·m]
    pub torque_pump_nm: f64,
    /// Port-A (high side) pressure. [Pa]
    pub p_a_pa: f64,
    /// Pressure in the pump's manifold (port A's unless the pump's port is blocked). [Pa]
    pub p_pump_pa: f64,
    /// Port-B (low side) pressure. [Pa]
    pub p_b_pa: f64,
    /// Pressure at the transducer (after its lag). [Pa]
    pub p_sensor_pa: f64,
    /// Fill accumulator pressure. [Pa]
    pub p_fill_pa: f64,
    /// Pump geometric flow B → A. [m³/s]
    pub pump_flow_m3_s: f64,
    /// Oil in the absorber. [m³]
    pub absorber_oil_m3: f64,
    /// Flow into the absorber. [m³/s]
    pub absorber_flow_m3_s: f64,
    /// Piston position. [m]
    pub x_m: f64,
    /// Piston velocity. [m/s]
    pub v_m_s: f64,
}

/// Energy bookkeeping since the start of the run. [J]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct EnergyBalance {
    /// Energy delivered by the drive (electrical at the motor terminals). [J]
    pub input_j: f64,
    /// Copper loss. [J]
    pub copper_loss_j: f64,
    /// Shaft and piston friction, damping and stop losses. [J]
    pub mechanical_loss_j: f64,
    /// Leakage, valve and absorber-inlet losses. [J]
    pub hydraulic_loss_j: f64,
    /// Work done on the external load. [J]
    pub external_work_j: f64,
    /// Energy removed by projections (sticking, poppet closing, current extinction). [J]
    pub projection_loss_j: f64,
    /// Stored energy now minus at the start. [J]
    pub stored_change_j: f64,
}

impl EnergyBalance {
    /// What is not accounted for: input − Δstored − every loss and work. [J]
    pub fn residual_j(&self) -> f64 {
        self.input_j
            - self.stored_change_j
            - self.copper_loss_j
            - self.mechanical_loss_j
            - self.hydraulic_loss_j
            - self.external_work_j
            - self.projection_loss_j
    }
}

/// Discrete state held over a step.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Discrete {
    shaft: Slip,
    piston: Slip,
    /// Bridge off and currents died out.
    extinguished: bool,
}

/// The inverter-driven part of one evaluation.
#[derive(Clone, Copy, Debug, Default)]
struct Electrical {
    u_d: f64,
    u_q: f64,
    did: f64,
    diq: f64,
    /// Electrical power into the motor terminals. [W]
    p_in: f64,
}

/// The drives of the two friction-bearing bodies in one evaluation (what the stick/slip
/// decisions need).
#[derive(Clone, Copy, Debug, Default)]
struct Aux {
    /// Net shaft torque except friction. [N·m]
    shaft_drive: f64,
    /// Net piston force except friction. [N]
    piston_drive: f64,
}

/// Everything of a derivative evaluation that depends on the shaft angle alone: the rotor
/// phasors, the magnet flux with its harmonics, the cogging torque and the pump's
/// displacement factor. Kept for the present state so that `sample`, `observe`, the
/// projection and the next step's first RK4 stage share one evaluation.
#[derive(Clone, Copy, Debug)]
struct AngleTerms {
    /// The shaft angle these belong to. [rad]
    theta: f64,
    rot_m: Phasor,
    rot_e: Phasor,
    flux: MagnetFlux,
    /// Cogging torque. [N·m]
    t_cog: f64,
    /// Pump displacement factor. [1]
    factor: f64,
}

/// The shaft-angle phasor of the present state, carried from step to step by rotation
/// through the step's angle increment (no `sincos`), re-derived from the angle itself every
/// [`ROTOR_RESYNC_STEPS`] steps so rounding cannot accumulate (≈ 1e-16 rad per rotation).
#[derive(Clone, Copy, Debug)]
struct RotorPhasor {
    /// The shaft angle. [rad]
    theta: f64,
    phasor: Phasor,
    rotations: u32,
}

impl RotorPhasor {
    /// The phasor computed afresh from the angle (one `sincos`).
    fn at(theta: f64) -> RotorPhasor {
        RotorPhasor {
            theta,
            phasor: Phasor::of(theta),
            rotations: 0,
        }
    }
}

/// Steps carried by rotation before the rotor phasor is computed afresh.
const ROTOR_RESYNC_STEPS: u32 = 1024;

/// The actuator model.
#[derive(Clone, Debug)]
pub struct Plant {
    motor: Motor,
    pole_pairs: u32,
    inverter: Inverter,
    inertia: f64,
    shaft_viscous: f64,
    shaft_friction: Friction,
    pump: Pump,
    cylinder: Cylinder,
    piston_friction: Friction,
    beta: f64,
    absorber: Absorber,
    fill_gas: GasCharge,
    check: Valve,
    /// Port B's relief valve (and port A's as built).
    relief: Valve,
    /// Port A's relief valve as it works now (none while stuck closed).
    relief_a: Valve,
    sensor_lag_s: f64,
    sensors: Sensors,
    max_step_s: f64,
    x: Vector,
    discrete: Discrete,
    t_s: f64,
    projection_loss_j: f64,
    stored0_j: f64,
    last_inputs: Inputs,
    rotor: RotorPhasor,
    angle: AngleTerms,
    /// A fault or the protection was ever switched on: the steps take the faulted path.
    faulted: bool,
    faults: PlantFaults,
    dc_link: DcLink,
    /// A short circuit's fault-path current ([`crate::faults`]). [A]
    i_fault: f64,
    oil_density: f64,
    protection: faulted::Protection,
    integrator: Integrator,
    /// The exponential integrator's rates, their slope and its linear blocks.
    exp: exponential::History,
    /// The transducer lag's discrete filter for a step: (h, e^{−h/τ}, τ/h·(1 − e^{−h/τ})).
    lag_filter: (f64, f64, f64),
}

impl Plant {
    /// A plant for a rig (validated here) from initial conditions, with sensor noise seeded
    /// by `seed`.
    pub fn new(rig: &Rig, init: &InitialConditions, seed: u64) -> Result<Plant, RigError> {
        rig.validate()?;
        for (name, v) in [
            ("initial.p_a_pa", init.p_a_pa),
            ("initial.p_b_pa", init.p_b_pa),
            ("initial.x_m", init.x_m),
            ("initial.omega_rad_s", init.omega_rad_s),
            ("initial.theta_m_rad", init.theta_m_rad),
        ] {
            if !v.is_finite() {
                return Err(RigError::new(name, "must be a finite number"));
            }
        }
        if libm::fabs(init.x_m) > rig.cylinder.half_stroke_m {
            return Err(RigError::new("initial.x_m", "must lie within the stroke"));
        }
        let absorber = Absorber::new(&rig.absorber);
        let fill_gas = GasCharge {
            shell_volume_m3: rig.fill.shell_volume_m3,
            precharge_pa: rig.fill.precharge_pa,
            exponent: rig.fill.polytropic_exponent,
        };
        let cylinder = Cylinder::new(&rig.cylinder);
        let mut x = [0.0; ix::N];
        x[ix::THETA] = init.theta_m_rad;
        x[ix::OMEGA] = init.omega_rad_s;
        x[ix::PA] = init.p_a_pa;
        x[ix::PB] = init.p_b_pa;
        x[ix::X] = if cylinder.blocked { 0.0 } else { init.x_m };
        x[ix::ABS_OIL] = if absorber.enabled {
            absorber.gas.oil_volume_m3(init.p_a_pa)
        } else {
            0.0
        };
        x[ix::FILL_OIL] = fill_gas.oil_volume_m3(rig.fill.pressure_pa);
        x[ix::FILL_PGAS] = rig.fill.pressure_pa + ATMOSPHERE_PA;
        x[ix::ABS_PGAS] = absorber.gas.pressure_pa(x[ix::ABS_OIL]) + ATMOSPHERE_PA;
        x[ix::P_SENSOR] = init.p_a_pa;
        x[ix::PP] = init.p_a_pa;
        let slip0 = |v: f64| {
            if v == 0.0 {
                Slip::Stuck
            } else if v < 0.0 {
                Slip::Sliding(-1.0)
            } else {
                Slip::Sliding(1.0)
            }
        };
        let mut plant = Plant {
            motor: Motor::new(&rig.motor),
            pole_pairs: rig.motor.pole_pairs,
            inverter: Inverter::new(&rig.inverter),
            inertia: rig.shaft.inertia_kg_m2(),
            shaft_viscous: rig.shaft.viscous_nm_s,
            shaft_friction: Friction::new(rig.shaft.coulomb_nm, rig.shaft.static_nm),
            pump: Pump::new(&rig.pump),
            cylinder,
            piston_friction: Friction::new(
                rig.cylinder.coulomb_friction_n,
                rig.cylinder.static_friction_n,
            ),
            beta: rig.oil.bulk_modulus_pa,
            absorber,
            fill_gas,
            check: Valve {
                cracking_pa: rig.fill.check_cracking_pa,
                conductance_m3_s_pa: rig.fill.check_conductance_m3_s_pa,
            },
            relief: Valve {
                cracking_pa: rig.fill.relief_cracking_pa,
                conductance_m3_s_pa: rig.fill.relief_conductance_m3_s_pa,
            },
            relief_a: Valve {
                cracking_pa: rig.fill.relief_cracking_pa,
                conductance_m3_s_pa: rig.fill.relief_conductance_m3_s_pa,
            },
            sensor_lag_s: rig.sensors.pressure.lag_time_constant_s,
            sensors: Sensors::new(&rig.sensors, rig.motor.pole_pairs, seed),
            max_step_s: rig.integration.max_step_s,
            x,
            discrete: Discrete {
                shaft: slip0(init.omega_rad_s),
                piston: Slip::Stuck,
                extinguished: true,
            },
            t_s: 0.0,
            projection_loss_j: 0.0,
            stored0_j: 0.0,
            last_inputs: Inputs::duties([0.5; 3], false),
            rotor: RotorPhasor::at(init.theta_m_rad),
            angle: AngleTerms {
                theta: f64::NAN,
                rot_m: Phasor { cos: 1.0, sin: 0.0 },
                rot_e: Phasor { cos: 1.0, sin: 0.0 },
                flux: MagnetFlux {
                    d_wb: 0.0,
                    q_wb: 0.0,
                    d_slope_wb: 0.0,
                    q_slope_wb: 0.0,
                    d_curvature_wb: 0.0,
                    q_curvature_wb: 0.0,
                },
                t_cog: 0.0,
                factor: 1.0,
            },
            faulted: false,
            faults: PlantFaults::default(),
            dc_link: DcLink::new(rig.inverter.u_dc_v),
            i_fault: 0.0,
            oil_density: rig.oil.density_kg_m3,
            protection: faulted::Protection::default(),
            integrator: Integrator::default(),
            exp: exponential::History::default(),
            lag_filter: (f64::NAN, 0.0, 0.0),
        };
        plant.angle = plant.angle_terms(init.theta_m_rad);
        plant.exp = exponential::History::new(&plant.motor, &plant.inverter);
        plant.stored0_j = plant.stored_energy_j(&plant.x);
        Ok(plant)
    }

    /// Turns the shaft's angle by `delta_rad` without touching its speed or any other state:
    /// a replay's kinematic phase lock, which keeps a simulated shaft in step with a logged
    /// angle without a torque the controller would have to answer. Non-finite `delta_rad`
    /// does nothing. [rad]
    pub fn shift_shaft_angle(&mut self, delta_rad: f64) {
        if !delta_rad.is_finite() {
            return;
        }
        let theta = self.x[ix::THETA] + delta_rad;
        self.x[ix::THETA] = theta;
        self.rotor = RotorPhasor::at(theta);
        self.angle = self.angle_terms_of(theta, self.rotor.phasor);
        self.exp.reset();
    }

    /// The integration scheme from now on (see [`Integrator`]).
    pub fn set_integrator(&mut self, integrator: Integrator) {
        self.integrator = integrator;
        self.exp.reset();
    }

    /// The integration scheme in use.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }

    /// The shaft's true angle, unwrapped (what [`Plant::observe`] reports as `theta_m_rad`,
    /// without evaluating the rest of the observables). [rad]
    pub fn shaft_angle_rad(&self) -> f64 {
        self.x[ix::THETA]
    }

    /// The port pressures (p_A, p_B), without evaluating the rest of the observables (a
    /// replay applying the pump's torque ripple at a logged angle needs only these). [Pa]
    pub fn port_pressures_pa(&self) -> (f64, f64) {
        (self.x[ix::PA], self.x[ix::PB])
    }

    /// Time since the start of the run. [s]
    pub fn time_s(&self) -> f64 {
        self.t_s
    }

    /// Advances the plant by `dt_s` with `inputs` held (zero-order hold). Never panics:
    /// non-finite inputs are treated as zero duty / zero force, non-positive `dt_s` does
    /// nothing.
    pub fn advance(&mut self, dt_s: f64, inputs: &Inputs) {
        if dt_s.is_nan() || dt_s <= 0.0 {
            return;
        }
        let mut inputs = sanitise(inputs);
        self.gate_enable(&mut inputs);
        self.last_inputs = inputs;
        let n = libm::ceil(dt_s / self.max_step_s).clamp(1.0, 1e9) as u64;
        let (n, h) = match self.integrator {
            Integrator::Rk4 { substeps } => {
                let s = u64::from(substeps.clamp(1, MAX_SUBSTEPS));
                (n * s, dt_s / (n * s) as f64)
            }
            Integrator::Exponential => (n, dt_s / n as f64),
        };
        if self.faulted {
            self.advance_faulted(n, h, inputs);
        } else {
            let exponential = self.integrator == Integrator::Exponential;
            for _ in 0..n {
                self.impose(&inputs);
                let p0 = self.x[ix::PA];
                if exponential && self.exponential_applies(&inputs) {
                    self.exp_step(h, &inputs);
                } else {
                    self.exp.reset();
                    self.step_with_events(h, &inputs);
                }
                self.filter_pressure_sensor(p0, h);
            }
        }
        self.t_s += dt_s;
    }

    /// Whether the exponential scheme takes the next step: the inverter drives (its bridge
    /// enabled, or off with the currents died out) and nothing is prescribed.
    fn exponential_applies(&self, inputs: &Inputs) -> bool {
        match inputs.drive {
            Drive::Inverter { enabled, .. } => {
                inputs.piston.is_none() && (enabled || self.discrete.extinguished)
            }
            _ => false,
        }
    }

    /// The pressure transducer's first-order lag over a step of `h` in which port A's
    /// pressure went from `p0` to its present value: the exact discrete filter of
    /// τ·ṗ_s = p − p_s for p linear over the step,
    /// p_s ← p_1 + (p_s − p_0)·e^{−h/τ} − (p_1 − p_0)·τ/h·(1 − e^{−h/τ}),
    /// stable and exact for any τ > 0 however short against the step.
    fn filter_pressure_sensor(&mut self, p0: f64, h: f64) {
        let tau = self.sensor_lag_s;
        if tau <= 0.0 {
            return;
        }
        if self.lag_filter.0 != h {
            let decay = libm::exp(-h / tau);
            let gain = -tau / h * libm::expm1(-h / tau);
            self.lag_filter = (h, decay, gain);
        }
        let (_, decay, gain) = self.lag_filter;
        let p1 = self.x[ix::PA];
        self.x[ix::P_SENSOR] = p1 + (self.x[ix::P_SENSOR] - p0) * decay - (p1 - p0) * gain;
    }

    /// Reads every sensor at the present instant (the ADC trigger at the PWM centre).
    pub fn sample(&mut self) -> SensorReadings {
        let i_abc = self.leg_currents(self.motor_phase_currents());
        let p_sensed = if self.sensor_lag_s > 0.0 {
            self.x[ix::P_SENSOR]
        } else {
            self.x[ix::PA]
        };
        let u_dc = self.dc_link_v();
        self.sensors
            .sample(self.t_s, &i_abc, u_dc, p_sensed, self.x[ix::THETA])
    }

    /// True physical quantities now, with the inputs of the last step.
    pub fn observe(&self) -> Observables {
        let x = &self.x;
        let at = self.angle_terms(x[ix::THETA]);
        // Only the drive side of an evaluation: the hydraulic flows are not observed.
        let el = if self.faulted {
            self.electrical::<true>(x, &self.last_inputs, &at)
        } else {
            self.electrical::<false>(x, &self.last_inputs, &at)
        };
        let i_abc_a = dq_to_abc(x[ix::ID], x[ix::IQ], at.rot_e.sin, at.rot_e.cos);
        Observables {
            t_s: self.t_s,
            i_d_a: x[ix::ID],
            i_q_a: x[ix::IQ],
            i_abc_a,
            i_bridge_abc_a: self.leg_currents(i_abc_a),
            u_dc_v: self.dc_link_v(),
            u_d_v: el.u_d,
            u_q_v: el.u_q,
            theta_m_rad: x[ix::THETA],
            omega_m_rad_s: x[ix::OMEGA],
            torque_em_nm: self.motor.torque_nm(x[ix::ID], x[ix::IQ], &at.flux),
            torque_cogging_nm: at.t_cog,
            torque_pump_nm: self
                .pump
                .load_torque(self.pump_pressure(x), x[ix::PB], at.factor),
            p_a_pa: x[ix::PA],
            p_pump_pa: self.pump_pressure(x),
            p_b_pa: x[ix::PB],
            p_sensor_pa: if self.sensor_lag_s > 0.0 {
                x[ix::P_SENSOR]
            } else {
                x[ix::PA]
            },
            p_fill_pa: x[ix::FILL_PGAS] - ATMOSPHERE_PA,
            pump_flow_m3_s: self.pump.geometric_flow(x[ix::OMEGA], at.factor),
            absorber_oil_m3: x[ix::ABS_OIL],
            absorber_flow_m3_s: x[ix::ABS_Q],
            x_m: x[ix::X],
            v_m_s: x[ix::V],
        }
    }

    /// Energy bookkeeping since the start.
    pub fn energy(&self) -> EnergyBalance {
        let x = &self.x;
        EnergyBalance {
            input_j: x[ix::E_IN],
            copper_loss_j: x[ix::E_CU],
            mechanical_loss_j: x[ix::E_MECH],
            hydraulic_loss_j: x[ix::E_HYD],
            external_work_j: x[ix::E_EXT],
            projection_loss_j: self.projection_loss_j,
            stored_change_j: self.stored_energy_j(x) - self.stored0_j,
        }
    }

    /// Oil in the closed circuit (chambers at their pressure-compressed volumes, absorber,
    /// fill accumulator) expressed at zero gauge pressure; constant up to O(p/β)² when no oil
    /// leaves the circuit. [m³]
    pub fn oil_inventory_m3(&self) -> f64 {
        let x = &self.x;
        let (v1, v2) = self.cylinder.volumes(x[ix::X]);
        v1 * (1.0 + x[ix::PA] / self.beta)
            + v2 * (1.0 + x[ix::PB] / self.beta)
            + x[ix::ABS_OIL]
            + x[ix::FILL_OIL]
    }

    /// The absorber model of this plant (for its natural frequency and damping).
    pub fn absorber(&self) -> &Absorber {
        &self.absorber
    }

    /// Writes prescribed quantities into the state before a step.
    fn impose(&mut self, inputs: &Inputs) {
        match inputs.drive {
            Drive::Inverter { enabled, .. } => {
                if enabled {
                    self.discrete.extinguished = false;
                }
                // A line confinement that begins now (the bridge switched off onto a short)
                // starts from the line, not from the three-phase currents.
                if self.faulted {
                    if let Some(line) = self.line_mode(enabled) {
                        self.project_line(line);
                    }
                }
            }
            Drive::Currents { i_d, i_q } => {
                self.x[ix::ID] = i_d;
                self.x[ix::IQ] = i_q;
            }
            Drive::ShaftSpeed { omega_rad_s } => {
                self.x[ix::ID] = 0.0;
                self.x[ix::IQ] = 0.0;
                self.x[ix::OMEGA] = omega_rad_s;
                self.discrete.shaft = Slip::Sliding(if omega_rad_s < 0.0 { -1.0 } else { 1.0 });
            }
        }
        if let Some((xp, vp)) = inputs.piston {
            self.x[ix::X] = xp;
            self.x[ix::V] = vp;
        }
        if self.cylinder.blocked {
            self.x[ix::X] = 0.0;
            self.x[ix::V] = 0.0;
        }
    }

    /// The shaft-angle terms at `theta`: the kept ones when they belong to it, else computed
    /// (from the kept rotor phasor when that belongs to it, else with one `sincos`).
    #[inline]
    fn angle_terms(&self, theta: f64) -> AngleTerms {
        if theta == self.angle.theta {
            self.angle
        } else if theta == self.rotor.theta {
            self.angle_terms_of(theta, self.rotor.phasor)
        } else {
            self.angle_terms_of(theta, Phasor::of(theta))
        }
    }

    /// The shaft-angle terms at `theta` near `a0.theta` (an RK4 stage), its phasor by rotating
    /// `a0`'s through the difference.
    #[inline]
    fn angle_terms_rotated(&self, a0: &AngleTerms, theta: f64) -> AngleTerms {
        self.angle_terms_of(theta, a0.rot_m * Phasor::small(theta - a0.theta))
    }

    /// One sincos per evaluation at most: every harmonic is a power of the shaft-angle phasor.
    #[inline]
    fn angle_terms_of(&self, theta: f64, rot_m: Phasor) -> AngleTerms {
        let rot_e = rot_m.pow(self.pole_pairs);
        AngleTerms {
            theta,
            rot_m,
            rot_e,
            flux: self.motor.magnet_flux_at(rot_e),
            t_cog: self.motor.cogging_torque_at(rot_m),
            factor: self.pump.displacement_factor_at(theta, rot_m),
        }
    }

    /// Enforces the non-smooth constraints at a step boundary and books the energy they
    /// remove.
    fn project(&mut self, inputs: &Inputs) {
        // The drive torque and force matter only to a stuck body or one whose velocity
        // reached zero; evaluate the model only then.
        let shaft_switch = match self.discrete.shaft {
            Slip::Stuck => true,
            Slip::Sliding(dir) => self.x[ix::OMEGA] * dir <= 0.0,
        };
        let piston_free = inputs.piston.is_none() && !self.cylinder.blocked;
        let shaft_switch = shaft_switch && !matches!(inputs.drive, Drive::ShaftSpeed { .. });
        let piston_switch = piston_free
            && match self.discrete.piston {
                Slip::Stuck => true,
                Slip::Sliding(dir) => self.x[ix::V] * dir <= 0.0,
            };
        let needs = (shaft_switch && self.shaft_friction.is_active())
            || (piston_switch && self.piston_friction.is_active());
        let aux = if needs {
            self.derivative(&self.x, inputs).1
        } else {
            Aux::default()
        };
        self.project_with(inputs, aux);
    }

    /// [`Plant::project`] with the drive torque and force `aux` of the present state given
    /// (only read for a body that may switch).
    fn project_with(&mut self, inputs: &Inputs, aux: Aux) {
        let piston_free = inputs.piston.is_none() && !self.cylinder.blocked;
        // Shaft stick/slip (not when the speed is prescribed).
        if !matches!(inputs.drive, Drive::ShaftSpeed { .. }) && self.shaft_friction.is_active() {
            let w = self.x[ix::OMEGA];
            let (slip, w_new) =
                self.shaft_friction
                    .transition(self.discrete.shaft, w, aux.shaft_drive);
            self.projection_loss_j += 0.5 * self.inertia * (w * w - w_new * w_new);
            self.discrete.shaft = slip;
            self.x[ix::OMEGA] = w_new;
        }
        // Piston stick/slip.
        if piston_free && self.piston_friction.is_active() {
            let v = self.x[ix::V];
            let (slip, v_new) =
                self.piston_friction
                    .transition(self.discrete.piston, v, aux.piston_drive);
            self.projection_loss_j += 0.5 * self.cylinder.mass_kg * (v * v - v_new * v_new);
            self.discrete.piston = slip;
            self.x[ix::V] = v_new;
        }
        // Absorber poppet: the bladder cannot push out oil it does not hold.
        if self.absorber.enabled && self.x[ix::ABS_OIL] <= 0.0 {
            let q = self.x[ix::ABS_Q];
            if q < 0.0 {
                self.projection_loss_j += 0.5 * self.absorber.inertance_kg_m4 * q * q;
                self.x[ix::ABS_Q] = 0.0;
            }
            self.x[ix::ABS_PGAS] = self.absorber.gas.precharge_abs_pa();
            // Oil overdrawn within the step returns from the port node.
            let overdraw = -self.x[ix::ABS_OIL];
            if overdraw > 0.0 {
                let (v1, _) = self.cylinder.volumes(self.x[ix::X]);
                let p_old = self.x[ix::PA];
                let p_new = p_old - self.beta * overdraw / v1;
                self.projection_loss_j += v1 / (2.0 * self.beta) * (p_old * p_old - p_new * p_new);
                self.x[ix::PA] = p_new;
                self.x[ix::ABS_OIL] = 0.0;
            }
        }
        // Bridge off: once the phase currents have died out through the diodes they stay
        // out while the line back-EMF cannot forward-bias the diodes.
        let line = match inputs.drive {
            Drive::Inverter { enabled, .. } if self.faulted => self.line_mode(enabled),
            _ => None,
        };
        if let Some(line) = line {
            self.project_line(line);
        }
        // A short keeps the motor's circuit closed with the bridge off.
        let closed_by_short = self.faulted && self.short_closes_circuit(line);
        if let (Drive::Inverter { enabled: false, .. }, false) = (inputs.drive, closed_by_short) {
            let (id, iq) = (self.x[ix::ID], self.x[ix::IQ]);
            let emf = self
                .motor
                .line_emf_peak_v(self.motor.pole_pairs * self.x[ix::OMEGA]);
            let small = id * id + iq * iq < 1e-6;
            if (self.discrete.extinguished || small) && emf < self.inverter.u_dc_v {
                self.projection_loss_j += self.motor.winding_energy_j(id, iq);
                self.x[ix::ID] = 0.0;
                self.x[ix::IQ] = 0.0;
                self.discrete.extinguished = true;
            }
        }
        // Cavitation floor: oil cannot be pulled below vapour pressure.
        for node in [ix::PA, ix::PB] {
            let floor = -0.99 * crate::accumulator::ATMOSPHERE_PA;
            if self.x[node] < floor {
                let (v1, v2) = self.cylinder.volumes(self.x[ix::X]);
                let v = if node == ix::PA { v1 } else { v2 };
                let p = self.x[node];
                self.projection_loss_j += v / (2.0 * self.beta) * (p * p - floor * floor);
                self.x[node] = floor;
            }
        }
        if self.sensor_lag_s <= 0.0 {
            self.x[ix::P_SENSOR] = self.x[ix::PA];
        }
        if self.faulted && !self.faults.pump_port_blocked {
            self.x[ix::PP] = self.x[ix::PA];
        }
    }

    /// The pump manifold's pressure in state `x`. [Pa]
    #[inline]
    fn pump_pressure(&self, x: &Vector) -> f64 {
        if self.faulted && self.faults.pump_port_blocked {
            x[ix::PP]
        } else {
            x[ix::PA]
        }
    }

    /// Stored energy of a state: windings, shaft and piston kinetic, slotting, spring,
    /// gravity, stops, oil compression, absorber gas and oil column, fill gas. [J]
    fn stored_energy_j(&self, x: &Vector) -> f64 {
        let (v1, v2) = self.cylinder.volumes(x[ix::X]);
        let c = &self.cylinder;
        let mut e = self.motor.winding_energy_j(x[ix::ID], x[ix::IQ])
            + 0.5 * self.inertia * x[ix::OMEGA] * x[ix::OMEGA]
            + self.motor.cogging_energy_j(x[ix::THETA])
            + 0.5 * c.mass_kg * x[ix::V] * x[ix::V]
            + 0.5 * c.spring * x[ix::X] * x[ix::X]
            + c.gravity_n * x[ix::X]
            + c.stop_energy_j(x[ix::X])
            + v1 * x[ix::PA] * x[ix::PA] / (2.0 * self.beta)
            + v2 * x[ix::PB] * x[ix::PB] / (2.0 * self.beta)
            + self.fill_gas.energy_j(x[ix::FILL_OIL]);
        if self.faults.pump_port_blocked {
            e += PUMP_MANIFOLD_VOLUME_M3 * x[ix::PP] * x[ix::PP] / (2.0 * self.beta);
        }
        if self.absorber.enabled {
            e += self.absorber.gas.energy_j(x[ix::ABS_OIL])
                + 0.5 * self.absorber.inertance_kg_m4 * x[ix::ABS_Q] * x[ix::ABS_Q];
        }
        e
    }

    /// The right-hand side of the state equations.
    #[inline]
    fn derivative(&self, x: &Vector, inputs: &Inputs) -> (Vector, Aux) {
        let at = self.angle_terms(x[ix::THETA]);
        if self.faulted {
            self.derivative_at::<true>(x, inputs, &at)
        } else {
            self.derivative_at::<false>(x, inputs, &at)
        }
    }

    /// The inverter's d-q voltages and the current derivatives (eq. 2) driven by them; zero
    /// unless the inverter drives and the currents are alive. The phase currents are formed
    /// only when the pole voltages depend on them (dead time, free-wheeling diodes).
    #[inline]
    fn electrical<const FAULTED: bool>(
        &self,
        x: &Vector,
        inputs: &Inputs,
        at: &AngleTerms,
    ) -> Electrical {
        let Drive::Inverter { duties, enabled } = inputs.drive else {
            return Electrical::default();
        };
        let line = if FAULTED {
            self.line_mode(enabled)
        } else {
            None
        };
        // Died out stays out, unless a short keeps the circuit closed.
        let shorted = FAULTED && self.short_closes_circuit(line);
        if !enabled && self.discrete.extinguished && !shorted {
            return Electrical::default();
        }
        let (i_d, i_q) = (x[ix::ID], x[ix::IQ]);
        let (s_e, c_e) = (at.rot_e.sin, at.rot_e.cos);
        let v_pole = if enabled && !self.inverter.has_dead_time() && line.is_none() {
            self.inverter.pole_voltages_ideal(&duties)
        } else {
            let i_abc = dq_to_abc(i_d, i_q, s_e, c_e);
            if enabled {
                self.inverter.pole_voltages(&duties, &i_abc)
            } else {
                // Free-wheeling diodes: a motor-bound current through the lower diode (pole
                // at 0 V), a returning one through the upper (U_dc).
                let u = self.inverter.u_dc_v;
                let pole = |i: f64| if i > 0.0 { 0.0 } else { u };
                let mut v = [pole(i_abc[0]), pole(i_abc[1]), pole(i_abc[2])];
                self.pin_shorted_pole(&mut v);
                v
            }
        };
        if let Some(line) = line {
            let (did, diq, v_n, i) = self.line_electrical(x, line, v_pole, at.rot_e, &at.flux);
            let n = line.idle_phase().line_direction();
            let (c, s) = crate::faults::rotor_projections(n, at.rot_e);
            return Electrical {
                u_d: v_n * c,
                u_q: v_n * s,
                did,
                diq,
                p_in: 1.5 * v_n * i,
            };
        }
        let (u_d, u_q) = pole_to_dq(&v_pole, s_e, c_e);
        let omega_e = self.motor.pole_pairs * x[ix::OMEGA];
        let (did, diq) = self
            .motor
            .current_derivatives(u_d, u_q, i_d, i_q, omega_e, &at.flux);
        Electrical {
            u_d,
            u_q,
            did,
            diq,
            p_in: 1.5 * (u_d * i_d + u_q * i_q),
        }
    }

    /// The right-hand side with the shaft-angle terms `at` of `x` supplied.
    #[inline]
    fn derivative_at<const FAULTED: bool>(
        &self,
        x: &Vector,
        inputs: &Inputs,
        at: &AngleTerms,
    ) -> (Vector, Aux) {
        let mut dx = [0.0; ix::N];
        let mut aux = Aux::default();
        let omega = x[ix::OMEGA];
        let (i_d, i_q) = (x[ix::ID], x[ix::IQ]);
        let flux = at.flux;

        // --- motor and inverter (eq. 1–3, 17–19)
        let el = self.electrical::<FAULTED>(x, inputs, at);
        dx[ix::ID] = el.did;
        dx[ix::IQ] = el.diq;
        let mut p_in = el.p_in;
        let t_em = self.motor.torque_nm(i_d, i_q, &flux);
        let t_cog = at.t_cog;
        dx[ix::E_CU] = 1.5 * self.motor.r_s_ohm * (i_d * i_d + i_q * i_q);

        // --- pump (eq. 9, 20) and shaft (eq. 4)
        let (p_a, p_b) = (x[ix::PA], x[ix::PB]);
        let blocked = FAULTED && self.faults.pump_port_blocked;
        let p_pump = if blocked { x[ix::PP] } else { p_a };
        let factor = at.factor;
        let t_pump = self.pump.load_torque(p_pump, p_b, factor);
        aux.shaft_drive =
            t_em + t_cog - t_pump - self.shaft_viscous * omega + inputs.external_torque_nm;
        let t_fric = self.shaft_friction.force(self.discrete.shaft);
        dx[ix::THETA] = omega;
        match inputs.drive {
            Drive::ShaftSpeed { .. } => {
                // The prescribed motion is supplied by the drive: its power is the input.
                p_in = (t_pump + self.shaft_viscous * omega + t_fric - t_cog) * omega;
            }
            _ => {
                if matches!(inputs.drive, Drive::Currents { .. }) {
                    p_in = t_em * omega + dx[ix::E_CU];
                }
                if self.discrete.shaft == Slip::Stuck && self.shaft_friction.is_active() {
                    dx[ix::THETA] = 0.0;
                } else {
                    dx[ix::OMEGA] = (aux.shaft_drive - t_fric) / self.inertia;
                }
            }
        }
        dx[ix::E_IN] = p_in;
        let mut p_mech = self.shaft_viscous * omega * omega + t_fric * omega;

        // --- hydraulics (eq. 9–12, 22–26)
        let p_fill = x[ix::FILL_PGAS] - ATMOSPHERE_PA;
        let q_geo = self.pump.geometric_flow(omega, factor);
        // The pump's manifold (pump, its leakage, check and relief valves) is port A's node
        // unless the pump's port is blocked ([`crate::faults`]).
        let q_int = self.pump.internal_leakage * (p_pump - p_b);
        let q_ext_a = (self.pump.external_leakage + self.pump.extra_leakage) * (p_pump - p_fill);
        let q_ext_b = self.pump.external_leakage * (p_b - p_fill);
        let q_cyl = self.cylinder.leakage * (p_a - p_b);
        let q_chk_a = self.check.flow(p_fill - p_pump);
        let q_chk_b = self.check.flow(p_fill - p_b);
        let q_rel_a = self.relief_a.flow(p_pump - p_fill);
        let q_rel_b = self.relief.flow(p_b - p_fill);
        let q_burst = if FAULTED {
            self.burst_outflow(p_a)
        } else {
            0.0
        };
        let (q_abs, abs_oil) = (x[ix::ABS_Q], x[ix::ABS_OIL]);
        let (xp, vp) = (x[ix::X], x[ix::V]);
        let (v1, v2) = self.cylinder.volumes(xp);
        let area = self.cylinder.area_m2;
        let net_b = -q_geo + q_int - q_ext_b + q_cyl + q_chk_b - q_rel_b + area * vp;
        if blocked {
            let net_pump = q_geo - q_int - q_ext_a + q_chk_a - q_rel_a;
            dx[ix::PP] = self.beta / PUMP_MANIFOLD_VOLUME_M3 * net_pump;
            dx[ix::PA] = self.beta / v1 * (-q_cyl - q_abs - area * vp - q_burst);
        } else {
            let net_a =
                q_geo - q_int - q_ext_a - q_cyl + q_chk_a - q_rel_a - q_abs - area * vp - q_burst;
            // The manifold's state follows port A's at each step's end (`project`).
            dx[ix::PA] = self.beta / v1 * net_a;
        }
        dx[ix::PB] = self.beta / v2 * net_b;
        dx[ix::FILL_OIL] = q_ext_a + q_ext_b + q_rel_a + q_rel_b - q_chk_a - q_chk_b;
        dx[ix::FILL_PGAS] =
            self.fill_gas
                .pressure_rate(x[ix::FILL_PGAS], x[ix::FILL_OIL], dx[ix::FILL_OIL]);
        let through = if blocked {
            q_int * (p_pump - p_b) + q_cyl * (p_a - p_b)
        } else {
            (q_int + q_cyl) * (p_a - p_b)
        };
        let mut p_hyd = through
            + q_ext_a * (p_pump - p_fill)
            + q_ext_b * (p_b - p_fill)
            + q_chk_a * (p_fill - p_pump)
            + q_chk_b * (p_fill - p_b)
            + q_rel_a * (p_pump - p_fill)
            + q_rel_b * (p_b - p_fill);
        if q_burst != 0.0 {
            p_hyd += q_burst * p_a;
        }
        if self.absorber.enabled {
            dx[ix::ABS_OIL] = q_abs;
            let p_gas = x[ix::ABS_PGAS] - ATMOSPHERE_PA;
            dx[ix::ABS_Q] = self.absorber.flow_derivative(p_a, p_gas, abs_oil, q_abs);
            dx[ix::ABS_PGAS] = self
                .absorber
                .gas
                .pressure_rate(x[ix::ABS_PGAS], abs_oil, q_abs);
            p_hyd += self.absorber.resistance_pa_s_m3 * q_abs * q_abs;
        }

        // --- piston (eq. 12)
        let c = &self.cylinder;
        aux.piston_drive = c.drive_force(p_a, p_b, xp, vp, inputs.external_force_n);
        dx[ix::X] = vp;
        if inputs.piston.is_none() && !c.blocked {
            let f_fric = self.piston_friction.force(self.discrete.piston);
            if self.discrete.piston == Slip::Stuck && self.piston_friction.is_active() {
                dx[ix::X] = 0.0;
            } else {
                dx[ix::V] = (aux.piston_drive - f_fric) / c.mass_kg;
            }
            // Stop contact: force minus its spring part is what the contact dissipates.
            let spring_part = -c.stop_k
                * if xp > c.half_stroke_m {
                    xp - c.half_stroke_m
                } else if xp < -c.half_stroke_m {
                    xp + c.half_stroke_m
                } else {
                    0.0
                };
            let stop = c.stop_force(xp, vp);
            p_mech += c.viscous * vp * vp + f_fric * vp - (stop - spring_part) * vp;
        } else {
            // Prescribed motion: the piston's force balance is supplied from outside.
            p_in += -aux.piston_drive * vp;
        }
        dx[ix::E_EXT] = -inputs.external_force_n * vp - inputs.external_torque_nm * x[ix::OMEGA];
        dx[ix::E_MECH] = p_mech;
        dx[ix::E_HYD] = p_hyd;

        // The pressure transducer's lag is filtered exactly after each step
        // ([`Plant::filter_pressure_sensor`]): its derivative stays zero here.
        dx[ix::E_IN] = p_in;
        (dx, aux)
    }
}

fn finite_or(v: f64, default: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        default
    }
}

fn sanitise(inputs: &Inputs) -> Inputs {
    let drive = match inputs.drive {
        Drive::Inverter { duties, enabled } => Drive::Inverter {
            duties: duties.map(|d| finite_or(d, 0.5).clamp(0.0, 1.0)),
            enabled,
        },
        Drive::Currents { i_d, i_q } => Drive::Currents {
            i_d: finite_or(i_d, 0.0),
            i_q: finite_or(i_q, 0.0),
        },
        Drive::ShaftSpeed { omega_rad_s } => Drive::ShaftSpeed {
            omega_rad_s: finite_or(omega_rad_s, 0.0),
        },
    };
    Inputs {
        drive,
        piston: inputs
            .piston
            .map(|(x, v)| (finite_or(x, 0.0), finite_or(v, 0.0))),
        external_force_n: finite_or(inputs.external_force_n, 0.0),
        external_torque_nm: finite_or(inputs.external_torque_nm, 0.0),
    }
}
