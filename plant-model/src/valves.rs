//! Check valves (fill accumulator to each port, Figure 1 item 6) and relief valves (each
//! port to the fill side, items 8–9): linear in the pressure beyond cracking, the usual
//! lumped valve model when only the opening and the limited pressure matter.

/// A spring-loaded valve that opens beyond its cracking pressure.
#[derive(Clone, Copy, Debug)]
pub struct Valve {
    /// Cracking pressure difference. [Pa]
    pub cracking_pa: f64,
    /// Conductance above cracking. [(m³/s)/Pa]
    pub conductance_m3_s_pa: f64,
}

impl Valve {
    /// Flow from the upstream to the downstream side for the pressure difference
    /// `dp = p_up − p_down` (never negative: the valve checks reverse flow). [m³/s]
    #[inline]
    pub fn flow(&self, dp: f64) -> f64 {
        let open = dp - self.cracking_pa;
        if open > 0.0 {
            self.conductance_m3_s_pa * open
        } else {
            0.0
        }
    }
}
