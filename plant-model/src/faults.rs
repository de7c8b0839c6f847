//! Faults of the power stage, the DC-link supply and the hydraulic circuit, switched on and
//! off while a run goes on ([`crate::Plant::set_faults`]); the sensors' own faults are in
//! [`crate::sensor_faults`]. One fault of each kind at a time.
//!
//! # Power stage (average model over a PWM period, as [`crate::inverter`])
//!
//! The current sensors sit at the bridge's outputs; the faults below are downstream of them
//! (cable, terminal box, winding), so a sensor measures its leg's current: the motor's
//! phase current plus whatever a short circuit draws through that leg.
//!
//! **Open phase x** (a broken cable or terminal): i_x = 0, so the motor is one circuit
//! between the two other terminals y, z (the cyclic successors of x). With the
//! amplitude-invariant Clarke transform its current vector lies on the unit direction
//! n_x = (u_y − u_z)/√3, perpendicular to phase x's axis u_x: i_αβ = i·n_x, and
//! i_y = −i_z = (√3/2)·i. Along n_x the winding is one inductance that depends on the rotor
//! angle (saliency), with c = n·e_d, s = n·e_q the projections on the rotor axes:
//!
//! ```text
//! L_n = L_d·c² + L_q·s²                      dL_n/dt = 2·ω_e·(L_d − L_q)·c·s
//! ψ_n = ψ_df·c + ψ_qf·s                      dψ_n/dt = ω_e·(ψ_df'·c + ψ_qf'·s + ψ_df·s − ψ_qf·c)
//! L_n·di/dt = v_n − R_s·i − i·dL_n/dt − dψ_n/dt,   v_n = (v_y − v_z)/√3
//! ```
//!
//! (the projection of eq. 2 on n; ' is ∂/∂θ_e), with the line voltage v_y − v_z from the
//! two pole voltages (bridge on) or the free-wheeling diodes (bridge off). The d-q states
//! follow as i_d = i·c, i_q = i·s, so the torque of eq. 3 needs no change; the power is
//! 1.5·v_n·i. Opening a phase that carries current removes its current at once: the
//! winding energy of that component goes into the arc (booked as a projection loss).
//!
//! **Short circuit** through a fault path of resistance R_f and inductance L_f, either
//! between two phases (insulation failure in the cable or terminal box) or from one phase
//! to a DC-link rail (a chafed cable on the bus bar). While the bridge is on its legs are
//! taken as stiff voltage sources (their on-resistance is small against the fault path's),
//! so the motor still sees the pole voltages and the fault path carries, besides,
//!
//! ```text
//! L_f·di_f/dt = v_f − R_f·i_f,   v_f = (d_x − d_y)·U_dc  (phase x to phase y)
//!                                v_f = U_dc − d_x·U_dc    (phase x to the positive rail)
//!                                v_f = −d_x·U_dc          (phase x to the negative rail)
//! ```
//!
//! solved exactly over each integration step (the voltage is held over the step), since
//! τ_f = L_f/R_f is of the order of the step. Leg x carries +i_f (to phase y, which carries
//! −i_f) or −i_f (a rail short feeds node x, the leg sinks it). With the bridge off the
//! legs float: a phase-to-phase short's path current is driven to zero by −U_dc through the
//! diodes within L_f·|i_f|/U_dc (a fraction of a microsecond), after which the short
//! connects the two motor terminals — the motor is then one circuit along n_z (z the third
//! phase, floating) closed through R_f, v_n = −(R_f/2)·i, and brakes the shaft with its
//! back-EMF; a rail short's current free-wheels through the leg's diode (v_f = 0, decaying
//! with τ_f) and pins its phase's pole at the rail, so a turning motor drives its back-EMF
//! through the short and the other legs' diodes: the shorted phase's current then comes
//! from the short, not from its leg, unless it flows the way the leg's diode to the same
//! rail conducts (that diode, not the resistive short, takes it). Diode conduction driven
//! by a back-EMF above U_dc (beyond the speed limit) is not modelled in these two states.
//!
//! # DC-link supply
//!
//! The bus voltage follows the supply's no-load voltage through the bus capacitor and the
//! supply's source resistance, a first-order lag: u(t) = u_s + (u(0) − u_s)·e^{−t/τ}. A sag
//! (brown-out) or a surge (line surge, regeneration into a stiff bus) steps u_s; a rectifier
//! ripple adds A·sin(2π·f·t) (f = 100 Hz behind a single-phase 50 Hz bridge, 300 Hz behind
//! a three-phase one).
//!
//! # Hydraulics
//!
//! - **Relief valve stuck closed** (port A's): no relief flow at any pressure.
//! - **Burst line**: a turbulent orifice of area A from port A to atmosphere,
//!   q = C_d·A·√(2Δp/ρ), made laminar below a transition Δp_t so the flow stays smooth
//!   through zero: q = C_d·A·√(2/ρ)·Δp/(Δp² + Δp_t²)^¼. The oil leaves the circuit.
//! - **Blocked pump port**: the delivery line between the pump's manifold (pump, check and
//!   relief valves) and the rest of port A (line, absorber, transducer, chamber 1) closes,
//!   e.g. a collapsed hose or a manual valve left shut. The manifold is then a node of its
//!   own with the small volume [`PUMP_MANIFOLD_VOLUME_M3`]; its relief valve still limits
//!   its pressure, the transducer no longer sees it.

use crate::motor::{MagnetFlux, Motor, Phasor};

/// √3.
const SQRT3: f64 = 1.732_050_807_568_877_2;

/// Oil volume of the pump's outlet passages and manifold up to the blocked line (assumed:
/// pump kidney port, manifold bores, fitting). [m³]
pub const PUMP_MANIFOLD_VOLUME_M3: f64 = 20e-6;
/// Discharge coefficient of a sharp-edged orifice. [1]
pub const ORIFICE_DISCHARGE_COEFFICIENT: f64 = 0.62;
/// Pressure difference below which a burst line's flow turns laminar (keeps the flow's
/// slope finite through zero). [Pa]
pub const ORIFICE_TRANSITION_PA: f64 = 1e4;

/// A motor phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Phase a.
    A = 0,
    /// Phase b.
    B = 1,
    /// Phase c.
    C = 2,
}

impl Phase {
    /// All three, in order.
    pub const ALL: [Phase; 3] = [Phase::A, Phase::B, Phase::C];

    /// Index 0, 1, 2.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The cyclic successor (a → b → c → a).
    pub fn next(self) -> Phase {
        match self {
            Phase::A => Phase::B,
            Phase::B => Phase::C,
            Phase::C => Phase::A,
        }
    }

    /// The phase that is neither `self` nor `other` (`self` itself's successor when equal).
    pub fn third(self, other: Phase) -> Phase {
        let n = self.next();
        if n == other {
            n.next()
        } else {
            n
        }
    }

    /// The unit α-β direction of this phase's axis u_x. [1]
    pub fn axis(self) -> [f64; 2] {
        match self {
            Phase::A => [1.0, 0.0],
            Phase::B => [-0.5, 0.5 * SQRT3],
            Phase::C => [-0.5, -0.5 * SQRT3],
        }
    }

    /// The direction n = (u_y − u_z)/√3 the current vector is confined to when this phase
    /// carries no current (y, z its cyclic successors). [1]
    pub fn line_direction(self) -> [f64; 2] {
        let y = self.next();
        let (uy, uz) = (y.axis(), y.next().axis());
        [(uy[0] - uz[0]) / SQRT3, (uy[1] - uz[1]) / SQRT3]
    }
}

/// A DC-link rail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rail {
    /// The negative rail (0 V).
    Negative,
    /// The positive rail (U_dc).
    Positive,
}

/// Where a short circuit connects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShortPath {
    /// Phase `from` to phase `to` (distinct).
    PhaseToPhase {
        /// First phase (its leg carries +i_f).
        from: Phase,
        /// Second phase (its leg carries −i_f).
        to: Phase,
    },
    /// Phase `phase` to a DC-link rail.
    PhaseToRail {
        /// The shorted phase.
        phase: Phase,
        /// The rail it touches.
        rail: Rail,
    },
}

/// A short circuit and its fault path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Short {
    /// Where it connects.
    pub path: ShortPath,
    /// Fault-path resistance R_f (> 0). [Ω]
    pub resistance_ohm: f64,
    /// Fault-path inductance L_f (> 0). [H]
    pub inductance_h: f64,
}

/// A fault of the DC-link supply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SupplyFault {
    /// The supply's no-load voltage steps to `to_v` (sag below, surge above nominal); the
    /// bus follows with `time_constant_s`.
    Step {
        /// New supply voltage. [V]
        to_v: f64,
        /// Bus capacitor × source resistance. [s]
        time_constant_s: f64,
    },
    /// Rectifier ripple on the bus.
    Ripple {
        /// Amplitude. [V]
        amplitude_v: f64,
        /// Frequency. [Hz]
        frequency_hz: f64,
    },
}

/// The plant's faults (none by default).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PlantFaults {
    /// An open phase.
    pub open_phase: Option<Phase>,
    /// A short circuit.
    pub short: Option<Short>,
    /// A supply fault.
    pub supply: Option<SupplyFault>,
    /// Port A's relief valve stuck closed.
    pub relief_stuck_closed: bool,
    /// Effective area of a burst line from port A to atmosphere (0: none). [m²]
    pub burst_area_m2: f64,
    /// The delivery line between the pump's manifold and port A closed.
    pub pump_port_blocked: bool,
}

impl PlantFaults {
    /// Checks the values; `Err` names the offending field.
    pub fn validate(&self) -> Result<(), &'static str> {
        if let Some(s) = self.short {
            if !(s.resistance_ohm.is_finite() && s.resistance_ohm > 0.0) {
                return Err("short.resistance_ohm must be finite and > 0");
            }
            if !(s.inductance_h.is_finite() && s.inductance_h > 0.0) {
                return Err("short.inductance_h must be finite and > 0");
            }
            if let ShortPath::PhaseToPhase { from, to } = s.path {
                if from == to {
                    return Err("short.path must join two distinct phases");
                }
            }
        }
        match self.supply {
            Some(SupplyFault::Step {
                to_v,
                time_constant_s,
            }) => {
                if !(to_v.is_finite() && to_v >= 0.0) {
                    return Err("supply.to_v must be finite and >= 0");
                }
                if !(time_constant_s.is_finite() && time_constant_s > 0.0) {
                    return Err("supply.time_constant_s must be finite and > 0");
                }
            }
            Some(SupplyFault::Ripple {
                amplitude_v,
                frequency_hz,
            }) => {
                if !(amplitude_v.is_finite() && amplitude_v >= 0.0) {
                    return Err("supply.amplitude_v must be finite and >= 0");
                }
                if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
                    return Err("supply.frequency_hz must be finite and > 0");
                }
            }
            None => {}
        }
        if !(self.burst_area_m2.is_finite() && self.burst_area_m2 >= 0.0) {
            return Err("burst_area_m2 must be finite and >= 0");
        }
        Ok(())
    }
}

/// How the motor's current is confined to one line this step, if it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Line {
    /// Phase `open` carries nothing; the other two are driven by the bridge (or its
    /// diodes).
    Open(Phase),
    /// The bridge is off and a phase-to-phase short joins the two phases other than
    /// `floating` through `resistance_ohm`.
    Shorted {
        /// The phase not in the short.
        floating: Phase,
        /// R_f. [Ω]
        resistance_ohm: f64,
    },
}

impl Line {
    /// The phase without current.
    pub fn idle_phase(self) -> Phase {
        match self {
            Line::Open(p) => p,
            Line::Shorted { floating, .. } => floating,
        }
    }
}

/// The line current i = n·i_αβ of d-q currents at the electrical-angle phasor `e`. [A]
#[inline]
pub fn line_current(n: [f64; 2], i_d: f64, i_q: f64, e: Phasor) -> f64 {
    let (c, s) = rotor_projections(n, e);
    i_d * c + i_q * s
}

/// (n·e_d, n·e_q): the projections of `n` on the rotor axes at `e`. [1]
#[inline]
pub fn rotor_projections(n: [f64; 2], e: Phasor) -> (f64, f64) {
    (n[0] * e.cos + n[1] * e.sin, -n[0] * e.sin + n[1] * e.cos)
}

/// di/dt of the line current `i` driven by `v_n` (module docs), and the d-q derivatives
/// that keep i_d = i·c, i_q = i·s. [A/s]
#[inline]
pub fn line_derivatives(
    motor: &Motor,
    n: [f64; 2],
    i: f64,
    v_n: f64,
    omega_e: f64,
    e: Phasor,
    flux: &MagnetFlux,
) -> (f64, f64, f64) {
    let (c, s) = rotor_projections(n, e);
    let l_n = motor.l_d_h * c * c + motor.l_q_h * s * s;
    let dl = 2.0 * omega_e * (motor.l_d_h - motor.l_q_h) * c * s;
    let dpsi =
        omega_e * (flux.d_slope_wb * c + flux.q_slope_wb * s + flux.d_wb * s - flux.q_wb * c);
    let di = (v_n - motor.r_s_ohm * i - i * dl - dpsi) / l_n;
    (di, di * c + i * omega_e * s, di * s - i * omega_e * c)
}

/// The fault path's driving voltage with the bridge on (module docs). [V]
#[inline]
pub fn fault_path_voltage(path: ShortPath, duties: &[f64; 3], u_dc: f64) -> f64 {
    let d = |p: Phase| duties.get(p.index()).copied().unwrap_or(0.5);
    match path {
        ShortPath::PhaseToPhase { from, to } => (d(from) - d(to)) * u_dc,
        ShortPath::PhaseToRail {
            phase,
            rail: Rail::Positive,
        } => u_dc - d(phase) * u_dc,
        ShortPath::PhaseToRail {
            phase,
            rail: Rail::Negative,
        } => -d(phase) * u_dc,
    }
}

/// The fault path's current after `h` seconds from `i0`, driven by `v` (bridge on), or with
/// the bridge off (`v` = None: a phase-to-phase path driven to zero by the diodes at
/// −U_dc·sign(i), a rail path free-wheeling). Exact for the held voltage. [A]
pub fn fault_path_current(short: &Short, i0: f64, v: Option<f64>, u_dc: f64, h: f64) -> f64 {
    let r = short.resistance_ohm;
    let tau = short.inductance_h / r;
    let decay = libm::exp(-h / tau);
    match (v, short.path) {
        (Some(v), _) => {
            let i_ss = v / r;
            i_ss + (i0 - i_ss) * decay
        }
        (None, ShortPath::PhaseToRail { .. }) => i0 * decay,
        (None, ShortPath::PhaseToPhase { .. }) => {
            if i0 == 0.0 {
                return 0.0;
            }
            // Toward −sign(i0)·U_dc/R; zero reached after τ·ln(1 + |i0|·R/U_dc).
            let toward = -libm::copysign(u_dc / r, i0);
            let i = toward + (i0 - toward) * decay;
            if i * i0 <= 0.0 {
                0.0
            } else {
                i
            }
        }
    }
}

/// What each bridge leg carries besides the motor's phase current for a fault-path current
/// `i_f`. [A]
#[inline]
pub fn leg_contribution(path: ShortPath, i_f: f64) -> [f64; 3] {
    let mut out = [0.0; 3];
    match path {
        ShortPath::PhaseToPhase { from, to } => {
            out[from.index()] += i_f;
            out[to.index()] -= i_f;
        }
        ShortPath::PhaseToRail { phase, .. } => out[phase.index()] -= i_f,
    }
    out
}

/// Flow through a burst line of area `area_m2` for the pressure difference `dp` to
/// atmosphere, oil density `rho` (module docs). [m³/s]
#[inline]
pub fn burst_flow(area_m2: f64, dp: f64, rho: f64) -> f64 {
    if area_m2 <= 0.0 {
        return 0.0;
    }
    let scale = libm::sqrt(libm::sqrt(
        dp * dp + ORIFICE_TRANSITION_PA * ORIFICE_TRANSITION_PA,
    ));
    ORIFICE_DISCHARGE_COEFFICIENT * area_m2 * libm::sqrt(2.0 / rho) * dp / scale
}

/// The DC link: the bus voltage's lag behind the supply, and the ripple.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcLink {
    /// Nominal supply voltage. [V]
    pub nominal_v: f64,
    /// Bus voltage without the ripple (the lag's state). [V]
    pub bus_v: f64,
    /// Supply voltage the bus is heading for. [V]
    pub target_v: f64,
    /// Lag time constant. [s]
    pub time_constant_s: f64,
    /// Ripple amplitude. [V]
    pub ripple_v: f64,
    /// Ripple frequency. [Hz]
    pub ripple_hz: f64,
}

/// Time constant of the bus's return to nominal after a supply fault is removed (bus
/// capacitor × source resistance of a stiff supply, assumed). [s]
pub const BUS_RECOVERY_TIME_CONSTANT_S: f64 = 5e-3;

impl DcLink {
    /// A stiff supply at `nominal_v`. [V]
    pub fn new(nominal_v: f64) -> DcLink {
        DcLink {
            nominal_v,
            bus_v: nominal_v,
            target_v: nominal_v,
            time_constant_s: BUS_RECOVERY_TIME_CONSTANT_S,
            ripple_v: 0.0,
            ripple_hz: 100.0,
        }
    }

    /// Takes the supply fault (or its removal) from now on.
    pub fn set_fault(&mut self, fault: Option<SupplyFault>) {
        self.ripple_v = 0.0;
        match fault {
            Some(SupplyFault::Step {
                to_v,
                time_constant_s,
            }) => {
                self.target_v = to_v;
                self.time_constant_s = time_constant_s;
            }
            Some(SupplyFault::Ripple {
                amplitude_v,
                frequency_hz,
            }) => {
                self.target_v = self.nominal_v;
                self.ripple_v = amplitude_v;
                self.ripple_hz = frequency_hz;
            }
            None => {
                if self.target_v != self.nominal_v {
                    self.target_v = self.nominal_v;
                    self.time_constant_s = BUS_RECOVERY_TIME_CONSTANT_S;
                }
            }
        }
    }

    /// The bus voltage at time `t_s`. [V]
    #[inline]
    pub fn voltage(&self, t_s: f64) -> f64 {
        let ripple = if self.ripple_v > 0.0 {
            self.ripple_v * libm::sin(core::f64::consts::TAU * self.ripple_hz * t_s)
        } else {
            0.0
        };
        (self.bus_v + ripple).max(0.0)
    }

    /// Advances the lag by `h`. [s]
    #[inline]
    pub fn advance(&mut self, h: f64) {
        if self.bus_v != self.target_v {
            self.bus_v =
                self.target_v + (self.bus_v - self.target_v) * libm::exp(-h / self.time_constant_s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::Rig;

    #[test]
    fn line_directions_are_perpendicular_to_the_open_phase() {
        for p in Phase::ALL {
            let (n, u) = (p.line_direction(), p.axis());
            assert!((n[0] * n[0] + n[1] * n[1] - 1.0).abs() < 1e-15);
            assert!((n[0] * u[0] + n[1] * u[1]).abs() < 1e-15);
            // The successor carries +√3/2·i along n.
            let y = p.next().axis();
            assert!((n[0] * y[0] + n[1] * y[1] - 0.5 * SQRT3).abs() < 1e-15);
        }
        assert_eq!(Phase::A.third(Phase::B), Phase::C);
        assert_eq!(Phase::C.third(Phase::B), Phase::A);
    }

    #[test]
    fn a_round_rotor_line_is_an_rl_circuit() {
        // L_d = L_q = L, no harmonics, standstill: L·di/dt = v − R·i, so di/dt(0) = v/L and
        // the steady current v/R (di/dt = 0 there).
        let mut rig = Rig::nominal();
        rig.motor.l_q_h = rig.motor.l_d_h;
        let m = Motor::new(&rig.motor);
        let flux = m.magnet_flux(0.3);
        let e = Phasor::of(0.3);
        let n = Phase::B.line_direction();
        let (di, _, _) = line_derivatives(&m, n, 0.0, 10.0, 0.0, e, &flux);
        assert!((di - 10.0 / rig.motor.l_d_h).abs() < 1e-9);
        let (di, _, _) = line_derivatives(&m, n, 10.0 / m.r_s_ohm, 10.0, 0.0, e, &flux);
        assert!(di.abs() < 1e-9);
    }

    #[test]
    fn the_line_emf_is_the_line_to_line_back_emf() {
        // Phase a open, shaft turning, no current: L_n·di/dt = −dψ_n/dt, and
        // √3·dψ_n/dt is the b–c line EMF √3·ψ_f·ω_e·cos(θ_e) (e_b − e_c of a
        // sinusoidal machine with e_x = −ψ_f·ω_e·sin(θ_e − φ_x)).
        let rig = Rig::nominal();
        let m = Motor::new(&rig.motor);
        let (omega_e, th) = (100.0, 0.7);
        let e = Phasor::of(th);
        let flux = m.magnet_flux(th);
        let n = Phase::A.line_direction();
        let (di, _, _) = line_derivatives(&m, n, 0.0, 0.0, omega_e, e, &flux);
        let (c, s) = rotor_projections(n, e);
        let l_n = m.l_d_h * c * c + m.l_q_h * s * s;
        let emf_line = -SQRT3 * di * l_n;
        let expected = SQRT3 * m.psi_f_wb * omega_e * libm::cos(th);
        assert!(
            (emf_line - expected).abs() < 1e-9,
            "{emf_line} vs {expected}"
        );
    }

    #[test]
    fn fault_path_current_is_the_rl_step_response() {
        let s = Short {
            path: ShortPath::PhaseToRail {
                phase: Phase::A,
                rail: Rail::Positive,
            },
            resistance_ohm: 0.05,
            inductance_h: 2e-6,
        };
        // Duty 0.5 at 280 V: 140 V across the path, 2800 A steady, τ = 40 µs.
        let v = fault_path_voltage(s.path, &[0.5; 3], 280.0);
        assert!((v - 140.0).abs() < 1e-12);
        let i = fault_path_current(&s, 0.0, Some(v), 280.0, 40e-6);
        assert!((i - 2800.0 * (1.0 - (-1.0f64).exp())).abs() < 1e-9);
        // Bridge off: free-wheels, e⁻¹ after τ.
        let j = fault_path_current(&s, 100.0, None, 280.0, 40e-6);
        assert!((j - 100.0 * (-1.0f64).exp()).abs() < 1e-9);
        // Phase to phase, bridge off: 50 A is gone after τ·ln(1 + 50·0.05/280) ≈ 0.36 µs.
        let p = Short {
            path: ShortPath::PhaseToPhase {
                from: Phase::A,
                to: Phase::B,
            },
            ..s
        };
        assert_eq!(fault_path_current(&p, 50.0, None, 280.0, 1e-6), 0.0);
        let t0 = 40e-6 * (1.0 + 50.0 * 0.05 / 280.0f64).ln();
        assert!(fault_path_current(&p, 50.0, None, 280.0, 0.9 * t0) > 0.0);
        assert_eq!(leg_contribution(p.path, 3.0), [3.0, -3.0, 0.0]);
        assert_eq!(leg_contribution(s.path, 3.0), [-3.0, 0.0, 0.0]);
    }

    #[test]
    fn burst_flow_is_turbulent_far_from_zero_and_smooth_through_it() {
        let (a, rho) = (1e-6, 870.0);
        let q = burst_flow(a, 5e6, rho);
        let turbulent = ORIFICE_DISCHARGE_COEFFICIENT * a * (2.0 * 5e6 / rho).sqrt();
        assert!((q / turbulent - 1.0).abs() < 1e-5, "{q} vs {turbulent}");
        assert_eq!(burst_flow(a, 0.0, rho), 0.0);
        assert!(burst_flow(a, -1e5, rho) < 0.0);
        assert_eq!(burst_flow(0.0, 5e6, rho), 0.0);
    }

    #[test]
    fn the_bus_follows_a_sag_with_its_time_constant() {
        let mut d = DcLink::new(280.0);
        d.set_fault(Some(SupplyFault::Step {
            to_v: 180.0,
            time_constant_s: 2e-3,
        }));
        for _ in 0..40 {
            d.advance(50e-6);
        }
        let expected = 180.0 + 100.0 * (-1.0f64).exp();
        assert!((d.voltage(0.0) - expected).abs() < 1e-9);
        d.set_fault(Some(SupplyFault::Ripple {
            amplitude_v: 30.0,
            frequency_hz: 100.0,
        }));
        assert!((d.voltage(0.0025) - (d.bus_v + 30.0)).abs() < 1e-9);
    }
}
