//! A precharge the log bounds from one side only. Below its precharge an absorber's bladder
//! rests on its poppet and takes no oil (the gas law of Section 4.3 closed at zero oil
//! volume), so a log whose pressure never reaches the precharge shows only that it lies
//! above the highest pressure: every higher value predicts the same pressures, and the
//! optimiser stops anywhere along that flat stretch, often at its search bound.
//!
//! The released precharge is then read at the least departure from the rig file's value
//! the log cannot tell from the fit: the lowest precharge whose objective is within one
//! noise unit of the fitted one, found by bisection between the rig file's value and the
//! fit. That is the bound the log sets, and it is what the report predicts with.

use crate::diagnose::calibration::{weighed_sse, Relation};
use crate::diagnose::hydraulic_relation::hyd;
use std::ops::Range;

/// How much worse than the fit, in noise units, the least precharge may fit. [1]
const FLAT: f64 = 1.0;

/// Bisection steps between the rig file's precharge and the fitted one: 2⁻²⁴ of their
/// difference. [1]
const STEPS: usize = 24;

/// The least precharge the log cannot tell from `values`' (the relation's fitted values,
/// their objective weighed by `scale` over `rows`), where the fitted precharge lies above
/// every pressure `p_pa` reaches on `rows` and above the rig file's `nominal_pa`; `None`
/// where the log sees the precharge (the fit's pressure reaches it, or the rig file's
/// value fits as well). [Pa]
pub fn least_unseen_precharge<R: Relation>(
    relation: &R,
    rows: &[Range<usize>],
    values: &[f64],
    scale: f64,
    p_pa: &[f64],
    nominal_pa: f64,
) -> Option<f64> {
    let fitted = *values.get(hyd::PRECHARGE)?;
    let highest = rows
        .iter()
        .flat_map(|r| p_pa.get(r.clone()).unwrap_or(&[]))
        .fold(f64::NEG_INFINITY, |m, &p| m.max(p));
    if !(fitted > highest && fitted > nominal_pa) {
        return None;
    }
    let mut trial = values.to_vec();
    let mut objective = |p: f64| {
        trial[hyd::PRECHARGE] = p;
        weighed_sse(relation, &trial, rows, scale)
    };
    let limit = objective(fitted) + FLAT;
    let (mut seen, mut unseen) = (nominal_pa, fitted);
    if objective(seen) <= limit {
        return None;
    }
    for _ in 0..STEPS {
        let mid = 0.5 * (seen + unseen);
        if objective(mid) <= limit {
            unseen = mid;
        } else {
            seen = mid;
        }
    }
    Some(unseen)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_log::BenchLog;
    use crate::diagnose::calibration::Release;
    use crate::diagnose::facts::LogFacts;
    use crate::diagnose::least_squares::ParamSpec;
    use plant_model::Rig;

    /// A relation whose objective is an absorber's: zero oil below the precharge, so the
    /// residual of each row grows with how far its pressure lies above the trial
    /// precharge, and nothing changes once the precharge passes the highest pressure.
    struct Absorber {
        p_pa: Vec<f64>,
        facts: LogFacts,
    }

    impl Relation for Absorber {
        fn specs(&self, _release: Release) -> Vec<ParamSpec> {
            Vec::new()
        }
        fn residuals(&self, values: &[f64], rows: &[Range<usize>]) -> Vec<f64> {
            let p0 = values[hyd::PRECHARGE];
            rows.iter()
                .flat_map(|r| self.p_pa[r.clone()].iter())
                .map(|&p| (p - p0).max(0.0) / 1e4)
                .collect()
        }
        fn released(&self, _release: Release) -> Option<(usize, Vec<f64>)> {
            None
        }
        fn facts(&self) -> &LogFacts {
            &self.facts
        }
    }

    fn absorber(p_pa: Vec<f64>) -> Absorber {
        let n = p_pa.len();
        let log = BenchLog {
            p_ref_pa: p_pa.clone(),
            p_pa: p_pa.clone(),
            speed_rad_s: vec![0.0; n],
            iq_a: vec![0.0; n],
            id_a: vec![0.0; n],
            t_s: (0..n).map(|k| k as f64 * 1e-3).collect(),
            ..BenchLog::default()
        };
        let facts = LogFacts::of(&log, &Rig::nominal());
        Absorber { p_pa, facts }
    }

    fn values_with(precharge: f64) -> Vec<f64> {
        let mut v = vec![0.0; hyd::PRECHARGE + 1];
        v[hyd::PRECHARGE] = precharge;
        v
    }

    #[test]
    fn a_precharge_above_every_pressure_is_read_at_the_highest_one() {
        // Pressures up to 4.2 MPa; the fit stopped at 9 MPa, the rig file says 3 MPa. One
        // noise unit is 10 kPa of one row above the precharge: the bound lies within
        // 10 kPa below 4.2 MPa.
        let p: Vec<f64> = (0..=42).map(|k| 1e5 * k as f64).collect();
        let a = absorber(p.clone());
        let rows = [0..21, 21..p.len()];
        let least = least_unseen_precharge(&a, &rows, &values_with(9e6), 1.0, &p, 3e6)
            .expect("the precharge is unseen");
        assert!(least > 4.19e6 && least <= 4.2e6, "{least}");
    }

    #[test]
    fn a_precharge_the_pressure_reaches_is_left_where_it_was_fitted() {
        let p: Vec<f64> = (0..=42).map(|k| 1e5 * k as f64).collect();
        let a = absorber(p.clone());
        let rows = [0..21, 21..p.len()];
        assert_eq!(
            least_unseen_precharge(&a, &rows, &values_with(3.5e6), 1.0, &p, 3e6),
            None
        );
        // Below the rig file's value: not the one-sided case.
        let low: Vec<f64> = p.iter().map(|x| x * 0.5).collect();
        assert_eq!(
            least_unseen_precharge(&a, &rows, &values_with(2.5e6), 1.0, &low, 3e6),
            None
        );
    }
}
