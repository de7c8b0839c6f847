//! The limits a drive's parameters are trended against:
//!
//! - **Absorber precharge** (`accumulator_precharge.precharge_pa`, a lower limit): the
//!   lowest precharge the project's accumulator selection method (the paper's Section 4.3,
//!   eq. 26–32, [`crate::study::accumulator_design`], `eha accumulator-design`) still
//!   accepts at the working pressure — the low end p_12 of its range [p_12, p_11], where
//!   the absorber's damping ratio reaches eq. 32's 0.707. Below it the design no longer
//!   holds; gas lost through the bladder takes the precharge there.
//! - **Extra leakage** (`extra_leakage.coefficient_m3_s_pa`, an upper limit): by default
//!   the rig file's own leakage conductance out of the high-pressure port (pump internal
//!   and external, cylinder across the piston, eq. 9–11). At that extra leakage the flow
//!   the pump must replace while holding — and with it the holding speed and the pump's
//!   pulsation frequency — has doubled: the pump is worn to twice its as-built leakage,
//!   which this project takes as the point to overhaul it. `--leakage-limit` sets another.
//!
//! Other parameters have no limit: their trends are reported without a crossing date.

use super::trend::Limit;
use crate::output::CliError;
use crate::study::accumulator_design;
use plant_model::Rig;

/// The trended parameter of the absorber's precharge.
pub const PRECHARGE: &str = "accumulator_precharge.precharge_pa";

/// The trended parameter of the extra leakage.
pub const LEAKAGE: &str = "extra_leakage.coefficient_m3_s_pa";

/// The limits of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Lowest acceptable precharge, gauge. [Pa]
    pub precharge_pa: f64,
    /// Highest acceptable extra leakage. [m³/(s·Pa)]
    pub leakage_m3_s_pa: f64,
    /// The working pressure the precharge limit is designed at, gauge. [Pa]
    pub working_pressure_pa: f64,
}

/// The rig's own leakage conductance out of the high-pressure port: pump internal and
/// external, cylinder across the piston. [m³/(s·Pa)]
pub fn rig_leakage_m3_s_pa(rig: &Rig) -> f64 {
    rig.pump.internal_leakage_m3_s_pa
        + rig.pump.external_leakage_m3_s_pa
        + rig.cylinder.internal_leakage_m3_s_pa
}

/// The limits for `rig` at working pressure `working_pa` (gauge) [Pa], with the leakage
/// limit `leakage` [m³/(s·Pa)] when given.
pub fn limits(rig: &Rig, working_pa: f64, leakage: Option<f64>) -> Result<Limits, CliError> {
    let design = accumulator_design::design(rig, working_pa)
        .map_err(|e| CliError::BadInput(format!("--pressure: {e}")))?;
    Ok(Limits {
        precharge_pa: design.precharge_range_pa[0],
        leakage_m3_s_pa: leakage.unwrap_or_else(|| rig_leakage_m3_s_pa(rig)),
        working_pressure_pa: working_pa,
    })
}

impl Limits {
    /// The limit of a trended parameter (`effect.parameter`), if it has one.
    pub fn of(&self, parameter: &str) -> Option<Limit> {
        match parameter {
            PRECHARGE => Some(Limit::Lower(self.precharge_pa)),
            LEAKAGE => Some(Limit::Upper(self.leakage_m3_s_pa)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_limits_follow_eq_32_and_the_rig_leakage() {
        // Eq. 32 at the precharge state, by hand from the rig's absorber (I = 3.85e5
        // kg/m⁴, R = 3e7 Pa·s/m³, V_0 = 0.4 L, n = 1.3): p_12 = R²·V_0/(2·n·I) − p_atm
        // = 9e14·4e-4/(2·1.3·3.85e5) − 101 325 ≈ 0.2583 MPa, below p_11 ≈ 1.22 MPa.
        let l = limits(&Rig::nominal(), 5e6, None).unwrap();
        let p12 = 9e14 * 4e-4 / (2.0 * 1.3 * 3.85e5) - 101_325.0;
        assert!((l.precharge_pa - p12).abs() < 1.0, "{}", l.precharge_pa);
        // Nominal leakages: pump 1e-13 + 1e-13, cylinder 1e-13 m³/(s·Pa).
        assert!((l.leakage_m3_s_pa - 3e-13).abs() < 1e-27);
        assert_eq!(l.of(PRECHARGE), Some(Limit::Lower(l.precharge_pa)));
        assert_eq!(l.of(LEAKAGE), Some(Limit::Upper(l.leakage_m3_s_pa)));
        assert_eq!(l.of("entrained_air.effective_bulk_modulus_pa"), None);
        let set = limits(&Rig::nominal(), 5e6, Some(5e-13)).unwrap();
        assert_eq!(set.leakage_m3_s_pa, 5e-13);
        assert!(limits(&Rig::nominal(), 1e3, None).is_err());
    }
}
