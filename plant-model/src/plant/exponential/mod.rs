//! The plant's default integrator: the fast linear subsystems solved exactly over each step,
//! the rest by a third-order exponential Adams–Bashforth scheme, one evaluation of the
//! model per step, switching events located inside the step.
//!
//! # Why
//! Classical RK4 ([`super::rk4`]) evaluates the whole model four times per 50 µs step. But
//! only two parts of the plant move on the step's time scale: the winding currents (the
//! inverter's voltage changes every PWM period, the rotor turns the voltage in the d-q frame,
//! and the speed couples the axes) and port A's node against the oil column of the absorber's
//! inlet (1/√(I·C_oil) ≈ 1.9e3 rad/s, damping ratio 0.02 at the nominal rig). Both are
//! linear at a given speed and chamber volume, so their exact solution over a step is cheap
//! ([`series`], [`blocks`]); everything else — the shaft, port B, the piston, the gases, the valves,
//! the angle-dependent torques and flows — changes on millisecond scales and is well served
//! by a polynomial extrapolation of its rates over the step.
//!
//! # The scheme
//! With the state split into the blocks y (i_d, i_q; p_A, q_abs) and the rest z, and g the
//! model's rates at a state without the blocks' own linear terms ([`explicit`], [`rates`]),
//! one step of
//! length τ from t_0 takes the quadratic g(t) ≈ g_0 + g_1·t + g_2·t² through the rates at
//! the last three step boundaries (Newton's divided differences on the actual step lengths)
//! and integrates it:
//!
//! ```text
//! y(τ) = e^{τA}·y_0 + τ·φ₁(τA)·g_0 + τ²·φ₂(τA)·g_1 + 2τ³·φ₃(τA)·g_2   (exact for it)
//! z(τ) = z_0 + τ·g_0 + τ²/2·g_1 + τ³/3·g_2                      (Adams–Bashforth 3)
//! ```
//!
//! which is third-order accurate in the slow part and exact in the linear blocks: their
//! oscillation and decay carry no phase or amplitude error, whatever the step. Third order
//! because the payload on its oil springs (≈ 270 rad/s at the nominal rig) is almost
//! undamped (ζ ≈ 1e-4): a second-order scheme's phase error, (5/12)·(ωh)³ per step, would
//! add up over a stroke to tens of pascals of its pressure ringing; the third order's,
//! (3/8)·(ωh)⁴, stays a hundred times smaller. AB3 is stable for |λh| < 0.54 on the real
//! axis and |ωh| < 0.72 on the imaginary one, beyond everything left in the slow part at the
//! 50 µs step (check valve near an end stop 0.35, dead time's current band 0.27). The shaft
//! takes the electromagnetic torque from the winding series itself, integrated over the
//! step by Simpson's rule (the current responds to a new duty within the step, which no
//! extrapolation from the past could see), and the rest of its torque extrapolated:
//!
//! ```text
//! ω(τ) = ω_0 + (∫T_e dt + τ·L_0 + τ²/2·L_1 + τ³/3·L_2)/J
//! θ(τ) = θ_0 + τ·ω_0 + (∫(τ − t)·T_e dt + τ²/2·L_0 + τ³/6·L_1 + τ⁴/12·L_2)/J
//! ```
//!
//! with the speed over the step taken as ω_0 + α_0·t in the winding series (α_0 the shaft's
//! acceleration at the step's start). The absorber's oil is the integral of its inlet flow by
//! the Hermite rule τ/2·(q_0 + q_1) + τ²/12·(q̇_0 − q̇_1) on the block's exact flow, and each
//! gas follows its polytropic law along the oil it takes, p_1 = p_0·(1 − ΔV/V_g)^(−n), so
//! pressure and volume never drift apart. Energies: input and copper loss by Simpson's rule
//! on the winding series, the absorber inlet's loss R·∫q² by the Hermite rule, friction's
//! and the external work exactly (their forces are constant within a segment: F·Δx, T·Δθ),
//! the other losses by the same extrapolation as the states.
//!
//! The first step, and every step after a switching event or a change of the bridge's enable,
//! has no rates from the past: it takes the secant of a predictor instead (Heun's method on
//! the slow part, one more evaluation), the next one the linear extrapolation (order two),
//! then the quadratic.
//!
//! # Events
//! As in RK4, switching inside a step is located by regula falsi on event functions that
//! cross zero there: a sliding body's velocity (it sticks or reverses), a stuck body's drive
//! against its breakaway, the absorber running empty while its poppet is open and its gas
//! giving way to the port while it is shut, and the piston meeting or leaving an end stop.
//! The step is cut there, the projection of `Plant::project` enforces the constraint and
//! books its energy, and the rest of the step restarts from the new state.
//!
//! # Where it applies
//! The inverter drive without faults, bridge enabled or with its currents died out. The
//! faulted plant, the replays' prescribed currents, speed and piston, and a disabled bridge
//! whose currents still free-wheel through the diodes take the RK4 path for those steps.
//!
//! # Accuracy
//! Against RK4 at a quarter of the step on the closed loop's own duty sequence
//! (`cargo run --release -p tests --example integrator_accuracy`, its table in
//! `docs/plant-model.md`), and in this crate's physics tests (energy and oil balances, the
//! analytic responses), which run on this integrator.
//!
//! # Where each part lives
//! [`step`] takes a step (segments, event location, commit); [`segment`] integrates one
//! segment, with [`winding`] for the currents by the series of [`series`] and
//! [`hydro_block`] for the hydraulic block by the matrix functions of [`blocks`]; [`explicit`] evaluates the [`rates`];
//! [`events`] holds the event functions and the projection; [`history`] what is carried
//! from step to step.

mod blocks;
mod events;
mod explicit;
mod gas;
mod history;
mod hydro_block;
mod rates;
mod segment;
mod series;
mod step;
mod winding;

pub(super) use history::History;
