//! The actuator model's composition: the component models (motor, inverter, shaft, pump,
//! cylinder, absorber, fill accumulator, valves, sensors) with the plant's state, built once
//! from a validated rig and initial conditions, and its plain accessors.

use super::exponential::History;
use super::inputs::Inputs;
use super::integrator::Integrator;
use super::protection::Protection;
use super::state::{ix, AngleTerms, Discrete, RotorPhasor, Vector};
use crate::accumulator::ATMOSPHERE_PA;
use crate::accumulator::{Absorber, GasCharge};
use crate::cylinder::Cylinder;
use crate::faults::{DcLink, PlantFaults};
use crate::friction::{Friction, Slip};
use crate::inverter::Inverter;
use crate::motor::{MagnetFlux, Motor, Phasor};
use crate::pump::Pump;
use crate::rig::{Rig, RigError};
use crate::sensors::Sensors;
use crate::valves::Valve;

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

/// The actuator model.
#[derive(Clone, Debug)]
pub struct Plant {
    pub(super) motor: Motor,
    pub(super) pole_pairs: u32,
    pub(super) inverter: Inverter,
    pub(super) inertia: f64,
    pub(super) shaft_viscous: f64,
    pub(super) shaft_friction: Friction,
    pub(super) pump: Pump,
    pub(super) cylinder: Cylinder,
    pub(super) piston_friction: Friction,
    pub(super) beta: f64,
    pub(super) absorber: Absorber,
    pub(super) fill_gas: GasCharge,
    pub(super) check: Valve,
    /// Port B's relief valve (and port A's as built).
    pub(super) relief: Valve,
    /// Port A's relief valve as it works now (none while stuck closed).
    pub(super) relief_a: Valve,
    pub(super) sensor_lag_s: f64,
    pub(super) sensors: Sensors,
    pub(super) max_step_s: f64,
    pub(super) x: Vector,
    pub(super) discrete: Discrete,
    pub(super) t_s: f64,
    pub(super) projection_loss_j: f64,
    pub(super) stored0_j: f64,
    pub(super) last_inputs: Inputs,
    pub(super) rotor: RotorPhasor,
    pub(super) angle: AngleTerms,
    /// A fault or the protection was ever switched on: the steps take the faulted path.
    pub(super) faulted: bool,
    pub(super) faults: PlantFaults,
    pub(super) dc_link: DcLink,
    /// A short circuit's fault-path current ([`crate::faults`]). [A]
    pub(super) i_fault: f64,
    pub(super) oil_density: f64,
    pub(super) protection: Protection,
    pub(super) integrator: Integrator,
    /// The exponential integrator's rates, their slope and its linear blocks.
    pub(super) exp: History,
    /// The transducer lag's discrete filter for a step: (h, e^{−h/τ}, τ/h·(1 − e^{−h/τ})).
    pub(super) lag_filter: (f64, f64, f64),
}

impl Plant {
    /// A plant for a rig (validated here) from initial conditions, with sensor noise seeded
    /// by `seed`.
    pub fn new(rig: &Rig, init: &InitialConditions, seed: u64) -> Result<Plant, RigError> {
        rig.validate()?;
        check_initial_conditions(rig, init)?;
        let mut plant = Plant::assemble(rig, init, seed);
        plant.angle = plant.angle_terms(init.theta_m_rad);
        plant.exp = History::new(
            &plant.motor,
            &plant.inverter,
            [plant.absorber.gas.exponent, plant.fill_gas.exponent],
        );
        plant.stored0_j = plant.stored_energy_j(&plant.x);
        Ok(plant)
    }

    /// The plant's components built from `rig` with the state of `init` and sensor noise
    /// seeded by `seed`; what depends on the assembled plant (the angle terms, the
    /// exponential integrator's blocks and the stored energy at the start) is left to
    /// [`Plant::new`] to fill in.
    fn assemble(rig: &Rig, init: &InitialConditions, seed: u64) -> Plant {
        let absorber = Absorber::new(&rig.absorber);
        let fill_gas = GasCharge {
            shell_volume_m3: rig.fill.shell_volume_m3,
            precharge_pa: rig.fill.precharge_pa,
            exponent: rig.fill.polytropic_exponent,
        };
        let cylinder = Cylinder::new(&rig.cylinder);
        let x = initial_state(rig, init, &cylinder, &absorber, &fill_gas);
        Plant {
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
            relief: relief_valve(rig),
            relief_a: relief_valve(rig),
            sensor_lag_s: rig.sensors.pressure.lag_time_constant_s,
            sensors: Sensors::new(&rig.sensors, rig.motor.pole_pairs, seed),
            max_step_s: rig.integration.max_step_s,
            x,
            discrete: Discrete {
                shaft: initial_slip(init.omega_rad_s),
                piston: Slip::Stuck,
                extinguished: true,
            },
            t_s: 0.0,
            projection_loss_j: 0.0,
            stored0_j: 0.0,
            last_inputs: Inputs::duties([0.5; 3], false),
            rotor: RotorPhasor::at(init.theta_m_rad),
            angle: unset_angle_terms(),
            faulted: false,
            faults: PlantFaults::default(),
            dc_link: DcLink::new(rig.inverter.u_dc_v),
            i_fault: 0.0,
            oil_density: rig.oil.density_kg_m3,
            protection: Protection::default(),
            integrator: Integrator::default(),
            exp: History::default(),
            lag_filter: (f64::NAN, 0.0, 0.0),
        }
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

    /// The absorber model of this plant (for its natural frequency and damping).
    pub fn absorber(&self) -> &Absorber {
        &self.absorber
    }
}

/// Checks that the initial conditions `init` are finite and put the piston within the
/// stroke of `rig`.
fn check_initial_conditions(rig: &Rig, init: &InitialConditions) -> Result<(), RigError> {
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
    Ok(())
}

/// The continuous state at the start from `init`: the piston centred if blocked, the
/// absorber in equilibrium with port A, the fill accumulator at the rig's fill pressure,
/// the pump's manifold and the pressure transducer at port A's.
fn initial_state(
    rig: &Rig,
    init: &InitialConditions,
    cylinder: &Cylinder,
    absorber: &Absorber,
    fill_gas: &GasCharge,
) -> Vector {
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
    x
}

/// The shaft's friction state at the start at speed `omega`: stuck at rest, else sliding
/// in its direction.
fn initial_slip(omega: f64) -> Slip {
    if omega == 0.0 {
        Slip::Stuck
    } else if omega < 0.0 {
        Slip::Sliding(-1.0)
    } else {
        Slip::Sliding(1.0)
    }
}

/// A relief valve of `rig`'s (port B's, and port A's as built).
fn relief_valve(rig: &Rig) -> Valve {
    Valve {
        cracking_pa: rig.fill.relief_cracking_pa,
        conductance_m3_s_pa: rig.fill.relief_conductance_m3_s_pa,
    }
}

/// The angle terms before the shaft's are computed: `theta` NaN matches no angle, so that
/// [`Plant::new`]'s first evaluation computes them rather than reusing these.
fn unset_angle_terms() -> AngleTerms {
    AngleTerms {
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
    }
}
