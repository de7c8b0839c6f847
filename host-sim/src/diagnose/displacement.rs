//! The pump's displacement in absolute terms, and the volume balance's readings at it.
//!
//! With the cylinder blocked the hydraulic relation (eq. 6–11) is driven by the pump's
//! swept volume D·θ/2π and is unchanged when D, every volume and the leakage are scaled
//! together: it fixes the leakage only relative to D, and its D sits anywhere within its
//! ±5 % band — where it sits moves the whole leakage by as much, a tenth of the rig's
//! leakage once the wear has doubled it. Two other relations fix D between them:
//! the torque balance (eq. 3–5) the ratio D/ψ_f, through the pump's torque D·Δp/2π
//! against the motor's 1.5·p_n·ψ_f·i_q, and the stator voltages (eq. 1–2) ψ_f itself,
//! through the back-EMF ω_e·ψ_f. Their product is the displacement; the leakage the
//! hydraulic relation found relative to its own D, read at it, is the leakage in absolute
//! terms, and so is the volume behind the entrained air's effective bulk modulus.
//! Without voltage columns ψ_f, and so D, stays within its band: both are reported as the
//! hydraulic relation found them.

use super::calibration::{Calibration, Release};
use super::candidates::Tested;
use super::electrical::ix as elec;
use super::hydraulic::nominal_leakage;
use super::hydraulic_relation::hyd;
use super::mechanical_relation::mech;
use plant_model::Rig;

/// Largest relative standard error of the displacement the shaft's relations give at
/// which it replaces the hydraulic relation's: a fifth of the ±5 % band that one lies in.
/// The fits' covariances leave the models' own error out; only a D they put well inside
/// the band is trusted. [1]
pub const SHARP_ENOUGH: f64 = 0.01;

/// Half-width of the pump displacement's tolerance band about the rig file's value, the
/// hydraulic relation's ([`super::calibration`]'s table). A displacement the shaft's
/// relations put beyond it says that they leave something on the shaft unexplained (a
/// torque the calibration does not model biases D/ψ_f), not that the pump is another. [1]
pub const DISPLACEMENT_BAND: f64 = 0.05;

/// The pump's displacement fixed by the torque balance and the stator voltages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Displacement {
    /// Displacement. [m³/rev]
    pub value: f64,
    /// Its relative standard error. [1]
    pub relative_se: f64,
}

/// Variance of ln(values[a]/values[b]) of a fit whose search coordinates of `a` and `b`
/// are logarithmic (`None` without a covariance).
fn log_ratio_variance(c: &Calibration, a: usize, b: usize) -> Option<f64> {
    let m = c.fitted.covariance_u.as_ref()?;
    let v = m[(a, a)] + m[(b, b)] - 2.0 * m[(a, b)];
    (v.is_finite() && v >= 0.0).then_some(v)
}

/// The displacement the mechanical calibration's D/ψ_f and the electrical calibration's
/// ψ_f give (`None` without voltages, when it is not sharper than [`SHARP_ENOUGH`] or when
/// it lies beyond `rig`'s band, [`DISPLACEMENT_BAND`]).
pub fn from_shaft(
    mechanical: &Calibration,
    electrical: Option<&Calibration>,
    rig: &Rig,
) -> Option<Displacement> {
    let e = electrical?;
    let (m, ev) = (&mechanical.fitted.values, &e.fitted.values);
    let ratio_var = log_ratio_variance(mechanical, mech::DISPLACEMENT, mech::PSI)?;
    let psi_se = e.fitted.standard_error(elec::PSI, 1.0);
    let relative_se = (ratio_var + psi_se * psi_se).sqrt();
    let value = m[mech::DISPLACEMENT] / m[mech::PSI] * ev[elec::PSI];
    let listed = rig.pump.displacement_m3_per_rev;
    let in_band = (value / listed - 1.0).abs() <= DISPLACEMENT_BAND;
    (value.is_finite() && in_band && relative_se <= SHARP_ENOUGH)
        .then_some(Displacement { value, relative_se })
}

/// Each volume-balance reading of `tested` taken at the displacement `d`: the extra
/// leakage's coefficient (beyond `rig`'s leakage) and the entrained air's effective bulk
/// modulus (at the rig file's volume, the one that V/β needs), with their standard errors,
/// the evidence saying so. The fits and the extensions stay as found (the predictions do
/// not depend on the scale).
pub fn read_volumes_at(tested: &mut [Tested], d: Displacement, rig: &Rig) {
    for t in tested.iter_mut() {
        if !matches!(t.release, Release::Leakage | Release::BulkModulus) {
            continue;
        }
        let Some(fit) = &t.fit else { continue };
        let v = &fit.fitted.values;
        let Some(&fit_d) = v.get(hyd::DISPLACEMENT) else {
            continue;
        };
        let k = d.value / fit_d;
        let (Some(p), Some(s)) = (t.parameters.first_mut(), t.standard_errors.first_mut()) else {
            continue;
        };
        let read = match t.release {
            Release::Leakage => {
                let total = v[hyd::LEAKAGE] * k;
                p.1 = total - nominal_leakage(rig);
                s.1 = (s.1 * k).hypot(total * d.relative_se);
                format!("a leakage of {total:.4e} m³/(s·Pa)")
            }
            Release::BulkModulus => {
                // The fit's volume is relative to its displacement as well.
                p.1 /= k;
                s.1 = (s.1 / k).hypot(p.1 * d.relative_se);
                format!("an effective bulk modulus of {:.4e} Pa", p.1)
            }
            _ => continue,
        };
        t.evidence.push_str(&format!(
            "; at the displacement the torque balance and the stator voltages fix \
             ({:.4e} m³/rev ± {:.1} %, the hydraulic fit's {:.4e}), {read}",
            d.value,
            100.0 * d.relative_se,
            fit_d,
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::least_squares::Fitted;
    use nalgebra::DMatrix;

    /// A calibration at `values` whose log-coordinate covariance is diagonal `variance`.
    fn calibration(values: Vec<f64>, variance: f64) -> Calibration {
        let n = values.len();
        Calibration {
            fitted: Fitted {
                u: vec![0.0; n],
                values,
                data_sse: 0.0,
                prior_sse: 0.0,
                residual_count: 1000,
                covariance_u: Some(DMatrix::from_diagonal_element(n, n, variance)),
                evaluations: 0,
            },
            scale: 1.0,
        }
    }

    /// The shaft's relations at displacement `d` and flux `psi` (the electrical relation's
    /// flux `psi_e`), each log coordinate known to `se`.
    fn shaft(d: f64, psi: f64, psi_e: f64, se: f64) -> (Calibration, Calibration) {
        let mut m = vec![0.0; 6];
        m[mech::DISPLACEMENT] = d;
        m[mech::PSI] = psi;
        let mut e = vec![0.0; 5];
        e[elec::PSI] = psi_e;
        (calibration(m, se * se), calibration(e, se * se))
    }

    #[test]
    fn the_displacement_is_the_torque_ratio_times_the_back_emf_flux() {
        let rig = Rig::nominal();
        let listed = rig.pump.displacement_m3_per_rev;
        // The torque balance fixes only D/ψ_f: read at a flux 4 % high, its D is 4 % high
        // as well. The back-EMF puts the flux 1 % under the listed one: so is D.
        let psi = rig.motor.psi_f_wb;
        let (m, e) = shaft(1.04 * listed, 1.04 * psi, 0.99 * psi, 0.002);
        let d = from_shaft(&m, Some(&e), &rig).expect("sharp and in band");
        assert!((d.value / (0.99 * listed) - 1.0).abs() < 1e-12, "{d:?}");
        // Three log coordinates at 0.2 % each, the ratio's two uncorrelated: √3 · 0.2 %.
        assert!((d.relative_se - 3f64.sqrt() * 0.002).abs() < 1e-12, "{d:?}");
        // No voltages, no absolute flux.
        assert_eq!(from_shaft(&m, None, &rig), None);
        // Known to 1.7 % only: not used.
        let (m, e) = shaft(listed, psi, psi, 0.01);
        assert_eq!(from_shaft(&m, Some(&e), &rig), None);
        // Sharp, but 11 % under the listed displacement: the shaft is not explained.
        let (m, e) = shaft(0.89 * listed, psi, psi, 0.002);
        assert_eq!(from_shaft(&m, Some(&e), &rig), None);
    }
}
