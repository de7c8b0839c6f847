//! The paper's accumulator selection method (Section 4.3, eq. 22–32) applied to a rig: the
//! precharge range [p_12, p_11] in which the pulsation absorber's natural frequency meets
//! the pump's flow pulsation (eq. 29) and its damping ratio is 0.707, the absorber's natural
//! frequency and damping ratio at the rig's precharge, and the pump's pulsation frequency
//! at the low-speed holding point.
//!
//! # Derivation of eq. 31–32 (garbled in the paper's text)
//!
//! **The model (eq. 22–26).** Fig. 9 reduces the bladder absorber to a piston of area A_a
//! between the oil (mass m_a, viscous damping B_a) and the gas (damping c_a, stiffness). The
//! gas is polytropic, p·V^n = const (absolute pressure; n = 1.3 in the paper), so about a
//! state (p, V_g) a volume change ΔV = A_a·Δx changes the pressure by Δp = −n·p·ΔV/V_g and
//! the force by A_a·Δp: the gas stiffness is n·p·A_a²/V_g — the paper's `k·p_1·A_a²/V_a0`,
//! with k the polytropic exponent. Eq. 26's equivalent stiffness is
//! k_x = k_a + n·p·A_a²/V_g, where k_a is any stiffness beyond the gas (a bladder's own
//! elasticity). The square root printed over this sum in eq. 26 is a typesetting error: k_x
//! must have the unit of a stiffness (N/m) to give ω_n = √(k_x/m_a). The plant model has no
//! bladder elasticity, so k_a = 0 here. Eq. 26 then gives
//!
//! ```text
//! ω_n = √(k_x/m_a),        ζ = (B_a + c_a) / (2·√(k_x·m_a)).
//! ```
//!
//! **In the plant's terms.** Dividing forces by A_a and multiplying displacements by A_a
//! turns the mechanical model into the hydraulic one of `plant_model::accumulator`: inlet
//! inertance I = m_a/A_a², loss resistance R = (B_a + c_a)/A_a², gas capacitance
//! C = A_a²/k_x = V_g/(n·p). Substituting, A_a cancels:
//!
//! ```text
//! ω_n = √((A_a²/C)/(I·A_a²)) = 1/√(I·C),    ζ = R·A_a²/(2·√(A_a²/C · I·A_a²)) = (R/2)·√(C/I).
//! ```
//!
//! **The state the paper linearises about.** Eq. 26 writes the gas stiffness with V_a0,
//! the gas volume at precharge, and eq. 31–32 solve it for the *inflation* pressure; that is
//! consistent only if the gas is at its precharge state, p = p_0 and V_g = V_0 (the moment
//! the poppet opens). Then C = V_0/(n·p_0) and
//!
//! - eq. 29/31, ω_n = ω_1 (the absorber tuned to the flow pulsation):
//!   n·p_0/(I·V_0) = ω_1², so **p_11 = ω_1²·I·V_0/n** = ω_1²·m_a·V_a0/(n·A_a²).
//!   (The paper's bracket is its expression for ω_1 from eq. 30; its m_a² is a misprint:
//!   ω_1²·m_a·V/A² has the unit of pressure, ω_1²·m_a²·V/A² does not.)
//! - eq. 32, ζ = 1/√2: R²·C/(4·I) = 1/2, C = 2·I/R², so **p_12 = R²·V_0/(2·n·I)**
//!   = [(B_a + c_a)²/(1.414²·m_a) − k_a]·V_a0/(n·A_a²) with k_a = 0. (The paper's fourth
//!   power is a misprint for the square divided by m_a, again by units.)
//!
//! Both are absolute pressures; the range reported is [min, max] of the two, as gauge.
//!
//! **The working point.** The absorber does its work at the working pressure p_w, not at
//! its precharge. There the gas has shrunk to V_w = V_0·(p_0/p_w)^(1/n) and
//! C = V_w/(n·p_w) — the plant's `GasCharge::capacitance_m3_per_pa`, from which
//! `Absorber::natural_frequency_rad_s` and `Absorber::damping_ratio` compute the reported
//! `natural_frequency_hz` and `damping_ratio`. At a fixed p_w this capacitance *grows* with
//! the precharge (more of the shell is gas), so ω_n falls as p_0 rises — the opposite of
//! the precharge-state linearisation, where ω_n ∝ √p_0 — until p_0 reaches p_w and the
//! absorber holds no oil at all (no capacitance, no absorption). The most compliant the
//! absorber can be at p_w is C_max = V_0/(n·p_w), as p_0 → p_w. Solving the two conditions
//! at the working point, p_0 = p_w·(n·p_w·C/V_0)^n with C = 1/(I·ω_1²) or 2·I/R², gives a
//! usable precharge only if it is below p_w; the output reports both, and says when they
//! are not.
//!
//! **ω_1.** Eq. 30 calls ω_1 the motor–pump's dominant natural frequency; eq. 29, the one
//! the selection rests on, calls it the flow pulsation frequency, which is what an absorber
//! must meet. We use the pump's kinematic flow pulsation at the holding speed: 2·z pulses
//! per revolution for an odd number of pistons z, z for an even one. The holding speed is
//! the speed at which the pump only replaces leakage, ω_hold = Q_leak/(D_p/2π), with the
//! leakage from port A at p_w of eq. 9 — C_ip·(p_w − p_r) + C_ep·p_w (plus any extra
//! leakage the rig sets) — and the cylinder's cross-piston leakage C_ic·(p_w − p_r), the
//! blocked cylinder's other chamber sitting at the fill pressure p_r.
//!
//! **Working pressure.** The paper's low-speed pressure-holding case: 5 MPa by default
//! (the pressure of its Section 5.3 measurements), `--pressure` to change it.
//!
//! **What the paper's numbers need.** The paper's range (4.5–5 MPa) rests on m_a, A_a, B_a
//! and c_a, which it does not give; the rig's I and R are this project's assumptions
//! (a 12 mm × 50 mm inlet, ζ ≈ 0.15 at 3 MPa precharge and 5 MPa). The output states the
//! inertance and resistance that would put p_11 and p_12 at the paper's 4.5 and 5 MPa,
//! rather than tuning the rig to them.

use plant_model::accumulator::{Absorber, ATMOSPHERE_PA};
use plant_model::rig::AbsorberParams;
use plant_model::Rig;
use serde::Serialize;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// The paper's optimum precharge range (Section 5.2), gauge, for the notes. [Pa]
pub const PAPER_RANGE_PA: [f64; 2] = [4.5e6, 5.0e6];

/// The damping ratio eq. 32 aims for. [1]
pub const TARGET_DAMPING_RATIO: f64 = core::f64::consts::FRAC_1_SQRT_2;

/// A working pressure the method cannot use.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DesignError {
    /// The working pressure does not exceed the fill pressure (no leakage to replace).
    #[error("working pressure {working_pa} Pa must exceed the fill pressure {fill_pa} Pa (fill.pressure_pa): below it the pump has no leakage to replace and no holding speed")]
    PressureBelowFill {
        /// Asked working pressure. [Pa]
        working_pa: f64,
        /// Rig's fill pressure. [Pa]
        fill_pa: f64,
    },
    /// The working pressure reaches the relief valve: the pump cannot hold it.
    #[error("working pressure {working_pa:e} Pa must be below the relief valve's cracking pressure {relief_pa:e} Pa (fill.relief_cracking_pa): the valve opens before it is reached")]
    PressureAboveRelief {
        /// Asked working pressure. [Pa]
        working_pa: f64,
        /// Rig's relief cracking pressure. [Pa]
        relief_pa: f64,
    },
}

/// Pulsation orders of the pump's kinematic flow ripple per shaft revolution: 2·z for an
/// odd number of pistons, z for an even one (eq. 20–21).
pub fn pulsation_order(pistons: u32) -> u32 {
    if pistons % 2 == 1 {
        2 * pistons
    } else {
        pistons
    }
}

/// Leakage from port A at gauge pressure `p` with the cylinder blocked: the pump's eq. 9
/// terms and the cylinder's cross-piston leakage to the fill-pressure side. [m³/s]
pub fn holding_leakage_m3_s(rig: &Rig, p: f64) -> f64 {
    let p_r = rig.fill.pressure_pa;
    let pump = &rig.pump;
    pump.internal_leakage_m3_s_pa * (p - p_r)
        + (pump.external_leakage_m3_s_pa + pump.extra_leakage_m3_s_pa) * p
        + rig.cylinder.internal_leakage_m3_s_pa * (p - p_r)
}

/// Shaft speed at which the pump only replaces the leakage at `p`. [rad/s]
pub fn holding_speed_rad_s(rig: &Rig, p: f64) -> f64 {
    holding_leakage_m3_s(rig, p) / rig.pump.displacement_m3_per_rad()
}

/// The selection method's results.
#[derive(Clone, Debug, Serialize)]
pub struct AccumulatorDesign {
    /// [p_12, p_11] ordered low to high, gauge (eq. 31–32, gas linearised at precharge). [Pa]
    pub precharge_range_pa: [f64; 2],
    /// Absorber natural frequency at the rig's precharge and the working pressure (0 when
    /// the absorber holds no oil there). [Hz]
    pub natural_frequency_hz: f64,
    /// Absorber damping ratio at the rig's precharge and the working pressure. [1]
    pub damping_ratio: f64,
    /// Pump flow pulsation frequency at the holding speed, ω_1. [Hz]
    pub pulsation_frequency_hz: f64,

    /// Working (holding) pressure, gauge. [Pa]
    pub working_pressure_pa: f64,
    /// The rig's absorber precharge, gauge. [Pa]
    pub precharge_pa: f64,
    /// Leakage from port A at the working pressure. [m³/s]
    pub leakage_flow_m3_s: f64,
    /// Holding speed: leakage / displacement. [rad/s]
    pub holding_speed_rad_s: f64,
    /// Holding speed. [rpm]
    pub holding_speed_rpm: f64,
    /// Flow pulsation cycles per shaft revolution. [1]
    pub pulsation_order_per_rev: u32,
    /// Eq. 31: precharge putting ω_n at ω_1 (gas at precharge), gauge. [Pa]
    pub p11_pa: f64,
    /// Eq. 32: precharge giving ζ = 0.707 (gas at precharge), gauge. [Pa]
    pub p12_pa: f64,
    /// Absorber natural frequency at the rig's precharge. [rad/s]
    pub natural_frequency_rad_s: f64,
    /// Gas capacitance at the rig's precharge and the working pressure. [m³/Pa]
    pub capacitance_m3_per_pa: f64,
    /// The same conditions solved at the working pressure instead.
    pub at_working_pressure: WorkingPointDesign,
    /// Absorber inlet inertance I = m_a/A_a² (rig). [kg/m⁴]
    pub inertance_kg_m4: f64,
    /// Absorber loss resistance R = (B_a + c_a)/A_a² (rig). [Pa·s/m³]
    pub resistance_pa_s_m3: f64,
    /// Inertance that would put p_11 at the paper's 4.5 MPa with this ω_1. [kg/m⁴]
    pub inertance_for_paper_p11_kg_m4: f64,
    /// Resistance that would put p_12 at the paper's 5 MPa with the rig's inertance. [Pa·s/m³]
    pub resistance_for_paper_p12_pa_s_m3: f64,
    /// How the numbers were obtained and where they depart from the paper.
    pub notes: Vec<String>,
}

/// Eq. 31–32's conditions solved with the gas at the working pressure.
#[derive(Clone, Debug, Serialize)]
pub struct WorkingPointDesign {
    /// Precharge giving ω_n = ω_1 at the working pressure, gauge; `None` when it would have
    /// to be at or above the working pressure (absorber empty). [Pa]
    pub p11_pa: Option<f64>,
    /// Precharge giving ζ = 0.707 at the working pressure, gauge; `None` likewise. [Pa]
    pub p12_pa: Option<f64>,
    /// Lowest natural frequency reachable at the working pressure (precharge → p_w). [Hz]
    pub lowest_natural_frequency_hz: f64,
    /// Highest damping ratio reachable at the working pressure (precharge → p_w). [1]
    pub highest_damping_ratio: f64,
}

/// Refuses a working pressure (gauge) [Pa] at or below the fill pressure or at or above
/// the relief valve's cracking pressure.
fn check_working_pressure(rig: &Rig, working_pa: f64) -> Result<(), DesignError> {
    let fill_pa = rig.fill.pressure_pa;
    if !working_pa.is_finite() || working_pa <= fill_pa {
        return Err(DesignError::PressureBelowFill {
            working_pa,
            fill_pa,
        });
    }
    if working_pa >= rig.fill.relief_cracking_pa {
        return Err(DesignError::PressureAboveRelief {
            working_pa,
            relief_pa: rig.fill.relief_cracking_pa,
        });
    }
    Ok(())
}

/// Eq. 31–32's conditions at the working pressure `working_pa` (gauge) [Pa] instead of
/// the precharge state, for the pulsation `omega_1` [rad/s]: p_0 = p_w·(n·p_w·C/V_0)^n.
fn working_point(a: &AbsorberParams, working_pa: f64, omega_1: f64) -> WorkingPointDesign {
    let (i, r, v0, n) = (
        a.inlet_inertance_kg_m4,
        a.inlet_resistance_pa_s_m3,
        a.shell_volume_m3,
        a.polytropic_exponent,
    );
    let pw_abs = working_pa + ATMOSPHERE_PA;
    let precharge_for = |c: f64| {
        let p0_abs = pw_abs * (n * pw_abs * c / v0).powf(n);
        (p0_abs < pw_abs).then_some(p0_abs - ATMOSPHERE_PA)
    };
    let c_max = v0 / (n * pw_abs);
    WorkingPointDesign {
        p11_pa: precharge_for(1.0 / (i * omega_1 * omega_1)),
        p12_pa: precharge_for(2.0 * i / (r * r)),
        lowest_natural_frequency_hz: 1.0 / (i * c_max).sqrt() / (2.0 * PI),
        highest_damping_ratio: 0.5 * r * (c_max / i).sqrt(),
    }
}

/// Applies the selection method to `rig` at working pressure `working_pa` (gauge).
pub fn design(rig: &Rig, working_pa: f64) -> Result<AccumulatorDesign, DesignError> {
    check_working_pressure(rig, working_pa)?;
    let a = &rig.absorber;
    let (i, r, v0, n) = (
        a.inlet_inertance_kg_m4,
        a.inlet_resistance_pa_s_m3,
        a.shell_volume_m3,
        a.polytropic_exponent,
    );

    let leakage = holding_leakage_m3_s(rig, working_pa);
    let speed = holding_speed_rad_s(rig, working_pa);
    let order = pulsation_order(rig.pump.pistons);
    let omega_1 = order as f64 * speed;

    // Eq. 31–32 with the gas at its precharge state (absolute pressures).
    let p11_abs = omega_1 * omega_1 * i * v0 / n;
    let p12_abs = r * r * v0 / (2.0 * n * i);
    let p11 = p11_abs - ATMOSPHERE_PA;
    let p12 = p12_abs - ATMOSPHERE_PA;

    // The rig's absorber at the working pressure: the plant's own model.
    let absorber = Absorber::new(a);
    let omega_n = absorber.natural_frequency_rad_s(working_pa);
    let zeta = absorber.damping_ratio(working_pa);
    let capacitance = absorber.gas.capacitance_m3_per_pa(working_pa);

    let working = working_point(a, working_pa, omega_1);

    let paper_p11_abs = PAPER_RANGE_PA[0] + ATMOSPHERE_PA;
    let paper_p12_abs = PAPER_RANGE_PA[1] + ATMOSPHERE_PA;
    let inertance_for_paper = n * paper_p11_abs / (omega_1 * omega_1 * v0);
    let resistance_for_paper = (2.0 * n * i * paper_p12_abs / v0).sqrt();

    let mut notes = vec![
        format!(
            "eq. 31-32 derived from eq. 26 with the gas linearised at its precharge state (p_0, V_0), as the paper's V_a0 implies: p_11 = w_1^2*I*V_0/n, p_12 = R^2*V_0/(2*n*I) (absolute); see the module docs of host_sim::study::accumulator_design"
        ),
        format!(
            "w_1 is the pump's flow pulsation, {order} per revolution ({} pistons) at the holding speed {:.3} rad/s = leakage {:.4e} m^3/s / displacement",
            rig.pump.pistons, speed, leakage
        ),
        format!(
            "natural_frequency_hz and damping_ratio are the rig's absorber (precharge {:.3} MPa) at the working pressure {:.3} MPa, the plant model's 1/sqrt(I*C) and (R/2)*sqrt(C/I)",
            a.precharge_pa / 1e6,
            working_pa / 1e6
        ),
    ];
    if absorber.gas.precharge_pa >= working_pa {
        notes.push(
            "the rig's precharge is at or above the working pressure: the absorber holds no oil there, so it has no natural frequency and absorbs nothing".into(),
        );
    }
    if working.p11_pa.is_none() || working.p12_pa.is_none() {
        notes.push(format!(
            "at the working pressure the conditions cannot be met with this absorber: even as the precharge approaches the working pressure its natural frequency stays at or above {:.2} Hz (w_1 is {:.2} Hz) and its damping ratio at or below {:.3} (target 0.707); the precharge-state range is the paper's method, not a working-point optimum",
            working.lowest_natural_frequency_hz,
            omega_1 / (2.0 * PI),
            working.highest_damping_ratio
        ));
    }
    notes.push(format!(
        "the paper's range {}-{} MPa is not reproduced: it rests on m_a, A_a, B_a, c_a the paper does not give; with this w_1 it would take an inlet inertance of {:.3e} kg/m^4 (rig: {:.3e}) for p_11 = 4.5 MPa and a resistance of {:.3e} Pa*s/m^3 (rig: {:.3e}) for p_12 = 5 MPa; the rig is not tuned to them",
        PAPER_RANGE_PA[0] / 1e6,
        PAPER_RANGE_PA[1] / 1e6,
        inertance_for_paper,
        i,
        resistance_for_paper,
        r
    ));

    Ok(AccumulatorDesign {
        precharge_range_pa: [p11.min(p12), p11.max(p12)],
        natural_frequency_hz: omega_n / (2.0 * PI),
        damping_ratio: zeta,
        pulsation_frequency_hz: omega_1 / (2.0 * PI),
        working_pressure_pa: working_pa,
        precharge_pa: a.precharge_pa,
        leakage_flow_m3_s: leakage,
        holding_speed_rad_s: speed,
        holding_speed_rpm: speed * 60.0 / (2.0 * PI),
        pulsation_order_per_rev: order,
        p11_pa: p11,
        p12_pa: p12,
        natural_frequency_rad_s: omega_n,
        capacitance_m3_per_pa: capacitance,
        at_working_pressure: working,
        inertance_kg_m4: i,
        resistance_pa_s_m3: r,
        inertance_for_paper_p11_kg_m4: inertance_for_paper,
        resistance_for_paper_p12_pa_s_m3: resistance_for_paper,
        notes,
    })
}

impl AccumulatorDesign {
    /// A short human-readable table.
    pub fn to_table(&self) -> String {
        let mpa = |p: f64| p / 1e6;
        let opt = |p: Option<f64>| {
            p.map_or("unreachable (needs precharge >= p_w)".to_string(), |p| {
                format!("{:.3} MPa", mpa(p))
            })
        };
        let mut s = String::new();
        let _ = writeln!(s, "Accumulator selection (paper Section 4.3, eq. 26-32)");
        let _ = writeln!(
            s,
            "  working pressure            {:>10.3} MPa",
            mpa(self.working_pressure_pa)
        );
        let _ = writeln!(
            s,
            "  holding speed               {:>10.3} rad/s ({:.1} rpm)",
            self.holding_speed_rad_s, self.holding_speed_rpm
        );
        let _ = writeln!(
            s,
            "  pump pulsation w_1          {:>10.3} Hz ({} per rev)",
            self.pulsation_frequency_hz, self.pulsation_order_per_rev
        );
        let _ = writeln!(
            s,
            "  p_11 (w_n = w_1)            {:>10.3} MPa",
            mpa(self.p11_pa)
        );
        let _ = writeln!(
            s,
            "  p_12 (zeta = 0.707)         {:>10.3} MPa",
            mpa(self.p12_pa)
        );
        let _ = writeln!(
            s,
            "  precharge range             {:>10.3} .. {:.3} MPa",
            mpa(self.precharge_range_pa[0]),
            mpa(self.precharge_range_pa[1])
        );
        let _ = writeln!(
            s,
            "  rig precharge               {:>10.3} MPa",
            mpa(self.precharge_pa)
        );
        let _ = writeln!(
            s,
            "  absorber w_n at p_w         {:>10.3} Hz",
            self.natural_frequency_hz
        );
        let _ = writeln!(
            s,
            "  absorber zeta at p_w        {:>10.3}",
            self.damping_ratio
        );
        let _ = writeln!(
            s,
            "  at p_w: p_11 {}, p_12 {}",
            opt(self.at_working_pressure.p11_pa),
            opt(self.at_working_pressure.p12_pa)
        );
        let _ = writeln!(s, "Notes:");
        for n in &self.notes {
            let _ = writeln!(s, "  - {n}");
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Independent hand computation from the nominal-rig table (nominal-rig.md) and the
    // rig's assumed absorber inlet (I = 3.85e5 kg/m⁴, R = 3e7 Pa·s/m³).
    const I: f64 = 3.85e5;
    const R: f64 = 3e7;
    const V0: f64 = 400e-6;
    const N: f64 = 1.3;
    const PATM: f64 = 101_325.0;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn holding_speed_is_leakage_over_displacement() {
        // 1e-13·(5e6 − 0.5e6) + 1e-13·5e6 + 1e-13·(5e6 − 0.5e6) = 1.4e-6 m³/s;
        // D = 1.5e-6/(2π) m³/rad → 5.8643 rad/s = 56.0 rpm ("about 60 rpm").
        let d = design(&Rig::nominal(), 5e6).unwrap();
        assert!(rel(d.leakage_flow_m3_s, 1.4e-6) < 1e-12);
        assert!(rel(d.holding_speed_rad_s, 1.4e-6 / (1.5e-6 / (2.0 * PI))) < 1e-12);
        assert!((d.holding_speed_rpm - 56.0).abs() < 0.01);
        // 9 pistons (odd) → 18 per revolution: 18 × 56/60 rev/s = 16.8 Hz.
        assert_eq!(d.pulsation_order_per_rev, 18);
        assert!(rel(d.pulsation_frequency_hz, 16.8) < 1e-9);
    }

    #[test]
    fn natural_frequency_and_damping_match_hand_computation() {
        // Gas at 5 MPa gauge from 3 MPa precharge: V = V0·(p0/p)^(1/n), C = V/(n·p).
        let (p0, p) = (3e6 + PATM, 5e6 + PATM);
        let c = V0 * (p0 / p).powf(1.0 / N) / (N * p);
        let wn = 1.0 / (I * c).sqrt();
        let zeta = R / 2.0 * (c / I).sqrt();
        let d = design(&Rig::nominal(), 5e6).unwrap();
        assert!(rel(d.natural_frequency_hz, wn / (2.0 * PI)) < 1e-9);
        assert!(rel(d.damping_ratio, zeta) < 1e-9);
        // Roughly 40 Hz and 0.155: the rig's assumption "ζ ≈ 0.15 at 3 MPa and 5 MPa".
        assert!((d.natural_frequency_hz - 40.0).abs() < 0.2);
        assert!((d.damping_ratio - 0.155).abs() < 0.002);
    }

    #[test]
    fn eq31_and_eq32_satisfy_their_defining_conditions() {
        // Check the closed forms against the definitions, not against themselves: at the
        // precharge state, ω_n = √(k_x/m_a) with k_x = n·p·A²/V0 and m_a = I·A² must equal
        // ω_1 at p_11, and ζ = (B_a+c_a)/(2√(k_x·m_a)) with B_a+c_a = R·A² must be 0.707 at
        // p_12; any area A gives the same result.
        let area = 1.3e-3;
        let d = design(&Rig::nominal(), 5e6).unwrap();
        let m_a = I * area * area;
        let k_x = |p_gauge: f64| N * (p_gauge + PATM) * area * area / V0;
        let w1 = 2.0 * PI * d.pulsation_frequency_hz;
        assert!(rel((k_x(d.p11_pa) / m_a).sqrt(), w1) < 1e-12);
        let zeta = R * area * area / (2.0 * (k_x(d.p12_pa) * m_a).sqrt());
        assert!(rel(zeta, 0.5f64.sqrt()) < 1e-12);
        assert_eq!(d.precharge_range_pa, [d.p12_pa, d.p11_pa]);
        // Numbers: p_11 = 105.56²·3.85e5·4e-4/1.3 − p_atm ≈ 1.219 MPa;
        // p_12 = 9e14·4e-4/(2·1.3·3.85e5) − p_atm ≈ 0.258 MPa.
        assert!((d.p11_pa - 1.219e6).abs() < 2e3, "{}", d.p11_pa);
        assert!((d.p12_pa - 0.2584e6).abs() < 1e3, "{}", d.p12_pa);
    }

    #[test]
    fn working_point_conditions_are_out_of_reach_on_the_nominal_rig() {
        // At 5 MPa the stiffest-possible-gas limit: C_max = V0/(n·p_w), ω_min = 1/√(I·C_max)
        // ≈ 33 Hz > 16.8 Hz, ζ_max ≈ 0.19 < 0.707: neither condition has a precharge below p_w.
        let d = design(&Rig::nominal(), 5e6).unwrap();
        let c_max = V0 / (N * (5e6 + PATM));
        let f_min = 1.0 / (I * c_max).sqrt() / (2.0 * PI);
        assert!(rel(d.at_working_pressure.lowest_natural_frequency_hz, f_min) < 1e-12);
        assert!(f_min > d.pulsation_frequency_hz);
        assert!(d.at_working_pressure.p11_pa.is_none());
        assert!(d.at_working_pressure.p12_pa.is_none());
        assert!(d.notes.iter().any(|n| n.contains("cannot be met")));
    }

    #[test]
    fn working_point_solution_meets_the_condition_when_it_exists() {
        // A softer absorber (10× the shell) makes the ω_n = ω_1 condition reachable at 5 MPa;
        // the reported precharge must then give ω_n = ω_1 in the plant's own model.
        let mut rig = Rig::nominal();
        rig.absorber.shell_volume_m3 = 4e-3;
        let d = design(&rig, 5e6).unwrap();
        let p0 = d
            .at_working_pressure
            .p11_pa
            .expect("reachable with a 4 L shell");
        rig.absorber.precharge_pa = p0;
        let wn = Absorber::new(&rig.absorber).natural_frequency_rad_s(5e6);
        assert!(rel(wn / (2.0 * PI), d.pulsation_frequency_hz) < 1e-9);
    }

    #[test]
    fn even_piston_counts_pulse_z_times_per_revolution() {
        assert_eq!(pulsation_order(9), 18);
        assert_eq!(pulsation_order(8), 8);
    }

    #[test]
    fn working_pressure_below_fill_is_rejected() {
        assert!(design(&Rig::nominal(), 0.4e6).is_err());
        assert!(design(&Rig::nominal(), f64::NAN).is_err());
    }
}
