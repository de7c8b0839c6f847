//! Gas-loaded accumulators: the bladder pulsation absorber on port A (eq. 22–26) and the
//! low-side fill accumulator.
//!
//! The gas follows the polytropic law p·V_g^n = p_0·V_0^n. Below its precharge the bladder
//! fills the shell and the poppet closes the port: no oil, no capacitance. Above it the gas
//! volume is V_0·(p_0/p)^(1/n), so the hydraulic capacitance is
//! `C_acc = −dV_g/dp = V_0·(p_0/p)^(1/n)/(n·p)` (the linearised gas stiffness k·p/V of eq.
//! 26). The absorber's oil does not follow the port pressure at once: the oil in its inlet
//! has inertance I = ρ·l/A and the inlet and bladder a loss resistance R (eq. 24–25's m_a and
//! B_b + c_a divided by A²), so `I·dq/dt = p_A − p_gas − R·q`. With the gas capacitance this
//! is the mass–spring–damper of eq. 26: natural frequency 1/√(I·C_acc), damping ratio
//! (R/2)·√(C_acc/I).

use crate::rig::AbsorberParams;

/// Polytropic gas charge of an accumulator.
#[derive(Clone, Copy, Debug)]
pub struct GasCharge {
    /// Shell (gas-at-precharge) volume V_0. [m³]
    pub shell_volume_m3: f64,
    /// Precharge p_0 (gauge). [Pa]
    pub precharge_pa: f64,
    /// Polytropic exponent n. [1]
    pub exponent: f64,
}

/// Atmospheric pressure: the gas law holds in absolute pressure. [Pa]
pub const ATMOSPHERE_PA: f64 = 101_325.0;

impl GasCharge {
    /// Gas pressure (gauge) with `oil_m3` of oil in the shell (0 ≤ oil < V_0). [Pa]
    #[inline]
    pub fn pressure_pa(&self, oil_m3: f64) -> f64 {
        let gas = self.shell_volume_m3 - oil_m3;
        let ratio = self.shell_volume_m3 / gas.max(1e-3 * self.shell_volume_m3);
        (self.precharge_pa + ATMOSPHERE_PA) * libm::pow(ratio, self.exponent) - ATMOSPHERE_PA
    }

    /// Rate of change of the absolute gas pressure `p_abs` while oil flows in at `q` with
    /// `oil_m3` inside: the polytropic law in rate form, dp/dt = n·p·q/V_g, which the plant
    /// integrates instead of evaluating p_0·(V_0/V_g)^n (a `pow`) at every stage. [Pa/s]
    #[inline]
    pub fn pressure_rate(&self, p_abs: f64, oil_m3: f64, q: f64) -> f64 {
        let gas = (self.shell_volume_m3 - oil_m3).max(1e-3 * self.shell_volume_m3);
        self.exponent * p_abs * q / gas
    }

    /// Absolute gas pressure at precharge. [Pa]
    pub fn precharge_abs_pa(&self) -> f64 {
        self.precharge_pa + ATMOSPHERE_PA
    }

    /// Oil volume in equilibrium with gauge pressure `p` (0 at or below precharge). [m³]
    pub fn oil_volume_m3(&self, p: f64) -> f64 {
        if p <= self.precharge_pa {
            0.0
        } else {
            let r = (self.precharge_pa + ATMOSPHERE_PA) / (p + ATMOSPHERE_PA);
            self.shell_volume_m3 * (1.0 - libm::pow(r, 1.0 / self.exponent))
        }
    }

    /// Quasi-static capacitance −dV_g/dp at gauge pressure `p` (0 below precharge). [m³/Pa]
    pub fn capacitance_m3_per_pa(&self, p: f64) -> f64 {
        if p <= self.precharge_pa {
            0.0
        } else {
            let pa = p + ATMOSPHERE_PA;
            let r = (self.precharge_pa + ATMOSPHERE_PA) / pa;
            self.shell_volume_m3 * libm::pow(r, 1.0 / self.exponent) / (self.exponent * pa)
        }
    }

    /// Energy stored in the gas by compression from precharge to `oil_m3` of oil. [J]
    pub fn energy_j(&self, oil_m3: f64) -> f64 {
        let n = self.exponent;
        let v0 = self.shell_volume_m3;
        let vg = (v0 - oil_m3).max(1e-3 * v0);
        let p0 = self.precharge_pa + ATMOSPHERE_PA;
        // ∫ p_abs dV from V_0 down to V_g, minus the atmosphere's share of the boundary work
        // (the gauge-pressure bookkeeping of the oil side).
        p0 * libm::pow(v0, n) / (n - 1.0) * (libm::pow(vg, 1.0 - n) - libm::pow(v0, 1.0 - n))
            - ATMOSPHERE_PA * (v0 - vg)
    }
}

/// The pulsation absorber on port A.
#[derive(Clone, Copy, Debug)]
pub struct Absorber {
    /// Fitted or not.
    pub enabled: bool,
    /// Gas charge.
    pub gas: GasCharge,
    /// Inlet inertance. [kg/m⁴]
    pub inertance_kg_m4: f64,
    /// Inlet resistance. [Pa·s/m³]
    pub resistance_pa_s_m3: f64,
}

impl Absorber {
    /// From validated parameters.
    pub fn new(p: &AbsorberParams) -> Absorber {
        Absorber {
            enabled: p.enabled,
            gas: GasCharge {
                shell_volume_m3: p.shell_volume_m3,
                precharge_pa: p.precharge_pa,
                exponent: p.polytropic_exponent,
            },
            inertance_kg_m4: p.inlet_inertance_kg_m4,
            resistance_pa_s_m3: p.inlet_resistance_pa_s_m3,
        }
    }

    /// dq/dt of the inlet flow `q` (into the absorber) with `oil_m3` inside at gas pressure
    /// `p_gas` (gauge), port at `p_a`; zero while the poppet is closed (empty absorber and
    /// port pressure below the gas). [m³/s²]
    #[inline]
    pub fn flow_derivative(&self, p_a: f64, p_gas: f64, oil_m3: f64, q: f64) -> f64 {
        let drive = p_a - p_gas - self.resistance_pa_s_m3 * q;
        if oil_m3 <= 0.0 && q <= 0.0 && drive < 0.0 {
            0.0
        } else {
            drive / self.inertance_kg_m4
        }
    }

    /// Undamped natural frequency of the absorber at port pressure `p`, 1/√(I·C). [rad/s]
    /// Zero below precharge (no oil, no spring).
    pub fn natural_frequency_rad_s(&self, p: f64) -> f64 {
        let c = self.gas.capacitance_m3_per_pa(p);
        if c > 0.0 {
            1.0 / libm::sqrt(self.inertance_kg_m4 * c)
        } else {
            0.0
        }
    }

    /// Damping ratio at port pressure `p`, (R/2)·√(C/I). [1]
    pub fn damping_ratio(&self, p: f64) -> f64 {
        let c = self.gas.capacitance_m3_per_pa(p);
        0.5 * self.resistance_pa_s_m3 * libm::sqrt(c / self.inertance_kg_m4)
    }
}
