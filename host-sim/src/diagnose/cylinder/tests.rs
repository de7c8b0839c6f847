//! The cylinder relation's tests: hand-built logs of the piston's force balance (eq. 12)
//! with Karnopp's friction and a transducer zero, against the levels they were built with.

use super::*;
use crate::diagnose::calibration::{
    calibrate, fit_relation, test_release, test_release_at_nominal, Pinned, ReleaseTest,
};
use crate::diagnose::decision::threshold;
use crate::diagnose::test_noise::gaussian;

/// Rig file's cylinder (nominal: A = 71 cm², m = 2000 kg, B = 150 N·s/m, no spring,
/// level) with these friction levels in the plant that made the log. [N]
const COULOMB_N: f64 = 400.0;
const BREAKAWAY_N: f64 = 650.0;
const P_LOW_PA: f64 = 0.5e6;
/// White noise on the logged port pressure, a transducer's. [Pa]
const NOISE_PA: f64 = 300.0;
/// How close the fitted breakaway must come (see the test). [N]
const BREAKAWAY_TOLERANCE_N: f64 = 0.5 + 3.0 * 1.5;

/// Time constant of the piston's speed after the breakaway. [s]
const TAU_S: f64 = 0.1;

/// A hand-built log of Karnopp's model at 1 kHz: the piston rests at 2 mm while the
/// force on it ramps at 1 N per row from −0.4 N, so it reaches F_s at 650.4 ms
/// (between rows 650 and 651); from then on the friction drops to F_c and the piston
/// speeds up as v = v_f·(1 − e^(−s/τ)), s = t − t_b, its acceleration at the breakaway
/// (F_s − F_c)/m, the force following the balance m·a + B·v + F_c exactly. The pressure
/// is logged with [`NOISE_PA`] of white noise.
fn breakaway_log() -> BenchLog {
    let rig = Rig::nominal();
    let c = &rig.cylinder;
    let (area, m, b) = (c.area_m2, c.mass_kg, c.viscous_n_s_per_m);
    let t_b = (BREAKAWAY_N + 0.4) / 1000.0;
    let v_f = (BREAKAWAY_N - COULOMB_N) / m * TAU_S;
    let n = 1000;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let (x, force): (Vec<f64>, Vec<f64>) = t
        .iter()
        .map(|&t| {
            if t < t_b {
                (2e-3, -0.4 + 1000.0 * t)
            } else {
                let e = (-(t - t_b) / TAU_S).exp();
                let (v, a) = (v_f * (1.0 - e), v_f / TAU_S * e);
                let x = 2e-3 + v_f * (t - t_b - TAU_S * (1.0 - e));
                (x, m * a + b * v + COULOMB_N)
            }
        })
        .unzip();
    let p = force
        .iter()
        .zip(gaussian(n, 17))
        .map(|(f, e)| P_LOW_PA + f / area + NOISE_PA * e)
        .collect();
    piston_log(t, x, p)
}

/// A log of the piston alone: times `t`, position `x` and port pressure `p`, the low side
/// at [`P_LOW_PA`] logged and set as the reference, the shaft at rest.
fn piston_log(t: Vec<f64>, x: Vec<f64>, p: Vec<f64>) -> BenchLog {
    let n = t.len();
    BenchLog {
        t_s: t,
        p_ref_pa: vec![P_LOW_PA; n],
        p_pa: p,
        speed_rad_s: vec![0.0; n],
        iq_a: vec![0.0; n],
        id_a: vec![0.0; n],
        x_m: Some(x),
        p_low_pa: Some(vec![P_LOW_PA; n]),
        ..BenchLog::default()
    }
}

#[test]
fn a_resting_piston_holds_up_to_the_breakaway_level_and_the_fit_finds_it() {
    let rig = Rig::nominal();
    let log = breakaway_log();
    let facts = LogFacts::of(&log, &rig);
    let rel = CylinderRelation::of(&log, &facts, &rig).expect("the piston moves");
    assert_eq!(rel.stick().breakaways.len(), 1);
    assert_eq!(rel.stick().breakaways[0].row, 650);
    let area = rig.cylinder.area_m2;

    // At rest the friction takes up the drive up to F_s: with F_s = 300 N a row whose
    // drive is 499.6 N is predicted at the breakaway level's pressure, 300 N/A over
    // p_low; one with 199.6 N at its measured pressure.
    let mut v = vec![2000.0, 150.0, 100.0, 300.0, 0.0];
    let mut out = vec![0.0; log.len()];
    rel.predict(&v, 200..601, &mut out);
    assert!(
        (out[500] - (P_LOW_PA + 300.0 / area)).abs() < 1e-6,
        "{}",
        out[500]
    );
    assert!((out[200] - log.p_pa[200]).abs() < 1e-6, "{}", out[200]);

    // The calibrated baseline, then both friction levels released: the breakaway comes
    // out within the half row (0.5 N) its crossing is known to and three standard
    // deviations of the two rows' mean pressure noise (A·σ/√2 = 1.5 N), the Coulomb
    // force within the percent the central differences' smearing of the kink allows.
    // The whole log after the start skip, in the calibration's one-second windows. The
    // piston strokes one way only, so both are read at the rig file's zero, the log's.
    let rows = facts.windows(facts.identification().start..log.len(), 1.0);
    let (t, at_zero) = test_release_at_nominal(
        &rel,
        &rows,
        Release::CylinderFriction,
        &calibrate(&rel, &rows),
        ix::ZERO,
        rel.strokes_both_ways(),
    );
    assert!(at_zero);
    let f = &t.fitted.values;
    let breakaway = breakaway_level(f);
    assert!(
        (breakaway - BREAKAWAY_N).abs() < BREAKAWAY_TOLERANCE_N,
        "{f:?}"
    );
    assert!(
        (f[ix::COULOMB] - COULOMB_N).abs() < 0.01 * COULOMB_N,
        "{f:?}"
    );

    // Started far above, the fit comes back down: the breakaway bounds F_s from above
    // where the resting rows leave it flat (the zero held at the rig file's).
    v[ix::COULOMB] = COULOMB_N;
    v[ix::BREAKAWAY] = 3000.0;
    let at_rig_zero = Pinned {
        relation: &rel,
        index: ix::ZERO,
        value: 0.0,
    };
    let high = fit_relation(
        &at_rig_zero,
        &rows,
        Release::CylinderFriction,
        1.0,
        Some(&v),
    );
    let breakaway = breakaway_level(&high.values);
    assert!(
        (breakaway - BREAKAWAY_N).abs() < BREAKAWAY_TOLERANCE_N,
        "{:?}",
        high.values
    );
}

#[test]
fn a_log_that_never_shows_the_piston_resting_keeps_the_breakaway_in_its_band() {
    // The same log from 10 ms after the breakaway: the piston slides throughout, the
    // breakaway level is not in it, and cylinder friction releases the Coulomb force
    // alone.
    let rig = Rig::nominal();
    let log = breakaway_log().tail(661);
    let facts = LogFacts::of(&log, &rig);
    let rel = CylinderRelation::of(&log, &facts, &rig).expect("the piston moves");
    assert!(!rel.sees_rest());
    let specs = rel.specs(Release::CylinderFriction);
    assert!(specs[ix::BREAKAWAY].band.is_some() && specs[ix::COULOMB].band.is_none());
}

/// A transducer reading this much high: two thirds of the zero's band, 142 N on the
/// 71 cm² piston. [Pa]
const ZERO_PA: f64 = 20e3;

/// A hand-built sliding log of the force balance at 1 kHz for 4 s: the piston follows
/// `x(t)` (a position, its speed and acceleration) under Coulomb friction `coulomb` (with
/// the sign's fade at [`COULOMB_FADE_M_S`]), the rig file's mass and damping, the low
/// side at [`P_LOW_PA`] logged; the port pressure logged [`ZERO_PA`] high with
/// [`NOISE_PA`] of white noise.
fn sliding_log(motion: impl Fn(f64) -> (f64, f64, f64), coulomb: f64) -> BenchLog {
    let rig = Rig::nominal();
    let c = &rig.cylinder;
    let n = 4000;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let (x, p): (Vec<f64>, Vec<f64>) = t
        .iter()
        .zip(gaussian(n, 23))
        .map(|(&t, e)| {
            let (x, v, a) = motion(t);
            let f =
                c.mass_kg * a + c.viscous_n_s_per_m * v + coulomb * (v / COULOMB_FADE_M_S).tanh();
            (x, P_LOW_PA + f / c.area_m2 + ZERO_PA + NOISE_PA * e)
        })
        .unzip();
    piston_log(t, x, p)
}

/// 10 mm of stroke each way at 0.25 Hz: the Coulomb force's step changes sign twice.
fn both_ways(t: f64) -> (f64, f64, f64) {
    let (x0, w) = (10e-3, 0.5 * std::f64::consts::PI);
    let (s, c) = (w * t).sin_cos();
    (x0 * s, x0 * w * c, -x0 * w * w * s)
}

/// 2 mm/s one way, steady.
fn one_way(t: f64) -> (f64, f64, f64) {
    (2e-3 * t, 2e-3, 0.0)
}

/// The sliding log of `motion` with Coulomb force `coulomb`, its relation and
/// identification rows handed to `check`.
fn on_sliding_log<T>(
    motion: fn(f64) -> (f64, f64, f64),
    coulomb: f64,
    check: impl FnOnce(&Rig, &CylinderRelation, &[Range<usize>]) -> T,
) -> T {
    let rig = Rig::nominal();
    let log = sliding_log(motion, coulomb);
    let facts = LogFacts::of(&log, &rig);
    let rel = CylinderRelation::of(&log, &facts, &rig).expect("the piston moves");
    let rows = facts.windows(facts.identification(), 1.0);
    check(&rig, &rel, &rows)
}

/// Cylinder friction released on `rel` over `rows`, read at the rig file's zero unless
/// the stroke tells the zero apart.
fn friction_at_rig_zero(rel: &CylinderRelation, rows: &[Range<usize>]) -> (ReleaseTest, bool) {
    test_release_at_nominal(
        rel,
        rows,
        Release::CylinderFriction,
        &calibrate(rel, rows),
        ix::ZERO,
        rel.strokes_both_ways(),
    )
}

#[test]
fn a_stroke_both_ways_tells_the_transducer_zero_from_the_coulomb_force() {
    // The Coulomb step flips with the motion and the zero does not: the released fit
    // finds both, the friction within the percent the central differences' smearing of
    // the reversals allows, the zero within 1 kPa (7 N on the piston), and the rig
    // file's zero (0) is rejected.
    on_sliding_log(both_ways, COULOMB_N, |_, rel, rows| {
        assert!(rel.strokes_both_ways());
        let (t, at_zero) = friction_at_rig_zero(rel, rows);
        let f = &t.fitted.values;
        assert!(!at_zero, "{f:?}");
        assert!((f[ix::ZERO] - ZERO_PA).abs() < 1e3, "{f:?}");
        assert!(
            (f[ix::COULOMB] - COULOMB_N).abs() < 0.01 * COULOMB_N,
            "{f:?}"
        );
    });
}

#[test]
fn along_a_one_way_stroke_a_zero_within_its_band_is_no_friction() {
    // The rig file's Coulomb force (15 N) and a zero 20 kPa high: 142 N of constant
    // pressure step, within what the zero's ±30 kPa (213 N) explains. Released, the
    // friction gains nothing significant; with the zero held at the rig file's value
    // the same step would be convicted.
    let nominal = Rig::nominal().cylinder.coulomb_friction_n;
    on_sliding_log(one_way, nominal, |rig, rel, rows| {
        assert!(!rel.strokes_both_ways());
        let (t, at_zero) = friction_at_rig_zero(rel, rows);
        assert!(at_zero);
        assert!(t.lambda < threshold(1), "Λ = {}", t.lambda);
        // Read at the rig file's zero, the friction is the whole step: 15 N + A·20 kPa.
        let apparent = nominal + ZERO_PA * rig.cylinder.area_m2;
        let f = &t.fitted.values;
        assert!((f[ix::ZERO] - 0.0).abs() < 1e-6, "{f:?}");
        assert!((f[ix::COULOMB] - apparent).abs() < 0.01 * apparent, "{f:?}");
        let held = Pinned {
            relation: rel,
            index: ix::ZERO,
            value: 0.0,
        };
        let convicted = test_release(
            &held,
            rows,
            Release::CylinderFriction,
            &calibrate(&held, rows),
        );
        assert!(convicted.lambda > threshold(1), "Λ = {}", convicted.lambda);
    });
}

#[test]
fn along_a_one_way_stroke_friction_beyond_the_band_is_read_at_the_rig_zero() {
    // 400 N of Coulomb force with the zero 20 kPa high: named, and read as the step
    // at the rig file's zero, 400 N + A·20 kPa = 542 N (the log cannot split it).
    on_sliding_log(one_way, COULOMB_N, |rig, rel, rows| {
        let (t, at_zero) = friction_at_rig_zero(rel, rows);
        assert!(at_zero && t.lambda > threshold(1), "Λ = {}", t.lambda);
        let apparent = COULOMB_N + ZERO_PA * rig.cylinder.area_m2;
        let f = &t.fitted.values;
        assert!((f[ix::COULOMB] - apparent).abs() < 0.01 * apparent, "{f:?}");
    });
}
