//! Commissioning: identifies the motor the drive is connected to and derives the
//! loop gains, as a state machine the controller steps once per PWM period in mode
//! Calibrating after the current offsets are measured.
//!
//! The steps, in order, each with its current limit, its time limit and a plausibility
//! check that faults instead of producing nonsense:
//!
//! 1. **Encoder offset and direction** — the current vector (0.8·I_max on d) is swept one
//!    electrical turn forward at a forced angle and held at θ_e = 0, then one turn back and
//!    held again; the rotor follows and settles on the d axis (q-current proportional to
//!    speed damps its ringing). The offset is the circular mean of the encoder's electrical
//!    angle over both holds, so friction and load torque, which displace the rotor opposite
//!    ways in the two directions, cancel. The encoder must travel about one electrical turn
//!    in the sweep's direction: opposite means reversed, little means no movement (fault
//!    15); the two holds must agree within 20°.
//! 2. **R_s** — d-current at 0.4·I_max and 0.8·I_max with the rotor locked on d, the PI's
//!    mean voltage at each: R_s = ΔU/ΔI, which cancels the inverter's dead-time voltage
//!    error (a constant once every phase current is beyond the dead-time band). A level the
//!    loop cannot reach is an open phase (fault 13).
//! 3. **L_d, L_q** — open-loop voltage pulses ±U_p on one axis around the bias (0.8·I_max
//!    on d, the hold voltages of step 2 on both axes): +U_p until the current has risen by
//!    0.4·I_max (this sets the pulse length n), then cycles of +U_p for n, −U_p for 2n,
//!    +U_p for n periods, which swing the current ±0.4·I_max and leave no net torque
//!    impulse on q. Per segment, eq. 2 at standstill integrated exactly over the held
//!    voltages gives L·Δi = Σ(u − u_hold)·T − R_s·∫(i − i_bias)dt; L is the least-squares
//!    slope over all segments. A pulse that does not reach its current in time is fault 13.
//! 4. **Current gains** — Kp = L·ω_c, Ki = R_s·ω_c ([`gains`]); the current loop uses them
//!    from here on.
//! 5. **Inertia and ψ_f** — with the identified offset: constant +i_q until the spin speed,
//!    speed control there, constant −i_q down to 30 %. ψ_f = (ū_q − R_s·ī_q −
//!    ω̄_e·L_d·ī_d)/ω̄_e (eq. 2 in steady state) over the speed-controlled window, ω̄_e from
//!    the encoder's travel. J = K_t·(ī₊ − ī₋)/(α₊ − α₋) from the two accelerations, so a
//!    load torque common to both cancels. No speed reached in time, or the wrong sign, is
//!    fault 15.
//!
//! Any identified value outside [nameplate / r, nameplate · r] (`plausible_ratio`) or not
//! finite is fault 14.
//!
//! Accuracy on the plant model with noise and quantisation (`tests/tests/commissioning.rs`,
//! 20 rigs with R_s, L_d, L_q, ψ_f off by up to ±30 %): R_s, L_d, ψ_f within 0.1 %, L_q
//! biased low by up to 1.1 % (the back-EMF of the rotor's small motion under the q pulses,
//! see [`CommissioningConfig::pulse_voltage_v`]), the offset within 0.2° electrical, J
//! about +1.5 %. Known limit: with inverter dead time the spin's small q-current sits in
//! the dead-time band, whose voltage error reads as extra back-EMF (ψ_f +1.6 % at 1 µs)
//! and as torque error in J (+8 %); R_s and the inductances are unaffected.
pub mod config;
pub mod estimate;
pub mod gains;
pub mod interface;
mod pulses;
pub mod sequence;

pub use config::CommissioningConfig;
pub use gains::{CurrentGains, SpeedGains};
pub use interface::{Action, CommissioningResult, Input};
pub use sequence::Commissioning;
