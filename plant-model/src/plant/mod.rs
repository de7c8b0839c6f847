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
//! (in [`observe`]), stable for any time constant. The fine-step
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
//!
//! # Where each part lives
//! - [`actuator`]: the composition of the component models with the state, built from a rig;
//!   [`inputs`], [`state`], [`integrator`], [`protection`]: what it holds and is given.
//! - The model's equations: [`equations`] (the right-hand side), [`electrical`] (inverter and
//!   windings), [`angle`] (the shaft-angle terms), [`constraints`] (projections, prescribed
//!   motion), [`energy`] (stored energy, balance, oil inventory).
//! - The integration: [`advance`] (the hold and the choice of scheme), [`exponential`],
//!   [`rk4`], and [`faulted`] (the faulted plant's path and its protection).
//! - What leaves it: [`observe`] (sensors, observables, the transducer's lag).

mod actuator;
mod advance;
mod angle;
mod constraints;
mod electrical;
mod energy;
mod equations;
mod exponential;
mod faulted;
mod inputs;
mod integrator;
mod observe;
mod protection;
mod rk4;
mod state;

pub use actuator::{InitialConditions, Plant};
pub use energy::EnergyBalance;
pub use inputs::{Drive, Inputs};
pub use integrator::Integrator;
pub use observe::Observables;
pub use protection::CurrentWatch;
